//! MJCF models read by iktc. The G1's MJCF (`data/robots/g1/g1_29dof_rev_1_0.xml`) against
//! the same robot's URDF (the built-in G1): same joints, ranges and efforts, and the same link
//! poses and centre of mass at seeded random configurations (the two files were exported
//! separately: their numbers differ by rounding, ~3e-7). `iktc profile init` on MuJoCo's
//! humanoid. (The Python test `test_mjcf.py` compares iktc with MuJoCo itself.)
#![cfg(feature = "mjcf")]

use iktc::model::RobotFiles;
use std::path::Path;

use iktc::model::*;
use nalgebra::{DVector, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Largest difference of a link position between the two files' models \[m\]: their numbers
/// differ by rounding (~3e-7 m per offset, ~14 offsets from the pelvis to a hand).
const POSITION_TOL: f64 = 1e-5;
/// Largest difference of a link orientation \[rad\], from the rounding of the MJCF's
/// quaternions (~1e-6 per quaternion, a few quaternions to a hand).
const ROTATION_TOL: f64 = 1e-5;
/// Largest difference of the centre of mass \[m\]: inertial positions and masses rounded.
const COM_TOL: f64 = 1e-5;
/// Largest difference of a joint range end \[rad\]: the MJCF prints six significant digits
/// (`1.97222` for the URDF's `1.972222054`, 2.1e-6 apart).
const RANGE_TOL: f64 = 1e-5;

/// The joints whose effort limits differ between Unitree's URDF (35 N·m) and MJCF (50 N·m).
const DIFFERENT_EFFORT: &[&str] = &[
    "left_ankle_pitch_joint",
    "left_ankle_roll_joint",
    "right_ankle_pitch_joint",
    "right_ankle_roll_joint",
    "waist_roll_joint",
    "waist_pitch_joint",
];

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/robots/g1")
        .join(name)
}

fn floating() -> ModelOptions {
    ModelOptions {
        base: BaseKind::Floating,
        ..ModelOptions::default()
    }
}

#[test]
fn the_g1_mjcf_has_the_urdfs_joints_ranges_and_efforts() {
    let m = Robot::from_mjcf_file(&data("g1_29dof_rev_1_0.xml"), &floating()).unwrap();
    let u = g1(&ModelOptions::default()).unwrap();
    assert_eq!((m.nq(), m.nv()), (u.nq(), u.nv()));
    let names = |r: &Robot| {
        r.active_joints()
            .map(|j| j.name.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(names(&m), names(&u));
    for (a, b) in m.active_joints().zip(u.active_joints()) {
        assert!(
            (a.limit.lower - b.limit.lower).abs() < RANGE_TOL,
            "{}",
            a.name
        );
        assert!(
            (a.limit.upper - b.limit.upper).abs() < RANGE_TOL,
            "{}",
            a.name
        );
        // Unitree's two files disagree on six efforts: the URDF says 35 N·m, the MJCF's
        // actuatorfrcrange ±50 N·m.
        let want = if DIFFERENT_EFFORT.contains(&a.name.as_str()) {
            50.0
        } else {
            b.limit.effort
        };
        assert_eq!(a.limit.effort, want, "{}", a.name);
        // MJCF has no velocity limit: unbounded, as documented.
        assert_eq!(a.limit.velocity, f64::INFINITY);
    }
    assert!((m.total_mass() - u.total_mass()).abs() < 1e-9 * u.total_mass());
    // Every body of the MJCF is a link of the URDF.
    for l in m.links() {
        assert!(u.links().iter().any(|k| k.name == l.name), "{}", l.name);
    }
    // The IMU sites are frames.
    assert!(m.frame_id("imu_in_pelvis").is_ok());
    assert!(m.warnings().iter().any(|w| w.contains("velocity")));
}

#[test]
fn the_g1_mjcf_places_every_link_where_the_urdf_does() {
    let m = Robot::from_mjcf_file(&data("g1_29dof_rev_1_0.xml"), &floating()).unwrap();
    let u = g1(&ModelOptions::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..20 {
        let mut q = DVector::zeros(u.nq());
        q.fixed_rows_mut::<3>(0)
            .copy_from(&Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0)));
        let r = UnitQuaternion::from_euler_angles(
            rng.random_range(-3.0..3.0),
            rng.random_range(-1.5..1.5),
            rng.random_range(-3.0..3.0),
        );
        q.fixed_rows_mut::<4>(3).copy_from(&r.coords);
        for (i, j) in u.active_joints().enumerate() {
            q[7 + i] = rng.random_range(j.limit.lower..j.limit.upper);
        }
        let s = State {
            q,
            qd: DVector::zeros(u.nv()),
        };
        let (km, ku) = (
            Kinematics::new(&m, &s).unwrap(),
            Kinematics::new(&u, &s).unwrap(),
        );
        for (i, l) in m.links().iter().enumerate() {
            let k = u.links().iter().position(|x| x.name == l.name).unwrap();
            let (a, b) = (km.link_pose(i).unwrap(), ku.link_pose(k).unwrap());
            worst.0 = worst
                .0
                .max((a.translation.vector - b.translation.vector).norm());
            worst.1 = worst.1.max(a.rotation.angle_to(&b.rotation));
        }
        worst.2 = worst.2.max((km.com() - ku.com()).norm());
    }
    eprintln!(
        "MJCF vs URDF, 20 configurations: position {:.2e} m, rotation {:.2e} rad, COM {:.2e} m",
        worst.0, worst.1, worst.2
    );
    assert!(
        worst.0 < POSITION_TOL,
        "link position differs by {} m",
        worst.0
    );
    assert!(
        worst.1 < ROTATION_TOL,
        "link rotation differs by {} rad",
        worst.1
    );
    assert!(worst.2 < COM_TOL, "centre of mass differs by {} m", worst.2);
}

/// `iktc profile init` on MuJoCo's humanoid (`tests/data/mjcf/humanoid.xml`): two feet, their
/// soles from the capsules under them. The ankle joints sit 4 cm above the foot bodies, so the
/// foot frames are the chain links `foot_*__ankle_x_*` at the ankle joint; in that frame the
/// capsules' end spheres (radius 0.027 m, centres at x = −0.07 and 0.14 m, y = ±0.01 and ±0.03
/// m, 0.04 m below) touch the ground at z = −0.067 m.
#[test]
fn profile_init_guesses_the_humanoids_feet_and_soles_from_its_capsules() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mjcf/humanoid.xml");
    let text = std::fs::read_to_string(&path).unwrap();
    let toml = iktc::profile::init_profile_toml_at(&text, "humanoid.xml", path.parent()).unwrap();
    assert!(toml.contains("base = \"floating\""), "{toml}");
    assert!(
        toml.contains("frame = \"foot_left__ankle_x_left\""),
        "{toml}"
    );
    assert!(
        toml.contains("sole = { length = 0.21, width = 0.06, offset_x = 0.035 }"),
        "{toml}"
    );
    assert!(toml.contains("ankle_height = 0.067"), "{toml}");
    assert!(toml.contains("left_hand = \"hand_left\""), "{toml}");
}
