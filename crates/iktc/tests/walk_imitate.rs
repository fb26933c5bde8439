//! The humanoid walks while it imitates, with the damping controller in the loop:
//! the ZMP stays inside the support polygon for the whole run, push included; with the
//! controller the ZMP oscillation after the push decays faster than without; no joint limit
//! is exceeded at any tick; the feet do not slide in stance.

use iktc::model::{jvrc1, ModelOptions, Robot};
use iktc::motion::{builtin_clip, builtin_map, retarget_joint_angles, RobotReferences};
use iktc::sim::{run_walk_imitate, WalkImitateConfig, WalkRun};
use iktc::walk::{Phase, Side};

/// Rounding allowed on a limit \[rad\], \[rad/s\], \[rad/s²\].
const LIMIT_ROUNDING: f64 = 1e-9;
/// Stance feet: largest horizontal error against the reference and drift within a stance
/// interval \[m\]. The feet are the top priority and the IK tracks them to about 0.2 mm at
/// Δt = 5 ms while the swing foot moves; 1 mm is the stated tolerance.
const FOOT_TOLERANCE: f64 = 1e-3;

fn setup() -> (Robot, RobotReferences) {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    let refs = retarget_joint_angles(&clip, &robot, &map)
        .unwrap()
        .resample(0.005)
        .unwrap();
    (robot, refs)
}

fn run(damping: bool) -> WalkRun {
    let (robot, refs) = setup();
    let cfg = WalkImitateConfig {
        damping,
        ..WalkImitateConfig::jvrc1().unwrap()
    };
    run_walk_imitate(&robot, &refs, &cfg).unwrap()
}

#[test]
fn the_default_walk_keeps_every_constraint() {
    let r = run(true);
    let s = &r.summary;
    assert!(
        s.zmp_inside,
        "ZMP left the support polygon by {} m",
        -s.min_zmp_margin
    );
    assert!(s.min_zmp_margin > 0.0);
    for (i, m) in s.worst_margins.iter().enumerate() {
        assert!(*m <= LIMIT_ROUNDING, "limit kind {i} exceeded by {m}");
    }
    assert!(
        s.max_stance_foot_error < FOOT_TOLERANCE,
        "stance foot error {}",
        s.max_stance_foot_error
    );
    assert!(
        s.max_stance_foot_slip < FOOT_TOLERANCE,
        "stance foot slip {}",
        s.max_stance_foot_slip
    );
    // The legs really walked: every footstep after the first moved the body forward.
    let first = r.steps.first().unwrap().com[0];
    let last = r.steps.last().unwrap().com[0];
    assert!(last - first > 0.25, "the COM advanced {} m", last - first);
    // Both single-support phases occurred, and the swing foot left the ground.
    for side in [Side::Left, Side::Right] {
        let single = Phase::SingleSupport { stance: side };
        assert!(r.steps.iter().any(|s| s.phase == single), "{side:?}");
    }
    let lift = r
        .steps
        .iter()
        .map(|s| s.feet[0][2].max(s.feet[1][2]))
        .fold(0.0, f64::max);
    let ground = r.steps[0].feet[0][2];
    assert!(lift - ground > 0.03, "swing height {}", lift - ground);
    // The narrowed joints still force corrections above the lowest level while walking.
    assert!(s.climbed_ticks > 0);
}

#[test]
fn the_damping_controller_damps_the_push() {
    let on = run(true).summary.push.expect("the default walk has a push");
    let off = run(false)
        .summary
        .push
        .expect("the default walk has a push");
    let zeta = |p: &iktc::sim::WalkPushSummary| p.x.damping_ratio.expect("a forward response");
    println!(
        "ζ with {:.3} / without {:.3}; settling {:?} / {:?}; peak {:.4} / {:.4} m",
        zeta(&on),
        zeta(&off),
        on.x.settling_time,
        off.x.settling_time,
        on.x.peak,
        off.x.peak
    );
    assert!(zeta(&off) < 0.1, "the open loop rings (ζ {})", zeta(&off));
    assert!(zeta(&on) > 3.0 * zeta(&off));
    assert!(zeta(&on) > 0.3, "ζ with the controller {}", zeta(&on));
    let settle_on = on.x.settling_time.expect("settles with the controller");
    match off.x.settling_time {
        None => {}
        Some(t) => assert!(settle_on < 0.5 * t),
    }
    assert!(off.zmp_excursion == 0.0 && on.zmp_excursion == 0.0);
}

