//! Robot profiles: glob locks, one error per profile key (each naming the key), the TOML round
//! trip, the starting profile guessed from a URDF.

use iktc::model::{jvrc1, JointRole, ModelOptions};
use iktc::profile::{
    builtin_profile_text, init_profile_toml, init_profile_toml_at, ProfileOrigin, RobotProfile,
    BUILTIN_PROFILES, DEFAULT_PUSH_VELOCITY_CHANGE,
};
use iktc::sim::{ImitateConfig, WalkImitateConfig};
use iktc::Error;

/// A JVRC-1 profile text with `extra` appended (built-in origin: the embedded URDF).
fn jvrc1_with(head: &str, extra: &str) -> String {
    format!(
        "name = \"t\"\nurdf = \"../robots/jvrc1/jvrc1.urdf\"\nbase = \"floating\"\n{head}\n\
         [feet.left]\nframe = \"l_ankle\"\nankle_height = 0.1\nsole = {{ length = 0.2, width = 0.1 }}\n\
         [feet.right]\nframe = \"r_ankle\"\nankle_height = 0.1\nsole = {{ length = 0.2, width = 0.1 }}\n\
         {extra}\n"
    )
}

fn parse(text: &str) -> iktc::Result<RobotProfile> {
    RobotProfile::from_toml_str(text, "test profile", ProfileOrigin::Builtin)
}

/// Parses and builds; returns the error.
fn build_error(text: &str) -> Error {
    match parse(text).and_then(|p| {
        let robot = p.robot()?;
        p.imitate_config(ImitateConfig::default())?;
        Ok(robot)
    }) {
        Ok(_) => panic!("expected an error for\n{text}"),
        Err(e) => e,
    }
}

fn assert_key(e: &Error, want_key: &str, want_value: &str, message_has: &str) {
    match e {
        Error::Profile {
            key,
            value,
            message,
        } => {
            assert_eq!(key, want_key, "{e}");
            assert_eq!(value, want_value, "{e}");
            assert!(message.contains(message_has), "`{message_has}` not in: {e}");
            assert!(e
                .to_string()
                .starts_with(&format!("profile key `{want_key}`")));
        }
        other => panic!("expected a profile error on `{want_key}`, got {other}"),
    }
}

#[test]
fn glob_locks_match_several_joints_and_equal_the_listed_locks() {
    let text = jvrc1_with(
        "[[lock]]\njoints = \"?_?THUMB\"\n[[lock]]\njoints = \"*INDEX\"\nvalue = 0.0\n[[lock]]\njoints = \"*LITTLE\"",
        "",
    );
    let robot = parse(&text).unwrap().robot().unwrap();
    let reference = jvrc1(&ModelOptions::default()).unwrap();
    assert_eq!(robot.nv(), 6 + 32);
    assert_eq!(robot.dof_names(), reference.dof_names());
    // Each pattern matched four joints: the two phalanges of a finger on both hands.
    for finger in ["THUMB", "INDEX", "LITTLE"] {
        let locked: Vec<&str> = robot
            .joints()
            .iter()
            .filter(|j| j.name.ends_with(finger) && matches!(j.role, JointRole::Locked { .. }))
            .map(|j| j.name.as_str())
            .collect();
        assert_eq!(locked.len(), 4, "{finger}: {locked:?}");
    }
}

#[test]
fn a_lock_value_is_applied_to_every_matched_joint() {
    let text = jvrc1_with("[[lock]]\njoints = \"?_ELBOW_?\"\nvalue = -0.5", "");
    let robot = parse(&text).unwrap().robot().unwrap();
    let locked: Vec<(String, f64)> = robot
        .joints()
        .iter()
        .filter_map(|j| match j.role {
            JointRole::Locked { value } => Some((j.name.clone(), value)),
            _ => None,
        })
        .collect();
    let mut names: Vec<&str> = locked.iter().map(|(n, _)| n.as_str()).collect();
    names.sort();
    assert_eq!(names, ["L_ELBOW_P", "L_ELBOW_Y", "R_ELBOW_P", "R_ELBOW_Y"]);
    assert!(locked.iter().all(|(_, v)| *v == -0.5));
}

