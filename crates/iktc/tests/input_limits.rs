//! Hostile input: every URDF limit attribute checked, resource bounds
//! checked before anything is allocated, configs that overflow refused. Each case asserts the
//! error's kind and that its text names what is wrong, its value and what was expected.

use iktc::model::RobotFiles;
use iktc::model::*;
use iktc::motion::{
    builtin_clip, builtin_map, read_bvh, read_deepmimic, retarget_joint_angles, BvhReadOptions,
    DEEPMIMIC_FRAME_LEN,
};
use iktc::resources::{ReadLimits, RunLimits};
use iktc::sim::{
    run_planar3r, ImitateConfig, Planar3rConfig, WalkImitateConfig, WalkingController,
};
use iktc::Error;

const GOOD: &str = r#"<robot name="r">
  <link name="a"><inertial><origin xyz="0 0 0.1"/><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="b"/>
  <joint name="j" type="revolute"><origin xyz="0 0 0.2"/><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
</robot>"#;

fn load(s: &str) -> Result<Robot, Error> {
    Robot::from_urdf_str(s, &ModelOptions::default())
}

/// The error text of loading GOOD with `from` replaced by `to`.
fn urdf_error(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "{from}");
    match load(&GOOD.replace(from, to)) {
        Ok(_) => panic!("`{to}` was accepted"),
        Err(e) => e.to_string(),
    }
}

fn assert_names(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "`{p}` missing from: {msg}");
    }
}

#[test]
fn good_urdf_still_loads_without_warnings() {
    let r = load(GOOD).unwrap();
    assert!(r.warnings().is_empty(), "{:?}", r.warnings());
    let j = r.active_joints().next().unwrap();
    assert_eq!((j.limit.velocity, j.limit.effort), (2.0, 1.0));
    // The shipped models load with no warning.
    assert!(jvrc1(&ModelOptions::default())
        .unwrap()
        .warnings()
        .is_empty());
}

#[test]
fn velocity_limits_that_would_vanish_are_errors() {
    // Before: each of these silently removed the velocity and acceleration limits.
    for v in ["-5", "NaN", "0", "inf", "-inf"] {
        let msg = urdf_error("velocity=\"2\"", &format!("velocity=\"{v}\""));
        assert_names(
            &msg,
            &[
                "joint `j`",
                &format!("velocity=\"{v}\""),
                "finite velocity limit > 0 [rad/s]",
            ],
        );
    }
}

#[test]
fn effort_limits() {
    for v in ["-1", "NaN", "inf"] {
        let msg = urdf_error("effort=\"1\"", &format!("effort=\"{v}\""));
        assert_names(
            &msg,
            &["joint `j`", &format!("effort=\"{v}\""), "effort limit >= 0"],
        );
    }
    // URDF allows effort="0": accepted, with a warning kept in the model.
    let r = load(&GOOD.replace("effort=\"1\"", "effort=\"0\"")).unwrap();
    assert_eq!(r.warnings().len(), 1);
    assert_names(
        &r.warnings()[0],
        &["joint `j`", "effort=\"0\"", "URDF allows it"],
    );
    assert_eq!(r.active_joints().next().unwrap().limit.effort, 0.0);
}

#[test]
fn position_ranges() {
    let e = load(&GOOD.replace("lower=\"-1\"", "lower=\"2\"")).unwrap_err();
    assert!(
        matches!(e, Error::InvalidLimit { lower, upper, .. } if lower == 2.0 && upper == 1.0),
        "{e}"
    );
    let msg = urdf_error("lower=\"-1\"", "lower=\"1\"");
    assert_names(
        &msg,
        &["joint `j`", "zero-width range [1, 1]", "fixed", "locked"],
    );
    // Missing lower and upper default to 0: the same error, which says so.
    let msg = urdf_error("lower=\"-1\" upper=\"1\"", "");
    assert_names(&msg, &["zero-width range [0, 0]", "default to 0"]);
    let msg = urdf_error("upper=\"1\"", "upper=\"inf\"");
    assert_names(
        &msg,
        &[
            "joint `j`",
            "upper=\"inf\"",
            "finite position",
            "continuous",
        ],
    );
}

