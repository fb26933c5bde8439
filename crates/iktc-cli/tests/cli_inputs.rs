//! Hostile command lines: each gives an error message and exit code 1,
//! or, for a closed pipe, a quiet exit 0; never a panic (exit 101).

use std::io::Read;
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

fn iktc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_iktc"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-cli-inputs-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> Output {
    iktc().args(args).output().unwrap()
}

/// Exit code 1 (not 101), and stderr holds every part.
fn assert_error(args: &[&str], parts: &[&str]) {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    for p in parts {
        assert!(err.contains(p), "{args:?}: `{p}` missing from {err}");
    }
}

#[test]
fn closed_pipe_ends_quietly() {
    // Before: `iktc model jvrc1 | head -1` exited 101 with a panic.
    for args in [&["model", "jvrc1"][..], &["model", "jvrc1", "--json"][..]] {
        let mut child = iktc()
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Close the reading end before the tool writes: every write hits a closed pipe.
        drop(child.stdout.take());
        let mut err = String::new();
        child
            .stderr
            .take()
            .unwrap()
            .read_to_string(&mut err)
            .unwrap();
        let st = child.wait().unwrap();
        assert_eq!(st.code(), Some(0), "{args:?}: {err}");
        assert!(err.is_empty(), "{args:?}: {err}");
    }
}

#[test]
fn negative_and_out_of_range_periods() {
    // Before: `--dt -0.005` was read as an unknown argument `-0`.
    let out = tmp("dt");
    let out = out.to_str().unwrap();
    for dt in ["-0.005", "1e-300", "1e-7", "10", "NaN", "0"] {
        assert_error(
            &["run", "planar3r", "--dt", dt, "--out", out],
            &["--dt", "control period in [0.00001, 0.1] s"],
        );
    }
    assert_error(
        &["imitate", "--dt", "1e308", "--out", out],
        &["--dt = 1e308", "control period"],
    );
    // Nothing was written by the refused runs.
    assert_eq!(std::fs::read_dir(out).unwrap().count(), 0);
}

#[test]
fn tick_bounds_name_their_option() {
    let out = tmp("ticks");
    let out = out.to_str().unwrap();
    // Before: 10 GB and rising.
    assert_error(
        &["walk", "--steps", "10000", "--out", out],
        &[
            "ticks of the walk",
            "exceeds the limit 200000",
            "--max-ticks",
        ],
    );
    // Walking is its own command; `imitate --walk` says so instead of running.
    assert_error(
        &["imitate", "--walk", "--out", out],
        &["iktc walk", "--steps"],
    );
    // Walking options exist only on `iktc walk` (a usage error, exit 2).
    let o = run(&["imitate", "--steps", "3", "--out", out]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("'--steps'"));
    assert_error(
        &["walk", "--push", "1,2", "--out", out],
        &["--push `1,2`", "TIME,IMPULSE_X,IMPULSE_Y"],
    );
    assert_error(
        &["walk", "--narrow", "L_KNEE=0.5", "--out", out],
        &["--narrow `L_KNEE=0.5`", "is not lo:hi"],
    );
    assert_error(
        &["run", "planar3r", "--max-ticks", "100", "--out", out],
        &["ticks of the 3R run", "= 400", "limit 100", "--max-ticks"],
    );
}

