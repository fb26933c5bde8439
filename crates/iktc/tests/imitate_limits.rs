//! The imitation runs that used to break a limit, now kept inside (viable bounds): a very large
//! acceleration limit on a narrowed joint, coarse control periods, a zero-width range; and a
//! start outside the limits, refused by default and recovered on request.

use iktc::limits::NarrowedJoint;
use iktc::limits::{BoundMethod, OutsideLimits, ViableSettings};
use iktc::model::{jvrc1, ModelOptions, Robot};
use iktc::motion::{builtin_clip, builtin_map, RobotReferences};
use iktc::sim::{imitation_references, run_imitate, ImitateConfig, ImitateRun};
use iktc::solver::Method;
use iktc::Error;

/// Rounding allowed on a limit [rad], [rad/s], [rad/s²], as in `imitate_default`: the solvers
/// accept a q̈ outside the box by up to `SolverSettings::box_tolerance` (1e-9 rad/s²).
const LIMIT_ROUNDING: f64 = 1e-6;

fn robot(options: ModelOptions) -> Robot {
    jvrc1(&options).unwrap()
}

fn references(robot: &Robot, clip: &str, cfg: &ImitateConfig) -> RobotReferences {
    let clip = builtin_clip(clip).unwrap();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    imitation_references(robot, &clip, &map, cfg).unwrap()
}

/// Every joint within its (narrowed) limits at every tick, checked from the recorded states
/// against the model's limits, not the run's own margins; returns the worst excursion.
fn worst_excursion(robot: &Robot, cfg: &ImitateConfig, run: &ImitateRun) -> f64 {
    let mut lims = robot.dof_limits();
    for n in &cfg.narrow {
        let d = robot.joint_v_index(&n.joint).unwrap();
        lims[d].lower = n.lower;
        lims[d].upper = n.upper;
    }
    let mut worst = f64::NEG_INFINITY;
    for s in &run.steps {
        for (d, l) in lims.iter().enumerate().skip(robot.base_nv()) {
            worst = worst
                .max(s.q[d] - l.upper)
                .max(l.lower - s.q[d])
                .max(s.qd[d].abs() - l.velocity)
                .max(s.qdd[d].abs() - l.acceleration);
        }
    }
    worst
}

fn assert_inside(robot: &Robot, cfg: &ImitateConfig, run: &ImitateRun, what: &str) {
    let s = &run.summary;
    let worst = worst_excursion(robot, cfg, run);
    assert!(worst <= LIMIT_ROUNDING, "{what}: excursion {worst}");
    assert!(
        s.worst_position_margin <= LIMIT_ROUNDING,
        "{what}: in-step position margin {}",
        s.worst_position_margin
    );
    assert!(s.worst_velocity_margin <= LIMIT_ROUNDING, "{what}");
    assert!(s.worst_acceleration_margin <= LIMIT_ROUNDING, "{what}");
    assert_eq!(s.empty_box_steps, 0, "{what}");
}

#[test]
fn knee_with_a_huge_acceleration_limit_stays_in_its_narrowed_range() {
    // `iktc imitate --accel L_KNEE=1e5` used to reach an empty box [500000, 2951] at tick 180
    // on the narrowed 0.55 rad limit and leave the range by 14 rad (IKTC and clamp): v_max of
    // the knee is far below a_stop Δt there, so braking by turning round inside the step broke
    // the velocity limit.
    let robot = robot(ModelOptions {
        acceleration_limits: vec![("L_KNEE".into(), 1e5)],
        ..ModelOptions::default()
    });
    for method in [Method::Iktc, Method::Clamp] {
        // The hard bounds only: no soft approach, the clip as captured (the knee reaches its
        // limit).
        let mut cfg = ImitateConfig {
            method,
            bounds: iktc::limits::BoundMethod::quiet(),
            smoothing: None,
            ..ImitateConfig::default()
        };
        // This test is about the joint limits: the run goes on when the feet task is given up
        // (clamping moves the feet), which the run's health report marks.
        cfg.health.keep_going = true;
        let refs = references(&robot, "humanoid3d_dance_b", &cfg);
        let run = run_imitate(&robot, &refs, &cfg).unwrap();
        assert_inside(&robot, &cfg, &run, method.name());
        assert_eq!(run.summary.fallback_steps, 0, "{}", method.name());
        // The knee does reach its narrowed lower limit (the case is not vacuous).
        let knee = robot.joint_v_index("L_KNEE").unwrap();
        let lowest = run
            .steps
            .iter()
            .map(|s| s.q[knee])
            .fold(f64::INFINITY, f64::min);
        assert!(lowest < 0.56, "{}: knee down to {lowest}", method.name());
    }
}

