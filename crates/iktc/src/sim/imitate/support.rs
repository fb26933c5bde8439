//! Foot soles and the support polygon of a double-support stance.

use nalgebra::{Isometry3, Point3, Vector3};

use crate::error::{Error, Result};

/// The sole of each foot: a rectangle under the ankle frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SupportSettings {
    /// Sole length along the foot's x axis \[m\] (JVRC-1: 0.2, nominal).
    pub sole_length: f64,
    /// Sole width along the foot's y axis \[m\] (JVRC-1: 0.1, nominal).
    pub sole_width: f64,
    /// Forward offset of the sole's centre from the ankle \[m\] (default 0).
    pub sole_offset_x: f64,
    /// Height of the ankle frame above the sole \[m\] (JVRC-1: 0.1, nominal); the run starts
    /// with the lowest sole on z = 0.
    pub ankle_height: f64,
}

impl Default for SupportSettings {
    fn default() -> Self {
        Self {
            sole_length: 0.2,
            sole_width: 0.1,
            sole_offset_x: 0.0,
            ankle_height: 0.1,
        }
    }
}

impl SupportSettings {
    /// Checks that the sizes are finite and positive (the offset finite).
    pub fn validate(&self) -> Result<()> {
        for (n, v) in [
            ("sole_length", self.sole_length),
            ("sole_width", self.sole_width),
            ("ankle_height", self.ankle_height),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::InvalidSetting {
                    name: format!("support.{n}"),
                    value: v.to_string(),
                    expected: "a finite length > 0 [m]".into(),
                });
            }
        }
        if !self.sole_offset_x.is_finite() {
            return Err(Error::InvalidSetting {
                name: "support.sole_offset_x".into(),
                value: self.sole_offset_x.to_string(),
                expected: "a finite offset [m]".into(),
            });
        }
        Ok(())
    }

    /// The four sole corners \[m\] of a foot whose ankle frame has pose `ankle`, world axes.
    pub fn sole_corners(&self, ankle: &Isometry3<f64>) -> [Vector3<f64>; 4] {
        let (l, w) = (0.5 * self.sole_length, 0.5 * self.sole_width);
        let x0 = self.sole_offset_x;
        let z = -self.ankle_height;
        [(x0 + l, w), (x0 - l, w), (x0 - l, -w), (x0 + l, -w)]
            .map(|(x, y)| (ankle * Point3::new(x, y, z)).coords)
    }
}

/// The support polygon of feet at poses `feet`: the convex hull (counter-clockwise, seen from
/// above, Andrew's monotone chain) of the sole corners projected on the ground (z = 0) \[m\].
pub fn support_polygon(feet: &[Isometry3<f64>], settings: &SupportSettings) -> Vec<Vector3<f64>> {
    let mut pts: Vec<(f64, f64)> = feet
        .iter()
        .flat_map(|f| settings.sole_corners(f))
        .map(|c| (c.x, c.y))
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    pts.dedup();
    if pts.len() < 3 {
        return pts.iter().map(|(x, y)| Vector3::new(*x, *y, 0.0)).collect();
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64)>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], *p) <= 0.0
            {
                hull.pop();
            }
            hull.push(*p);
        }
        hull.pop();
    }
    hull.iter()
        .map(|(x, y)| Vector3::new(*x, *y, 0.0))
        .collect()
}

/// Signed distance \[m\] from the ground projection of `p` to the boundary of the convex
/// counter-clockwise polygon `hull`: positive inside, negative outside (−∞ for fewer than 3
/// vertices).
pub fn polygon_margin(hull: &[Vector3<f64>], p: &Vector3<f64>) -> f64 {
    if hull.len() < 3 {
        return f64::NEG_INFINITY;
    }
    let mut margin = f64::INFINITY;
    for i in 0..hull.len() {
        let a = hull[i];
        let b = hull[(i + 1) % hull.len()];
        let e = (b - a).xy();
        let len = e.norm();
        if len == 0.0 {
            continue;
        }
        // Inward normal of a counter-clockwise edge: (−e_y, e_x).
        let d = ((p.xy() - a.xy()).perp(&e)) / len;
        margin = margin.min(-d);
    }
    margin
}
