//! Marker sources: C3D files (float and integer) and points CSV files written by the tests;
//! marker groups, gap filling, malformed files, format detection.

use std::path::PathBuf;

use iktc::motion::{
    builtin_body_map, load_motion, read_c3d, read_points_csv, BodyPoint, LengthUnit, MotionFormat,
    MotionOptions, UpAxis,
};
use iktc::Error;
use nalgebra::Vector3;

/// Plug-in-Gait-like markers of a standing subject \[mm\], Z up, facing +X, left along +Y.
fn pig_markers() -> Vec<(&'static str, [f64; 3])> {
    let left: [(&str, [f64; 3]); 14] = [
        ("LASI", [100.0, 100.0, 1000.0]),
        ("LPSI", [-80.0, 50.0, 1050.0]),
        ("LFHD", [80.0, 60.0, 1700.0]),
        ("LBHD", [-80.0, 60.0, 1680.0]),
        ("LSHO", [0.0, 180.0, 1420.0]),
        ("LELB", [0.0, 200.0, 1120.0]),
        ("LWRA", [20.0, 210.0, 850.0]),
        ("LWRB", [-20.0, 210.0, 850.0]),
        ("LKNE", [0.0, 100.0, 520.0]),
        ("LANK", [-10.0, 100.0, 80.0]),
        ("LTOE", [150.0, 90.0, 40.0]),
        ("LTHI", [0.0, 130.0, 760.0]),
        ("LHEE", [-60.0, 100.0, 50.0]),
        ("LFIN", [0.0, 210.0, 780.0]),
    ];
    let mut out: Vec<(&'static str, [f64; 3])> = Vec::new();
    for (name, p) in left {
        out.push((name, p));
        let right: &'static str = Box::leak(format!("R{}", &name[1..]).into_boxed_str());
        out.push((right, [p[0], -p[1], p[2]]));
    }
    out.extend([
        ("C7", [-60.0, 0.0, 1450.0]),
        ("T10", [-100.0, 0.0, 1250.0]),
        ("CLAV", [40.0, 0.0, 1420.0]),
        ("STRN", [80.0, 0.0, 1300.0]),
    ]);
    out
}

/// A C3D file (Intel) of `frames` frames at `rate` Hz: float samples when `scale < 0`, else
/// 16-bit integers times `scale`; `None` marks a marker not seen (residual −1).
fn c3d_bytes(labels: &[&str], frames: &[Vec<Option<[f64; 3]>>], rate: f32, scale: f32) -> Vec<u8> {
    c3d_bytes_as(84, labels, frames, rate, scale)
}

/// The 4 bytes of `v` as processor type `processor` stores a float: Intel (84) IEEE
/// little-endian, DEC (85) VAX F-floating (the IEEE bits of `4v` with their 16-bit words
/// swapped), MIPS (86) IEEE big-endian.
fn float_as(processor: u8, v: f32) -> [u8; 4] {
    match processor {
        85 if v == 0.0 => [0; 4],
        85 => {
            let b = (4.0 * v).to_le_bytes();
            [b[2], b[3], b[0], b[1]]
        }
        86 => v.to_be_bytes(),
        _ => v.to_le_bytes(),
    }
}

/// As [`c3d_bytes`], for processor type `processor` (84 Intel, 85 DEC, 86 MIPS); more than 255
/// labels continue in `POINT:LABELS2`, `POINT:LABELS3`, ….
fn c3d_bytes_as(
    processor: u8,
    labels: &[&str],
    frames: &[Vec<Option<[f64; 3]>>],
    rate: f32,
    scale: f32,
) -> Vec<u8> {
    let i16_as = |v: i16| {
        if processor == 86 {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let mut b = vec![0u8; 512];
    b[0] = 2;
    b[1] = 0x50;
    let put16 =
        |b: &mut Vec<u8>, at: usize, v: u16| b[at..at + 2].copy_from_slice(&i16_as(v as i16));
    put16(&mut b, 2, labels.len() as u16);
    put16(&mut b, 4, 0);
    put16(&mut b, 6, 1);
    put16(&mut b, 8, frames.len() as u16);
    b[12..16].copy_from_slice(&float_as(processor, scale));
    put16(&mut b, 16, 0); // data start block, set below
    b[20..24].copy_from_slice(&float_as(processor, rate));
    // Parameters.
    let mut p: Vec<u8> = vec![1, 0x50, 0, processor];
    p.extend([5u8, (-1i8) as u8]);
    p.extend(b"POINT");
    p.extend(i16_as(3));
    p.push(0);
    let len = 4usize;
    for (k, chunk) in labels.chunks(255).enumerate() {
        let name = match k {
            0 => "LABELS".to_string(),
            _ => format!("LABELS{}", k + 1),
        };
        p.extend([name.len() as u8, 1]);
        p.extend(name.as_bytes());
        let data = len * chunk.len();
        p.extend(i16_as((2 + 1 + 1 + 2 + data + 1) as i16));
        p.extend([(-1i8) as u8, 2, len as u8, chunk.len() as u8]);
        for l in chunk {
            let mut s = l.as_bytes().to_vec();
            s.resize(len, b' ');
            p.extend(s);
        }
        p.push(0);
    }
    p.extend([4u8, 1]);
    p.extend(b"RATE");
    p.extend(i16_as(0));
    p.extend([4u8, 0]);
    p.extend(float_as(processor, rate));
    p.push(0);
    let blocks = p.len().div_ceil(512);
    p[2] = blocks as u8;
    p.resize(blocks * 512, 0);
    b.extend(p);
    put16(&mut b, 16, (2 + blocks) as u16);
    for frame in frames {
        for m in frame {
            let (xyz, residual) = match m {
                Some(v) => (*v, 0.0),
                None => ([0.0; 3], -1.0),
            };
            for v in xyz.iter().chain(std::iter::once(&residual)) {
                if scale < 0.0 {
                    b.extend(float_as(processor, *v as f32));
                } else {
                    let i = if *v < 0.0 && std::ptr::eq(v, &residual) {
                        -1
                    } else {
                        (*v / scale as f64).round() as i16
                    };
                    b.extend(i16_as(i));
                }
            }
        }
    }
    b
}

/// Marker positions per frame \[mm\], `None` where unseen.
type Frames = Vec<Vec<Option<[f64; 3]>>>;

/// Frames of the PiG markers moving +10 mm along x per frame; `hide(frame, marker)` hides one.
fn pig_frames(n: usize, hide: &dyn Fn(usize, &str) -> bool) -> (Vec<&'static str>, Frames) {
    let markers = pig_markers();
    let labels: Vec<&'static str> = markers.iter().map(|(n, _)| *n).collect();
    let frames = (0..n)
        .map(|f| {
            markers
                .iter()
                .map(|(name, p)| (!hide(f, name)).then_some([p[0] + 10.0 * f as f64, p[1], p[2]]))
                .collect()
        })
        .collect();
    (labels, frames)
}

fn temp(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("iktc_markers_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn close(a: Vector3<f64>, b: Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol
}

#[test]
fn a_plug_in_gait_c3d_gives_marker_centroids_with_a_short_gap_filled() {
    // LWRB unseen in frame 2: filled linearly, which is exact for this linear motion.
    let (labels, frames) = pig_frames(5, &|f, m| f == 2 && m == "LWRB");
    let path = temp("pig.c3d", &c3d_bytes(&labels, &frames, 100.0, -1.0));
    let m = load_motion(&path, &MotionOptions::default()).unwrap();
    assert_eq!(m.format, MotionFormat::C3d);
    assert_eq!(m.units.unit, LengthUnit::Millimetres, "{}", m.units);
    assert_eq!(m.up.up, UpAxis::Z);
    let k = m.keypoints(0.1).unwrap();
    assert_eq!(k.frame_count(), 5);
    assert!((k.times[4] - 0.04).abs() < 1e-12);
    assert_eq!(k.filled_gaps.len(), 1);
    assert_eq!(
        (
            k.filled_gaps[0].marker.as_str(),
            k.filled_gaps[0].first_frame
        ),
        ("LWRB", 2)
    );
    // Wrist: centroid of LWRA and LWRB; head: of the four head markers; pelvis: of the four
    // pelvis markers; all in metres.
    assert!(close(
        k.position(2, BodyPoint::LeftWrist).unwrap(),
        Vector3::new(0.020, 0.210, 0.850),
        1e-6
    ));
    assert!(close(
        k.position(0, BodyPoint::Head).unwrap(),
        Vector3::new(0.0, 0.0, 1.690),
        1e-6
    ));
    assert!(close(
        k.position(1, BodyPoint::Pelvis).unwrap(),
        Vector3::new(0.020, 0.0, 1.025),
        1e-6
    ));
    assert!(close(
        k.position(3, BodyPoint::RightKnee).unwrap(),
        Vector3::new(0.030, -0.100, 0.520),
        1e-6
    ));
    assert!(k.orientations.is_none());
}

#[test]
fn integer_c3d_samples_are_scaled() {
    let (labels, frames) = pig_frames(3, &|_, _| false);
    let path = temp("int.c3d", &c3d_bytes(&labels, &frames, 50.0, 0.1));
    let set = read_c3d(&std::fs::read(&path).unwrap(), "int.c3d").unwrap();
    assert_eq!(set.names.len(), labels.len());
    assert_eq!(set.names[0], "LASI");
    let k = labels.iter().position(|l| *l == "LTOE").unwrap();
    let p = set.positions[2 * labels.len() + k].unwrap();
    assert!(
        close(p, Vector3::new(170.0, 90.0, 40.0), 0.05 + 1e-9),
        "{p:?}"
    );
    assert!((set.times[1] - 0.02).abs() < 1e-12);
}

#[test]
fn a_long_gap_is_an_error_naming_the_marker_and_frames() {
    let (labels, frames) = pig_frames(6, &|f, m| (1..=3).contains(&f) && m == "LKNE");
    let path = temp("gap.c3d", &c3d_bytes(&labels, &frames, 10.0, -1.0));
    let m = load_motion(&path, &MotionOptions::default()).unwrap();
    let e = m.keypoints(0.1).unwrap_err().to_string();
    assert!(
        e.contains("LKNE") && e.contains("frames 1–3") && e.contains("gap.c3d"),
        "{e}"
    );
    // Allowed with a longer maximum gap.
    assert!(m.keypoints(0.5).is_ok());
}

#[test]
fn a_missing_marker_is_an_error_naming_it() {
    let markers = pig_markers();
    let (labels, frames): (Vec<&str>, Frames) = {
        let (l, f) = pig_frames(2, &|_, _| false);
        let keep: Vec<usize> = (0..l.len()).filter(|i| l[*i] != "LWRB").collect();
        (
            keep.iter().map(|i| l[*i]).collect(),
            f.iter()
                .map(|fr| keep.iter().map(|i| fr[*i]).collect())
                .collect(),
        )
    };
    assert_eq!(labels.len(), markers.len() - 1);
    let path = temp("nolwrb.c3d", &c3d_bytes(&labels, &frames, 100.0, -1.0));
    // Recognition cannot form the left wrist: the error lists it as missing.
    let e = load_motion(&path, &MotionOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("missing: left_wrist") && e.contains("nolwrb.c3d"),
        "{e}"
    );
    // With the Plug-in-Gait map given, the keypoints name the marker that is not in the file.
    let options = MotionOptions {
        body_map: Some(builtin_body_map("plug_in_gait").unwrap()),
        ..MotionOptions::default()
    };
    let m = load_motion(&path, &options).unwrap();
    let e = m.keypoints(0.1).unwrap_err();
    assert!(matches!(e, Error::UnknownName { .. }));
    let e = e.to_string();
    assert!(
        e.contains("LWRB") && e.contains("left_wrist") && e.contains("nolwrb.c3d"),
        "{e}"
    );
}

#[test]
fn a_bad_c3d_header_or_truncated_data_is_an_error_naming_the_file() {
    let (labels, frames) = pig_frames(2, &|_, _| false);
    let good = c3d_bytes(&labels, &frames, 100.0, -1.0);
    let mut bad = good.clone();
    bad[1] = 0x51;
    let e = read_c3d(&bad, "bad.c3d").unwrap_err().to_string();
    assert!(e.contains("bad.c3d") && e.contains("0x50"), "{e}");
    let e = read_c3d(&good[..300], "short.c3d").unwrap_err().to_string();
    assert!(e.contains("short.c3d"), "{e}");
    let e = read_c3d(&good[..good.len() - 10], "cut.c3d")
        .unwrap_err()
        .to_string();
    assert!(e.contains("cut.c3d") && e.contains("truncated"), "{e}");
    let mut other = good.clone();
    other[512 + 3] = 87;
    let e = read_c3d(&other, "cpu.c3d").unwrap_err().to_string();
    assert!(
        e.contains("cpu.c3d") && e.contains("processor type 87"),
        "{e}"
    );
    // Every prefix of the file fails cleanly or reads: never a panic.
    for n in (0..good.len()).step_by(7) {
        let _ = read_c3d(&good[..n], "prefix.c3d");
    }
}

/// DEC (VAX floats, little-endian words) and MIPS (big-endian) files read as the Intel file
/// of the same points does, float and integer samples alike; more than 255 points take their
/// names from `POINT:LABELS2` and `POINT:LABELS3`.
#[test]
fn dec_and_mips_c3d_files_and_more_than_255_labels_read() {
    let (labels, frames) = pig_frames(3, &|f, m| f == 1 && m == "LKNE");
    for scale in [-1.0, 0.5] {
        let intel = read_c3d(&c3d_bytes(&labels, &frames, 120.0, scale), "i.c3d").unwrap();
        for processor in [85u8, 86] {
            let bytes = c3d_bytes_as(processor, &labels, &frames, 120.0, scale);
            let set = read_c3d(&bytes, "p.c3d").unwrap();
            assert_eq!(set.names, intel.names, "processor {processor}");
            assert_eq!(set.times, intel.times, "processor {processor}");
            assert_eq!(set.positions, intel.positions, "processor {processor}");
        }
    }
    // 600 points: 255 names in LABELS, 255 in LABELS2, 90 in LABELS3.
    let names: Vec<String> = (0..600).map(|k| format!("M{k:03}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let frames: Frames = (0..2)
        .map(|f| (0..600).map(|k| Some([k as f64, f as f64, 1.0])).collect())
        .collect();
    for processor in [84u8, 85, 86] {
        let set = read_c3d(
            &c3d_bytes_as(processor, &names, &frames, 100.0, -1.0),
            "m.c3d",
        )
        .unwrap();
        assert_eq!(set.names, names, "processor {processor}");
        let at = set.names.len() + 599;
        let p = set.positions[at].expect("seen");
        assert_eq!((p.x, p.y, p.z), (599.0, 1.0, 1.0));
    }
}

/// A points CSV in metres, Z up, with the body points' own names.
fn keypoint_csv(rows: usize, cell: &dyn Fn(usize, &str, usize) -> String) -> String {
    let points: [(&str, [f64; 3]); 14] = [
        ("pelvis", [0.0, 0.0, 0.95]),
        ("head", [0.0, 0.0, 1.62]),
        ("left_shoulder", [0.0, 0.18, 1.42]),
        ("left_elbow", [0.0, 0.2, 1.12]),
        ("left_wrist", [0.0, 0.21, 0.85]),
        ("left_hip", [0.0, 0.09, 0.9]),
        ("left_knee", [0.0, 0.1, 0.5]),
        ("left_ankle", [0.0, 0.1, 0.08]),
        ("right_shoulder", [0.0, -0.18, 1.42]),
        ("right_elbow", [0.0, -0.2, 1.12]),
        ("right_wrist", [0.0, -0.21, 0.85]),
        ("right_hip", [0.0, -0.09, 0.9]),
        ("right_knee", [0.0, -0.1, 0.5]),
        ("right_ankle", [0.0, -0.1, 0.08]),
    ];
    let mut header = vec!["frame".to_string(), "time".to_string()];
    for (n, _) in &points {
        for a in ["x", "y", "z"] {
            header.push(format!("{n}_{a}"));
        }
    }
    let mut out = format!("# test\n{}\n", header.join(","));
    for r in 0..rows {
        let mut row = vec![r.to_string(), format!("{}", r as f64 / 30.0)];
        for (n, p) in &points {
            for (a, v) in p.iter().enumerate() {
                let default = format!("{}", v + if a == 0 { 0.01 * r as f64 } else { 0.0 });
                let c = cell(r, n, a);
                row.push(if c == "=" { default } else { c });
            }
        }
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

#[test]
fn a_points_csv_with_keypoint_names_reads_in_metres_z_up() {
    let text = keypoint_csv(4, &|r, n, _| {
        if r == 2 && n == "left_knee" {
            String::new()
        } else {
            "=".to_string()
        }
    });
    let path = temp("points.csv", text.as_bytes());
    let m = load_motion(&path, &MotionOptions::default()).unwrap();
    assert_eq!(m.format, MotionFormat::PointsCsv);
    assert_eq!((m.units.unit, m.up.up), (LengthUnit::Metres, UpAxis::Z));
    let k = m.keypoints(0.1).unwrap();
    assert!(close(
        k.position(3, BodyPoint::LeftWrist).unwrap(),
        Vector3::new(0.03, 0.21, 0.85),
        1e-12
    ));
    // The empty cells are a gap, filled linearly.
    assert!(close(
        k.position(2, BodyPoint::LeftKnee).unwrap(),
        Vector3::new(0.02, 0.1, 0.5),
        1e-12
    ));
    assert_eq!(k.filled_gaps.len(), 1);
}

#[test]
fn a_csv_with_a_nan_is_an_error_naming_line_and_column() {
    let text = keypoint_csv(3, &|r, n, a| {
        if r == 1 && n == "head" && a == 2 {
            "NaN".to_string()
        } else {
            "=".to_string()
        }
    });
    match read_points_csv(&text, "nan.csv").unwrap_err() {
        Error::Parse {
            source_name,
            line,
            message,
        } => {
            assert_eq!(source_name, "nan.csv");
            assert_eq!(line, 4);
            assert!(
                message.contains("head_z") && message.contains("NaN"),
                "{message}"
            );
        }
        other => panic!("{other}"),
    }
    // A point with only some coordinates, a row of the wrong length, no time column.
    let partial = keypoint_csv(2, &|r, n, a| {
        if r == 1 && n == "head" && a == 0 {
            String::new()
        } else {
            "=".to_string()
        }
    });
    assert!(read_points_csv(&partial, "p.csv")
        .unwrap_err()
        .to_string()
        .contains("all three"));
    let e = read_points_csv("frame,pelvis_x,pelvis_y,pelvis_z\n0,1,2,3\n", "t.csv").unwrap_err();
    assert!(e.to_string().contains("`time`"), "{e}");
}

#[test]
fn pose_estimator_names_are_recognised_with_the_pelvis_between_the_hips() {
    let names = [
        "nose",
        "left_shoulder",
        "right_shoulder",
        "left_elbow",
        "right_elbow",
        "left_wrist",
        "right_wrist",
        "left_hip",
        "right_hip",
        "left_knee",
        "right_knee",
        "left_ankle",
        "right_ankle",
        "left_foot_index",
        "right_foot_index",
    ];
    let map = iktc::motion::recognise_markers(
        &names.iter().map(|s| s.to_string()).collect::<Vec<_>>(),
        "pose.csv",
    )
    .unwrap();
    assert_eq!(
        map.get(BodyPoint::Pelvis),
        Some(&iktc::motion::PointSource::Markers(vec![
            "left_hip".into(),
            "right_hip".into()
        ]))
    );
    assert_eq!(
        map.get(BodyPoint::RightToe),
        Some(&iktc::motion::PointSource::Markers(vec![
            "right_foot_index".into()
        ]))
    );
    assert_eq!(
        map.get(BodyPoint::Head),
        Some(&iktc::motion::PointSource::Markers(vec!["nose".into()]))
    );
}

#[test]
fn the_format_is_detected_from_content_and_a_wrong_guess_says_what_was_tried() {
    // A C3D named .dat and a CSV named .txt are read by their content.
    let (labels, frames) = pig_frames(2, &|_, _| false);
    let p = temp("markers.dat", &c3d_bytes(&labels, &frames, 100.0, -1.0));
    assert_eq!(
        load_motion(&p, &MotionOptions::default()).unwrap().format,
        MotionFormat::C3d
    );
    let p = temp(
        "points.txt",
        keypoint_csv(2, &|_, _, _| "=".to_string()).as_bytes(),
    );
    assert_eq!(
        load_motion(&p, &MotionOptions::default()).unwrap().format,
        MotionFormat::PointsCsv
    );
    // Unknown extension and content.
    let p = temp("notes.dat", b"hello\nworld\n");
    let e = load_motion(&p, &MotionOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("notes.dat") && e.contains("HIERARCHY") && e.contains("C3D"),
        "{e}"
    );
    // A .bvh whose content is not BVH: read as BVH by the extension, and the error says so.
    let p = temp("fake.bvh", b"ROOT Hips\n");
    let e = load_motion(&p, &MotionOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("read as BVH because of the extension") && e.contains("fake.bvh"),
        "{e}"
    );
    // Binary data in a text format.
    let p = temp("bin.amc", &[0xff, 0xfe, 0x00, 0x41]);
    assert!(load_motion(&p, &MotionOptions::default()).is_err());
}

/// A C3D whose rate is no capture rate (1e30 Hz, 0.01 Hz) is refused, naming the file and
/// the frame time; 100 Hz loads.
#[test]
fn a_c3d_rate_outside_the_capture_rates_is_refused() {
    let (labels, frames) = pig_frames(3, &|_, _| false);
    for rate in [1e30f32, 0.01] {
        let path = temp("rate.c3d", &c3d_bytes(&labels, &frames, rate, -1.0));
        let e = load_motion(&path, &MotionOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("rate.c3d") && e.contains("frame 1: frame time"),
            "{rate}: {e}"
        );
    }
}

/// A points CSV whose time steps are 1e-12 s is refused, naming the file and the frame;
/// steps of 0.01 s load.
#[test]
fn a_points_csv_with_picosecond_steps_is_refused() {
    let (labels, frames) = pig_frames(3, &|_, _| false);
    let csv = |step: f64| {
        let mut text = "time".to_string();
        for l in &labels {
            text.push_str(&format!(",{l}_x,{l}_y,{l}_z"));
        }
        text.push('\n');
        for (f, frame) in frames.iter().enumerate() {
            text.push_str(&format!("{:e}", f as f64 * step));
            for p in frame {
                let p = p.unwrap();
                text.push_str(&format!(",{},{},{}", p[0], p[1], p[2]));
            }
            text.push('\n');
        }
        text
    };
    let path = temp("steps.csv", csv(0.01).as_bytes());
    load_motion(&path, &MotionOptions::default()).unwrap();
    let path = temp("steps.csv", csv(1e-12).as_bytes());
    let e = load_motion(&path, &MotionOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("steps.csv") && e.contains("frame 1"), "{e}");
}
