//! The Unitree G1 (29 joints): model facts counted from the URDF text independently of the
//! parser, and the imitation and walking runs from its built-in profile keeping every limit.

use iktc::model::{Kinematics, State, G1_URDF};
use iktc::motion::{builtin_clip, RobotReferences, Track};
use iktc::profile::RobotProfile;
use iktc::sim::{
    imitation_references, run_imitate, run_walk_imitate, ImitateConfig, WalkImitateConfig,
};

/// The URDF text without its `<!-- … -->` comments (the G1 file comments out a floating joint).
fn without_comments(mut s: &str) -> String {
    let mut out = String::new();
    while let Some(a) = s.find("<!--") {
        out.push_str(&s[..a]);
        s = s[a..].find("-->").map_or("", |b| &s[a + b + 3..]);
    }
    out.push_str(s);
    out
}

/// The values of `attr="…"` inside every `<tag …>` element opening.
fn attribute_values(xml: &str, tag: &str, attr: &str) -> Vec<String> {
    xml.split(&format!("<{tag} "))
        .skip(1)
        .filter_map(|rest| {
            let head = &rest[..rest.find('>').unwrap_or(rest.len())];
            let key = format!("{attr}=\"");
            let i = head.find(&key)? + key.len();
            Some(head[i..i + head[i..].find('"')?].to_string())
        })
        .collect()
}

#[test]
fn g1_model_facts_match_a_scan_of_the_urdf() {
    let xml = without_comments(G1_URDF);
    let types = attribute_values(&xml, "joint", "type");
    let revolute = types.iter().filter(|t| *t == "revolute").count();
    let fixed = types.iter().filter(|t| *t == "fixed").count();
    assert_eq!(revolute, 29);
    assert_eq!(
        types.len(),
        revolute + fixed,
        "only revolute and fixed joints: {types:?}"
    );
    let mass: f64 = attribute_values(&xml, "mass", "value")
        .iter()
        .map(|v| v.parse::<f64>().unwrap())
        .sum();
    let links = attribute_values(&xml, "link", "name").len();

    let profile = RobotProfile::builtin("g1").unwrap();
    let robot = profile.robot().unwrap();
    assert_eq!(robot.nq(), 7 + revolute);
    assert_eq!(robot.nv(), 6 + revolute);
    assert_eq!(robot.links().len(), links);
    assert!(
        (robot.total_mass() - mass).abs() < 1e-9 * mass,
        "{} vs {mass}",
        robot.total_mass()
    );
    // The G1's inertials add up to 33.3 kg (its datasheet's 35 kg includes parts not modelled).
    assert!((33.0..34.0).contains(&mass), "{mass}");

    // Kinematic sanity at the zero posture: the feet 0.23 m apart (hip offsets ±0.1165 m),
    // level, below the pelvis by the leg length; the COM between the feet.
    let kin = Kinematics::new(&robot, &State::neutral(&robot)).unwrap();
    let pose = |f: &str| kin.frame_pose(&robot, robot.frame_id(f).unwrap()).unwrap();
    let (l, r, p) = (
        pose("left_ankle_roll_link"),
        pose("right_ankle_roll_link"),
        pose("pelvis"),
    );
    // Lateral offsets of the left leg's joint origins (hip pitch, hip roll, knee, ankle pitch).
    let half = 0.064452 + 0.052 + 0.0021489 - 9.4445e-5;
    assert!((l.translation.y - r.translation.y - 2.0 * half).abs() < 1e-9);
    assert!(l.rotation.angle() < 1e-9 && r.rotation.angle() < 1e-9);
    // Pelvis → hip roll: 0.1027 + 0.030465 down; the thigh (hip yaw + knee origins) in the hip
    // roll frame, pitched by -0.1749 rad: z' = -x sin(θ) + z cos(θ); the knee's +0.1749 rad
    // cancels it, so the shank (0.30001 + 0.017558) is vertical.
    let (x, z, th) = (0.025001 - 0.078273, -0.12412 - 0.17734, -0.1749_f64);
    let thigh = -(-x * th.sin() + z * th.cos());
    let leg = 0.1027 + 0.030465 + thigh + 0.30001 + 0.017558;
    let drop = p.translation.z - l.translation.z;
    assert!((drop - leg).abs() < 1e-9, "{drop} vs {leg}");
    let com = kin.com();
    assert!(com.y.abs() < 0.01 && com.y < l.translation.y && com.y > r.translation.y);
}

