//! Experiments as library calls (`iktc::sim::experiment`, `iktc::sim::viewer`): clips and maps
//! by name or path with errors that name what exists, the one rule that clamps references into
//! a range, and the viewer data of a standing and a walking run checked against the runs.

use iktc::motion::{shrunk_range, MotionFormat, MotionOptions};
use iktc::sim::viewer::{imitation_viewer, walking_viewer, SKELETON_OFFSET};
use iktc::sim::{load_clip, load_map, Experiment, WalkImitateConfig};
use iktc::walk::{Phase, Side};
use iktc::Error;
use proptest::prelude::*;

#[test]
fn an_unknown_clip_names_the_built_in_ones() {
    let e = load_clip("no_such_clip", &MotionOptions::default()).unwrap_err();
    match e {
        Error::UnknownName { name, valid, .. } => {
            assert_eq!(name, "no_such_clip");
            assert!(valid.iter().any(|v| v == "humanoid3d_dance_b"), "{valid:?}");
        }
        other => panic!("expected UnknownName, got {other}"),
    }
    let c = load_clip("humanoid3d_punch", &MotionOptions::default()).unwrap();
    assert_eq!(c.format, MotionFormat::DeepMimic);
    assert!(c.decided.is_none(), "a built-in clip has nothing decided");
}

#[test]
fn a_map_is_a_built_in_name_or_a_readable_file_checked_against_the_robot() {
    let (e, _) = Experiment::jvrc1().unwrap();
    let missing = std::env::temp_dir().join("iktc-experiment-no-such-map.toml");
    let err = load_map(missing.to_str().unwrap(), &e.robot)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("deepmimic_jvrc1") && err.contains("no-such-map"),
        "{err}"
    );
    assert!(load_map("deepmimic_jvrc1", &e.robot).is_ok());
    // The G1's map names joints JVRC-1 lacks.
    let err = load_map("deepmimic_g1", &e.robot).unwrap_err().to_string();
    assert!(err.contains("joint"), "{err}");
}

proptest! {
    #[test]
    fn shrunk_range_stays_inside_and_is_the_middle_when_too_narrow(
        lower in -3.0f64..3.0,
        width in 0.0f64..2.0,
        margin in 0.0f64..0.5,
    ) {
        let upper = lower + width;
        let (lo, hi) = shrunk_range(lower, upper, margin);
        prop_assert!(lower <= lo && lo <= hi && hi <= upper, "{lo} {hi}");
        if width >= 2.0 * margin {
            prop_assert!((lo - (lower + margin)).abs() <= 1e-12);
            prop_assert!((hi - (upper - margin)).abs() <= 1e-12);
        } else {
            prop_assert_eq!(lo, hi);
            prop_assert!((lo - 0.5 * (lower + upper)).abs() <= 1e-12);
        }
    }
}

/// Whether `p` is inside the convex polygon `poly` (counter-clockwise) or on its edge.
fn inside(poly: &[[f32; 3]], p: [f64; 2]) -> bool {
    (0..poly.len()).all(|i| {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let cross = (b[0] as f64 - a[0] as f64) * (p[1] - a[1] as f64)
            - (b[1] as f64 - a[1] as f64) * (p[0] - a[0] as f64);
        cross >= -1e-6
    })
}

/// The link orientations of the viewer agree with its link positions: a revolute or fixed
/// joint's child link sits at `p_parent + R_parent · t_origin`, whatever the joint's angle.
fn orientations_agree_with_positions(
    v: &iktc::sim::viewer::ViewerData,
    robot: &iktc::model::Robot,
) {
    use iktc::model::JointKind;
    use nalgebra::{Quaternion, UnitQuaternion, Vector3};
    assert_eq!(v.robot_rotations.len(), v.robot.frames.len());
    let mut checked = 0;
    for (pos, rot) in v.robot.frames.iter().zip(&v.robot_rotations) {
        assert_eq!(rot.len(), robot.links().len());
        for j in robot.joints() {
            if matches!(j.kind, JointKind::Prismatic { .. }) {
                continue;
            }
            let r = rot[j.parent].map(f64::from);
            let q = UnitQuaternion::from_quaternion(Quaternion::new(r[3], r[0], r[1], r[2]));
            let p = |i: usize| Vector3::from(pos[i].map(f64::from));
            let want = p(j.parent) + q * j.origin.translation.vector;
            // f32 storage: positions of a few metres to ~1e-6 m, quaternions to ~1e-7.
            assert!((p(j.child) - want).norm() < 1e-5, "joint {}", j.name);
            checked += 1;
        }
    }
    assert!(checked > 0);
}

