//! Runs that go wrong say so: each check of `iktc::sim::health` triggered by
//! a constructed case, the error naming time, quantity, value and tolerance; with `keep_going`
//! the run goes on and its summary lists the failure; the default runs pass (no false alarm);
//! a sideways push is measured along ỹ.

use iktc::balance::{run_push, PushScenario, SupportPhase};
use iktc::model::RobotFiles;
use iktc::model::{jvrc1, BaseKind, ModelOptions, Robot, JVRC1_URDF};
use iktc::motion::{builtin_clip, builtin_map, retarget_joint_angles, RobotReferences};
use iktc::sim::{
    imitation_references, run_imitate, run_walk_imitate, HealthCheck, HealthMonitor,
    HealthSettings, ImitateConfig, Push, Verdict, WalkImitateConfig,
};
use iktc::walk::{Pose2, SupportPolygon};
use iktc::Error;

fn clip_refs(robot: &Robot, cfg: &ImitateConfig) -> RobotReferences {
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    imitation_references(robot, &clip, &map, cfg).unwrap()
}

fn failure(e: Error) -> iktc::sim::HealthIssue {
    match e {
        Error::RunFailed(issue) => *issue,
        other => panic!("expected RunFailed, got {other}"),
    }
}

#[test]
fn the_default_imitation_is_healthy() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let cfg = ImitateConfig::default();
    let run = run_imitate(&robot, &clip_refs(&robot, &cfg), &cfg).unwrap();
    let h = &run.summary.health;
    assert!(h.healthy && h.completed && h.issues.is_empty(), "{h:?}");
    assert_eq!(h.failed_ticks, 0);
    // No corrected span is written as a number it does not have.
    let json = serde_json::to_string(&run.summary).unwrap();
    assert!(!json.contains("null") && !json.contains("NaN"));
}

/// A feet tolerance below what the default run drifts (about 0.5 mm): the run stops at the
/// first tick whose drift exceeds it, and the error carries that tick's drift.
#[test]
fn a_foot_past_its_tolerance_stops_the_run() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let tol = 1e-4;
    let mut cfg = ImitateConfig::default();
    cfg.health.foot_position_tolerance = tol;
    let refs = clip_refs(&robot, &cfg);
    let issue = failure(run_imitate(&robot, &refs, &cfg).unwrap_err());
    assert_eq!(issue.check, HealthCheck::FootPosition);
    assert!(issue.quantity.contains("ankle"), "{}", issue.quantity);
    assert!(issue.value > tol && issue.tolerance == tol);
    // The same run with keep_going: the first drift past the tolerance is at that time, and
    // it is the recorded drift of that tick (computed independently from the recorded steps).
    cfg.health.keep_going = true;
    let run = run_imitate(&robot, &refs, &cfg).unwrap();
    let first = run.steps.iter().find(|s| s.foot_drift > tol).unwrap();
    assert!((first.t - issue.time).abs() < 1e-12);
    assert!((first.foot_drift - issue.value).abs() <= 1e-12 * issue.value.max(1.0));
    let h = &run.summary.health;
    assert!(!h.healthy && h.completed);
    let recorded = run.steps.iter().filter(|s| s.foot_drift > tol).count();
    assert!(h.failed_ticks >= recorded && recorded > 0);
    assert_eq!(run.steps.len(), run.summary.steps);
    let msg = Error::RunFailed(Box::new(issue)).to_string();
    assert!(
        msg.contains("t = ") && msg.contains("tolerance 1.0000e-4"),
        "{msg}"
    );
}