#[test]
fn coarse_control_periods_keep_every_limit() {
    // `--dt 0.1` (punch) left a range by 2.1e6 rad, `--dt 0.5` (dance_b) by 62 rad.
    let robot = robot(ModelOptions::default());
    for (clip, dt) in [("humanoid3d_punch", 0.1), ("humanoid3d_dance_b", 0.5)] {
        let mut cfg = ImitateConfig {
            dt,
            // Periods above the default range of RunLimits (0.1 s), on purpose.
            run_limits: iktc::resources::RunLimits {
                max_dt: 0.5,
                ..Default::default()
            },
            ..ImitateConfig::default()
        };
        // About the joint limits: at such periods the feet drift past their tolerance, which
        // the health report marks; the run goes on.
        cfg.health.keep_going = true;
        let refs = references(&robot, clip, &cfg);
        let run = run_imitate(&robot, &refs, &cfg).unwrap();
        assert_inside(&robot, &cfg, &run, clip);
    }
}

#[test]
fn zero_width_range_holds_the_joint() {
    // A zero-width range on a movable joint is a held joint: its only viable state is at rest
    // on it and its box is {0}. (It used to leave the range by 4.4e-4 rad with 31 empty-box
    // steps and no fallback reported.)
    let robot = robot(ModelOptions::default());
    let mut cfg = ImitateConfig::default();
    cfg.narrow.retain(|n| n.joint != "L_KNEE");
    cfg.narrow.push(NarrowedJoint {
        joint: "L_KNEE".into(),
        lower: 0.8,
        upper: 0.8,
    });
    // A joint driven by the references (its references clamped to the single value) and a
    // leg joint that the pelvis tasks push (`--narrow L_HIP_R=0:0` ended in NaN).
    cfg.narrow.retain(|n| n.joint != "L_HIP_R");
    for (joint, value) in [("R_SHOULDER_P", 0.0), ("L_HIP_R", 0.0)] {
        cfg.narrow.push(NarrowedJoint {
            joint: joint.into(),
            lower: value,
            upper: value,
        });
    }
    let refs = references(&robot, "humanoid3d_dance_b", &cfg);
    let run = run_imitate(&robot, &refs, &cfg).unwrap();
    assert_inside(&robot, &cfg, &run, "zero width");
    assert_eq!(run.summary.fallback_steps, 0);
    for (joint, value) in [("L_KNEE", 0.8), ("R_SHOULDER_P", 0.0), ("L_HIP_R", 0.0)] {
        let d = robot.joint_v_index(joint).unwrap();
        for s in &run.steps {
            assert!(
                (s.q[d] - value).abs() <= LIMIT_ROUNDING,
                "{joint} t = {}",
                s.t
            );
            assert!(s.qd[d].abs() <= LIMIT_ROUNDING, "{joint} t = {}", s.t);
        }
    }
}

fn recover() -> BoundMethod {
    BoundMethod::Viable(ViableSettings {
        outside: OutsideLimits::Recover,
        approach_rate: 0.0,
        ..ViableSettings::default()
    })
}

