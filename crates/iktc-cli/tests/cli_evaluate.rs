//! `iktc evaluate` on the files `iktc retarget` writes: the figures of `motion.csv` and
//! `motion.npz`, read back from disk by the command, equal the position figures of the run's
//! own `quality.json`; a CSV without a joint, with a column the robot lacks, or a bad rate is
//! an error naming it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn iktc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_iktc"))
}

fn walk() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../iktc/data/motions/deepmimic/humanoid3d_walk.txt")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-evaluate-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn evaluate(trajectory: &Path, extra: &[&str]) -> Output {
    iktc()
        .arg("evaluate")
        .arg(walk())
        .args(["--robot", "g1", "--trajectory"])
        .arg(trajectory)
        .args(extra)
        .output()
        .unwrap()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn evaluate_reads_back_a_retarget_run_and_names_bad_files() {
    let dir = tmp("run");
    let out = dir.join("out");
    let run = iktc()
        .arg("retarget")
        .arg(walk())
        .args(["--robot", "g1", "--no-viewer", "--jobs", "1", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let clip = out.join("humanoid3d_walk");
    let own = json(&clip.join("quality.json"))["summary"]["keypoints"]["fidelity"].clone();
    for file in ["motion.csv", "motion.npz"] {
        let report = dir.join(format!("{file}.json"));
        let o = evaluate(&clip.join(file), &["--out", report.to_str().unwrap()]);
        assert!(
            o.status.success(),
            "{file}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(stdout.contains("mean keypoint error"), "{stdout}");
        let e = json(&report);
        assert_eq!(e["resampled"], false, "{file}");
        let f = &e["fidelity"];
        for key in [
            "ticks",
            "scale",
            "heading_deg",
            "keypoint_mean_cm",
            "points",
            "posture",
            "contacts",
        ] {
            assert_eq!(f[key], own[key], "{file}: {key}");
        }
        assert!(e["smoothness_note"]
            .as_str()
            .unwrap_or("")
            .contains("second differences"));
    }
    // A joint dropped, then renamed.
    let csv = std::fs::read_to_string(clip.join("motion.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let drop = header.iter().position(|h| *h == "left_knee_joint").unwrap();
    let without: String = csv
        .lines()
        .map(|l| {
            let v: Vec<&str> = l
                .split(',')
                .enumerate()
                .filter(|(i, _)| *i != drop)
                .map(|(_, v)| v)
                .collect();
            v.join(",") + "\n"
        })
        .collect();
    let bad = dir.join("without.csv");
    std::fs::write(&bad, without).unwrap();
    let o = evaluate(&bad, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("left_knee_joint have no column"), "{err}");
    let renamed = dir.join("renamed.csv");
    std::fs::write(&renamed, csv.replacen("left_knee_joint", "knee_l", 1)).unwrap();
    let o = evaluate(&renamed, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("knee_l are no joint of the robot"), "{err}");
    let o = evaluate(&clip.join("motion.csv"), &["--rate", "0"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("--rate"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