#[test]
fn a_lock_pattern_matching_nothing_is_named() {
    let e = build_error(&jvrc1_with(
        "[[lock]]\njoints = \"*THUMB\"\n[[lock]]\njoints = \"*F??\"",
        "",
    ));
    assert_key(&e, "lock[1].joints", "*F??", "matches no movable joint");
    assert!(e.to_string().contains("R_HIP_P"), "lists the joints: {e}");
}

#[test]
fn every_frame_key_names_itself_and_the_valid_frames() {
    for (key, toml) in [
        ("feet.left.frame", None),
        ("feet.right.frame", None),
        ("frames.pelvis", Some("[frames]\npelvis = \"NOPE\"")),
        ("frames.torso", Some("[frames]\ntorso = \"NOPE\"")),
        ("frames.head", Some("[frames]\nhead = \"NOPE\"")),
        ("frames.left_hand", Some("[frames]\nleft_hand = \"NOPE\"")),
        ("frames.right_hand", Some("[frames]\nright_hand = \"NOPE\"")),
    ] {
        let text = match toml {
            Some(extra) => jvrc1_with("", extra),
            None => {
                let foot = if key.contains("left") {
                    "l_ankle"
                } else {
                    "r_ankle"
                };
                jvrc1_with("", "").replace(&format!("\"{foot}\""), "\"NOPE\"")
            }
        };
        let e = build_error(&text);
        assert_key(&e, key, "NOPE", "no such frame; frames are");
        assert!(e.to_string().contains("PELVIS_S"), "lists the frames: {e}");
    }
}

#[test]
fn every_joint_key_names_itself() {
    for (toml, key, value, says) in [
        (
            "[posture]\nR_KNEES = 0.3",
            "posture.R_KNEES",
            "R_KNEES",
            "no such active joint",
        ),
        // A locked joint is not active.
        (
            "[posture]\nR_UTHUMB = 0.3",
            "posture.R_UTHUMB",
            "R_UTHUMB",
            "no such active joint",
        ),
        (
            "[narrow]\nL_KNEES = [0.1, 0.2]",
            "narrow.L_KNEES",
            "L_KNEES",
            "no such active joint",
        ),
        (
            "[narrow]\nL_KNEE = [-5.0, 0.2]",
            "narrow.L_KNEE",
            "[-5, 0.2]",
            "inside the joint's own",
        ),
        (
            "[acceleration]\nlimits = { L_KNEES = 10.0 }",
            "acceleration.limits.L_KNEES",
            "L_KNEES",
            "no such movable joint",
        ),
        (
            "[jerk]\nlimits = { L_KNEES = 10.0 }",
            "jerk.limits.L_KNEES",
            "L_KNEES",
            "no such movable joint",
        ),
    ] {
        let head = "[[lock]]\njoints = \"*THUMB\"";
        let e = build_error(&jvrc1_with(head, toml));
        assert_key(&e, key, value, says);
    }
}

