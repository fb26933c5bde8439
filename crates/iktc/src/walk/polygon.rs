//! Support polygons: sole rectangles and their convex hull, in fixed-size storage.

use serde::Serialize;

use super::footstep::Pose2;

/// Most soles a support polygon can be the hull of (two feet and two hands, or four feet).
pub const MAX_SOLES: usize = 4;

/// Most vertices a support polygon can have (four corners per sole).
pub const MAX_POLYGON_VERTICES: usize = 4 * MAX_SOLES;

/// A convex polygon on the ground, counter-clockwise, without allocation: up to
/// [`MAX_POLYGON_VERTICES`] vertices `(x, y)` \[m\] in a fixed array.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SupportPolygon {
    points: [(f64, f64); MAX_POLYGON_VERTICES],
    len: usize,
}

impl Default for SupportPolygon {
    fn default() -> Self {
        Self {
            points: [(0.0, 0.0); MAX_POLYGON_VERTICES],
            len: 0,
        }
    }
}

/// The four corners of a sole of `length × width` \[m\] centred on `pose`, counter-clockwise
/// (world coordinates \[m\]).
pub fn sole_corners(pose: &Pose2, length: f64, width: f64) -> [(f64, f64); 4] {
    let (hl, hw) = (0.5 * length, 0.5 * width);
    [
        pose.transform_point(hl, hw),
        pose.transform_point(-hl, hw),
        pose.transform_point(-hl, -hw),
        pose.transform_point(hl, -hw),
    ]
}

/// One edge of a [`SupportPolygon`] and a point's signed distance to it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PolygonEdge {
    /// First vertex (counter-clockwise order) \[m\].
    pub start: (f64, f64),
    /// Second vertex \[m\].
    pub end: (f64, f64),
    /// Unit normal pointing out of the polygon \[–\].
    pub outward_normal: (f64, f64),
    /// Signed distance of the point to the edge's line \[m\]: positive inside.
    pub margin: f64,
}

fn cross(o: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
}

impl SupportPolygon {
    /// The vertices, counter-clockwise \[m\].
    pub fn vertices(&self) -> &[(f64, f64)] {
        &self.points[..self.len]
    }

    /// Sets the polygon to one sole rectangle.
    pub fn set_sole(&mut self, pose: &Pose2, length: f64, width: f64) {
        let c = sole_corners(pose, length, width);
        self.points[..4].copy_from_slice(&c);
        self.len = 4;
    }

    /// Sets the polygon to the convex hull of two sole rectangles
    /// ([`SupportPolygon::set_hull_of_sole_poses`]). Allocation-free.
    pub fn set_hull_of_soles(&mut self, a: &Pose2, b: &Pose2, length: f64, width: f64) {
        self.set_hull_of_sole_poses(&[*a, *b], length, width);
    }

    /// Sets the polygon to the convex hull of the sole rectangles at `soles` (Andrew's
    /// monotone chain: sort the corners by `x` then `y`, build the lower and upper chains,
    /// dropping points that do not turn left; collinear points are dropped). Soles beyond
    /// [`MAX_SOLES`] are ignored (callers check the count); none empties the polygon.
    /// Allocation-free.
    pub fn set_hull_of_sole_poses(&mut self, soles: &[Pose2], length: f64, width: f64) {
        let soles = &soles[..soles.len().min(MAX_SOLES)];
        let mut pts = [(0.0, 0.0); MAX_POLYGON_VERTICES];
        for (chunk, pose) in pts.chunks_exact_mut(4).zip(soles) {
            chunk.copy_from_slice(&sole_corners(pose, length, width));
        }
        let pts = &mut pts[..4 * soles.len()];
        pts.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.total_cmp(&q.1)));
        // Hull buffer: at most 2n points during construction.
        let mut hull = [(0.0, 0.0); 2 * MAX_POLYGON_VERTICES];
        let mut k = 0usize;
        for &p in pts.iter() {
            while k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0.0 {
                k -= 1;
            }
            hull[k] = p;
            k += 1;
        }
        let lower = k + 1;
        for &p in pts.iter().rev().skip(1) {
            while k >= lower && cross(hull[k - 2], hull[k - 1], p) <= 0.0 {
                k -= 1;
            }
            hull[k] = p;
            k += 1;
        }
        // The last point repeats the first.
        let n = k.saturating_sub(1).min(MAX_POLYGON_VERTICES);
        self.points[..n].copy_from_slice(&hull[..n]);
        self.len = n;
    }

    /// Signed distance \[m\] from `p` to the boundary: positive inside, negative outside
    /// (for an outside point, a lower bound on the distance's magnitude: the largest
    /// violation of one edge's half-plane). `−∞` for an empty polygon.
    pub fn margin(&self, p: (f64, f64)) -> f64 {
        self.closest_edge(p).map_or(f64::NEG_INFINITY, |e| e.margin)
    }

    /// The edge whose half-plane `p` is least inside (most outside): the edge that
    /// [`SupportPolygon::margin`] measures against. For the counter-clockwise edge `a → b` of
    /// length `L`, the signed distance is `((b − a) × (p − a)) / L` (positive on the inner,
    /// left side) and the outward normal is `(b_y − a_y, −(b_x − a_x)) / L`. `None` for a
    /// polygon without an edge of positive length (a single foot's rectangle always has one).
    pub fn closest_edge(&self, p: (f64, f64)) -> Option<PolygonEdge> {
        let v = self.vertices();
        let mut best: Option<PolygonEdge> = None;
        for i in 0..v.len() {
            let a = v[i];
            let b = v[(i + 1) % v.len()];
            let len = (b.0 - a.0).hypot(b.1 - a.1);
            if len > 0.0 {
                let margin = cross(a, b, p) / len;
                if best.is_none_or(|e| margin < e.margin) {
                    best = Some(PolygonEdge {
                        start: a,
                        end: b,
                        outward_normal: ((b.1 - a.1) / len, -(b.0 - a.0) / len),
                        margin,
                    });
                }
            }
        }
        best
    }

    /// Whether `p` is inside the polygon shrunk by `margin` \[m\] (`margin ≥ 0` shrinks).
    pub fn contains(&self, p: (f64, f64), margin: f64) -> bool {
        self.margin(p) >= margin
    }

    /// `p` pulled along the segment to `toward` until it is at least `margin` \[m\] inside:
    /// `p` itself if it already is, `toward` if `toward` is not, else the point of the segment
    /// nearest `p` that is (bisection of the fraction from `toward` to `p`, to 2⁻⁴⁰).
    pub fn pull_towards(&self, p: (f64, f64), toward: (f64, f64), margin: f64) -> (f64, f64) {
        if self.margin(p) >= margin {
            return p;
        }
        let c = toward;
        if self.margin(c) < margin {
            return c;
        }
        let (mut lo, mut hi) = (0.0, 1.0); // fraction of the way from c to p
        for _ in 0..PULL_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            let q = (c.0 + mid * (p.0 - c.0), c.1 + mid * (p.1 - c.1));
            if self.margin(q) >= margin {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (c.0 + lo * (p.0 - c.0), c.1 + lo * (p.1 - c.1))
    }
}

/// Bisection steps of [`SupportPolygon::pull_towards`].
const PULL_BISECTIONS: usize = 40;