#[test]
fn the_standing_viewer_pins_the_skeleton_beside_the_robot() {
    let (e, cfg) = Experiment::jvrc1().unwrap();
    let run = e.imitate(&cfg).unwrap();
    let v = imitation_viewer(&run, &e).unwrap();
    let stride = (0.02 / cfg.dt).round() as usize;
    assert_eq!(v.robot.frames.len(), run.steps.len().div_ceil(stride));
    assert_eq!(v.skeleton.frames.len(), v.robot.frames.len());
    assert_eq!(v.com.len(), v.robot.frames.len());
    assert!((v.dt - stride as f64 * cfg.dt).abs() < 1e-12);
    // The skeleton's root (its first point) is pinned at (0, SKELETON_OFFSET) on the ground
    // plane in every frame: its horizontal motion is removed.
    for f in &v.skeleton.frames {
        assert!((f[0][0] as f64).abs() < 1e-5, "root x {}", f[0][0]);
        assert!(
            (f[0][1] as f64 - SKELETON_OFFSET).abs() < 1e-5,
            "root y {}",
            f[0][1]
        );
    }
    // The COM of each frame is the run's COM at that tick.
    for (c, st) in v.com.iter().zip(run.steps.iter().step_by(stride)) {
        assert!((c[0] as f64 - st.com[0]).abs() < 1e-5);
    }
    orientations_agree_with_positions(&v, &e.robot);
}

#[test]
fn the_walking_viewer_draws_the_soles_that_carry_the_robot() {
    let (e, imitate) = Experiment::jvrc1().unwrap();
    let cfg = WalkImitateConfig {
        imitate,
        steps: 2,
        push: None,
        ..WalkImitateConfig::jvrc1().unwrap()
    };
    let run = e.walk(&cfg).unwrap();
    let sole = [
        cfg.imitate.support.sole_length,
        cfg.imitate.support.sole_width,
    ];
    let v = walking_viewer(&run, &e, cfg.imitate.dt, sole).unwrap();
    orientations_agree_with_positions(&v, &e.robot);
    let stride = (0.02 / cfg.imitate.dt).round() as usize;
    assert_eq!(v.support_frames.len(), v.robot.frames.len());
    assert_eq!(v.phases.len(), v.robot.frames.len());
    assert_eq!(v.footsteps.len(), run.footsteps.len());
    for ((poly, phase), st) in v
        .support_frames
        .iter()
        .zip(&v.phases)
        .zip(run.steps.iter().step_by(stride))
    {
        // The ankles of the feet in support stand over the polygon (JVRC-1's soles are centred
        // under its ankles), the swing foot's does not in single support.
        let ankle = |i: usize| [st.feet_reference[i][0], st.feet_reference[i][1]];
        match st.phase {
            Phase::DoubleSupport => {
                assert_eq!(phase, "double");
                assert!(
                    inside(poly, ankle(0)) && inside(poly, ankle(1)),
                    "t {}",
                    st.t
                );
            }
            Phase::SingleSupport { stance } => {
                let (on, off) = if stance == Side::Left { (0, 1) } else { (1, 0) };
                assert!(phase.starts_with("single"), "{phase}");
                assert!(inside(poly, ankle(on)), "t {}", st.t);
                assert!(!inside(poly, ankle(off)), "t {}", st.t);
            }
        }
    }
    // Each footstep outline is a sole of the given size around its footstep.
    for (outline, (_, p)) in v.footsteps.iter().zip(&run.footsteps) {
        assert_eq!(outline.len(), 4);
        let d = |a: [f32; 3], b: [f32; 3]| {
            ((a[0] as f64 - b[0] as f64).powi(2) + (a[1] as f64 - b[1] as f64).powi(2)).sqrt()
        };
        assert!((d(outline[0], outline[1]) - sole[0]).abs() < 1e-5);
        assert!((d(outline[1], outline[2]) - sole[1]).abs() < 1e-5);
        let cx = outline.iter().map(|c| c[0] as f64).sum::<f64>() / 4.0;
        assert!((cx - p[0]).abs() < 1e-5);
    }
}
