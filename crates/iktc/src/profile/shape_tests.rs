//! `iktc profile init` on humanoids whose link names say nothing: the parts are found from
//! the tree's shape, checked against the values the synthetic URDFs were built with.

use crate::model::RobotFiles;
use nalgebra::Vector3;

use super::{init_profile_toml, init_profile_toml_with, InitOptions, Sole};
use crate::model::{BaseKind, Kinematics, ModelOptions, Robot, State};
use crate::profile::init::CROUCH;

/// A joint of the synthetic humanoid: parent, child, kind, origin `xyz` \[m\], axis.
struct J<'a>(&'a str, &'a str, &'a str, [f64; 3], [f64; 3]);

/// Which synthetic humanoid.
#[derive(Clone, Copy)]
struct Build {
    /// Movable joints per leg (5, 6 or 7).
    leg: usize,
    /// Two fingers on each hand, a neck joint, five arm joints; else four arm joints ending at
    /// the elbow and a head fixed to the torso.
    hands: bool,
    /// The foot's collision shape: a box 0.22 × 0.1 × 0.03 m centred 0.04 m ahead of and
    /// 0.05 m below the ankle; else a cylinder of radius 0.05 m, 0.02 m long, centred 0.03 m
    /// ahead and 0.04 m below; else a box 0.2 × 0.04 × 0.02 m centred 0.05 m below.
    foot: u8,
}

/// Link names `l<k>` handed out in the order the links are made (right side first, so the
/// file's order says nothing about the sides either).
struct Names(usize);

impl Names {
    fn next(&mut self) -> String {
        self.0 += 1;
        format!("l{}", self.0)
    }
}

fn link(name: &str, extra: &str) -> String {
    format!(
        r#"<link name="{name}"><inertial><origin xyz="0 0 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>{extra}</link>"#
    )
}

fn joint(k: usize, j: &J) -> String {
    let J(parent, child, kind, o, a) = j;
    let limit = match *kind {
        "fixed" => String::new(),
        // The knees (axis y, named in the kind) bend one way.
        "knee" => {
            r#"<axis xyz="0 1 0"/><limit lower="0" upper="2.5" velocity="5" effort="10"/>"#.into()
        }
        _ => format!(
            r#"<axis xyz="{} {} {}"/><limit lower="-1.5" upper="1.5" velocity="5" effort="10"/>"#,
            a[0], a[1], a[2]
        ),
    };
    let kind = if *kind == "knee" { "revolute" } else { kind };
    format!(
        r#"<joint name="j{k}" type="{kind}"><origin xyz="{} {} {}"/><parent link="{parent}"/><child link="{child}"/>{limit}</joint>"#,
        o[0], o[1], o[2]
    )
}

