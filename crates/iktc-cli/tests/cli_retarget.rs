//! `iktc retarget` over the shared DeepMimic clips plus generated bad ones (a corrupt file, an
//! empty file, a one-frame clip): good clips written, bad ones listed with their errors, exit
//! status 1, a second run skipping the good clips, `--force` redoing them, a killed batch
//! leaving only complete files; the NPZ read back by the independent reader below (zip central
//! directory and `.npy` headers parsed from their specifications) equals the CSV by its stated
//! columns and the joint trajectories `iktc imitate` writes for the same clip (keypoint
//! retargeting, the default of both); the joint route (`--retarget joints`) resampled at other
//! rates.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::SystemTime;

const CLIPS: [&str; 4] = [
    "humanoid3d_dance_a",
    "humanoid3d_dance_b",
    "humanoid3d_punch",
    "humanoid3d_walk",
];
const BAD: [&str; 3] = ["bad/corrupt", "bad/empty", "bad/short"];
/// Control period of the test runs [s] (twice the default: half the ticks).
const DT: &str = "0.01";
/// Two runs of one clip (`iktc retarget` and `iktc imitate`) agree to this relative tolerance
/// [–]: rounding may differ between processes, far below any tracking figure.
const SAME_RUN: f64 = 1e-9;
/// Half the last printed digit of `keypoints_trajectory.csv`'s time (four decimals) [s].
const PRINTED_TIME: f64 = 5e-5;
/// Half the last printed digit of its angles (six decimals) [rad].
const PRINTED_ANGLE: f64 = 5e-7;

fn iktc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_iktc"))
}

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../iktc/data/motions/deepmimic")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc-retarget-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The shared clips and the bad ones under `dir/in`.
fn inputs(dir: &Path) -> PathBuf {
    let input = dir.join("in");
    std::fs::create_dir_all(input.join("bad")).unwrap();
    for c in CLIPS {
        std::fs::copy(
            data().join(format!("{c}.txt")),
            input.join(format!("{c}.txt")),
        )
        .unwrap();
    }
    let walk = std::fs::read_to_string(data().join("humanoid3d_walk.txt")).unwrap();
    std::fs::write(input.join("bad/corrupt.txt"), &walk[..walk.len() / 2]).unwrap();
    std::fs::write(input.join("bad/empty.txt"), "").unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&walk).unwrap();
    let frames = v["Frames"].as_array_mut().unwrap();
    frames.truncate(1);
    std::fs::write(input.join("bad/short.txt"), v.to_string()).unwrap();
    input
}

fn retarget(args: &[&str]) -> Output {
    iktc()
        .arg("retarget")
        .args(args)
        .args(["--dt", DT, "--jobs", "2"])
        .output()
        .unwrap()
}

/// `iktc retarget CLIP --robot g1 --out OUT --no-viewer` with `extra` arguments.
fn retarget_on_g1(clip: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        clip.to_str().unwrap(),
        "--robot",
        "g1",
        "--out",
        out.to_str().unwrap(),
        "--no-viewer",
    ];
    args.extend_from_slice(extra);
    retarget(&args)
}

fn batch_json(out: &Path) -> BTreeMap<String, serde_json::Value> {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("batch.json")).unwrap()).unwrap();
    v["clips"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| (c["name"].as_str().unwrap().to_string(), c.clone()))
        .collect()
}

fn statuses(out: &Path) -> BTreeMap<String, String> {
    batch_json(out)
        .into_iter()
        .map(|(k, v)| (k, v["status"].as_str().unwrap().to_string()))
        .collect()
}

fn mtime(p: &Path) -> SystemTime {
    std::fs::metadata(p).unwrap().modified().unwrap()
}

/// Every file under `dir`, recursively.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p);
            }
        }
    }
    out
}

// ---- an independent reader of NumPy's .npz (zip of .npy) ----

fn u16_at(b: &[u8], i: usize) -> usize {
    u16::from_le_bytes([b[i], b[i + 1]]) as usize
}

fn u32_at(b: &[u8], i: usize) -> usize {
    u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]) as usize
}

/// A value read from an `.npy` member.
#[derive(Debug)]
enum Npy {
    F64(Vec<usize>, Vec<f64>),
    Str(Vec<String>),
}

