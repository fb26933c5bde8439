//! `iktc map`: built-in maps printed as files that read back; a body map written from a motion
//! file reads back, is accepted with `--map`, and a bad one is refused with a message.

use std::path::PathBuf;
use std::process::Command;

use iktc::motion::{builtin_body_map, builtin_map, BodyMap, RetargetMap};

fn iktc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_iktc"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-cli-map-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn stdout(args: &[&str]) -> String {
    let out = iktc().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn built_in_maps_print_as_files_that_read_back() {
    let text = stdout(&["map", "show", "bvh_jvrc1"]);
    assert_eq!(
        RetargetMap::from_toml_str(&text, "shown").unwrap(),
        builtin_map("bvh_jvrc1").unwrap()
    );
    for name in ["plug_in_gait", "deepmimic"] {
        let text = stdout(&["map", "show", name]);
        let shown = BodyMap::from_toml_str(&text, "shown").unwrap();
        let builtin = builtin_body_map(name).unwrap();
        let sources = |m: &BodyMap| {
            m.points
                .iter()
                .map(|p| (p.point, p.source.clone()))
                .collect::<Vec<_>>()
        };
        assert_eq!(sources(&shown), sources(&builtin));
    }
    let out = iktc().args(["map", "show", "nope"]).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("nope") && err.contains("plug_in_gait"),
        "{err}"
    );
}

#[test]
fn map_init_writes_a_body_map_that_is_accepted_back() {
    let dir = tmp("init");
    let clip = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../iktc/tests/data/motions/cmu/scaled_131_02.bvh");
    let out = dir.join("cmu.map.toml");
    let printed = stdout(&[
        "map",
        "init",
        "--motion",
        clip.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        printed.contains("units m") && printed.contains("decided"),
        "{printed}"
    );
    let written = std::fs::read_to_string(&out).unwrap();
    let map = BodyMap::from_toml_str(&written, "cmu.map.toml").unwrap();
    assert_eq!(map.name, "scaled_131_02");
    assert_eq!(map.points.len(), 18);
    // Passed back, edited: the left wrist moved to the hand joint.
    let edited = written.replace("left_wrist = \"LeftWrist\"", "left_wrist = \"lhand\"");
    assert_ne!(edited, written);
    let edited_path = dir.join("edited.toml");
    std::fs::write(&edited_path, &edited).unwrap();
    let again = dir.join("again.toml");
    stdout(&[
        "map",
        "init",
        "--motion",
        clip.to_str().unwrap(),
        "--map",
        edited_path.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
    ]);
    assert!(std::fs::read_to_string(&again)
        .unwrap()
        .contains("left_wrist = \"lhand\"  # given"));
    // A map naming a joint the skeleton does not have is refused, naming it.
    std::fs::write(
        &edited_path,
        written.replace("\"LeftElbow\"", "\"LeftElbw\""),
    )
    .unwrap();
    let out = iktc()
        .args(["map", "init", "--motion", clip.to_str().unwrap(), "--map"])
        .arg(&edited_path)
        .arg("--out")
        .arg(dir.join("bad.toml"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("LeftElbw") && err.contains("LeftElbow"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A marker set whose wrists are missing: `map init` still writes a map, with the points found
/// (the shoulders from their front/back pair) and a commented entry for each missing one.
#[test]
fn map_init_writes_what_was_found_when_points_are_missing() {
    let dir = tmp("partial");
    // Standing subject, metres, z up: (name, x, y, z) for the left side, mirrored for the right.
    let left = [
        ("Shoulder_Front", 0.05, 0.2, 1.45),
        ("Shoulder_Back", -0.05, 0.2, 1.45),
        ("Elbow_Lateral", 0.0, 0.23, 1.15),
        ("ASIS", 0.1, 0.1, 0.95),
        ("PSIS", -0.1, 0.1, 0.95),
        ("Knee_Lateral", 0.0, 0.13, 0.5),
        ("Ankle_Lateral", 0.0, 0.13, 0.08),
        ("Toe", 0.15, 0.1, 0.02),
    ];
    let mut names = vec![
        ("Head_Front", 0.1, 0.0, 1.65),
        ("Head_Back", -0.1, 0.0, 1.65),
    ];
    let mut rows: Vec<(String, f64, f64, f64)> = names
        .drain(..)
        .map(|(n, x, y, z)| (n.to_string(), x, y, z))
        .collect();
    for (side, s) in [("L", 1.0), ("R", -1.0)] {
        for (n, x, y, z) in left {
            rows.push((format!("{side}_{n}"), x, s * y, z));
        }
    }
    let header: Vec<String> = rows
        .iter()
        .flat_map(|(n, ..)| ["x", "y", "z"].map(|a| format!("{n}_{a}")))
        .collect();
    let mut csv = format!("time,{}\n", header.join(","));
    for t in [0.0, 0.01] {
        let cells: Vec<String> = rows
            .iter()
            .flat_map(|(_, x, y, z)| [x, y, z].map(|v| v.to_string()))
            .collect();
        csv.push_str(&format!("{t},{}\n", cells.join(",")));
    }
    let motion = dir.join("custom.csv");
    std::fs::write(&motion, csv).unwrap();
    let out_path = dir.join("custom.map.toml");
    let out = iktc()
        .args(["map", "init", "--motion"])
        .arg(&motion)
        .arg("--out")
        .arg(&out_path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&out_path).unwrap();
    assert!(
        text.contains("left_shoulder = [\"L_Shoulder_Front\", \"L_Shoulder_Back\"]"),
        "{text}"
    );
    assert!(
        text.contains("left_hip = [\"L_ASIS\", \"L_PSIS\"]"),
        "{text}"
    );
    assert!(
        text.contains("# left_wrist = [\"...\"]  # REQUIRED"),
        "{text}"
    );
    assert!(
        text.contains("# right_wrist = [\"...\"]  # REQUIRED"),
        "{text}"
    );
    // Filled in, it is accepted back.
    let filled = text
        .replace(
            "# left_wrist = [\"...\"]",
            "left_wrist = [\"L_Elbow_Lateral\"]",
        )
        .replace(
            "# right_wrist = [\"...\"]",
            "right_wrist = [\"R_Elbow_Lateral\"]",
        );
    BodyMap::from_toml_str(&filled, "filled").unwrap();
}