#[test]
fn unknown_tags_and_attributes_in_a_joint() {
    // A misspelled <limit> used to give the range [0, 0] silently.
    let msg = urdf_error("<limit ", "<limits ");
    assert_names(
        &msg,
        &[
            "joint `j`",
            "<limits>",
            "misspelled <limit>",
            "expected one of",
        ],
    );
    // Within two edits of a URDF element, or containing one: a misspelling, an error.
    for (tag, known) in [
        ("lmit", "limit"),
        ("Limit", "limit"),
        ("joint_limit", "limit"),
        ("axes", "axis"),
        ("orgin", "origin"),
    ] {
        let replaced = match known {
            "limit" => GOOD.replace("<limit ", &format!("<{tag} ")),
            "axis" => GOOD.replace("<axis ", &format!("<{tag} ")),
            _ => GOOD.replace(
                "<origin xyz=\"0 0 0.2\"",
                &format!("<{tag} xyz=\"0 0 0.2\""),
            ),
        };
        assert_ne!(replaced, GOOD, "{tag}");
        let msg = load(&replaced).unwrap_err().to_string();
        assert_names(
            &msg,
            &[
                "joint `j`",
                &format!("<{tag}>"),
                &format!("misspelled <{known}>"),
            ],
        );
    }
    let msg = urdf_error("velocity=", "veloctiy=");
    assert_names(&msg, &["joint `j`", "`veloctiy`", "velocity"]);
    // No <limit> at all on a revolute joint: URDF requires one.
    let no_limit = GOOD.replace(
        r#"<limit lower="-1" upper="1" velocity="2" effort="1"/>"#,
        "",
    );
    let msg = load(&no_limit).unwrap_err().to_string();
    assert_names(&msg, &["joint `j`", "no <limit>", "requires"]);
    // A continuous joint needs none.
    let r = load(&no_limit.replace("revolute", "continuous")).unwrap();
    assert_eq!(
        r.active_joints().next().unwrap().limit.velocity,
        f64::INFINITY
    );
    // With one, URDF ignores its range (the joint turns without end) and keeps its rates.
    let r = load(&GOOD.replace("revolute", "continuous")).unwrap();
    let l = r.active_joints().next().unwrap().limit;
    assert_eq!(
        (l.lower, l.upper, l.velocity),
        (f64::NEG_INFINITY, f64::INFINITY, 2.0)
    );
    // An exporter's extension inside <joint> (onshape-to-robot writes <joint_properties>)
    // misspells nothing URDF defines: ignored, with a warning naming it; the joint is as
    // without it.
    let extended = GOOD.replace(
        "<axis xyz=\"0 0 1\"/>",
        "<axis xyz=\"0 0 1\"/><joint_properties friction=\"0.0\"/>",
    );
    assert_ne!(extended, GOOD);
    let r = load(&extended).unwrap();
    assert_eq!(
        r.warnings(),
        ["joint `j`: <joint_properties> is not URDF; ignored"]
    );
    let plain = load(GOOD).unwrap();
    let (a, b) = (
        r.active_joints().next().unwrap(),
        plain.active_joints().next().unwrap(),
    );
    assert_eq!(
        (a.limit.lower, a.limit.upper, a.limit.velocity),
        (b.limit.lower, b.limit.upper, b.limit.velocity)
    );
    // A misspelled <mass> inside <inertial>.
    let msg = urdf_error("<mass value", "<mas value");
    assert_names(&msg, &["link `a`", "<mas>", "<mass>"]);
}

