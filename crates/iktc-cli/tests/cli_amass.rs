//! `iktc retarget` on an AMASS archive: with `--body-model` the clip is retargeted onto G1 (a
//! folder given as input yields the archive and not the body model beside it); without, the
//! clip fails with the error that names the model file it needs and the flag.

#[path = "../../iktc/tests/amass_fixture/mod.rs"]
mod amass_fixture;

use std::path::{Path, PathBuf};
use std::process::Output;

use amass_fixture::{Archive, ModelSpec, SMPLX};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-cli-amass-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn retarget(input: &Path, out: &Path, extra: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_iktc"))
        .arg("retarget")
        .arg(input)
        .args([
            "--robot",
            "g1",
            "--dt",
            "0.01",
            "--jobs",
            "1",
            "--no-viewer",
        ])
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

fn batch(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("batch.json")).unwrap()).unwrap()
}

#[test]
fn an_amass_archive_is_retargeted_with_its_body_model_and_refused_without() {
    let d = tmp("retarget");
    let input = d.join("in");
    std::fs::create_dir_all(&input).unwrap();
    let clip = input.join("walk_poses.npz");
    std::fs::write(&clip, Archive::walk(SMPLX, 2.0).bytes()).unwrap();
    let model = input.join("SMPLX_FEMALE.npz");
    std::fs::write(&model, ModelSpec::smplx().bytes()).unwrap();

    // With the body model, the folder: the archive is the only clip found.
    let out = d.join("out");
    let o = retarget(
        &input,
        &out,
        &["--body-model", model.to_str().unwrap(), "--format", "npz"],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let b = batch(&out);
    let clips = b["clips"].as_array().unwrap();
    assert_eq!(clips.len(), 1, "{b}");
    assert_eq!(clips[0]["name"], "walk_poses");
    assert_eq!(clips[0]["status"], "retargeted", "{b}");
    assert!(out.join("walk_poses/motion.npz").is_file());

    // Without it, the file named directly: the error names the model and the flag.
    let out = d.join("out-none");
    let o = retarget(&clip, &out, &[]);
    assert!(!o.status.success());
    let b = batch(&out);
    let error = b["clips"][0]["error"].as_str().unwrap().to_string();
    for word in [
        "SMPL-X",
        "SMPLX_FEMALE.npz",
        "--body-model",
        "smpl-x.is.tue.mpg.de",
    ] {
        assert!(error.contains(word), "`{word}` missing from: {error}");
    }
}
