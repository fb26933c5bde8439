//! `iktc retarget` on awkward folders and re-runs: link cycles and dangling links in the input
//! folder, a robot whose URDF is edited between runs, a clip that fails after an earlier run
//! succeeded, the viewer asked for after a run without it, and a batch stopped by SIGINT.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Control period of the test runs [s] (twice the default: half the ticks).
const DT: &str = "0.01";

fn iktc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_iktc"))
}

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../iktc/data")
}

fn clip(name: &str) -> PathBuf {
    data().join(format!("motions/deepmimic/{name}.txt"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-robust-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `iktc retarget INPUT --out OUT --dt DT --jobs 1` with `extra` arguments.
fn retarget(input: &Path, out: &Path, extra: &[&str]) -> Output {
    iktc()
        .arg("retarget")
        .arg(input)
        .arg("--out")
        .arg(out)
        .args(["--dt", DT, "--jobs", "1"])
        .args(extra)
        .output()
        .unwrap()
}

fn batch_json(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("batch.json")).unwrap()).unwrap()
}

fn statuses(out: &Path) -> BTreeMap<String, String> {
    batch_json(out)["clips"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["name"].as_str().unwrap().to_string(),
                c["status"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

/// Every path under `dir`, recursively (links not followed).
fn tree(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if std::fs::symlink_metadata(&p).unwrap().is_dir() {
                stack.push(p.clone());
            }
            out.push(p);
        }
    }
    out
}

fn no_temporaries(out: &Path) {
    for p in tree(out) {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            !(name.starts_with('.') && (name.ends_with(".tmp") || name.ends_with(".old"))),
            "left behind: {}",
            p.display()
        );
    }
}

/// The values of column `name` of a CSV file.
fn column(csv: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

/// A folder with a link to itself, a link to its parent, a second name for its clip and a
/// dangling link: the batch ends, retargets the clip once, and names the dangling link.
#[cfg(unix)]
#[test]
fn link_cycles_end_each_clip_runs_once_and_a_dangling_link_is_named() {
    use std::os::unix::fs::symlink;
    let dir = tmp("cycles");
    let input = dir.join("in");
    std::fs::create_dir_all(input.join("sub")).unwrap();
    std::fs::copy(clip("humanoid3d_punch"), input.join("punch.txt")).unwrap();
    symlink(&input, input.join("sub/up")).unwrap();
    symlink(".", input.join("loop")).unwrap();
    symlink("../punch.txt", input.join("sub/again.txt")).unwrap();
    symlink(input.join("missing.txt"), input.join("gone.txt")).unwrap();
    let out = dir.join("out");
    let o = retarget(&input, &out, &["--no-viewer"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let st = statuses(&out);
    let gone = input.join("gone.txt").display().to_string();
    let expected: BTreeMap<String, String> = [
        ("punch".to_string(), "retargeted".to_string()),
        (gone.clone(), "failed".to_string()),
    ]
    .into();
    assert_eq!(st, expected, "{err}");
    let bj = batch_json(&out);
    let failed = &bj["clips"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == gone.as_str())
        .unwrap()["error"];
    assert!(failed.as_str().unwrap().contains("cannot read"), "{failed}");
    // One output folder (plus the summary files).
    let folders: Vec<PathBuf> = tree(&out).into_iter().filter(|p| p.is_dir()).collect();
    assert_eq!(folders, [out.join("punch")]);
}

/// G1's profile and URDF copied to `dir`; returns the profile's path and the URDF's.
fn g1_copy(dir: &Path) -> (PathBuf, PathBuf) {
    std::fs::create_dir_all(dir.join("robots/g1")).unwrap();
    std::fs::create_dir_all(dir.join("profiles")).unwrap();
    let urdf = dir.join("robots/g1/g1_29dof_rev_1_0.urdf");
    std::fs::copy(data().join("robots/g1/g1_29dof_rev_1_0.urdf"), &urdf).unwrap();
    let profile = dir.join("profiles/g1.toml");
    std::fs::copy(data().join("profiles/g1.toml"), &profile).unwrap();
    (profile, urdf)
}

/// The hip pitch range written into the edited URDF [rad]: it holds G1's standing posture
/// (hip pitch −0.3 rad) and cuts the walk clip's swing.
const TIGHT_HIP: (f64, f64) = (-0.45, 0.1);
/// How far a joint may end past its URDF range in the written motion [rad]: the solver keeps
/// the range up to its rounding.
const LIMIT_ROUNDING: f64 = 1e-9;

/// Editing the robot's URDF between two runs (a tighter left hip pitch range) redoes the clip,
/// and the new motion keeps the new range, which the first run's did not; a third run with
/// nothing changed skips it.
#[test]
fn an_edited_urdf_redoes_the_clip_under_its_new_limits() {
    let dir = tmp("urdf");
    let (profile, urdf) = g1_copy(&dir);
    let input = dir.join("walk.txt");
    std::fs::copy(clip("humanoid3d_walk"), &input).unwrap();
    let out = dir.join("out");
    let robot = ["--robot", profile.to_str().unwrap(), "--no-viewer"];
    let o = retarget(&input, &out, &robot);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = out.join("walk/motion.csv");
    let first = column(&csv, "left_hip_pitch_joint");
    assert!(
        first.iter().any(|q| *q < TIGHT_HIP.0 || *q > TIGHT_HIP.1),
        "the first run must leave the range the edit sets"
    );

    let text = std::fs::read_to_string(&urdf).unwrap();
    let old = r#"<limit lower="-2.5307" upper="2.8798" effort="88" velocity="32"/>"#;
    let new = format!(
        r#"<limit lower="{}" upper="{}" effort="88" velocity="32"/>"#,
        TIGHT_HIP.0, TIGHT_HIP.1
    );
    let at = text.find("<joint name=\"left_hip_pitch_joint\"").unwrap();
    let (head, rest) = text.split_at(at);
    // The limit replaced is the hip pitch joint's own (inside its element).
    assert!(rest.find(old).unwrap() < rest.find("</joint>").unwrap());
    std::fs::write(&urdf, format!("{head}{}", rest.replacen(old, &new, 1))).unwrap();

    let o = retarget(&input, &out, &robot);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(statuses(&out)["walk"], "retargeted");
    for q in column(&csv, "left_hip_pitch_joint") {
        assert!(
            q >= TIGHT_HIP.0 - LIMIT_ROUNDING && q <= TIGHT_HIP.1 + LIMIT_ROUNDING,
            "{q} outside {TIGHT_HIP:?}"
        );
    }
    let o = retarget(&input, &out, &robot);
    assert!(o.status.success());
    assert_eq!(statuses(&out)["walk"], "skipped");
}

/// A clip done once whose input then fails (replaced by a corrupt file): its earlier folder is
/// removed, so nothing reads as finished for it, and nothing temporary is left.
#[test]
fn a_clip_that_now_fails_leaves_no_finished_looking_folder() {
    let dir = tmp("fails");
    let input = dir.join("punch.txt");
    std::fs::copy(clip("humanoid3d_punch"), &input).unwrap();
    let out = dir.join("out");
    let o = retarget(&input, &out, &["--robot", "g1", "--no-viewer"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("punch/.record").is_file());
    let text = std::fs::read_to_string(&input).unwrap();
    std::fs::write(&input, &text[..text.len() / 2]).unwrap();
    let o = retarget(&input, &out, &["--robot", "g1", "--no-viewer"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(statuses(&out)["punch"], "failed");
    assert!(!out.join("punch").exists());
    no_temporaries(&out);
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        !index.contains("href=\"punch/"),
        "no link to a failed clip's files"
    );
}

/// A run without the viewer links none; a run asking for it then redoes the clip and links
/// the viewer it wrote; a third run without it skips the clip and links the viewer still there.
#[test]
fn the_report_links_a_viewer_only_when_it_was_written() {
    let dir = tmp("viewer");
    let input = dir.join("punch.txt");
    std::fs::copy(clip("humanoid3d_punch"), &input).unwrap();
    let out = dir.join("out");
    let index = || std::fs::read_to_string(out.join("index.html")).unwrap();
    let link = "href=\"punch/viewer.html\"";
    for (extra, status, linked) in [
        (&["--no-viewer"][..], "retargeted", false),
        (&[][..], "retargeted", true),
        (&["--no-viewer"][..], "skipped", true),
    ] {
        let mut args = vec!["--robot", "g1"];
        args.extend_from_slice(extra);
        let o = retarget(&input, &out, &args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(statuses(&out)["punch"], status, "{extra:?}");
        assert_eq!(out.join("punch/viewer.html").is_file(), linked, "{extra:?}");
        assert_eq!(index().contains(link), linked, "{extra:?}");
        assert!(index().contains("href=\"punch/motion.csv\""));
    }
}

/// SIGINT after the first clip of eight (one worker): the batch takes no more clips, the one in
/// hand finishes, and batch.json lists every clip as retargeted (its folder complete) or not
/// run (no folder), with nothing temporary left; the exit status is 1.
#[cfg(unix)]
#[test]
fn sigint_stops_the_batch_and_writes_its_summary() {
    use std::io::BufRead;
    let dir = tmp("sigint");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    for i in 0..8 {
        std::fs::copy(clip("humanoid3d_walk"), input.join(format!("walk_{i}.txt"))).unwrap();
    }
    let out = dir.join("out");
    let mut child = iktc()
        .arg("retarget")
        .arg(&input)
        .arg("--out")
        .arg(&out)
        .args(["--dt", DT, "--jobs", "1", "--robot", "g1", "--no-viewer"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = Vec::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        let first = line.starts_with("[1/8]");
        seen.push(line);
        if first {
            break;
        }
    }
    assert!(
        seen.last().is_some_and(|l| l.starts_with("[1/8]")),
        "{seen:?}"
    );
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let rest: Vec<String> = lines.map(|l| l.unwrap()).collect();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(1), "{rest:?}");
    assert!(rest.iter().any(|l| l.contains("interrupted")), "{rest:?}");
    let bj = batch_json(&out);
    assert_eq!(bj["interrupted"], true);
    let st = statuses(&out);
    assert_eq!(st.len(), 8, "{st:?}");
    let done = st.values().filter(|s| *s == "retargeted").count();
    let not_run = st.values().filter(|s| *s == "interrupted").count();
    assert_eq!(done + not_run, 8, "{st:?}");
    assert!(done >= 1 && not_run >= 1, "{st:?}");
    for (name, s) in &st {
        let folder = out.join(name);
        if s == "retargeted" {
            for f in [".record", "motion.csv", "motion.npz", "quality.json"] {
                assert!(folder.join(f).is_file(), "{name}/{f}");
            }
        } else {
            assert!(!folder.exists(), "{name}");
        }
    }
    no_temporaries(&out);
    // The next run does the rest and skips what was done.
    let o = retarget(&input, &out, &["--robot", "g1", "--no-viewer"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let again = statuses(&out);
    assert_eq!(again.values().filter(|s| *s == "skipped").count(), done);
    assert_eq!(
        again.values().filter(|s| *s == "retargeted").count(),
        not_run
    );
}
