//! A foot's sole guessed from its geometry (`iktc profile init`).
//!
//! The points of the foot link and of the links fixed below it, in the foot's frame: the
//! corners of collision boxes, the lowest point of spheres and of capsules' end spheres,
//! points around both rims of cylinders, the vertices of meshes (read from the URDF's folder); from the collision
//! geometry, else from the visual geometry. The ankle height is the depth of the lowest point
//! below the foot's origin; the sole is the bounding rectangle (in x and y) of the points
//! within [`SOLE_BAND`] of the lowest one.

use nalgebra::{Isometry3, Point3, Vector3};

use super::shape::Tree;

/// A guessed sole: `(length, width, offset_x, ankle_height)` \[m\].
pub(super) type SoleGuess = (f64, f64, f64, f64);

/// Points of the geometry up to this height above its lowest one make the sole \[m\]: the flat
/// underside of a foot, not the toe's upward curve or the ankle's housing above it.
pub(crate) const SOLE_BAND: f64 = 0.01;

/// A sole narrower than this is questioned in the written profile \[m\] (a foot's geometry
/// that is a rod or a contact line rather than a sole).
pub(crate) const NARROW_SOLE: f64 = 0.06;

/// A sole longer than this is questioned in the written profile \[m\] (geometry that takes in
/// more than the foot).
pub(crate) const LONG_SOLE: f64 = 0.40;

/// Points taken around each rim of a cylinder \[–\].
const RIM_POINTS: usize = 32;

/// The sole over the points `v` (see the module documentation): `None` for a rectangle
/// without length or width, or a lowest point not below the origin.
pub(super) fn sole_from_points(v: &[Vector3<f64>]) -> Option<SoleGuess> {
    let zmin = v.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in v.iter().filter(|p| p.z <= zmin + SOLE_BAND) {
        xmin = xmin.min(p.x);
        xmax = xmax.max(p.x);
        ymin = ymin.min(p.y);
        ymax = ymax.max(p.y);
    }
    let (l, w) = (xmax - xmin, ymax - ymin);
    (l > 0.0 && w > 0.0 && zmin < 0.0).then(|| (l, w, 0.5 * (xmin + xmax), -zmin))
}

/// The points of one primitive shape `g` posed at `at` (box corners, a sphere's lowest point,
/// the lowest points of a capsule's end spheres, cylinder rims); meshes and other shapes give
/// none.
fn primitive_points(g: &urdf_rs::Geometry, at: &Isometry3<f64>) -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    match g {
        urdf_rs::Geometry::Sphere { radius } => {
            out.push(at.translation.vector - Vector3::z() * *radius);
        }
        urdf_rs::Geometry::Box { size } => {
            let h = Vector3::new(size[0], size[1], size[2]) * 0.5;
            for sx in [-1.0, 1.0] {
                for sy in [-1.0, 1.0] {
                    for sz in [-1.0, 1.0] {
                        let corner = h.component_mul(&Vector3::new(sx, sy, sz));
                        out.push((at * Point3::from(corner)).coords);
                    }
                }
            }
        }
        urdf_rs::Geometry::Capsule { radius, length } => {
            // The lowest points of its two end spheres.
            for z in [-0.5 * length, 0.5 * length] {
                out.push((at * Point3::new(0.0, 0.0, z)).coords - Vector3::z() * *radius);
            }
        }
        urdf_rs::Geometry::Cylinder { radius, length } => {
            for k in 0..RIM_POINTS {
                let a = std::f64::consts::TAU * k as f64 / RIM_POINTS as f64;
                for z in [-0.5 * length, 0.5 * length] {
                    let p = Point3::new(radius * a.cos(), radius * a.sin(), z);
                    out.push((at * p).coords);
                }
            }
        }
        _ => {}
    }
    out
}

/// The points of the collision (`collision`) or visual geometry of link `foot` of `t` and of
/// the links fixed below it, in `foot`'s frame; meshes read from `dir` (skipped without it or
/// when one cannot be read).
pub(super) fn link_points(
    u: &urdf_rs::Robot,
    t: &Tree,
    foot: usize,
    dir: Option<&std::path::Path>,
    collision: bool,
) -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    let inv = t.pose[foot].inverse();
    for k in t.fixed_below(foot) {
        let Some(link) = u.links.iter().find(|l| l.name == t.names[k]) else {
            continue;
        };
        let shapes: Vec<(&urdf_rs::Geometry, &urdf_rs::Pose)> = if collision {
            link.collision
                .iter()
                .map(|c| (&c.geometry, &c.origin))
                .collect()
        } else {
            link.visual
                .iter()
                .map(|v| (&v.geometry, &v.origin))
                .collect()
        };
        let to_foot = inv * t.pose[k];
        for (g, o) in shapes {
            out.extend(primitive_points(g, &(to_foot * crate::model::urdf_pose(o))));
            if let Some(Ok(Some(v))) = dir.map(|d| crate::mesh::urdf::mesh_vertices(g, o, d)) {
                out.extend(v.iter().map(|p| (to_foot * Point3::from(*p)).coords));
            }
        }
    }
    out
}