/// The first `n` ticks of `r`.
fn first_ticks(r: &RobotReferences, n: usize) -> RobotReferences {
    let cut = |t: &Track| Track {
        position: t.position[..n].to_vec(),
        velocity: t.velocity[..n].to_vec(),
        acceleration: t.acceleration[..n].to_vec(),
    };
    RobotReferences {
        dt: r.dt,
        times: r.times[..n].to_vec(),
        joint_names: r.joint_names.clone(),
        joints: r.joints.iter().map(cut).collect(),
        height: cut(&r.height),
        angles: [cut(&r.angles[0]), cut(&r.angles[1]), cut(&r.angles[2])],
        attitude: r.attitude[..n].to_vec(),
        angular_velocity: r.angular_velocity[..n].to_vec(),
        angular_acceleration: r.angular_acceleration[..n].to_vec(),
    }
}

/// Largest excursion past a limit the runs may show (margins > 0 exceed) \[rad, rad/s, rad/s²\]:
/// rounding only.
const LIMIT_SLACK: f64 = 1e-9;

#[test]
fn g1_imitates_the_default_clip_within_its_limits() {
    let profile = RobotProfile::builtin("g1").unwrap();
    let robot = profile.robot().unwrap();
    let map = profile.retarget_map("deepmimic", &robot).unwrap();
    let cfg = profile.imitate_config(ImitateConfig::default()).unwrap();
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let refs = imitation_references(&robot, &clip, &map, &cfg).unwrap();
    // The first second of the clip (200 ticks).
    let refs = first_ticks(&refs, 200);
    let run = run_imitate(&robot, &refs, &cfg).unwrap();
    let s = &run.summary;
    assert_eq!(s.steps, 200);
    assert_eq!(s.nv, 35);
    for (what, m) in [
        ("position", s.worst_position_margin),
        ("velocity", s.worst_velocity_margin),
        ("acceleration", s.worst_acceleration_margin),
    ] {
        assert!(m <= LIMIT_SLACK, "{what} margin {m} (> 0: exceeded)");
    }
    // The feet hold (first level), the COM stays over the soles.
    assert!(s.foot_drift < 1e-3, "foot drift {} m", s.foot_drift);
    assert!(s.com_inside_support, "COM margin {}", s.com_min_margin);
    // The arms move: the upper-body level tracks the retargeted references.
    let moved = run
        .steps
        .iter()
        .map(|st| st.q[robot.joint_v_index("left_shoulder_pitch_joint").unwrap()])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q), b.max(q))
        });
    assert!(
        moved.1 - moved.0 > 0.1,
        "left shoulder pitch range {moved:?}"
    );
}

#[test]
fn g1_walks_while_imitating_within_its_limits() {
    let profile = RobotProfile::builtin("g1").unwrap();
    let robot = profile.robot().unwrap();
    let map = profile.retarget_map("deepmimic", &robot).unwrap();
    let mut cfg = WalkImitateConfig::jvrc1().unwrap();
    cfg.imitate = profile.imitate_config(cfg.imitate).unwrap();
    cfg.steps = 2;
    cfg.push = None;
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let refs = iktc::motion::retarget_joint_angles(&clip, &robot, &map)
        .unwrap()
        .resample(cfg.imitate.dt)
        .unwrap();
    let run = run_walk_imitate(&robot, &refs, &cfg).unwrap();
    let s = &run.summary;
    for m in s.worst_margins {
        assert!(
            m <= LIMIT_SLACK,
            "margins {:?} (> 0: exceeded)",
            s.worst_margins
        );
    }
    assert!(
        s.max_stance_foot_error < 0.01,
        "stance foot error {}",
        s.max_stance_foot_error
    );
    assert!(s.zmp_inside, "ZMP margin {}", s.min_zmp_margin);
}