#[test]
fn a_floating_joint_from_a_massless_root_is_the_base() {
    // Some exporters mark the floating base as a `floating` joint from a `world` link.
    let marked = GOOD.replace(
        "<link name=\"b\"/>",
        "<link name=\"b\"/><link name=\"world\"/>\
         <joint name=\"float\" type=\"floating\"><parent link=\"world\"/><child link=\"a\"/></joint>",
    );
    assert_ne!(marked, GOOD);
    let floating = ModelOptions {
        base: BaseKind::Floating,
        ..ModelOptions::default()
    };
    let r = Robot::from_urdf_str(&marked, &floating).unwrap();
    let plain = Robot::from_urdf_str(GOOD, &floating).unwrap();
    assert_eq!((r.nq(), r.nv()), (plain.nq(), plain.nv()));
    assert_eq!((r.nq(), r.nv()), (8, 7));
    assert_eq!(r.total_mass(), plain.total_mass());
    assert_eq!(r.warnings().len(), 1);
    assert_names(&r.warnings()[0], &["`float`", "`world`", "base at `a`"]);
    // Fixed, as ModelOptions says by default.
    assert_eq!(load(&marked).unwrap().nq(), 1);
    // A root with mass is a body: its floating joint stays unsupported.
    let heavy = marked.replace(
        "<link name=\"world\"/>",
        "<link name=\"world\"><inertial><mass value=\"1\"/><inertia ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial></link>",
    );
    let msg = load(&heavy).unwrap_err().to_string();
    assert_names(&msg, &["joint `float`", "Floating", "ModelOptions::base"]);
    // So is a floating joint below the root.
    let inner = GOOD.replace("type=\"revolute\"", "type=\"floating\"");
    let msg = load(&inner).unwrap_err().to_string();
    assert_names(&msg, &["joint `j`", "Floating"]);
}

#[test]
fn absurd_masses_origins_and_inertias() {
    // Before: `total mass inf kg`.
    let msg = urdf_error("<mass value=\"1\"", "<mass value=\"1e308\"");
    assert_names(&msg, &["mass of link `a`", "1e308", "at most 1e5 kg"]);
    let msg = urdf_error("<origin xyz=\"0 0 0.2\"/>", "<origin xyz=\"0 0 1e308\"/>");
    assert_names(&msg, &["origin of joint `j`", "at most 1e3 m"]);
    let msg = urdf_error("<origin xyz=\"0 0 0.1\"/>", "<origin xyz=\"1e308 0 0\"/>");
    assert_names(&msg, &["centre of mass of link `a`", "at most 1e3 m"]);
    let msg = urdf_error("ixx=\"0.1\"", "ixx=\"1e308\"");
    assert_names(&msg, &["inertia of link `a`", "1e308", "kg·m²"]);
    let msg = urdf_error("ixx=\"0.1\"", "ixx=\"-0.1\"");
    assert_names(&msg, &["inertia of link `a`", "-0.1", ">= 0"]);
    let msg = urdf_error("velocity=\"2\"", "velocity=\"1e300\"");
    assert_names(&msg, &["velocity limit of joint `j`", "1e300"]);
}

/// `depth` links nested inside each other (not valid URDF, but valid XML).
fn nested(depth: usize) -> String {
    let mut s = String::from("<robot name=\"deep\">");
    s.push_str(&"<link name=\"a\">".repeat(depth));
    s.push_str(&"</link>".repeat(depth));
    s.push_str("</robot>");
    s
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    // Before: a stack overflow (the XML tree parser recurses once per level).
    let e = load(&nested(20_000)).unwrap_err();
    assert!(matches!(e, Error::ResourceLimit { .. }), "{e}");
    assert_names(
        &e.to_string(),
        &[
            "XML nesting depth",
            "= 65",
            "limit 64",
            "ReadLimits::max_xml_depth",
        ],
    );
    // The limit is a setting: at 100 the 70-deep document gets past the depth check (urdf-rs
    // then ignores the links nested inside the first one).
    let limits = ReadLimits {
        max_xml_depth: 100,
        ..ReadLimits::default()
    };
    let r = Robot::from_urdf_str_with(&nested(70), &ModelOptions::default(), &limits);
    assert!(!matches!(r, Err(Error::ResourceLimit { .. })), "{r:?}");
}