/// JVRC-1 read from its URDF with the fingers free (nv = 40): the run gives up the feet and
/// stops instead of writing 18 m of drift.
#[test]
fn jvrc1_urdf_with_free_fingers_stops_on_the_feet() {
    let robot = Robot::from_urdf_str(
        JVRC1_URDF,
        &ModelOptions {
            base: BaseKind::Floating,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(robot.nv(), 40);
    let cfg = ImitateConfig::default();
    let refs = clip_refs(&robot, &cfg);
    match run_imitate(&robot, &refs, &cfg) {
        Ok(run) => {
            // Fixed at the root: then it must be healthy.
            assert!(run.summary.health.healthy, "{:?}", run.summary.health);
        }
        Err(e) => {
            let issue = failure(e);
            assert!(
                matches!(
                    issue.check,
                    HealthCheck::FootPosition | HealthCheck::FootRotation
                ),
                "{issue}"
            );
            assert!(issue.value > issue.tolerance);
        }
    }
}

#[test]
fn a_non_finite_state_stops_even_when_asked_to_keep_going() {
    let names: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
    let mut strict = HealthMonitor::new(HealthSettings::default()).unwrap();
    let issue = failure(
        strict
            .check_finite(0.25, "velocity q̇ [rad/s]", &names, &[0.0, f64::NAN, 1.0])
            .unwrap_err(),
    );
    assert_eq!(issue.check, HealthCheck::NonFinite);
    assert_eq!(issue.time, 0.25);
    assert!(issue.value.is_nan());
    assert!(issue.detail.contains("entry 1, b"), "{}", issue.detail);
    let mut lenient = HealthMonitor::new(HealthSettings {
        keep_going: true,
        ..Default::default()
    })
    .unwrap();
    assert_eq!(
        lenient
            .check_finite(0.0, "q", &names, &[1.0, 2.0, 3.0])
            .unwrap(),
        Verdict::Continue
    );
    assert_eq!(
        lenient
            .check_finite(0.1, "q", &names, &[f64::INFINITY, 2.0, 3.0])
            .unwrap(),
        Verdict::Stop
    );
    let r = lenient.report();
    assert!(!r.healthy && !r.completed);
    // The report's JSON carries no bare non-finite number.
    let json = serde_json::to_string(&r).unwrap();
    assert!(json.contains("\"inf\"") && !json.contains("null"), "{json}");
}

/// The ZMP check names the edge crossed, the direction and the distance, against a sole whose
/// edges are known by hand: a 0.2 × 0.1 m sole turned by 90° at (1, 2) spans x ∈ [0.95, 1.05],
/// y ∈ [1.9, 2.1].
#[test]
fn a_zmp_outside_names_the_edge_and_the_distance() {
    let mut sole = SupportPolygon::default();
    sole.set_sole(&Pose2::new(1.0, 2.0, std::f64::consts::FRAC_PI_2), 0.2, 0.1);
    let mut m = HealthMonitor::new(HealthSettings::default()).unwrap();
    assert_eq!(
        m.check_support(0.0, &sole, (1.04, 2.09), "ZMP", "world axes")
            .unwrap(),
        Verdict::Continue
    );
    let issue = failure(
        m.check_support(1.5, &sole, (0.93, 2.0), "ZMP", "world axes")
            .unwrap_err(),
    );
    assert_eq!(issue.check, HealthCheck::ZmpOutside);
    assert!((issue.value - 0.02).abs() < 1e-12, "{}", issue.value);
    assert!(issue.detail.contains("−x (back)"), "{}", issue.detail);
    let edge = sole.closest_edge((1.0, 2.13)).unwrap();
    assert!((edge.margin + 0.03).abs() < 1e-12);
    assert!((edge.outward_normal.0).abs() < 1e-12 && (edge.outward_normal.1 - 1.0).abs() < 1e-12);
    assert!((edge.start.1 - 2.1).abs() < 1e-12 && (edge.end.1 - 2.1).abs() < 1e-12);
}

fn walk(push: Push, keep_going: bool) -> iktc::Result<iktc::sim::WalkRun> {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    let refs = retarget_joint_angles(&clip, &robot, &map)
        .unwrap()
        .resample(0.005)
        .unwrap();
    let mut cfg = WalkImitateConfig {
        push: Some(push),
        ..WalkImitateConfig::jvrc1().unwrap()
    };
    cfg.imitate.health.keep_going = keep_going;
    run_walk_imitate(&robot, &refs, &cfg)
}

/// A 20 N·s forward push in single support puts the measured ZMP outside the stance sole:
/// the walk stops, naming the front edge.
#[test]
fn a_big_push_while_walking_is_a_fall() {
    let push = Push {
        time: 2.15,
        impulse: [20.0, 0.0],
    };
    let issue = failure(walk(push, false).unwrap_err());
    assert_eq!(issue.check, HealthCheck::ZmpOutside);
    assert!(issue.time >= 2.15 && issue.value > 0.0);
    assert!(issue.detail.contains("+x (front)"), "{}", issue.detail);
    // Continued: the excursion in the summary is the recorded steps' worst margin.
    let run = walk(push, true).unwrap();
    let p = run.summary.push.unwrap();
    let worst = run
        .steps
        .iter()
        .filter(|s| s.t >= push.time)
        .map(|s| s.zmp_margin)
        .fold(f64::INFINITY, f64::min);
    assert!((p.zmp_excursion + worst).abs() < 1e-15 && p.zmp_excursion > 0.0);
    assert!(!run.summary.health.healthy);
}

/// A sideways push is measured along ỹ: its peak is the recorded lateral deviation's, far
/// above the forward one, and a damped mode is fitted to it.
#[test]
fn a_sideways_push_is_measured_along_y() {
    let push = Push {
        time: 2.15,
        impulse: [0.0, 3.0],
    };
    let run = walk(push, true).unwrap();
    let p = run.summary.push.unwrap();
    let peak_y = run
        .steps
        .iter()
        .filter(|s| s.t >= push.time)
        .map(|s| s.zmp_deviation[1].abs())
        .fold(0.0, f64::max);
    assert!(
        (p.y.peak - peak_y).abs() < 1e-15,
        "{} vs {peak_y}",
        p.y.peak
    );
    assert!(p.y.peak > 2.0 * p.x.peak, "{:?}", p);
    let zeta =
        p.y.damping_ratio
            .expect("a lateral response above the noise");
    assert!(zeta > 0.0 && zeta < 1.0, "{zeta}");
}

/// The balance push scenario: a sideways push big enough to leave the double-support
/// polygon stops it; the default pushes stay inside in both phases.
#[test]
fn balance_pushes_check_the_support_polygon() {
    for phase in [SupportPhase::Double, SupportPhase::Single] {
        let r = run_push(&PushScenario::new(phase).unwrap()).unwrap();
        assert!(r.health.healthy, "{:?}", r.health);
        assert_eq!(r.zmp_excursion_closed, 0.0);
        assert_eq!(r.zmp_excursion_open, 0.0);
    }
    let mut s = PushScenario::new(SupportPhase::Single).unwrap();
    s.impulse = [0.0, 6.0];
    let issue = failure(run_push(&s).unwrap_err());
    assert_eq!(issue.check, HealthCheck::ZmpOutside);
    assert!(issue.detail.contains("y ("), "{}", issue.detail);
    s.health.keep_going = true;
    let r = run_push(&s).unwrap();
    // Independently: the open loop's largest violation of the sole's half-planes
    // (x̃ ∈ [−0.1, 0.1], ỹ ∈ [−0.05, 0.05] m).
    let beyond = r.zmp_open[0]
        .iter()
        .zip(&r.zmp_open[1])
        .map(|(x, y)| (x.abs() - 0.1).max(y.abs() - 0.05))
        .fold(0.0, f64::max);
    assert!(beyond > 0.0);
    assert!((r.zmp_excursion_open - beyond).abs() < 1e-12);
    assert!(!r.health.healthy);
}