#[test]
fn every_number_key_names_itself() {
    let base = jvrc1_with("", "");
    for (from, to, key) in [
        (
            "ankle_height = 0.1\nsole = { length = 0.2, width = 0.1 }\n[feet.right]",
            "ankle_height = -0.1\nsole = { length = 0.2, width = 0.1 }\n[feet.right]",
            "feet.left.ankle_height",
        ),
        (
            "sole = { length = 0.2, width = 0.1 }\n[feet.right]",
            "sole = { length = 0.0, width = 0.1 }\n[feet.right]",
            "feet.left.sole.length",
        ),
        (
            "sole = { length = 0.2, width = 0.1 }\n\n",
            "sole = { length = 0.2, width = -1.0 }\n\n",
            "feet.right.sole.width",
        ),
    ] {
        assert!(base.contains(from), "{from}");
        let e = build_error(&base.replacen(from, to, 1));
        assert_key(&e, key, &e_value(&e), "expected");
    }
    for (extra, key) in [
        (
            "[acceleration]\nper_velocity = 0.0",
            "acceleration.per_velocity",
        ),
        ("[jerk]\nper_acceleration = -2.0", "jerk.per_acceleration"),
        ("[jerk]\nlimits = { L_KNEE = 0.0 }", "jerk.limits.L_KNEE"),
        ("[narrow]\nL_KNEE = [0.9, 0.5]", "narrow.L_KNEE"),
        ("[posture]\nL_KNEE = nan", "posture.L_KNEE"),
        ("[walk]\nssp_duration = 0.0", "walk.ssp_duration"),
        ("[walk]\ndsp_duration = -0.1", "walk.dsp_duration"),
        ("[walk]\nstep_length = nan", "walk.step_length"),
        ("[walk]\nswing_height = -0.01", "walk.swing_height"),
        (
            "[walk]\npush = { time = -1.0, impulse = [1.0, 0.0] }",
            "walk.push.time",
        ),
        (
            "[walk]\npush = { time = 1.0, impulse = [inf, 0.0] }",
            "walk.push.impulse",
        ),
    ] {
        let e = build_error(&jvrc1_with("", extra));
        assert_key(&e, key, &e_value(&e), "expected");
    }
}

fn e_value(e: &Error) -> String {
    match e {
        Error::Profile { value, .. } => value.clone(),
        _ => String::new(),
    }
}

#[test]
fn missing_keys_the_imitation_needs_are_named() {
    let no_feet = "name = \"t\"\nurdf = \"../robots/jvrc1/jvrc1.urdf\"\nbase = \"floating\"\n[frames]\npelvis = \"PELVIS_S\"\n";
    assert_key(&build_error(no_feet), "feet", "(missing)", "feet.left");
    let no_pelvis = jvrc1_with("", "");
    assert_key(
        &build_error(&no_pelvis),
        "frames.pelvis",
        "(missing)",
        "pelvis",
    );
    let right = "frame = \"r_ankle\"\nankle_height = 0.1\nsole = { length = 0.2, width = 0.1 }";
    let different = jvrc1_with("", "[frames]\npelvis = \"PELVIS_S\"")
        .replace(right, &right.replace("width = 0.1", "width = 0.12"));
    let e = build_error(&different);
    assert_key(&e, "feet.right.sole", &e_value(&e), "one sole");
    let g1 = RobotProfile::builtin("g1").unwrap();
    let robot = g1.robot().unwrap();
    let e = g1.retarget_map("bvh", &robot).unwrap_err();
    assert_key(&e, "imitate.maps.bvh", "(missing)", "deepmimic");
}