#[test]
fn bad_files_are_errors() {
    let dir = tmp("files");
    // A BVH whose frame lasts a million seconds: refused at its header (no capture rate).
    let bvh = dir.join("slow.bvh");
    std::fs::write(
        &bvh,
        "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n End Site\n {\n  OFFSET 0 10 0\n }\n}\nMOTION\nFrames: 2\nFrame Time: 1e6\n0 0 0\n0 0 0\n",
    )
    .unwrap();
    assert_error(
        &[
            "imitate",
            "--motion",
            bvh.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
        ],
        &["slow.bvh:13", "Frame Time 1000000 s", "1 to 2000 Hz"],
    );
    // A config with 7 base velocities (expects 6), and one with 1e308.
    let c7 = dir.join("seven.toml");
    std::fs::write(&c7, "base_velocity = [0, 0, 0, 0, 0, 0, 1]\n").unwrap();
    assert_error(
        &["model", "jvrc1", "--config", c7.to_str().unwrap()],
        &["base_velocity", "expected 6, got 7"],
    );
    let huge = dir.join("huge.json");
    std::fs::write(&huge, "{\"joints\": {\"R_KNEE\": 1e308}}").unwrap();
    assert_error(
        &["model", "jvrc1", "--config", huge.to_str().unwrap()],
        &["R_KNEE", "1e308", "MAX_CONFIG_MAGNITUDE"],
    );
    // A URDF whose velocity limit would vanish; one with effort="0" (a warning, exit 0).
    let urdf = |v: &str, e: &str| {
        format!(
            r#"<robot name="r"><link name="a"/><link name="b"/>
<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" velocity="{v}" effort="{e}"/></joint></robot>"#
        )
    };
    let bad = dir.join("bad.urdf");
    std::fs::write(&bad, urdf("-5", "1")).unwrap();
    assert_error(
        &["model", bad.to_str().unwrap()],
        &["joint `j`", "velocity=\"-5\"", "finite velocity limit > 0"],
    );
    let warn = dir.join("warn.urdf");
    std::fs::write(&warn, urdf("1", "0")).unwrap();
    let o = run(&["model", warn.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning: joint `j`: <limit effort=\"0\">"),
        "{err}"
    );
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("effort=\"0\""),
        "the model summary lists the warning: {text}"
    );
}

/// JVRC-1's built-in BVH map names a `Spine` joint CMU's rig lacks: keypoint retargeting runs
/// from the start posture and says so; the same map given with `--map` is an error naming the
/// joint.
#[test]
fn keypoints_on_a_rig_the_profile_map_does_not_fit() {
    let clip = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../iktc/tests/data/motions/cmu/131_01.bvh"
    );
    let out = tmp("rig");
    let o = run(&[
        "imitate",
        "--robot",
        "jvrc1",
        "--motion",
        clip,
        "--out",
        out.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        text.contains("posture level: the start posture") && text.contains("Spine"),
        "{text}"
    );
    assert_error(
        &[
            "imitate",
            "--robot",
            "jvrc1",
            "--motion",
            clip,
            "--map",
            "bvh_jvrc1",
            "--out",
            out.to_str().unwrap(),
        ],
        &["Spine"],
    );
}

#[test]
fn counts_and_rates_are_bounded_up_front() {
    let out = tmp("bounds");
    let out = out.to_str().unwrap();
    let clip = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../iktc/tests/data/motions/cmu/131_01.bvh"
    );
    // Before: 1e12 Hz aborted allocating 7.9 TB; 1e300 Hz wrote 0 frames with exit 0.
    for rate in ["1e12", "1e300", "0.5"] {
        assert_error(
            &["retarget", clip, "--rate", rate, "--out", out],
            &["--rate", "output rate in [1, 100000] Hz"],
        );
    }
    // Before: 2^32 passes ran unbounded and diverged.
    assert_error(
        &["walk", "--zmp-passes", "4294967296", "--out", out],
        &["--zmp-passes", "at most 10"],
    );
    // Worker threads: 1 to resources::MAX_JOBS = 1024.
    for jobs in ["0", "1025", "18446744073709551615"] {
        assert_error(
            &["retarget", clip, "--jobs", jobs, "--out", out],
            &[
                &format!("--jobs = {jobs}"),
                "worker count in [1, 1024] threads",
            ],
        );
    }
    // The keypoint route's period ends where its held feet's tracking turns unstable.
    assert_error(
        &["retarget", clip, "--dt", "0.05", "--out", out],
        &["--dt", "below 0.0414 s"],
    );
    assert_eq!(std::fs::read_dir(out).unwrap().count(), 0);
}