fn bvh(frames: &str, frame_time: &str, lines: usize) -> String {
    let mut s = format!(
        "HIERARCHY\nROOT Hips\n{{\n\tOFFSET 0 0 0\n\tCHANNELS 3 Zrotation Xrotation Yrotation\n\tEnd Site\n\t{{\n\t\tOFFSET 0 10 0\n\t}}\n}}\nMOTION\nFrames: {frames}\nFrame Time: {frame_time}\n"
    );
    for _ in 0..lines {
        s.push_str("0 0 0\n");
    }
    s
}

#[test]
fn clip_duration_and_frames_are_bounded() {
    let opts = BvhReadOptions::default();
    assert!(read_bvh(&bvh("2", "0.01", 2), "ok.bvh", &opts).is_ok());
    // Before: Frame Time 1e6 tried to allocate ~100 GB when resampled; no capture runs at
    // 1e-6 Hz, so it is now refused as a frame time.
    let msg = read_bvh(&bvh("2", "1e6", 2), "slow.bvh", &opts)
        .unwrap_err()
        .to_string();
    assert_names(
        &msg,
        &["slow.bvh:13", "Frame Time 1000000 s", "1 to 2000 Hz"],
    );
    // 5000 frames at 1 Hz last 4999 s, beyond the hour allowed.
    let msg = read_bvh(&bvh("5000", "1", 5000), "long.bvh", &opts)
        .unwrap_err()
        .to_string();
    assert_names(
        &msg,
        &[
            "long.bvh:13",
            "duration of long.bvh",
            "4999",
            "3600",
            "--max-clip-duration",
        ],
    );
    // A huge declared frame count is refused at the header, before reading any frame.
    let msg = read_bvh(&bvh("5000000", "0.01", 1), "many.bvh", &opts)
        .unwrap_err()
        .to_string();
    assert_names(
        &msg,
        &[
            "frames in many.bvh",
            "5000000",
            "ReadLimits::max_clip_frames",
        ],
    );
    // Raised limits accept it (then the missing frame lines are the error).
    let raised = BvhReadOptions {
        limits: ReadLimits {
            max_clip_duration: 5000.0,
            ..ReadLimits::default()
        },
        ..Default::default()
    };
    assert!(read_bvh(&bvh("5000", "1", 5000), "long.bvh", &raised).is_ok());
}

#[test]
fn deepmimic_frame_of_a_million_seconds() {
    let frame = |d: f64| {
        let mut v = vec![0.0; DEEPMIMIC_FRAME_LEN];
        v[0] = d;
        for start in [4, 8, 12, 16, 21, 25, 30, 35, 39] {
            v[start] = 1.0; // identity quaternions (w first)
        }
        format!("{v:?}")
    };
    let text = |d: f64| format!("{{\"Frames\": [{}, {}]}}", frame(d), frame(0.0));
    assert!(read_deepmimic(&text(0.03), "ok.txt").is_ok());
    let e = read_deepmimic(&text(1e6), "long.txt").unwrap_err();
    assert!(matches!(e, Error::ResourceLimit { .. }), "{e}");
    assert_names(&e.to_string(), &["duration of long.txt", "1000000", "3600"]);
}