#[test]
fn without_the_offset_feedforward_the_com_follows_the_damping_offset_more_slowly() {
    use iktc::sim::WalkingController;
    let (robot, refs) = setup();
    let mut cfg = WalkImitateConfig::jvrc1().unwrap();
    cfg.push = None;
    let mut on = WalkingController::new(&robot, &refs, &cfg).unwrap();
    let mut off = on.clone();
    off.set_offset_feedforward(false);
    let (mut lag_on, mut lag_off) = (0.0_f64, 0.0_f64);
    // A constant measured ZMP deviation of 1 cm forward: the same offsets, followed within a
    // tick with the feedforward, through the COM task's second-order response without.
    for k in 0..40 {
        let a = on.tick(k, [0.01, 0.0]).unwrap();
        let b = off.tick(k, [0.01, 0.0]).unwrap();
        assert_eq!(a.com_offset, b.com_offset);
        let com = |c: &WalkingController| c.imitation().kinematics().com();
        let (ca, cb) = (com(&on), com(&off));
        lag_on = lag_on.max((ca.xy() - a.com_reference).norm());
        lag_off = lag_off.max((cb.xy() - b.com_reference).norm());
        on.integrate().unwrap();
        off.integrate().unwrap();
    }
    assert!(lag_on < lag_off, "{lag_on} vs {lag_off}");
}

/// Every reference track held at its first value: the upper body and pelvis stand still.
fn held(refs: &RobotReferences) -> RobotReferences {
    let mut r = refs.clone();
    let hold = |t: &mut iktc::motion::Track| {
        let p0 = t.position[0];
        t.position.iter_mut().for_each(|p| *p = p0);
        t.velocity.iter_mut().for_each(|v| *v = 0.0);
        t.acceleration.iter_mut().for_each(|a| *a = 0.0);
    };
    r.joints.iter_mut().for_each(hold);
    hold(&mut r.height);
    r.angles.iter_mut().for_each(hold);
    let a0 = r.attitude[0];
    r.attitude.iter_mut().for_each(|a| *a = a0);
    r.angular_velocity
        .iter_mut()
        .for_each(|w| *w = nalgebra::Vector3::zeros());
    r.angular_acceleration
        .iter_mut()
        .for_each(|w| *w = nalgebra::Vector3::zeros());
    r
}