/// Reads the archive from its end-of-central-directory record, as zip readers do.
fn read_npz(bytes: &[u8]) -> BTreeMap<String, Npy> {
    let eocd = (0..=bytes.len() - 22)
        .rev()
        .find(|&i| u32_at(bytes, i) == 0x0605_4b50)
        .expect("end of central directory");
    let count = u16_at(bytes, eocd + 10);
    let mut at = u32_at(bytes, eocd + 16);
    let mut out = BTreeMap::new();
    for _ in 0..count {
        assert_eq!(u32_at(bytes, at), 0x0201_4b50, "central header");
        assert_eq!(u16_at(bytes, at + 10), 0, "stored");
        let size = u32_at(bytes, at + 24);
        let nlen = u16_at(bytes, at + 28);
        let (elen, clen) = (u16_at(bytes, at + 30), u16_at(bytes, at + 32));
        let local = u32_at(bytes, at + 42);
        let name = std::str::from_utf8(&bytes[at + 46..at + 46 + nlen]).unwrap();
        at += 46 + nlen + elen + clen;
        assert_eq!(u32_at(bytes, local), 0x0403_4b50, "local header");
        let start = local + 30 + u16_at(bytes, local + 26) + u16_at(bytes, local + 28);
        let npy = &bytes[start..start + size];
        out.insert(name.trim_end_matches(".npy").to_string(), parse_npy(npy));
    }
    out
}

fn parse_npy(b: &[u8]) -> Npy {
    assert_eq!(&b[..6], b"\x93NUMPY");
    let hlen = u16_at(b, 8);
    let header = std::str::from_utf8(&b[10..10 + hlen]).unwrap();
    let field = |key: &str| {
        let i = header.find(key).unwrap() + key.len();
        header[i..].trim_start_matches([':', ' ', '\''])
    };
    let descr: String = field("'descr'")
        .chars()
        .take_while(|c| *c != '\'')
        .collect();
    assert!(field("'fortran_order'").starts_with("False"));
    let shape_text = field("'shape'");
    let shape: Vec<usize> = shape_text[1..shape_text.find(')').unwrap()]
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let data = &b[10 + hlen..];
    let n: usize = shape.iter().product();
    if descr == "<f8" {
        assert_eq!(data.len(), 8 * n);
        let v = data
            .chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        Npy::F64(shape, v)
    } else {
        let width: usize = descr.strip_prefix("<U").unwrap().parse().unwrap();
        assert_eq!(data.len(), 4 * width * n);
        Npy::Str(
            data.chunks(4 * width)
                .map(|c| {
                    c.chunks(4)
                        .map(|u| u32::from_le_bytes(u.try_into().unwrap()))
                        .filter(|u| *u != 0)
                        .map(|u| char::from_u32(u).unwrap())
                        .collect()
                })
                .collect(),
        )
    }
}

fn floats<'a>(npz: &'a BTreeMap<String, Npy>, name: &str) -> (&'a [usize], &'a [f64]) {
    match &npz[name] {
        Npy::F64(s, v) => (s, v),
        other => panic!("{name}: {other:?}"),
    }
}

fn strings<'a>(npz: &'a BTreeMap<String, Npy>, name: &str) -> &'a [String] {
    match &npz[name] {
        Npy::Str(v) => v,
        other => panic!("{name}: {other:?}"),
    }
}