#[test]
fn planar3r_control_periods() {
    let run = |dt: f64| {
        run_planar3r(&Planar3rConfig {
            dt,
            ..Default::default()
        })
    };
    // Before: 1e-300 panicked (capacity overflow), 1e-7 allocated gigabytes, 10 printed
    // `q1 min inf deg` (zero ticks), a negative or NaN period was refused only by accident.
    for dt in [1e-300, 1e-7, 10.0, -0.005, 0.0, f64::NAN, f64::INFINITY] {
        let e = run(dt).unwrap_err();
        assert!(matches!(e, Error::InvalidSetting { .. }), "{dt}: {e}");
        assert_names(
            &e.to_string(),
            &["dt", "control period in [0.00001, 0.1] s"],
        );
    }
    // A long run at a valid period: the tick bound, which names its option.
    let e = run_planar3r(&Planar3rConfig {
        duration: 1e4,
        ..Default::default()
    })
    .unwrap_err();
    assert!(matches!(e, Error::ResourceLimit { .. }), "{e}");
    assert_names(&e.to_string(), &["2000000", "200000", "--max-ticks"]);
    // Raising the bound admits it (checked without running: a short run with a tiny bound).
    let e = run_planar3r(&Planar3rConfig {
        run_limits: RunLimits {
            max_ticks: 10,
            ..RunLimits::default()
        },
        ..Default::default()
    })
    .unwrap_err();
    assert_names(&e.to_string(), &["= 400", "limit 10"]);
}

#[test]
fn imitation_and_walking_bounds() {
    let cfg = ImitateConfig {
        dt: 1e308,
        ..ImitateConfig::jvrc1()
    };
    let e = cfg.validate().unwrap_err();
    assert_names(&e.to_string(), &["dt = 1e308", "control period"]);
    // Resampling a clip at a tiny period: refused before the samples are allocated.
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = builtin_clip("humanoid3d_walk").unwrap().to_z_up();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    let r = retarget_joint_angles(&clip, &robot, &map).unwrap();
    let tight = RunLimits {
        max_ticks: 100,
        ..RunLimits::default()
    };
    let e = r.resample_with(0.005, &tight).unwrap_err();
    assert!(matches!(e, Error::ResourceLimit { .. }), "{e}");
    // `iktc walk --steps 10000` (before: 10 GB and rising): refused before the plan is built.
    let refs = r.resample(0.005).unwrap();
    let mut wcfg = WalkImitateConfig::jvrc1().unwrap();
    wcfg.steps = 10_000;
    let e = WalkingController::new(&robot, &refs, &wcfg).err().unwrap();
    assert!(matches!(e, Error::ResourceLimit { .. }), "{e}");
    assert_names(&e.to_string(), &["ticks of the walk", "--max-ticks"]);
}

#[test]
fn configs_with_wrong_counts_or_huge_values() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    // Before: the 7th value was dropped silently (TOML).
    let e = StateConfig::from_toml_str("base_velocity = [1, 2, 3, 4, 5, 6, 7]", "c.toml")
        .and_then(|c| c.state(&robot))
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::DimensionMismatch {
                expected: 6,
                got: 7,
                ..
            }
        ),
        "{e}"
    );
    let e = StateConfig::from_json_str("{\"base_velocity\": [1, 2, 3, 4, 5]}", "c.json")
        .and_then(|c| c.state(&robot))
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::DimensionMismatch {
                expected: 6,
                got: 5,
                ..
            }
        ),
        "{e}"
    );
    // Before: 1e308 gave `drift [-inf, …]`.
    for text in [
        "joints = { R_KNEE = 1e308 }",
        "velocities = { R_KNEE = 1e308 }",
        "base_velocity = [1e308, 0, 0, 0, 0, 0]",
        "base = { position = [0, 0, 1e308] }",
    ] {
        let e = StateConfig::from_toml_str(text, "c.toml")
            .and_then(|c| c.state(&robot))
            .unwrap_err();
        assert_names(&e.to_string(), &["1e308", "MAX_CONFIG_MAGNITUDE"]);
    }
    let e = StateConfig::from_toml_str("joints = { R_KNEE = nan }", "c.toml")
        .and_then(|c| c.state(&robot))
        .unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    let e = StateConfig::from_toml_str("jionts = {}", "c.toml").unwrap_err();
    assert!(matches!(e, Error::Parse { line: 1, .. }), "{e}");
}
