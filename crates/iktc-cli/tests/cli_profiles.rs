//! `--robot NAME|profile.toml|robot.urdf`: the G1 imitates (and walks) from its built-in
//! profile within its limits; errors name the flag or profile key that caused them;
//! `iktc profile show` prints a profile that parses back; `iktc profile init` writes one.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn iktc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_iktc"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-cli-profiles-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> Output {
    iktc().args(args).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Largest violation of a limit a run may show [rad, rad/s, rad/s²]: rounding only.
const LIMIT_SLACK: f64 = 1e-9;

/// The G1's URDF copied alone into a fresh directory (no profile next to it).
fn bare_g1_urdf(dir: &Path) -> PathBuf {
    let src = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../iktc/data/robots/g1/g1_29dof_rev_1_0.urdf"
    );
    let dst = dir.join("g1.urdf");
    std::fs::copy(src, &dst).unwrap();
    dst
}

#[test]
fn g1_imitates_the_default_clip_within_its_limits() {
    let out = tmp("g1");
    let o = iktc()
        .args(["imitate", "--retarget", "joints", "--robot", "g1", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let s = json(&out.join("summary.json"));
    for k in [
        "worst_position_margin",
        "worst_velocity_margin",
        "worst_acceleration_margin",
    ] {
        let m = s[k].as_f64().unwrap();
        assert!(m <= LIMIT_SLACK, "{k} = {m} (> 0: exceeded)");
    }
    assert_eq!(s["nv"].as_u64(), Some(35));
    assert!(s["foot_drift"].as_f64().unwrap() < 1e-3);
    // The imitation's defaults, reported: the soft approach at the tasks' rate √k_p and the
    // clip low-passed at 6 Hz.
    assert_eq!(s["approach_rate"].as_f64(), Some(10.0));
    assert_eq!(s["smoothing_hz"].as_f64(), Some(6.0));
    let viewer = std::fs::read_to_string(out.join("viewer.html")).unwrap();
    assert!(
        viewer.contains("\"g1_29dof_rev_1_0\""),
        "the viewer shows the G1"
    );
}

/// `--approach-rate 0 --no-smoothing` turn the defaults off (the summary says so); an
/// approach rate with the paper's bound, a negative rate and both smoothing flags are errors
/// naming the flag or setting.
#[test]
fn the_approach_and_the_low_pass_can_be_turned_off_and_bad_values_are_named() {
    let out = tmp("off");
    let o = iktc()
        .args([
            "imitate",
            "--retarget",
            "joints",
            "--approach-rate",
            "0",
            "--no-smoothing",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let s = json(&out.join("summary.json"));
    assert_eq!(s["approach_rate"].as_f64(), Some(0.0));
    assert!(s["smoothing_hz"].is_null(), "{}", s["smoothing_hz"]);
    assert!(s["worst_position_margin"].as_f64().unwrap() <= LIMIT_SLACK);
    let o = run(&[
        "imitate",
        "--retarget",
        "joints",
        "--bounds",
        "paper",
        "--approach-rate",
        "5",
    ]);
    assert!(
        !o.status.success() && stderr(&o).contains("--approach-rate"),
        "{}",
        stderr(&o)
    );
    let o = run(&["imitate", "--retarget", "joints", "--approach-rate", "-1"]);
    assert!(
        !o.status.success() && stderr(&o).contains("approach_rate"),
        "{}",
        stderr(&o)
    );
    let o = run(&["imitate", "--smoothing", "6", "--no-smoothing"]);
    assert!(
        !o.status.success() && stderr(&o).contains("--no-smoothing"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn g1_retargets_the_default_clip_by_keypoints_beside_the_joint_route() {
    let out = tmp("g1kp");
    let o = iktc()
        .args(["imitate", "--robot", "g1", "--reach", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let s = json(&out.join("keypoints_summary.json"));
    // `--reach`: the static reach of the keypoint route beside its error on the same ticks,
    // printed; the joint route has none.
    let (reach, run) = (&s["keypoints"]["reach_cm"], &s["keypoints"]["reach_run_cm"]);
    assert!(
        reach.as_f64().unwrap() <= run.as_f64().unwrap(),
        "{reach} {run}"
    );
    assert!(s["joints"]["reach_cm"].is_null());
    assert!(String::from_utf8_lossy(&o.stdout).contains("static reach"));
    for route in ["keypoints", "joints"] {
        let q = &s[route];
        for k in ["position_margin", "velocity_margin", "acceleration_margin"] {
            let m = q[k].as_f64().unwrap();
            assert!(m <= LIMIT_SLACK, "{route} {k} = {m} (> 0: exceeded)");
        }
        // One error per body point the G1 has (its head frame sits at the pelvis).
        assert_eq!(q["points"].as_array().unwrap().len(), 13, "{route}");
    }
    // Why tasks were sacrificed: every level of the keypoint stack counted, over the clip's
    // recorded ticks and over the settling's (at most 1.5 s at 200 Hz, shorter once the robot
    // is at rest), no level more often than there are ticks.
    let settle = s["settle_sacrificed"]["ticks"].as_u64().unwrap();
    assert!((1..=300).contains(&settle), "settling {settle} ticks");
    for (key, ticks) in [
        ("sacrificed", s["keypoints"]["ticks"].as_u64().unwrap()),
        ("settle_sacrificed", settle),
    ] {
        assert_eq!(s[key]["ticks"].as_u64(), Some(ticks), "{key}");
        let levels = s[key]["levels"].as_object().unwrap();
        assert_eq!(levels.len(), iktc::retarget::KEYPOINT_LEVELS.len(), "{key}");
        let total: u64 = levels.values().map(|v| v.as_u64().unwrap()).sum();
        assert!(total <= ticks, "{key}: {total} of {ticks}");
    }
    assert!(String::from_utf8_lossy(&o.stdout).contains("levels sacrificed to the joint limits"));
    let csv = std::fs::read_to_string(out.join("keypoints_trajectory.csv")).unwrap();
    assert_eq!(csv.lines().next().unwrap().split(',').count(), 1 + 29);
    let viewer = std::fs::read_to_string(out.join("viewer.html")).unwrap();
    assert!(
        viewer.contains("\"g1_29dof_rev_1_0\""),
        "the viewer shows the G1"
    );
    assert!(
        !out.join("summary.json").exists(),
        "the joint route's own summary and figures are not written"
    );
}

/// Runs `iktc walk --robot g1` with `extra` arguments and returns its walk_summary.json and
/// output directory, after checking that every joint limit held (with and without damping)
/// and that the viewer was written.
fn g1_walk(name: &str, extra: &[&str]) -> (serde_json::Value, PathBuf) {
    let out = tmp(name);
    let o = iktc()
        .args(["walk", "--robot", "g1"])
        .args(extra)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let s = json(&out.join("walk_summary.json"));
    for run in ["with_damping", "without_damping"] {
        let r = &s[run];
        for m in r["worst_margins"].as_array().unwrap() {
            assert!(m.as_f64().unwrap() <= LIMIT_SLACK, "{}", r["worst_margins"]);
        }
    }
    let viewer = std::fs::read_to_string(out.join("walk_viewer.html")).unwrap();
    assert!(
        viewer.contains("\"g1_29dof_rev_1_0\""),
        "the viewer shows the G1"
    );
    (s, out)
}

#[test]
fn g1_walks_while_imitating_within_its_limits() {
    // JVRC-1's push (5 N·s, sized for its 62.4 kg) moves the 33 kg G1's ZMP about 3.6 cm
    // past the front of its sole: the run's health check reports it, so the run is asked to
    // go on and the limits are checked.
    let (s, _) = g1_walk("g1walk", &["--push", "2.15,5,0", "--keep-going"]);
    assert_eq!(s["with_damping"]["health"]["healthy"], false);
}

/// `iktc walk --no-smoothing --approach-rate 0`: the defaults off, and the summary says so.
#[test]
fn the_walk_takes_the_clip_as_captured_and_no_approach_when_asked() {
    let (s, _) = g1_walk(
        "g1walkraw",
        &["--no-smoothing", "--approach-rate", "0", "--keep-going"],
    );
    for run in ["with_damping", "without_damping"] {
        assert_eq!(s[run]["approach_rate"].as_f64(), Some(0.0), "{run}");
        assert!(s[run]["smoothing_hz"].is_null(), "{run}");
    }
    let (s, _) = g1_walk("g1walk8", &["--smoothing", "8", "--keep-going"]);
    assert_eq!(s["with_damping"]["smoothing_hz"].as_f64(), Some(8.0));
}

#[test]
fn g1_walks_healthily_under_its_default_push_scaled_to_its_mass() {
    // The G1 profile gives no push: the default one changes the COM velocity as much as 5 N·s
    // changes JVRC-1's (5 N·s / 62.4 kg = 0.080 m/s → 2.67 N·s on 33.3 kg). Every run check
    // passes, no --keep-going, and the measured ZMP stays inside the support polygon of the
    // soles (sole offset included).
    let (s, _) = g1_walk("g1walkscaled", &[]);
    for run in ["with_damping", "without_damping"] {
        let r = &s[run];
        // The imitation's defaults, reported.
        assert_eq!(r["approach_rate"].as_f64(), Some(10.0), "{run}");
        assert_eq!(r["smoothing_hz"].as_f64(), Some(6.0), "{run}");
        let impulse = r["push"]["push"]["impulse"][0].as_f64().unwrap();
        assert!((impulse - 2.67).abs() < 0.01, "{run}: push {impulse} N·s");
        assert_eq!(r["health"]["healthy"], true, "{run}: {}", r["health"]);
        assert!(
            r["zmp_inside"].as_bool().unwrap(),
            "{run}: {}",
            r["min_zmp_margin"]
        );
    }
}

/// `iktc walk --zmp-passes 1`: the commanded motion's own ZMP (the links' masses and
/// inertias) leaves the pattern's polygon on far fewer ticks than the cart-table pattern's
/// (without the damping controller: 270 → 115 single-support ticks with the dance on G1).
#[test]
fn the_zmp_correction_keeps_the_walks_own_zmp_inside_more_often() {
    let (plain, _) = g1_walk("g1walkzmp0", &[]);
    let (fixed, _) = g1_walk("g1walkzmp1", &["--zmp-passes", "1"]);
    let outside = |s: &serde_json::Value| {
        s["without_damping"]["plan_zmp_outside_single"]
            .as_u64()
            .unwrap()
    };
    assert!(outside(&plain) > 100, "{}", outside(&plain));
    assert!(
        2 * outside(&fixed) < outside(&plain),
        "{} against {}",
        outside(&fixed),
        outside(&plain)
    );
}

#[test]
fn a_bare_urdf_names_the_missing_flag_and_key() {
    let dir = tmp("bare");
    let urdf = bare_g1_urdf(&dir);
    let u = urdf.to_str().unwrap();
    // No feet: the flag and the profile key to set.
    let o = run(&[
        "imitate",
        "--robot",
        u,
        "--map",
        "deepmimic_g1",
        "--out",
        "/nonexistent",
    ]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("--feet") && e.contains("`feet`"), "{e}");
    // And the command that guesses every missing key into a profile.
    assert!(e.contains(&format!("`iktc profile init {u} --out ")), "{e}");
    // With feet but no sole.
    let feet = "left_ankle_roll_link,right_ankle_roll_link";
    let o = run(&["imitate", "--robot", u, "--feet", feet]);
    let e = stderr(&o);
    assert!(e.contains("--sole") && e.contains("feet.left.sole"), "{e}");
    // With feet and sole, no pelvis.
    let with_feet = [
        "imitate",
        "--retarget",
        "joints",
        "--robot",
        u,
        "--feet",
        feet,
        "--sole",
        "0.17,0.05,0.035",
        "--ankle-height",
        "0.035",
    ];
    let o = run(&[&with_feet[..], &["--map", "deepmimic_g1"]].concat());
    let e = stderr(&o);
    assert!(e.contains("--pelvis") && e.contains("frames.pelvis"), "{e}");
    // No map: the JVRC-1 map is never applied to another robot.
    let o = run(&[&with_feet[..], &["--pelvis", "pelvis"]].concat());
    let e = stderr(&o);
    assert!(
        e.contains("--map") && e.contains("imitate.maps.deepmimic"),
        "{e}"
    );
    assert!(!e.contains("WAIST_Y"), "{e}");
}

#[test]
fn a_wrong_name_from_a_flag_names_the_flag_the_key_and_the_valid_names() {
    let dir = tmp("flag");
    let urdf = bare_g1_urdf(&dir);
    let u = urdf.to_str().unwrap();
    let common = [
        "imitate",
        "--retarget",
        "joints",
        "--robot",
        u,
        "--feet",
        "left_ankle_roll_link,right_ankle_roll_link",
        "--sole",
        "0.17,0.05,0.035",
        "--ankle-height",
        "0.035",
        "--map",
        "deepmimic_g1",
    ];
    for (flag, value, key, valid) in [
        ("--pelvis", "PELVIS_S", "frames.pelvis", "torso_link"),
        (
            "--posture",
            "R_HIP_P=0.1",
            "posture.R_HIP_P",
            "left_knee_joint",
        ),
        (
            "--narrow",
            "L_KNEE=0.1:0.2",
            "narrow.L_KNEE",
            "left_knee_joint",
        ),
        (
            "--lock",
            "*_FINGER_*=0",
            "lock[0].joints",
            "left_knee_joint",
        ),
    ] {
        let mut args: Vec<&str> = common.to_vec();
        if flag != "--pelvis" {
            args.extend(["--pelvis", "pelvis"]);
        }
        args.extend([flag, value]);
        let o = run(&args);
        assert!(!o.status.success());
        let e = stderr(&o);
        assert!(
            e.contains(&format!("{flag}: profile key `{key}`")),
            "{flag}: {e}"
        );
        assert!(e.contains(valid), "{flag}: {e}");
    }
    // The map entry that produced an unknown joint.
    let mut args: Vec<&str> = common.to_vec();
    args.extend(["--pelvis", "pelvis"]);
    let n = args.len();
    args[n - 3] = "deepmimic_jvrc1";
    let o = run(&args);
    let e = stderr(&o);
    assert!(
        e.contains("--map `deepmimic_jvrc1`")
            && e.contains("entry `chest`")
            && e.contains("WAIST_Y"),
        "{e}"
    );
}

#[test]
fn profile_show_prints_a_profile_that_parses_back() {
    for name in ["jvrc1", "g1"] {
        let o = run(&["profile", "show", name]);
        assert!(o.status.success(), "{}", stderr(&o));
        let dir = tmp(&format!("show-{name}"));
        // Next to a copy of the data it names, the printed profile loads and builds.
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../iktc/data");
        let profiles = dir.join("profiles");
        std::fs::create_dir_all(&profiles).unwrap();
        let robots = dir.join("robots").join(name);
        std::fs::create_dir_all(&robots).unwrap();
        for e in std::fs::read_dir(data.join("robots").join(name)).unwrap() {
            let e = e.unwrap();
            std::fs::copy(e.path(), robots.join(e.file_name())).unwrap();
        }
        let file = profiles.join(format!("{name}.toml"));
        std::fs::write(&file, &o.stdout).unwrap();
        let loaded = iktc::profile::RobotProfile::load(&file).unwrap();
        assert_eq!(loaded, iktc::profile::RobotProfile::builtin(name).unwrap());
        let m = run(&["model", file.to_str().unwrap(), "--json"]);
        assert!(m.status.success(), "{}", stderr(&m));
    }
}

#[test]
fn profile_init_writes_a_profile_the_commands_accept() {
    let dir = tmp("init");
    let urdf = bare_g1_urdf(&dir);
    let file = dir.join("g1.toml");
    let o = iktc()
        .args(["profile", "init"])
        .arg(&urdf)
        .arg("--out")
        .arg(&file)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.contains("# guessed"));
    let p = iktc::profile::RobotProfile::load(&file).unwrap();
    assert_eq!(p.urdf, "g1.urdf");
    let m = run(&["model", file.to_str().unwrap(), "--json"]);
    assert!(m.status.success(), "{}", stderr(&m));
    let s: serde_json::Value = serde_json::from_slice(&m.stdout).unwrap();
    assert_eq!(s["nv"].as_u64(), Some(35));
}