/// The commanded motion's own ZMP (the links' masses and inertias, `plan_zmp_*`) on G1,
/// without the damping controller and the push. With the upper body and pelvis held the walk
/// is the cart-table's and its ZMP stays inside the pattern's polygon on every tick (as
/// MuJoCo's inverse dynamics of the same plan says); the dance's upper body takes it outside
/// on many single-support ticks, which the pattern's cart-table model does not see.
#[test]
fn the_plans_own_zmp_leaves_the_polygon_only_with_the_dance() {
    let profile = iktc::profile::RobotProfile::builtin("g1").unwrap();
    let robot = profile.robot().unwrap();
    let mut cfg = profile
        .walk_config(&robot, WalkImitateConfig::jvrc1().unwrap())
        .unwrap();
    cfg.damping = false;
    cfg.push = None;
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = profile.retarget_map("deepmimic", &robot).unwrap();
    let refs = iktc::sim::imitation_references(&robot, &clip, &map, &cfg.imitate).unwrap();
    let still = run_walk_imitate(&robot, &held(&refs), &cfg)
        .unwrap()
        .summary;
    let dance = run_walk_imitate(&robot, &refs, &cfg).unwrap().summary;
    eprintln!(
        "G1 plan ZMP outside (single, double): held {} {} (margin {:.4} m), dance {} {}",
        still.plan_zmp_outside_single,
        still.plan_zmp_outside_double,
        still.plan_zmp_min_margin,
        dance.plan_zmp_outside_single,
        dance.plan_zmp_outside_double
    );
    assert_eq!(
        (still.plan_zmp_outside_single, still.plan_zmp_outside_double),
        (0, 0)
    );
    assert!(still.plan_zmp_min_margin > 0.0);
    assert!(
        dance.plan_zmp_outside_single > 100,
        "{}",
        dance.plan_zmp_outside_single
    );
    // One pass of the ZMP correction moves the COM where the dance's ZMP leaves the polygon:
    // it is outside on far fewer ticks (0.2.0: 270 → 115 single-support, 54 → 22 double);
    // the held walk, already inside, is left as it was.
    let corrected = WalkImitateConfig {
        zmp_passes: 1,
        ..cfg.clone()
    };
    let fixed = run_walk_imitate(&robot, &refs, &corrected).unwrap().summary;
    let still2 = run_walk_imitate(&robot, &held(&refs), &corrected)
        .unwrap()
        .summary;
    eprintln!(
        "with one correction pass: dance {} {}, held {} {} (margin {:.4} m)",
        fixed.plan_zmp_outside_single,
        fixed.plan_zmp_outside_double,
        still2.plan_zmp_outside_single,
        still2.plan_zmp_outside_double,
        still2.plan_zmp_min_margin
    );
    assert!(
        2 * fixed.plan_zmp_outside_single < dance.plan_zmp_outside_single,
        "{} against {}",
        fixed.plan_zmp_outside_single,
        dance.plan_zmp_outside_single
    );
    assert_eq!(
        (
            still2.plan_zmp_outside_single,
            still2.plan_zmp_outside_double
        ),
        (0, 0)
    );
}

/// Passes of the ZMP correction on G1's dance (where the plan's own ZMP leaves the polygon):
/// at most `MAX_ZMP_PASSES` are accepted; the passes kept shrink the plan's largest ZMP move
/// `|Δp|` pass after pass (a pass that does not is undone and ends them); the run stays
/// finite and its measured ZMP inside the support polygon where it was without passes.
#[test]
fn zmp_correction_passes_stop_before_they_diverge() {
    use iktc::resources::MAX_ZMP_PASSES;
    let profile = iktc::profile::RobotProfile::builtin("g1").unwrap();
    let robot = profile.robot().unwrap();
    let mut cfg = profile
        .walk_config(&robot, WalkImitateConfig::jvrc1().unwrap())
        .unwrap();
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = profile.retarget_map("deepmimic", &robot).unwrap();
    let refs = iktc::sim::imitation_references(&robot, &clip, &map, &cfg.imitate).unwrap();
    cfg.zmp_passes = MAX_ZMP_PASSES + 1;
    match run_walk_imitate(&robot, &refs, &cfg) {
        Err(iktc::Error::InvalidSetting { name, .. }) => assert!(name.contains("zmp_passes")),
        other => panic!("{:?}", other.map(|_| ())),
    }
    cfg.zmp_passes = MAX_ZMP_PASSES;
    let s = run_walk_imitate(&robot, &refs, &cfg).unwrap().summary;
    let c = &s.zmp_corrections;
    eprintln!("ZMP correction |Δp| per pass [m]: {c:?}");
    assert!(!c.is_empty() && c.len() <= MAX_ZMP_PASSES);
    assert!(c.iter().all(|d| d.is_finite()), "{c:?}");
    // Every pass but the last shrank |Δp|; the last did too unless it ended the passes early.
    let kept = if c.len() < MAX_ZMP_PASSES && c.len() > 1 {
        c.len() - 1
    } else {
        c.len()
    };
    assert!(c[..kept].windows(2).all(|w| w[1] < w[0]), "{c:?}");
    // The measured ZMP stays inside wherever it did without the correction.
    cfg.zmp_passes = 0;
    let s0 = run_walk_imitate(&robot, &refs, &cfg).unwrap().summary;
    assert!(s.min_zmp_margin.is_finite());
    assert!(
        s.zmp_inside || !s0.zmp_inside,
        "ZMP outside by {} m with the passes, inside without",
        -s.min_zmp_margin
    );
}