/// The sole of link `foot` (see the module documentation), with where it came from.
pub(super) fn sole_of(
    u: &urdf_rs::Robot,
    t: &Tree,
    foot: usize,
    dir: Option<&std::path::Path>,
) -> Option<(SoleGuess, &'static str)> {
    sole_from_points(&link_points(u, t, foot, dir, true))
        .map(|s| {
            (
                s,
                "from the collision geometry of the link and the links fixed to it",
            )
        })
        .or_else(|| {
            sole_from_points(&link_points(u, t, foot, dir, false)).map(|s| {
                (
                    s,
                    "from the visual geometry of the link and the links fixed to it",
                )
            })
        })
}

/// A comment questioning the sole `(length, width)` \[m\] (see [`NARROW_SOLE`],
/// [`LONG_SOLE`]), or `None` when it looks like a foot's.
pub(super) fn questioned(length: f64, width: f64) -> Option<String> {
    let mut why = Vec::new();
    if width < NARROW_SOLE {
        why.push(format!(
            "{:.1} cm wide (under {:.0} cm)",
            100.0 * width,
            100.0 * NARROW_SOLE
        ));
    }
    if length > LONG_SOLE {
        why.push(format!(
            "{:.1} cm long (over {:.0} cm)",
            100.0 * length,
            100.0 * LONG_SOLE
        ));
    }
    (!why.is_empty()).then(|| {
        format!(
            "# CHECK this sole: {}; the geometry may not be the foot's sole: measure the robot\n",
            why.join(", ")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box foot 0.2 × 0.08 m whose underside is 0.05 m below the frame, centred 0.03 m ahead
    /// of it, with a toe tip raised 0.02 m (above the sole band) reaching 0.05 m further and an
    /// ankle housing above: the sole is the underside's rectangle.
    #[test]
    fn the_sole_is_the_underside() {
        let mut v = Vec::new();
        for x in [-0.07, 0.13] {
            for y in [-0.04, 0.04] {
                v.push(Vector3::new(x, y, -0.05));
                v.push(Vector3::new(x, y, 0.0));
            }
        }
        v.push(Vector3::new(0.18, 0.0, -0.05 + 2.0 * SOLE_BAND));
        v.push(Vector3::new(0.0, 0.06, 0.1));
        let (l, w, off, ankle) = sole_from_points(&v).unwrap();
        for (got, want) in [(l, 0.2), (w, 0.08), (off, 0.03), (ankle, 0.05)] {
            assert!((got - want).abs() < 1e-12, "{got} {want}");
        }
        let above: Vec<_> = v.iter().map(|p| p + Vector3::z()).collect();
        assert!(sole_from_points(&above).is_none());
        let level: Vec<_> = v.iter().map(|p| p + 0.05 * Vector3::z()).collect();
        assert!(sole_from_points(&level).is_none());
        assert!(sole_from_points(&[]).is_none());
        let line = [
            Vector3::new(-0.07, 0.0, -0.05),
            Vector3::new(0.13, 0.0, -0.05),
        ];
        assert!(sole_from_points(&line).is_none());
    }

    /// A vertical cylinder of radius 0.04 m and length 0.1 m centred 0.02 m ahead and 0.05 m
    /// below the frame: its lower rim is a circle of diameter 0.08 m at −0.1 m.
    #[test]
    fn a_cylinder_sole_is_its_lower_rim() {
        let g = urdf_rs::Geometry::Cylinder {
            radius: 0.04,
            length: 0.1,
        };
        let at = Isometry3::translation(0.02, 0.0, -0.05);
        let (l, w, off, ankle) = sole_from_points(&primitive_points(&g, &at)).unwrap();
        for (got, want) in [(l, 0.08), (w, 0.08), (off, 0.02), (ankle, 0.1)] {
            assert!((got - want).abs() < 1e-12, "{got} {want}");
        }
    }

    #[test]
    fn narrow_or_long_soles_are_questioned() {
        assert!(questioned(0.2, 0.08).is_none());
        assert!(questioned(0.2, 0.03).unwrap().contains("3.0 cm wide"));
        assert!(questioned(0.45, 0.08).unwrap().contains("45.0 cm long"));
    }
}
