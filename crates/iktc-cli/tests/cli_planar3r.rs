//! The command line, end to end: `iktc run planar3r` reproduces errata 2.1 (asserted from the
//! `summary.json` it writes), and bad input gives an error message, never a panic.

use std::path::PathBuf;
use std::process::Command;

fn iktc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_iktc"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-cli-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn planar3r_summary_reproduces_errata_2_1() {
    let out = tmp("3r");
    let st = iktc()
        .args([
            "run", "planar3r", "--solver", "iktc", "--bounds", "viable", "--out",
        ])
        .arg(&out)
        .status()
        .unwrap();
    assert!(st.success());
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let deg = std::f64::consts::PI / 180.0;
    let f = |k: &str| s[k].as_f64().unwrap();
    // No limit exceeded (signed margins ≤ 0 up to round-off).
    assert!(f("worst_position_margin") <= 1e-9);
    assert!(f("worst_velocity_margin") <= 1e-9);
    assert!(f("worst_acceleration_margin") <= 1e-9);
    // q1 stops at 60°; θ3 sacrificed by about 33°; P_x and P_y tracked.
    assert!((f("min_q1") / deg - 60.0).abs() < 0.5);
    let fe: Vec<f64> = s["final_error"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(
        (fe[2].abs() / deg - 33.0).abs() < 3.0,
        "θ3 error {}°",
        fe[2] / deg
    );
    assert!(fe[0].abs() < 1e-3 && fe[1].abs() < 1e-3);
    assert_eq!(s["qp_per_step_max"].as_u64(), Some(1));
    for f in [
        "trajectory.csv",
        "fig4_motion.svg",
        "fig4_motion.png",
        "fig5_q1.png",
        "fig8_errors.svg",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    // The CSV has one row per step (2 s at 5 ms) plus the header.
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert_eq!(csv.lines().count(), 401);
}

#[test]
fn gf_runs_three_qps_per_step() {
    let out = tmp("gf");
    let st = iktc()
        .args(["run", "planar3r", "--solver", "gf", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(st.success());
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["qp_per_step_max"].as_u64(), Some(3));
    assert_eq!(s["qp_per_step_mean"].as_f64(), Some(3.0));
}

#[test]
fn model_json_describes_jvrc1() {
    let o = iktc().args(["model", "jvrc1", "--json"]).output().unwrap();
    assert!(o.status.success());
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["nv"].as_u64(), Some(38));
    assert_eq!(s["nq"].as_u64(), Some(39));
    assert_eq!(s["joints"].as_array().unwrap().len(), 32);
    assert_eq!(s["locked"].as_array().unwrap().len(), 12);
}

#[test]
fn bad_input_gives_a_message_not_a_panic() {
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["model", "no_such_robot"], "neither a built-in robot"),
        (
            vec!["run", "planar3r", "--priority", "Px,Py"],
            "three tasks",
        ),
        (
            vec!["run", "planar3r", "--priority", "Px,Py,Pz"],
            "unknown task",
        ),
        (vec!["run", "planar3r", "--dt=-1"], "dt"),
        (vec!["model", "jvrc1", "--lock", "NOPE=1"], "NOPE"),
    ];
    for (args, want) in cases {
        let o = iktc().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} should fail");
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
        assert!(err.contains(want), "{args:?}: expected `{want}` in: {err}");
    }
    // A malformed URDF file and a config with an unknown frame.
    let dir = tmp("bad");
    std::fs::create_dir_all(&dir).unwrap();
    let urdf = dir.join("bad.urdf");
    std::fs::write(&urdf, "<robot name=\"x\"><link name=\"a\"></robot>").unwrap();
    let o = iktc().arg("model").arg(&urdf).output().unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot parse"));
    let cfg = dir.join("q.json");
    std::fs::write(&cfg, r#"{"joints": {"q1": 1.0}}"#).unwrap();
    let o = iktc()
        .args(["model", "planar3r", "--jacobian", "hand", "--config"])
        .arg(&cfg)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("hand") && err.contains("tip"),
        "{err}"
    );
    std::fs::write(&cfg, r#"{"joints": {"q1": NaN}}"#).unwrap();
    let o = iktc()
        .args(["model", "planar3r", "--config"])
        .arg(&cfg)
        .output()
        .unwrap();
    assert!(!o.status.success());
}