/// A joint as built: parent, child, kind, origin \[m\], axis.
type Joint = (String, String, &'static str, [f64; 3], [f64; 3]);

/// The hand-known parts of a synthetic humanoid, `[left, right]` where paired.
#[derive(Debug)]
struct Known {
    pelvis: String,
    torso: String,
    head: String,
    feet: [String; 2],
    hips: [String; 2],
    hands: [String; 2],
}

/// A humanoid: pelvis `l1` at the root, a waist joint to the torso 0.2 m up; legs from
/// y = ±0.1 m, 0.1 m below the pelvis, thighs and shanks 0.4 m; arms from y = ±0.2 m, 0.3 m
/// above the torso, upper arm and forearm 0.25 m; see [`Build`].
fn humanoid(b: Build) -> (String, Known) {
    let mut n = Names(1);
    let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let mut joints: Vec<Joint> = Vec::new();
    let mut extra: Vec<(String, String)> = Vec::new();
    let torso = n.next();
    joints.push(("l1".into(), torso.clone(), "revolute", [0.0, 0.0, 0.2], z));
    let (mut feet, mut hips, mut hands) = (Vec::new(), Vec::new(), Vec::new());
    for side in [-1.0, 1.0] {
        // Hip yaw, roll, pitch (the 5-joint leg has no yaw), knee, ankle pitch, roll; the
        // 7-joint leg an ankle yaw before them.
        let mut leg: Vec<(&str, [f64; 3], [f64; 3])> = Vec::new();
        if b.leg >= 6 {
            leg.push(("revolute", [0.0, 0.1 * side, -0.1], z));
        }
        let first = [
            0.0,
            if b.leg >= 6 { 0.0 } else { 0.1 * side },
            if b.leg >= 6 { 0.0 } else { -0.1 },
        ];
        leg.push(("revolute", first, x));
        leg.push(("revolute", [0.0; 3], y));
        leg.push(("knee", [0.0, 0.0, -0.4], y));
        if b.leg == 7 {
            leg.push(("revolute", [0.0, 0.0, -0.4], z));
            leg.push(("revolute", [0.0; 3], y));
        } else {
            leg.push(("revolute", [0.0, 0.0, -0.4], y));
        }
        leg.push(("revolute", [0.0; 3], x));
        let mut parent = "l1".to_string();
        for (k, (kind, o, a)) in leg.into_iter().enumerate() {
            let child = n.next();
            if k == 0 {
                hips.push(child.clone());
            }
            joints.push((parent, child.clone(), kind, o, a));
            parent = child;
        }
        let shape = match b.foot {
            0 => {
                r#"<collision><origin xyz="0.04 0 -0.05"/><geometry><box size="0.22 0.1 0.03"/></geometry></collision>"#
            }
            1 => {
                r#"<collision><origin xyz="0.03 0 -0.04"/><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision>"#
            }
            _ => {
                r#"<collision><origin xyz="0 0 -0.05"/><geometry><box size="0.2 0.04 0.02"/></geometry></collision>"#
            }
        };
        extra.push((parent.clone(), shape.to_string()));
        feet.push(parent);
        // Arms: shoulder pitch, roll, yaw, elbow, (wrist yaw, two fingers).
        let mut parent = torso.clone();
        let mut arm: Vec<(&str, [f64; 3], [f64; 3])> = vec![
            ("revolute", [0.0, 0.2 * side, 0.3], y),
            ("revolute", [0.0; 3], x),
            ("revolute", [0.0, 0.0, -0.25], z),
            ("revolute", [0.0; 3], y),
        ];
        if b.hands {
            arm.push(("revolute", [0.0, 0.0, -0.25], z));
        }
        for (kind, o, a) in arm {
            let child = n.next();
            joints.push((parent, child.clone(), kind, o, a));
            parent = child;
        }
        if b.hands {
            for fx in [-0.02, 0.02] {
                let finger = n.next();
                joints.push((parent.clone(), finger, "revolute", [fx, 0.0, -0.05], y));
            }
            hands.push(parent);
        } else {
            // A forearm without a hand: its centre of mass 0.12 m along it.
            extra.push((parent.clone(), "com 0 0 -0.12".into()));
            hands.push("left_hand".into());
        }
    }
    // The head: a neck joint above the torso, else a link fixed there (and an IMU below it).
    let head = n.next();
    if b.hands {
        joints.push((torso.clone(), head.clone(), "revolute", [0.0, 0.0, 0.35], z));
    } else {
        joints.push((torso.clone(), head.clone(), "fixed", [0.0, 0.0, 0.4], z));
        let imu = n.next();
        joints.push((torso.clone(), imu, "fixed", [0.0, 0.0, 0.05], z));
    }
    let mut x = String::from(r#"<robot name="anonymous">"#);
    let mut links = vec!["l1".to_string()];
    links.extend(joints.iter().map(|j| j.1.clone()));
    for l in &links {
        let mut body = String::new();
        for (owner, e) in &extra {
            if owner == l {
                if let Some(c) = e.strip_prefix("com ") {
                    body = format!(
                        r#"<inertial><origin xyz="{c}"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>"#
                    );
                }
            }
        }
        let shapes: String = extra
            .iter()
            .filter(|(o, e)| o == l && !e.starts_with("com "))
            .map(|(_, e)| e.clone())
            .collect();
        if body.is_empty() {
            x += &link(l, &shapes);
        } else {
            x += &format!(r#"<link name="{l}">{body}{shapes}</link>"#);
        }
    }
    for (k, (p, c, kind, o, a)) in joints.iter().enumerate() {
        x += &joint(k + 1, &J(p, c, kind, *o, *a));
    }
    x += "</robot>";
    let hands = if b.hands {
        [hands[1].clone(), hands[0].clone()]
    } else {
        ["left_hand".into(), "right_hand".into()]
    };
    let known = Known {
        pelvis: "l1".into(),
        torso,
        head,
        feet: [feet[1].clone(), feet[0].clone()],
        hips: [hips[1].clone(), hips[0].clone()],
        hands,
    };
    (x, known)
}

/// The value (a string's text, unquoted) of `key` in table `table` of the written profile.
fn value(toml: &str, table: &str, key: &str) -> Option<String> {
    let block = toml.split(&format!("\n[{table}]\n")).nth(1)?;
    let block = block.split("\n[").next()?;
    block.lines().find_map(|l| {
        let (k, v) = l.split_once(" = ")?;
        (k == key).then(|| {
            let v = v.split(" # ").next().unwrap_or(v).trim();
            v.trim_matches('"').to_string()
        })
    })
}

/// The `[posture]` entries of a written profile.
fn posture(toml: &str) -> Vec<(String, f64)> {
    let block = toml.split("[posture]\n").nth(1).unwrap();
    block
        .split("\n\n")
        .next()
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let (k, v) = l.split_once(" = ").unwrap();
            (k.trim_matches('"').to_string(), v.parse().unwrap())
        })
        .collect()
}

/// Checks the guessed posture by the kinematics: each foot `CROUCH` of its leg's length higher
/// relative to the base, straight above where it was, and kept level (its z axis vertical).
fn check_posture(urdf: &str, toml: &str, k: &Known, per_leg: usize) {
    let values = posture(toml);
    assert_eq!(values.len(), 2 * per_leg, "{toml}");
    let options = ModelOptions {
        base: BaseKind::Floating,
        ..ModelOptions::default()
    };
    let robot = Robot::from_urdf_str(urdf, &options).unwrap();
    let zero = State::neutral(&robot);
    let mut bent = zero.clone();
    for (name, v) in &values {
        bent.set_joint(&robot, name, *v).unwrap();
    }
    let (k0, k1) = (
        Kinematics::new(&robot, &zero).unwrap(),
        Kinematics::new(&robot, &bent).unwrap(),
    );
    for (foot, hip) in k.feet.iter().zip(&k.hips) {
        let (f, h) = (robot.frame_id(foot).unwrap(), robot.frame_id(hip).unwrap());
        let (a, b) = (
            k0.frame_pose(&robot, f).unwrap(),
            k1.frame_pose(&robot, f).unwrap(),
        );
        let leg =
            (a.translation.vector - k0.frame_pose(&robot, h).unwrap().translation.vector).norm();
        let rise = b.translation.vector - a.translation.vector;
        // Joints written to 1 mrad: under 3 mm and 6 mrad over legs of 0.8–0.9 m.
        assert!(
            (rise.z - CROUCH * leg).abs() < 3e-3 && rise.xy().norm() < 3e-3,
            "{foot}: {rise:?}"
        );
        let up = b.rotation * Vector3::z();
        assert!(up.angle(&Vector3::z()) < 6e-3, "{foot}: {up:?}");
    }
}

#[test]
fn a_humanoid_with_meaningless_names_is_found_by_its_shape() {
    let (urdf, k) = humanoid(Build {
        leg: 6,
        hands: true,
        foot: 0,
    });
    let toml = init_profile_toml(&urdf, "a.urdf").unwrap();
    assert_eq!(
        value(&toml, "feet.left", "frame").unwrap(),
        k.feet[0],
        "{toml}"
    );
    assert_eq!(value(&toml, "feet.right", "frame").unwrap(), k.feet[1]);
    assert_eq!(value(&toml, "frames", "left_hand").unwrap(), k.hands[0]);
    assert_eq!(value(&toml, "frames", "right_hand").unwrap(), k.hands[1]);
    assert_eq!(value(&toml, "frames", "head").unwrap(), k.head);
    assert_eq!(value(&toml, "frames", "torso").unwrap(), k.torso);
    assert_eq!(value(&toml, "frames", "pelvis").unwrap(), k.pelvis);
    // The box's underside: 0.22 × 0.1 m, 0.04 m ahead, 0.065 m below the ankle.
    assert!(toml.contains("ankle_height = 0.065 "), "{toml}");
    assert!(toml.contains("sole = { length = 0.22, width = 0.1, offset_x = 0.04 }"));
    assert!(!toml.contains("CHECK this sole"));
    assert!(toml.contains("base = \"floating\""));
    check_posture(&urdf, &toml, &k, 6);
}

#[test]
fn five_joint_legs_and_bare_forearms() {
    let (urdf, k) = humanoid(Build {
        leg: 5,
        hands: false,
        foot: 1,
    });
    let toml = init_profile_toml(&urdf, "a.urdf").unwrap();
    assert_eq!(
        value(&toml, "feet.left", "frame").unwrap(),
        k.feet[0],
        "{toml}"
    );
    assert_eq!(value(&toml, "feet.right", "frame").unwrap(), k.feet[1]);
    // The cylinder's lower rim: 0.1 m across, 0.03 m ahead, 0.05 m below the ankle.
    assert!(toml.contains("ankle_height = 0.05 "), "{toml}");
    assert!(toml.contains("sole = { length = 0.1, width = 0.1, offset_x = 0.03 }"));
    // Four-joint arms end at the forearm: a frame at twice its centre of mass.
    for key in ["left_hand", "right_hand"] {
        assert_eq!(value(&toml, "frames", key).unwrap(), key);
        assert!(toml.contains(&format!("name = \"{key}\"")));
    }
    assert!(toml.contains("xyz = [0.0, 0.0, -0.24]"), "{toml}");
    // The head: the highest link fixed to the torso (not the IMU below it).
    assert_eq!(value(&toml, "frames", "head").unwrap(), k.head);
    check_posture(&urdf, &toml, &k, 5);
}

#[test]
fn seven_joint_legs_and_a_narrow_sole() {
    let (urdf, k) = humanoid(Build {
        leg: 7,
        hands: true,
        foot: 2,
    });
    let toml = init_profile_toml(&urdf, "a.urdf").unwrap();
    assert_eq!(
        value(&toml, "feet.left", "frame").unwrap(),
        k.feet[0],
        "{toml}"
    );
    assert_eq!(value(&toml, "feet.right", "frame").unwrap(), k.feet[1]);
    assert_eq!(value(&toml, "frames", "left_hand").unwrap(), k.hands[0]);
    // A 4 cm wide sole is questioned.
    assert!(toml.contains("# CHECK this sole: 4.0 cm wide"), "{toml}");
    assert!(toml.contains("sole = { length = 0.2, width = 0.04, offset_x = 0.0 }"));
    check_posture(&urdf, &toml, &k, 7);
}

#[test]
fn given_parts_replace_the_guesses_and_are_checked() {
    let (urdf, k) = humanoid(Build {
        leg: 6,
        hands: true,
        foot: 0,
    });
    let options = InitOptions {
        feet: Some([k.feet[1].clone(), k.feet[0].clone()]),
        hands: Some([k.hands[1].clone(), k.hands[0].clone()]),
        head: Some(k.torso.clone()),
        torso: Some("l1".into()),
        pelvis: Some(k.torso.clone()),
        sole: Some(Sole {
            length: 0.3,
            width: 0.12,
            offset_x: 0.01,
        }),
    };
    let toml = init_profile_toml_with(&urdf, "a.urdf", None, &options).unwrap();
    assert_eq!(value(&toml, "feet.left", "frame").unwrap(), k.feet[1]);
    assert_eq!(value(&toml, "frames", "left_hand").unwrap(), k.hands[1]);
    assert_eq!(value(&toml, "frames", "head").unwrap(), k.torso);
    assert_eq!(value(&toml, "frames", "torso").unwrap(), "l1");
    assert_eq!(value(&toml, "frames", "pelvis").unwrap(), k.torso);
    assert!(toml.contains("sole = { length = 0.3, width = 0.12, offset_x = 0.01 } # given"));
    // A link the URDF does not have, and a sole without width, are errors.
    let bad = InitOptions {
        head: Some("nowhere".into()),
        ..InitOptions::default()
    };
    let e = init_profile_toml_with(&urdf, "a.urdf", None, &bad).unwrap_err();
    assert!(
        e.to_string().contains("nowhere") && e.to_string().contains("frames.head"),
        "{e}"
    );
    let bad = InitOptions {
        sole: Some(Sole {
            length: 0.2,
            width: 0.0,
            offset_x: 0.0,
        }),
        ..InitOptions::default()
    };
    assert!(init_profile_toml_with(&urdf, "a.urdf", None, &bad).is_err());
}

/// The built-in robots' profiles name the feet and hands found by the shape.
#[test]
fn g1_and_jvrc1_get_their_builtin_feet_and_hands() {
    for (urdf, name) in [
        (crate::model::G1_URDF, "g1"),
        (crate::model::JVRC1_URDF, "jvrc1"),
    ] {
        let toml = init_profile_toml(urdf, "r.urdf").unwrap();
        let builtin = super::builtin_profile_text(name).unwrap();
        for (table, key) in [
            ("feet.left", "frame"),
            ("feet.right", "frame"),
            ("frames", "left_hand"),
            ("frames", "right_hand"),
            ("frames", "pelvis"),
            ("frames", "torso"),
            ("frames", "head"),
        ] {
            assert_eq!(
                value(&toml, table, key),
                value(builtin, table, key),
                "{name} {table}.{key}:\n{toml}"
            );
        }
    }
}

/// URDFs the model rejects get no profile: the model's error.
#[test]
fn a_urdf_the_model_rejects_gets_no_profile() {
    let (urdf, _) = humanoid(Build {
        leg: 6,
        hands: true,
        foot: 0,
    });
    for (from, to) in [
        // A joint whose parent link does not exist.
        (
            r#"<parent link="l1"/><child link="l2"/>"#,
            r#"<parent link="l99"/><child link="l2"/>"#,
        ),
        // A zero axis.
        (r#"<axis xyz="0 0 1"/>"#, r#"<axis xyz="0 0 0"/>"#),
        // An absurd mass.
        (r#"<mass value="1"/>"#, r#"<mass value="1e308"/>"#),
    ] {
        assert!(urdf.contains(from), "{from}");
        let bad = urdf.replacen(from, to, 1);
        let model = Robot::from_urdf_str(&bad, &ModelOptions::default()).unwrap_err();
        let e = init_profile_toml(&bad, "a.urdf").unwrap_err();
        assert_eq!(e.to_string(), model.to_string());
    }
}

/// The profile holds one sole for both feet: a foot without geometry takes the other's
/// (the right foot's box removed here), and the profile written says so and loads.
#[test]
fn a_foot_without_geometry_takes_the_other_feet_sole() {
    let (urdf, _) = humanoid(Build {
        leg: 6,
        hands: true,
        foot: 0,
    });
    let boxed = r#"<collision><origin xyz="0.04 0 -0.05"/><geometry><box size="0.22 0.1 0.03"/></geometry></collision>"#;
    assert_eq!(urdf.matches(boxed).count(), 2);
    let one = urdf.replacen(boxed, "", 1);
    let toml = init_profile_toml(&one, "a.urdf").unwrap();
    assert_eq!(
        toml.matches("sole = { length = 0.22, width = 0.1, offset_x = 0.04 }")
            .count(),
        2,
        "{toml}"
    );
    assert_eq!(toml.matches("ankle_height = 0.065 ").count(), 2, "{toml}");
    assert!(toml.contains("the other has no geometry"), "{toml}");
    assert!(!toml.contains("PLACEHOLDER"), "{toml}");
}