#[test]
fn the_urdf_key_and_unknown_keys_are_named() {
    let e = build_error(&jvrc1_with("", "").replace("jvrc1/jvrc1.urdf", "jvrc1/none.urdf"));
    assert_key(&e, "urdf", "../robots/jvrc1/none.urdf", "embedded files");
    let file = std::env::temp_dir().join(format!("iktc_profile_{}.toml", std::process::id()));
    std::fs::write(
        &file,
        jvrc1_with("", "").replace("jvrc1/jvrc1.urdf", "x/missing.urdf"),
    )
    .unwrap();
    let e = RobotProfile::load(&file).unwrap().robot().unwrap_err();
    std::fs::remove_file(&file).ok();
    assert_key(&e, "urdf", "../robots/x/missing.urdf", "cannot read");
    match parse(&jvrc1_with("", "[frames]\npelvs = \"PELVIS_S\"")) {
        Err(Error::Parse { line, message, .. }) => {
            assert!(message.contains("pelvs"), "{message}");
            assert_eq!(line, 14, "{message}");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn map_entries_with_unknown_joints_are_named() {
    // The JVRC-1 map applied to the G1: the first unknown joint, its entry and the valid ones.
    let g1 = RobotProfile::builtin("g1").unwrap();
    let robot = g1.robot().unwrap();
    let map = iktc::motion::builtin_map("deepmimic_jvrc1").unwrap();
    let e = iktc::profile::check_map_joints(&robot, &map).unwrap_err();
    let text = e.to_string();
    for part in [
        "deepmimic_jvrc1",
        "entry `chest`",
        "WAIST_Y",
        "waist_yaw_joint",
    ] {
        assert!(text.contains(part), "`{part}` not in {text}");
    }
}

#[test]
fn printed_profiles_parse_back_to_the_same_profile() {
    for name in BUILTIN_PROFILES {
        let p = RobotProfile::builtin(name).unwrap();
        let printed = p.to_toml_string().unwrap();
        let back = parse(&printed).unwrap();
        assert_eq!(back, p, "{name}:\n{printed}");
        // The commented text `iktc profile show` prints is the same profile too.
        let shown = parse(builtin_profile_text(name).unwrap()).unwrap();
        assert_eq!(shown, p);
        // And both build the robot.
        back.robot().unwrap();
    }
    assert!(matches!(
        RobotProfile::builtin("atlas"),
        Err(Error::UnknownName { .. })
    ));
}

#[test]
fn the_jvrc1_profile_gives_the_paper_settings() {
    let p = RobotProfile::builtin("jvrc1").unwrap();
    let cfg = p.imitate_config(ImitateConfig::default()).unwrap();
    let paper = ImitateConfig::jvrc1();
    assert_eq!(cfg.feet, paper.feet);
    assert_eq!(cfg.pelvis, paper.pelvis);
    assert_eq!(cfg.support, paper.support);
    let sorted = |mut v: Vec<(String, f64)>| {
        v.sort_by(|a, b| a.0.cmp(&b.0));
        v
    };
    assert_eq!(sorted(cfg.initial_posture), sorted(paper.initial_posture));
    // TOML tables carry no order: the profile's narrowed joints come sorted by name.
    let mut narrow = paper.narrow.clone();
    narrow.sort_by(|a, b| a.joint.cmp(&b.joint));
    assert_eq!(cfg.narrow, narrow);
}

#[test]
fn init_guesses_the_g1_feet_pelvis_and_hands_and_marks_them() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/data/robots/g1");
    let text = std::fs::read_to_string(format!("{dir}/g1_29dof_rev_1_0.urdf")).unwrap();
    let toml = init_profile_toml(&text, "g1_29dof_rev_1_0.urdf").unwrap();
    assert!(toml.matches("# guessed").count() >= 8, "{toml}");
    let p =
        RobotProfile::from_toml_str(&toml, "init", ProfileOrigin::Directory(dir.into())).unwrap();
    let feet = p.feet.clone().unwrap();
    assert_eq!(feet.left.frame, "left_ankle_roll_link");
    assert_eq!(feet.right.frame, "right_ankle_roll_link");
    // The four contact spheres (radius 5 mm) at x = -0.05, 0.12 m, y = ±0.025, ±0.03 m,
    // z = -0.03 m: contact points 0.035 m below the ankle.
    let s = feet.left.sole;
    assert!(
        (s.length - 0.17).abs() < 1e-12 && (s.width - 0.06).abs() < 1e-12,
        "{s:?}"
    );
    assert!((s.offset_x - 0.035).abs() < 1e-12 && (feet.left.ankle_height - 0.035).abs() < 1e-12);
    assert_eq!(p.frames.pelvis.as_deref(), Some("pelvis"));
    assert_eq!(p.frames.torso.as_deref(), Some("torso_link"));
    assert_eq!(p.frames.head.as_deref(), Some("head_link"));
    assert_eq!(p.frames.left_hand.as_deref(), Some("left_rubber_hand"));
    assert_eq!(p.frames.right_hand.as_deref(), Some("right_rubber_hand"));
    assert_eq!(p.robot().unwrap().nv(), 6 + 29);
}

#[test]
fn init_on_jvrc1_finds_its_ankles_and_fingers() {
    let toml = init_profile_toml(iktc::model::JVRC1_URDF, "../robots/jvrc1/jvrc1.urdf").unwrap();
    let p = parse(&toml).unwrap();
    let feet = p.feet.clone().unwrap();
    assert_eq!(
        (feet.left.frame.as_str(), feet.right.frame.as_str()),
        ("l_ankle", "r_ankle")
    );
    assert!(
        toml.contains("PLACEHOLDER"),
        "no collision geometry on the ankles: {toml}"
    );
    assert_eq!(p.lock.len(), 12, "{toml}");
    assert_eq!(p.robot().unwrap().nv(), 6 + 32);
}

#[test]
fn walking_settings_come_from_the_profile_and_the_default_push_scales_with_the_mass() {
    let base = WalkImitateConfig::jvrc1().unwrap();
    // Every walking key given: each lands in the walking settings.
    let p = parse(&jvrc1_with(
        "",
        "[frames]\npelvis = \"PELVIS_S\"\n[walk]\nstep_length = 0.07\nswing_height = 0.03\nssp_duration = 0.5\n\
         dsp_duration = 0.2\npush = { time = 1.5, impulse = [1.0, -2.0] }",
    ))
    .unwrap();
    let robot = p.robot().unwrap();
    // From a base whose imitation knows no robot: the profile's feet and pelvis come in.
    let blank = WalkImitateConfig {
        imitate: ImitateConfig {
            feet: Vec::new(),
            pelvis: String::new(),
            ..ImitateConfig::default()
        },
        ..base.clone()
    };
    let cfg = p.walk_config(&robot, blank).unwrap();
    assert_eq!(cfg.step_length, 0.07);
    assert_eq!(cfg.walk.swing_height, 0.03);
    assert_eq!(cfg.walk.ssp_duration, 0.5);
    assert_eq!(cfg.walk.dsp_duration, 0.2);
    let push = cfg.push.unwrap();
    assert_eq!((push.time, push.impulse), (1.5, [1.0, -2.0]));
    // The imitation's robot-specific fields are the profile's.
    assert_eq!(
        cfg.imitate.feet,
        vec!["r_ankle".to_string(), "l_ankle".into()]
    );
    // A base without a push stays without one.
    let none = p
        .walk_config(
            &robot,
            WalkImitateConfig {
                push: None,
                ..base.clone()
            },
        )
        .unwrap();
    assert_eq!(none.push, None);

    // No key: the default push changes the COM velocity by the same Δv on any robot,
    // Δv = impulse / m, with m summed here from the URDF's links.
    for name in ["g1", "jvrc1"] {
        let p = RobotProfile::builtin(name).unwrap();
        let robot = p.robot().unwrap();
        let mut bare = p.clone();
        bare.walk = Default::default();
        let mass: f64 = robot.links().iter().map(|l| l.mass).sum();
        let push = bare
            .walk_config(&robot, base.clone())
            .unwrap()
            .push
            .unwrap();
        let dv = push.impulse[0] / mass;
        assert!(
            (dv - DEFAULT_PUSH_VELOCITY_CHANGE).abs() < 1e-12,
            "{name}: Δv {dv} m/s"
        );
        assert_eq!(push.impulse[1], 0.0);
        if name == "jvrc1" {
            // Without its key, JVRC-1 still gets the paper's push: 5 N·s on its 62.4 kg.
            assert!((push.impulse[0] - 5.0).abs() < 1e-3, "{}", push.impulse[0]);
        }
    }
    // The built-in JVRC-1 profile states the paper's 5 N·s.
    let p = RobotProfile::builtin("jvrc1").unwrap();
    let cfg = p.walk_config(&p.robot().unwrap(), base).unwrap();
    assert_eq!(cfg.push.unwrap().impulse, [5.0, 0.0]);
}

/// `jerk.per_acceleration` scales every joint's acceleration limit; `jerk.limits` overrides
/// one joint; without the key no joint has a jerk limit. Checked against the robot's own
/// acceleration limits.
#[test]
fn jerk_limits_come_from_the_profile() {
    let plain = parse(&jvrc1_with("", "")).unwrap().robot().unwrap();
    let limits = iktc::limits::JointLimits::from_robot(&plain).unwrap();
    assert!(!limits.has_jerk_limits());
    let text = jvrc1_with(
        "",
        "[jerk]\nper_acceleration = 20.0\nlimits = { L_KNEE = 3000.0 }",
    );
    let robot = parse(&text).unwrap().robot().unwrap();
    let limits = iktc::limits::JointLimits::from_robot(&robot).unwrap();
    let knee = robot.joint_v_index("L_KNEE").unwrap();
    for (i, d) in limits.dofs().iter().enumerate() {
        if i < robot.base_nv() {
            assert_eq!(d.jerk_max, f64::INFINITY);
        } else if i == knee {
            assert_eq!(d.jerk_max, 3000.0);
        } else {
            assert_eq!(d.jerk_max, 20.0 * d.acceleration_max, "dof {i}");
        }
    }
    // Printed and read back, the key survives.
    let p = parse(&text).unwrap();
    assert_eq!(parse(&p.to_toml_string().unwrap()).unwrap().jerk, p.jerk);
}

/// A binary STL of the axis-aligned box `[lo, hi]` \[m\] (12 triangles).
fn box_stl(lo: [f32; 3], hi: [f32; 3]) -> Vec<u8> {
    let c = |i: usize| -> [f32; 3] {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    let faces = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    let mut out = vec![0u8; 80];
    out.extend_from_slice(&12u32.to_le_bytes());
    for f in faces {
        for t in [[f[0], f[1], f[2]], [f[0], f[2], f[3]]] {
            out.extend_from_slice(&[0u8; 12]);
            for i in t {
                for x in c(i) {
                    out.extend_from_slice(&x.to_le_bytes());
                }
            }
            out.extend_from_slice(&[0u8; 2]);
        }
    }
    out
}

/// Feet without collision boxes or spheres: their soles come from their meshes in the URDF's
/// folder (the collision mesh before the visual one), to 0.1 mm; without the folder they are
/// placeholders as before.
#[test]
fn init_guesses_the_soles_from_the_feet_meshes() {
    let dir = std::env::temp_dir().join(format!("iktc-init-meshes-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    // Visual: a 0.22 × 0.09 m foot 0.04 m below the ankle, 0.02 m ahead of it; collision: a
    // 0.2 × 0.08 m box 0.05 m below, 0.03 m ahead (the one taken).
    std::fs::write(
        dir.join("meshes/visual.stl"),
        box_stl([-0.09, -0.045, -0.04], [0.13, 0.045, 0.01]),
    )
    .unwrap();
    std::fs::write(
        dir.join("meshes/collision.stl"),
        box_stl([-0.07, -0.04, -0.05], [0.13, 0.04, 0.0]),
    )
    .unwrap();
    let foot = |side: &str, collision: bool| {
        format!(
            r#"<link name="{side}_foot"><visual><geometry><mesh filename="meshes/visual.stl"/></geometry></visual>{}</link>
  <joint name="{side}_ankle" type="revolute"><parent link="pelvis"/><child link="{side}_foot"/><axis xyz="0 1 0"/>
    <origin xyz="0 {} -0.6"/><limit lower="-1" upper="1" velocity="5" effort="10"/></joint>"#,
            if collision {
                r#"<collision><geometry><mesh filename="package://robot_description/meshes/collision.stl"/></geometry></collision>"#
            } else {
                ""
            },
            if side == "left" { 0.1 } else { -0.1 }
        )
    };
    for collision in [true, false] {
        let urdf = format!(
            "<robot name=\"r\"><link name=\"pelvis\"/>{}{}</robot>",
            foot("left", collision),
            foot("right", collision)
        );
        let toml = init_profile_toml_at(&urdf, "r.urdf", Some(&dir)).unwrap();
        let p = parse(&toml).unwrap();
        let feet = p.feet.clone().unwrap();
        let want = if collision {
            (0.2, 0.08, 0.03, 0.05, "from the collision geometry")
        } else {
            (0.22, 0.09, 0.02, 0.04, "from the visual geometry")
        };
        for f in [&feet.left, &feet.right] {
            let got = (f.sole.length, f.sole.width, f.sole.offset_x, f.ankle_height);
            assert_eq!(got, (want.0, want.1, want.2, want.3), "{toml}");
        }
        assert!(toml.contains(want.4), "{toml}");
        let bare = init_profile_toml(&urdf, "r.urdf").unwrap();
        assert!(bare.contains("PLACEHOLDER"), "{bare}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A frame the profile adds (key `frame`) sits at its offset in its parent, for every
/// configuration (checked against the parent's pose); the other keys can name it; a wrong
/// parent, a taken name or a non-finite offset is an error naming the key.
#[test]
fn added_frames_sit_at_their_offset_and_bad_ones_name_their_key() {
    use iktc::model::{Kinematics, State};
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
    let text = jvrc1_with(
        "[[frame]]\nname = \"l_tip\"\nparent = \"L_ELBOW_Y_S\"\nxyz = [0.1, -0.02, -0.25]\nrpy = [0.3, -0.2, 0.1]\n\
         [[frame]]\nname = \"l_tip2\"\nparent = \"l_tip\"\nxyz = [0.0, 0.0, 0.05]\n",
        "[frames]\npelvis = \"PELVIS_S\"\nleft_hand = \"l_tip2\"\nright_hand = \"R_WRIST_Y_S\"",
    );
    let p = parse(&text).unwrap();
    let robot = p.robot().unwrap();
    let mut state = State::neutral(&robot);
    for (k, q) in state.q.iter_mut().enumerate().skip(7) {
        *q = 0.3 * ((k as f64) * 1.7).sin();
    }
    let kin = Kinematics::new(&robot, &state).unwrap();
    let parent = kin
        .frame_pose(&robot, robot.frame_id("L_ELBOW_Y_S").unwrap())
        .unwrap();
    let offset = Isometry3::from_parts(
        Translation3::new(0.1, -0.02, -0.25),
        UnitQuaternion::from_euler_angles(0.3, -0.2, 0.1),
    );
    let tip = kin
        .frame_pose(&robot, robot.frame_id("l_tip").unwrap())
        .unwrap();
    let want = parent * offset;
    assert!((tip.translation.vector - want.translation.vector).norm() < 1e-12);
    assert!(tip.rotation.angle_to(&want.rotation) < 1e-12);
    // A frame on an added frame: 5 cm along the first one's z axis.
    let tip2 = kin
        .frame_pose(&robot, robot.frame_id("l_tip2").unwrap())
        .unwrap();
    let d = tip2.translation.vector - tip.translation.vector;
    assert!((d - tip.rotation * Vector3::new(0.0, 0.0, 0.05)).norm() < 1e-12);
    // The hands' key takes it.
    assert_eq!(p.frames.left_hand.as_deref(), Some("l_tip2"));
    for (frame, key, what) in [
        (
            "name = \"x\"\nparent = \"NOPE\"",
            "frame[0].parent",
            "valid names are (nearest first):",
        ),
        (
            "name = \"PELVIS_S\"\nparent = \"L_ELBOW_Y_S\"",
            "frame[0].name",
            "no link or frame",
        ),
        (
            "name = \"x\"\nparent = \"L_ELBOW_Y_S\"\nxyz = [0.0, nan, 0.0]",
            "frame[0].xyz",
            "finite",
        ),
    ] {
        let e = build_error(&jvrc1_with(&format!("[[frame]]\n{frame}\n"), "")).to_string();
        assert!(e.contains(key) && e.contains(what), "{e}");
    }
}

/// A robot without hand links (Unitree H1's arms end at the elbow link): `profile init` adds a
/// hand frame at the far end of each forearm, from its mesh when the folder is known, else at
/// twice its centre of mass; the profile builds and names them as the hands.
#[test]
fn init_adds_hand_frames_at_the_end_of_bare_forearms() {
    let dir = std::env::temp_dir().join(format!("iktc-init-hands-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    // The forearm mesh: from the elbow to 0.28 m along x, 3 cm thick.
    std::fs::write(
        dir.join("meshes/forearm.stl"),
        box_stl([-0.02, -0.015, -0.015], [0.28, 0.015, 0.015]),
    )
    .unwrap();
    let side = |s: &str, y: f64| {
        format!(
            r#"<link name="{s}_ankle_link"><collision><origin xyz="0.05 0 -0.05"/><geometry><box size="0.2 0.08 0.02"/></geometry></collision></link>
  <joint name="{s}_ankle_joint" type="revolute"><parent link="pelvis"/><child link="{s}_ankle_link"/><axis xyz="0 1 0"/>
    <origin xyz="0 {y} -0.8"/><limit lower="-1" upper="1" velocity="5" effort="10"/></joint>
  <link name="{s}_elbow_link"><inertial><origin xyz="0.12 0 0"/><mass value="0.5"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
    <visual><geometry><mesh filename="meshes/forearm.stl"/></geometry></visual></link>
  <joint name="{s}_elbow_joint" type="revolute"><parent link="torso_link"/><child link="{s}_elbow_link"/><axis xyz="0 1 0"/>
    <origin xyz="0 {y} 0.3"/><limit lower="-1" upper="1" velocity="5" effort="10"/></joint>"#
        )
    };
    let urdf = format!(
        r#"<robot name="h"><link name="pelvis"/><link name="torso_link"/>
  <joint name="torso_joint" type="revolute"><parent link="pelvis"/><child link="torso_link"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="5" effort="10"/></joint>{}{}</robot>"#,
        side("left", 0.2),
        side("right", -0.2)
    );
    std::fs::write(dir.join("h.urdf"), &urdf).unwrap();
    for (folder, x, why) in [
        (
            Some(dir.as_path()),
            0.28,
            "farthest point of its visual geometry",
        ),
        (None, 0.24, "twice its centre of mass"),
    ] {
        let toml = init_profile_toml_at(&urdf, "h.urdf", folder).unwrap();
        assert!(toml.contains(why), "{toml}");
        let p = RobotProfile::from_toml_str(&toml, "init", ProfileOrigin::Directory(dir.clone()))
            .unwrap();
        assert_eq!(p.added_frames.len(), 2, "{toml}");
        for (f, parent) in p
            .added_frames
            .iter()
            .zip(["left_elbow_link", "right_elbow_link"])
        {
            assert_eq!(f.parent, parent);
            assert!(
                (f.xyz[0] - x).abs() < 1e-9 && f.xyz[1].abs() <= 0.015,
                "{:?}",
                f.xyz
            );
        }
        assert_eq!(p.frames.left_hand.as_deref(), Some("left_hand"));
        assert_eq!(p.frames.right_hand.as_deref(), Some("right_hand"));
        let robot = p.robot().unwrap();
        assert!(robot.frame_id("left_hand").is_ok() && robot.frame_id("right_hand").is_ok());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