#[test]
fn start_outside_the_range_is_an_error_naming_the_joint_or_is_recovered() {
    let robot = robot(ModelOptions::default());
    // A posture outside the narrowed range [0.55, 0.95] of L_KNEE, and a narrowing that
    // excludes the default start posture (0.8 rad).
    let mut posture = ImitateConfig::default();
    posture.initial_posture.push(("L_KNEE".into(), 1.2));
    let mut narrowing = ImitateConfig::default();
    narrowing.narrow.retain(|n| n.joint != "L_KNEE");
    narrowing.narrow.push(NarrowedJoint {
        joint: "L_KNEE".into(),
        lower: 0.3,
        upper: 0.6,
    });
    for (cfg, value, range) in [(posture, 1.2, (0.55, 0.95)), (narrowing, 0.8, (0.3, 0.6))] {
        let refs = references(&robot, "humanoid3d_dance_b", &cfg);
        match run_imitate(&robot, &refs, &cfg) {
            Err(Error::StateOutsideLimits {
                joint,
                value: v,
                lower,
                upper,
                ..
            }) => {
                assert_eq!(joint, "L_KNEE");
                assert_eq!((v, lower, upper), (value, range.0, range.1));
            }
            other => panic!("expected StateOutsideLimits, got {:?}", other.map(|_| ())),
        }
        // On request, the knee is brought back and stays; no other limit is crossed.
        let cfg = ImitateConfig {
            bounds: recover(),
            ..cfg
        };
        let run = run_imitate(&robot, &refs, &cfg).unwrap();
        let knee = robot.joint_v_index("L_KNEE").unwrap();
        let recovering: Vec<usize> = run
            .steps
            .iter()
            .take_while(|s| s.recovering.contains(&knee))
            .map(|s| s.recovering.len())
            .collect();
        assert!(!recovering.is_empty(), "no tick reported the recovery");
        assert!(recovering.iter().all(|&n| n == 1), "only the knee recovers");
        let back = recovering.len();
        assert_eq!(run.summary.recovering_steps, back);
        // The excursion only shrinks while recovering, then the joint stays inside.
        let outside = |q: f64| (q - range.1).max(range.0 - q).max(0.0);
        for w in run.steps[..=back].windows(2) {
            assert!(outside(w[1].q[knee]) <= outside(w[0].q[knee]) + 1e-15);
        }
        for s in &run.steps[back..] {
            assert!(
                outside(s.q[knee]) <= LIMIT_ROUNDING,
                "t = {}: {}",
                s.t,
                s.q[knee]
            );
        }
        // Velocity and acceleration limits of every joint, and every other range, kept all
        // along; the knee's range from the tick it is back.
        let lims = robot.dof_limits();
        for s in &run.steps {
            for (d, l) in lims.iter().enumerate().skip(robot.base_nv()) {
                assert!(
                    s.qd[d].abs() <= l.velocity + LIMIT_ROUNDING,
                    "dof {d} t = {}",
                    s.t
                );
                assert!(s.qdd[d].abs() <= l.acceleration + LIMIT_ROUNDING, "dof {d}");
            }
        }
        let others = ImitateConfig {
            narrow: cfg
                .narrow
                .iter()
                .filter(|n| n.joint != "L_KNEE")
                .cloned()
                .collect(),
            ..cfg.clone()
        };
        let mut lims_without_knee = robot.dof_limits();
        for n in &others.narrow {
            let d = robot.joint_v_index(&n.joint).unwrap();
            lims_without_knee[d].lower = n.lower;
            lims_without_knee[d].upper = n.upper;
        }
        for s in &run.steps {
            for (d, l) in lims_without_knee.iter().enumerate().skip(robot.base_nv()) {
                if d != knee {
                    assert!(
                        s.q[d] >= l.lower - LIMIT_ROUNDING && s.q[d] <= l.upper + LIMIT_ROUNDING,
                        "dof {d} t = {}",
                        s.t
                    );
                }
            }
        }
    }
}

#[test]
fn locking_a_joint_outside_its_range_is_an_error() {
    let err = jvrc1(&ModelOptions {
        locked: vec![("L_KNEE".into(), 10.0)],
        ..ModelOptions::default()
    })
    .unwrap_err();
    match err {
        Error::StateOutsideLimits { joint, value, .. } => {
            assert_eq!((joint.as_str(), value), ("L_KNEE", 10.0));
        }
        other => panic!("expected StateOutsideLimits, got {other:?}"),
    }
}