/// A CSV of numbers: header and rows.
fn read_csv(p: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn batch_of_good_and_bad_clips_skip_force_and_formats() {
    let dir = tmp("batch");
    let input = inputs(&dir);
    let out = dir.join("out");
    let o = retarget(&[input.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let st = statuses(&out);
    for c in CLIPS {
        assert_eq!(st[c], "retargeted", "{c}: {err}");
        for f in [
            "motion.csv",
            "motion.npz",
            "quality.json",
            "viewer.html",
            ".record",
        ] {
            assert!(out.join(c).join(f).is_file(), "{c}/{f}");
        }
    }
    let bj = batch_json(&out);
    for (b, why) in BAD
        .iter()
        .zip(["EOF while parsing", "EOF while parsing", "1 frame"])
    {
        assert_eq!(st[*b], "failed", "{b}");
        let e = bj[*b]["error"].as_str().unwrap();
        assert!(
            e.contains(why) && e.contains(&b.replace("bad/", "")),
            "{b}: {e}"
        );
        assert!(err.contains(&format!("{b}: FAILED")), "{err}");
        assert!(!out.join(b).exists(), "{b}: no folder for a failed clip");
    }
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(index.contains("Failures (3)"));
    for c in CLIPS {
        assert!(index.contains(&format!("href=\"{c}/viewer.html\"")), "{c}");
    }
    assert!(
        files(&out)
            .iter()
            .all(|f| !f.to_string_lossy().contains(".tmp")),
        "temporary files left"
    );

    // A second run skips every good clip (their files untouched); the bad ones fail again.
    let before: Vec<SystemTime> = CLIPS
        .iter()
        .map(|c| mtime(&out.join(c).join("motion.npz")))
        .collect();
    let o = retarget(&[input.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let st = statuses(&out);
    for (c, t) in CLIPS.iter().zip(&before) {
        assert_eq!(st[*c], "skipped", "{c}");
        assert_eq!(mtime(&out.join(c).join("motion.npz")), *t, "{c}");
    }
    // The report of a run that skipped everything still shows every clip's figures.
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(index.contains("humanoid3d_walk") && index.contains("data-v="));

    // A touched input (a later time, the same bytes) is skipped; an input replaced by another
    // clip with an older time (as `cp -p` or `rsync -a` leave it) is redone, from its new bytes.
    let walk = input.join("humanoid3d_walk.txt");
    std::fs::File::options()
        .append(true)
        .open(&walk)
        .unwrap()
        .set_modified(SystemTime::now() + std::time::Duration::from_secs(5))
        .unwrap();
    let punch = input.join("humanoid3d_punch.txt");
    let old_time = mtime(&punch) - std::time::Duration::from_secs(3600 * 24 * 365);
    std::fs::copy(data().join("humanoid3d_dance_a.txt"), &punch).unwrap();
    std::fs::File::options()
        .append(true)
        .open(&punch)
        .unwrap()
        .set_modified(old_time)
        .unwrap();
    let o = retarget(&[input.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let st = statuses(&out);
    assert_eq!(st["humanoid3d_walk"], "skipped");
    assert_eq!(st["humanoid3d_punch"], "retargeted");
    assert_eq!(
        read_csv(&out.join("humanoid3d_punch/motion.csv")).1.len(),
        read_csv(&out.join("humanoid3d_dance_a/motion.csv")).1.len(),
        "the punch folder holds the dance clip it was replaced by"
    );
    std::fs::copy(data().join("humanoid3d_punch.txt"), &punch).unwrap();

    // --force redoes every clip; the good ones alone exit 0.
    let goods: Vec<String> = CLIPS
        .iter()
        .map(|c| input.join(format!("{c}.txt")).display().to_string())
        .collect();
    let mut args: Vec<&str> = goods.iter().map(|s| s.as_str()).collect();
    args.extend(["--out", out.to_str().unwrap(), "--force"]);
    let o = retarget(&args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let st = statuses(&out);
    for c in CLIPS {
        assert_eq!(st[c], "retargeted", "{c}");
    }

    // The NPZ, the CSV and `iktc imitate`'s keypoints_trajectory.csv of the same clip agree.
    let clip = "humanoid3d_punch";
    let npz = read_npz(&std::fs::read(out.join(clip).join("motion.npz")).unwrap());
    let (csv_header, csv_rows) = read_csv(&out.join(clip).join("motion.csv"));
    let imitate_dir = dir.join("imitate");
    let o = iktc()
        .args(["imitate", "--motion"])
        .arg(input.join(format!("{clip}.txt")))
        .args(["--dt", DT, "--out"])
        .arg(&imitate_dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (jh, jrows) = read_csv(&imitate_dir.join("keypoints_trajectory.csv"));
    let names = strings(&npz, "joint_names");
    let (fps_shape, fps) = floats(&npz, "fps");
    assert!(fps_shape.is_empty());
    assert_eq!(fps[0], 100.0);
    let (tshape, time) = floats(&npz, "time");
    let n = tshape[0];
    assert_eq!(
        n,
        jrows.len(),
        "one frame per control tick at the control rate"
    );
    assert_eq!(n, csv_rows.len());
    let (qshape, q) = floats(&npz, "joint_pos");
    let (_, qd) = floats(&npz, "joint_vel");
    assert_eq!(qshape, [n, names.len()]);
    assert_eq!(
        &csv_header[8..],
        names,
        "CSV joint columns in the NPZ's order"
    );
    assert_eq!(
        &csv_header[..8],
        ["t", "base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw"]
    );
    let (_, base_pos) = floats(&npz, "base_pos");
    let (_, quat) = floats(&npz, "base_quat_xyzw");
    let m = names.len();
    for k in 0..n {
        let row = &csv_rows[k];
        assert_eq!(row[0], time[k]);
        assert_eq!(&row[1..4], &base_pos[3 * k..3 * k + 3]);
        assert_eq!(&row[4..8], &quat[4 * k..4 * k + 4]);
        let norm: f64 = quat[4 * k..4 * k + 4].iter().map(|x| x * x).sum();
        assert!((norm - 1.0).abs() < 1e-12);
        assert_eq!(&row[8..], &q[m * k..m * (k + 1)]);
        // keypoints_trajectory.csv of `iktc imitate`, by column name, written with four
        // decimals of time and six of angle.
        assert!((jrows[k][0] - time[k]).abs() <= PRINTED_TIME, "{k}");
        for (j, name) in names.iter().enumerate() {
            let col = jh.iter().position(|h| h == name).unwrap();
            let (a, b) = (jrows[k][col], q[m * k + j]);
            assert!(
                (a - b).abs() <= PRINTED_ANGLE + SAME_RUN * (1.0 + a.abs()),
                "{name} at tick {k}: {a} {b}"
            );
        }
    }
    let quality: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join(clip).join("quality.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(quality["route"], "keypoints");
    assert_eq!(quality["figures"]["route"], "keypoints");
    // The verdict says why whenever it is not healthy, and no joint limit is among the reasons.
    let failures = quality["figures"]["failures"].as_array().unwrap();
    assert_eq!(
        quality["figures"]["healthy"].as_bool().unwrap(),
        failures.is_empty(),
        "{quality}"
    );
    assert!(
        !failures
            .iter()
            .any(|m| m.as_str().unwrap().contains("limit")),
        "{quality}"
    );
    assert!(quality["summary"]["keypoints"]["points"].is_array());
    for key in [
        "mean_keypoint_error",
        "foot_slip",
        "penetration",
        "rms_jerk",
    ] {
        assert!(quality["figures"][key].is_f64(), "{key}");
    }
    // The report shows the keypoint route's columns, not the joint route's.
    assert!(index.contains(
        "<th>mean keypoint error against the person (joint centres, leg scale) [m]</th>"
    ));
    assert!(!index.contains("<th>upper-body RMS error [rad]</th>"));
    // Constant acceleration over a tick: (q⁺ − q)/Δt = (q̇ + q̇⁺)/2 for every joint.
    let dt: f64 = DT.parse().unwrap();
    for k in 0..n - 1 {
        for j in 0..m {
            let fd = (q[m * (k + 1) + j] - q[m * k + j]) / dt;
            let mean = 0.5 * (qd[m * (k + 1) + j] + qd[m * k + j]);
            assert!(
                (fd - mean).abs() < 1e-9 * (1.0 + mean.abs()),
                "{k} {j}: {fd} {mean}"
            );
        }
    }
    // Body positions: the pelvis is the root link (its position is the base's).
    let bodies = strings(&npz, "body_names");
    let (bshape, body) = floats(&npz, "body_pos_w");
    assert_eq!(bshape, [n, bodies.len(), 3]);
    let nb = bodies.len();
    let pelvis = bodies.iter().position(|b| b == "PELVIS_S").unwrap();
    for k in 0..n {
        let p = &body[3 * (nb * k + pelvis)..3 * (nb * k + pelvis) + 3];
        for i in 0..3 {
            assert!((p[i] - base_pos[3 * k + i]).abs() < 1e-12);
        }
    }
}

/// Joint positions (frames × joints), times and base positions of an `.npz`.
fn trajectory(p: &Path) -> (Vec<f64>, usize, Vec<f64>, Vec<f64>, Vec<f64>) {
    let npz = read_npz(&std::fs::read(p).unwrap());
    let (_, t) = floats(&npz, "time");
    let (s, q) = floats(&npz, "joint_pos");
    let (_, b) = floats(&npz, "base_pos");
    let (bs, body) = floats(&npz, "body_pos_w");
    // The pelvis (root link, first body frame) is the base: FK of the resampled configuration.
    for k in 0..t.len() {
        for i in 0..3 {
            assert!((body[3 * bs[1] * k + i] - b[3 * k + i]).abs() < 1e-12);
        }
    }
    (t.to_vec(), s[1], q.to_vec(), b.to_vec(), body.to_vec())
}

#[test]
fn output_rate_interpolates_the_control_ticks_linearly() {
    let dir = tmp("rate");
    let clip = data().join("humanoid3d_walk.txt");
    let run = |rate: &str, sub: &str| {
        let o = retarget(&[
            clip.to_str().unwrap(),
            "--out",
            dir.join(sub).to_str().unwrap(),
            "--rate",
            rate,
            "--no-viewer",
            "--retarget",
            "joints",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let quality =
            std::fs::read_to_string(dir.join(sub).join("humanoid3d_walk/quality.json")).unwrap();
        assert!(quality.contains("\"route\": \"joints\""), "{quality}");
        trajectory(&dir.join(sub).join("humanoid3d_walk/motion.npz"))
    };
    let (t100, m, q100, b100, _) = run("100", "r100");
    let dt: f64 = DT.parse().unwrap();
    for rate in [50.0, 30.0, 37.5] {
        let (t, m2, q, b, _) = run(&rate.to_string(), &format!("r{rate}"));
        assert_eq!(m2, m);
        let last = t100[t100.len() - 1];
        assert_eq!(
            t.len(),
            (last * rate + 1e-9).floor() as usize + 1,
            "{rate} Hz"
        );
        for (j, tj) in t.iter().enumerate() {
            assert!((tj - j as f64 / rate).abs() < 1e-12);
            // The ticks around t_j and the linear weight, from the 100 Hz output.
            let k = ((tj / dt + 1e-9).floor() as usize).min(t100.len() - 1);
            let s = if k + 1 < t100.len() {
                tj / dt - k as f64
            } else {
                0.0
            };
            let k1 = (k + 1).min(t100.len() - 1);
            for d in 0..m {
                let want = q100[m * k + d] + s * (q100[m * k1 + d] - q100[m * k + d]);
                assert!(
                    (q[m * j + d] - want).abs() < 1e-9,
                    "{rate} Hz frame {j} joint {d}"
                );
            }
            for i in 0..3 {
                let want = b100[3 * k + i] + s * (b100[3 * k1 + i] - b100[3 * k + i]);
                assert!((b[3 * j + i] - want).abs() < 1e-9);
            }
        }
    }
}

#[test]
fn killed_batch_leaves_only_complete_files() {
    let dir = tmp("kill");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    // Eight clips, one worker: a kill after the first lands mid-batch.
    for i in 0..2 {
        for c in CLIPS {
            std::fs::copy(
                data().join(format!("{c}.txt")),
                input.join(format!("{c}_{i}.txt")),
            )
            .unwrap();
        }
    }
    let out = dir.join("out");
    let mut child = iktc()
        .args([
            "retarget",
            input.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(["--jobs", "1", "--dt", DT])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let marked = |out: &Path| files(out).iter().filter(|f| f.ends_with(".record")).count();
    while !out.is_dir() || marked(&out) == 0 {
        assert!(child.try_wait().unwrap().is_none(), "the batch ended first");
        assert!(start.elapsed().as_secs() < 120);
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done = marked(&out);
    assert!(done < 8, "the kill came after the whole batch");
    // Every file under its final name, outside the temporary folders, is complete; a marked
    // clip has all its files.
    for f in files(&out) {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let temporary = f.components().any(|c| {
            let c = c.as_os_str().to_string_lossy();
            c.starts_with('.') && c.ends_with(".tmp")
        });
        if temporary {
            continue;
        }
        match name.as_str() {
            "motion.npz" => {
                trajectory(&f);
            }
            "quality.json" | "batch.json" => {
                serde_json::from_str::<serde_json::Value>(&std::fs::read_to_string(&f).unwrap())
                    .unwrap();
            }
            "motion.csv" => {
                let (h, rows) = read_csv(&f);
                assert!(rows.iter().all(|r| r.len() == h.len()));
            }
            "viewer.html" => {
                assert!(std::fs::read_to_string(&f)
                    .unwrap()
                    .trim_end()
                    .ends_with("</html>"))
            }
            ".record" => {
                let d = f.parent().unwrap();
                for o in ["motion.csv", "motion.npz", "quality.json", "viewer.html"] {
                    assert!(d.join(o).is_file(), "{}", d.join(o).display());
                }
            }
            other => panic!("unexpected file {other}"),
        }
    }
    // The re-run does the rest, skips what was done, and leaves no temporary file.
    let o = retarget(&[input.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let st = statuses(&out);
    assert_eq!(st.values().filter(|s| *s == "skipped").count(), done);
    assert_eq!(st.values().filter(|s| *s == "retargeted").count(), 8 - done);
    assert!(files(&out)
        .iter()
        .all(|f| !f.to_string_lossy().contains(".tmp")));
}

/// `--standing`: G1's feet (the profile's ankle frames) and pelvis stay where they start while
/// the clip's upper body moves the hands; the option enters the settings fingerprint (a run
/// without it redoes the clip); `--smoothing` is checked, and both are refused by the joint
/// route.
#[test]
fn standing_holds_feet_and_pelvis_and_is_part_of_the_settings() {
    let dir = tmp("standing");
    let clip = data().join("humanoid3d_dance_b.txt");
    let out = dir.join("out");
    let run = |extra: &[&str]| retarget_on_g1(&clip, &out, extra);
    let o = run(&["--standing", "--smoothing", "6"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let npz = read_npz(&std::fs::read(out.join("humanoid3d_dance_b/motion.npz")).unwrap());
    let bodies = strings(&npz, "body_names");
    let (shape, body) = floats(&npz, "body_pos_w");
    let (n, nb) = (shape[0], shape[1]);
    let travel = |name: &str| {
        let i = bodies.iter().position(|b| b == name).unwrap();
        let at = |k: usize| &body[3 * (nb * k + i)..3 * (nb * k + i) + 3];
        (0..n)
            .map(|k| {
                (0..3)
                    .map(|d| (at(k)[d] - at(0)[d]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(0.0, f64::max)
    };
    // Held by the first level (sub-millimetre) and under the COM level (millimetres).
    for foot in ["left_ankle_roll_link", "right_ankle_roll_link"] {
        assert!(travel(foot) < 1e-3, "{foot}: {}", travel(foot));
    }
    assert!(travel("pelvis") < 1e-2, "pelvis: {}", travel("pelvis"));
    assert!(travel("left_rubber_hand") > 0.1);
    // Without the options the settings differ: the clip is redone, not skipped.
    let o = run(&[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(statuses(&out)["humanoid3d_dance_b"], "retargeted");
    let o = run(&["--smoothing", "0"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("smoothing") && err.contains("> 0"), "{err}");
    let o = run(&["--standing", "--retarget", "joints"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--retarget keypoints only"));
}

/// `--max-leg-extension` reaches the run: a smaller share of the leg lowers the pelvis on a
/// walk (the cap binds where the person's knees are straighter than the cap's knee angle, 74°
/// at 0.8), the clip is redone (the option is part of the settings), a share outside (0, 1]
/// is an error naming the setting, and the joint route refuses the option.
#[test]
fn max_leg_extension_option_lowers_the_pelvis() {
    let dir = tmp("extension");
    let clip = data().join("humanoid3d_walk.txt");
    let out = dir.join("out");
    let run = |extra: &[&str]| retarget_on_g1(&clip, &out, extra);
    let pelvis_median_height = || {
        let npz = read_npz(&std::fs::read(out.join("humanoid3d_walk/motion.npz")).unwrap());
        let bodies = strings(&npz, "body_names");
        let (shape, body) = floats(&npz, "body_pos_w");
        let i = bodies.iter().position(|b| b == "pelvis").unwrap();
        let nb = shape[1];
        let mut z: Vec<f64> = (0..shape[0]).map(|k| body[3 * (nb * k + i) + 2]).collect();
        z.sort_by(f64::total_cmp);
        z[z.len() / 2]
    };
    let o = run(&[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let default = pelvis_median_height();
    let o = run(&["--max-leg-extension", "0.8"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(statuses(&out)["humanoid3d_walk"], "retargeted");
    let lowered = pelvis_median_height();
    // G1's leg is about 0.6 m: 0.12 of it is about 7 cm; at least 2 cm must show.
    assert!(
        default - lowered > 0.02,
        "pelvis median {default} m by default, {lowered} m at 0.8"
    );
    let o = run(&["--max-leg-extension", "1.5"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("max_leg_extension"), "{err}");
    let o = run(&["--max-leg-extension", "0.9", "--retarget", "joints"]);
    assert!(!o.status.success());
}

/// `--hands segments` places the hands along the arm instead of by the leg ratio (the default):
/// the robot's hands move differently (centimetres apart somewhere in the clip), the option
/// enters the settings fingerprint (the clip is redone, not skipped), and the joint route
/// refuses it.
#[test]
fn hands_option_moves_the_hands_and_is_part_of_the_settings() {
    let dir = tmp("hands");
    let clip = data().join("humanoid3d_punch.txt");
    let out = dir.join("out");
    let run = |extra: &[&str]| retarget_on_g1(&clip, &out, extra);
    let hand = || {
        let npz = read_npz(&std::fs::read(out.join("humanoid3d_punch/motion.npz")).unwrap());
        let bodies = strings(&npz, "body_names");
        let (shape, body) = floats(&npz, "body_pos_w");
        let i = bodies
            .iter()
            .position(|b| b == "right_rubber_hand")
            .unwrap();
        let nb = shape[1];
        (0..shape[0])
            .map(|k| body[3 * (nb * k + i)..3 * (nb * k + i) + 3].to_vec())
            .collect::<Vec<_>>()
    };
    let o = run(&[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let leg = hand();
    let o = run(&["--hands", "segments"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(statuses(&out)["humanoid3d_punch"], "retargeted");
    let seg = hand();
    assert_eq!(leg.len(), seg.len());
    let apart = leg
        .iter()
        .zip(&seg)
        .map(|(a, b)| (0..3).map(|d| (a[d] - b[d]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    assert!(apart > 0.02, "hands at most {apart} m apart");
    let o = run(&["--hands", "leg", "--retarget", "joints"]);
    assert!(!o.status.success());
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("--hands applies to --retarget keypoints only")
    );
}

/// `--reach`: each clip's `quality.json` has the static reach beside the run's error on the
/// same sampled ticks (at most it, and both in metres), the report gets its column, the motion
/// written is the same as without it, a run without it leaves both `null`, and the joint
/// route refuses it.
#[test]
fn reach_option_reports_the_static_reach() {
    let dir = tmp("reach");
    let clip = data().join("humanoid3d_walk.txt");
    let out = dir.join("out");
    let run = |extra: &[&str]| retarget_on_g1(&clip, &out, extra);
    let figures = || -> serde_json::Value {
        let q: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join("humanoid3d_walk/quality.json")).unwrap(),
        )
        .unwrap();
        q["figures"].clone()
    };
    let csv = || std::fs::read_to_string(out.join("humanoid3d_walk/motion.csv")).unwrap();
    let o = run(&[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let f = figures();
    assert!(f["reach_keypoint_error"].is_null() && f["reach_run_keypoint_error"].is_null());
    assert!(f["balanced_reach_keypoint_error"].is_null());
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(!index.contains("static reach"));
    let without = csv();
    let o = run(&["--reach"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(statuses(&out)["humanoid3d_walk"], "retargeted");
    let f = figures();
    let reach = f["reach_keypoint_error"].as_f64().unwrap();
    let sampled = f["reach_run_keypoint_error"].as_f64().unwrap();
    let mean = f["mean_keypoint_error"].as_f64().unwrap();
    assert!(0.0 < reach && reach <= sampled, "{reach} {sampled}");
    // Keeping the feet and the balance, a posture comes no closer than within the ranges
    // alone on this clip (both descents start at the run's posture).
    let balanced = f["balanced_reach_keypoint_error"].as_f64().unwrap();
    assert!(
        reach <= balanced && balanced < mean,
        "{reach} {balanced} {mean}"
    );
    // Sampled every 0.05 s, the run's error is close to its mean over every tick (metres).
    assert!((sampled - mean).abs() < 0.1 * mean, "{sampled} {mean}");
    assert_eq!(csv(), without);
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(index.contains("static reach") && index.contains("balanced reach"));
    let o = run(&["--reach", "--retarget", "joints"]);
    assert!(!o.status.success());
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("--reach applies to --retarget keypoints only")
    );
}

/// `--no-pivot`: on `humanoid3d_dance_a`, which spins on its feet, the feet keep their yaw
/// over every stance, so the motion differs from the default run's (and the changed setting
/// redoes the clip rather than skipping it); a clip without a turning stance
/// (`humanoid3d_dance_b`) is the same either way; the joint route refuses it.
#[test]
fn no_pivot_holds_the_feet_of_a_spinning_clip() {
    let dir = tmp("no-pivot");
    let out = dir.join("out");
    for (clip, spins) in [("humanoid3d_dance_a", true), ("humanoid3d_dance_b", false)] {
        let path = data().join(format!("{clip}.txt"));
        let csv = || std::fs::read_to_string(out.join(format!("{clip}/motion.csv"))).unwrap();
        let o = retarget_on_g1(&path, &out, &[]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let pivoting = csv();
        let o = retarget_on_g1(&path, &out, &["--no-pivot"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(statuses(&out)[clip], "retargeted");
        assert_eq!(csv() != pivoting, spins, "{clip}");
    }
    let o = retarget_on_g1(
        &data().join("humanoid3d_walk.txt"),
        &out,
        &["--no-pivot", "--retarget", "joints"],
    );
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr)
        .contains("--no-pivot applies to --retarget keypoints only"));
}

/// A batch whose `--out` lies inside its input folder, beside the output of an earlier batch
/// and of `iktc imitate` there: no output folder is searched for motion (their `quality.json` files are not
/// clips), not even an `--out` that an interrupted run left without `batch.json` and without
/// a clip's settings marker, so the same command runs again, skips the clip as up to date and
/// succeeds.
#[test]
fn output_folders_inside_the_input_folder_are_not_searched() {
    let dir = tmp("inside");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    std::fs::copy(
        data().join("humanoid3d_walk.txt"),
        input.join("humanoid3d_walk.txt"),
    )
    .unwrap();
    let (out, earlier) = (input.join("out"), input.join("earlier"));
    let o = retarget_on_g1(&input, &earlier, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::create_dir_all(out.join("humanoid3d_walk")).unwrap();
    std::fs::write(out.join("humanoid3d_walk/quality.json"), "{}").unwrap();
    // What `iktc imitate --out` writes (its summary is JSON, not a clip).
    let imitated = input.join("imitated");
    std::fs::create_dir_all(&imitated).unwrap();
    std::fs::write(imitated.join("keypoints_summary.json"), "{}").unwrap();
    for (pass, folders) in [("retargeted", 3), ("skipped", 3)] {
        let o = retarget_on_g1(&input, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        let s = statuses(&out);
        assert_eq!(s.len(), 1, "{s:?}");
        assert_eq!(s["humanoid3d_walk"], pass);
        let note = format!("not searched: {folders} folder(s) of iktc output");
        assert!(err.contains(&note), "{err}");
    }
}

/// `--format gmr,lafan-csv --format mjlab` writes those three files (and not motion.csv or
/// motion.npz); a second run skips the clip; a run asking for a file the folder lacks redoes
/// it; the LAFAN1 CSV holds the columns of motion.csv but its time, the mjlab NPZ the rate and
/// the base; an unknown format is refused with the valid names.
#[test]
fn formats_are_chosen_checked_by_the_skip_and_unknown_ones_refused() {
    let dir = tmp("formats");
    let clip = data().join("humanoid3d_walk.txt");
    let out = dir.join("out");
    let walk = out.join("humanoid3d_walk");
    let chosen = [
        "--rate",
        "30",
        "--format",
        "gmr,lafan-csv",
        "--format",
        "mjlab",
    ];
    for pass in ["retargeted", "skipped"] {
        let o = retarget_on_g1(&clip, &out, &chosen);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(statuses(&out)["humanoid3d_walk"], pass);
    }
    for f in [
        "motion_gmr.pkl",
        "motion_lafan.csv",
        "motion_mjlab.npz",
        "quality.json",
    ] {
        assert!(walk.join(f).is_file(), "{f}");
    }
    for f in ["motion.csv", "motion.npz"] {
        assert!(!walk.join(f).exists(), "{f}");
    }
    let files = batch_json(&out)["humanoid3d_walk"]["files"].clone();
    assert!(files.to_string().contains("motion_gmr.pkl"), "{files}");
    let lafan: Vec<Vec<f64>> = std::fs::read_to_string(walk.join("motion_lafan.csv"))
        .unwrap()
        .lines()
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let quality: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(walk.join("quality.json")).unwrap()).unwrap();
    assert_eq!(quality["output_rate_hz"], 30.0);
    assert_eq!(lafan.len() as u64, quality["frames"].as_u64().unwrap());
    assert!(lafan.iter().all(|r| r.len() == 7 + 29));
    let npz = read_npz(&std::fs::read(walk.join("motion_mjlab.npz")).unwrap());
    assert_eq!(floats(&npz, "fps"), (&[1][..], &[30.0][..]));
    let (shape, body) = floats(&npz, "body_pos_w");
    assert_eq!(shape, [lafan.len(), 30, 3]);
    let (_, quat) = floats(&npz, "body_quat_w");
    for (j, row) in lafan.iter().enumerate() {
        assert_eq!(
            &body[j * 90..j * 90 + 3],
            &row[..3],
            "pelvis = base, frame {j}"
        );
        let xyzw = &quat[j * 120..j * 120 + 4];
        let wxyz_of_row = [row[6], row[3], row[4], row[5]];
        let sign = if xyzw[0] * wxyz_of_row[0] < 0.0 {
            -1.0
        } else {
            1.0
        };
        for k in 0..4 {
            assert!(
                (xyzw[k] - sign * wxyz_of_row[k]).abs() <= SAME_RUN,
                "frame {j}"
            );
        }
    }

    // The default (csv, npz) is missing from the folder: the clip is redone, its folder
    // rewritten whole; the LAFAN1 rows are motion.csv's rows without the time.
    let o = retarget_on_g1(&clip, &out, &["--rate", "30"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(statuses(&out)["humanoid3d_walk"], "retargeted");
    assert!(!walk.join("motion_gmr.pkl").exists());
    let (header, rows) = read_csv(&walk.join("motion.csv"));
    assert_eq!(header.len(), 1 + 7 + 29);
    assert_eq!(rows.len(), lafan.len());
    for (r, l) in rows.iter().zip(&lafan) {
        assert_eq!(&r[1..], &l[..]);
    }

    let o = retarget_on_g1(&clip, &out, &["--format", "gmr,bvh"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("unknown output format `bvh`"), "{err}");
    for name in ["csv", "npz", "gmr", "lafan-csv", "mjlab"] {
        assert!(err.contains(name), "{err}");
    }
}
