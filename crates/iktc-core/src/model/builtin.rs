//! The planar 3R arm of the paper's Section 3.3, built in code (the humanoids, read from their
//! URDFs, are in the `iktc` crate).

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

use super::joint::{JointKind, JointLimit};
use super::robot::{JointSpec, Link, ModelOptions, Robot, RobotBuilder};

/// The planar 3R arm of Section 3.3: three revolute joints about z, unit links along x, joint
/// ranges q1 ∈ \[60°, 180°\], q2, q3 ∈ \[−120°, 120°\], 180°/s and 1800°/s² for every joint. Each
/// link has 1 kg at its middle. Frame `tip` is the end of the third link.
pub fn planar3r() -> Robot {
    let deg = std::f64::consts::PI / 180.0;
    let ranges = [(60.0, 180.0), (-120.0, 120.0), (-120.0, 120.0)];
    let mut b = RobotBuilder::new("planar3r").link(Link::massless("base"));
    for i in 1..=3 {
        b = b.link(Link {
            name: format!("link{i}"),
            mass: 1.0,
            com: Vector3::new(0.5, 0.0, 0.0),
            inertia: Matrix3::from_diagonal(&Vector3::new(0.0, 1.0 / 12.0, 1.0 / 12.0)),
        });
        let (lo, hi) = ranges[i - 1];
        b = b.joint(JointSpec {
            name: format!("q{i}"),
            parent: if i == 1 {
                "base".into()
            } else {
                format!("link{}", i - 1)
            },
            child: format!("link{i}"),
            origin: Isometry3::from_parts(
                Translation3::new(if i == 1 { 0.0 } else { 1.0 }, 0.0, 0.0),
                UnitQuaternion::identity(),
            ),
            kind: JointKind::Revolute {
                axis: Vector3::z_axis(),
            },
            limit: JointLimit {
                lower: lo * deg,
                upper: hi * deg,
                velocity: 180.0 * deg,
                acceleration: 1800.0 * deg,
                jerk: f64::INFINITY,
                effort: f64::INFINITY,
            },
            mimic: None,
        });
    }
    b = b.frame("tip", "link3", Isometry3::translation(1.0, 0.0, 0.0));
    // Every number above is finite and every name unique: building cannot fail.
    match b.build(&ModelOptions::default()) {
        Ok(r) => r,
        Err(e) => unreachable!("the built-in planar 3R model is valid: {e}"),
    }
}
