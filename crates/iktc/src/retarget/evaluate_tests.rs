//! Tests of [`evaluate_trajectory`] and the trajectory readers: iktc's own run read back from
//! its files gives the run's figures, hand-computed figures of synthetic trajectories, and
//! every bad input named.

use nalgebra::Vector3;

use super::*;
use crate::batch::{npz_bytes, zip_stored, NpyArray, TrainingTrajectory};
use crate::motion::{
    BodyPoint, LengthUnit, Measured, UnitsDecision, UpAxis, UpDecision, DEFAULT_MAX_GAP,
};
use crate::retarget::centres::JOINT_CENTRES;
use crate::retarget::fidelity::robot_samples;
use crate::retarget::{builtin_motion, retarget_keypoints, KeypointSettings};

/// Relative difference allowed between q̈ by second differences of written positions and the
/// mean of two commanded q̈ \[–\]: rounding of positions of order 1 rad divided by Δt² = 2.5e-5
/// s² is of order 1e-11 rad/s² on accelerations of order 1–100 rad/s².
const FD_ROUNDING: f64 = 1e-6;

/// Rounding of distances built from positions of order 1 m \[cm\].
const CM_ROUNDING: f64 = 1e-9;

/// Largest keypoint error the spline resampling of a 50 Hz trajectory of smooth joints (a
/// quadratic elbow) adds at 200 Hz \[cm\]: the natural end conditions bend a quadratic by
/// about q̈ h² / 8 ≈ 5e-5 rad near the ends, under 0.01 mm at a 0.2 m forearm.
const RESAMPLE_CM: f64 = 0.01;

/// G1's profile and robot.
fn g1() -> (RobotProfile, Robot) {
    let p = RobotProfile::builtin("g1").expect("built-in g1");
    let r = p.robot().expect("g1 robot");
    (p, r)
}

/// iktc's own keypoint run of the built-in walk on G1, written as `motion.csv` and
/// `motion.npz` at the control rate and evaluated from those files, gives the run's own
/// figures: every position figure bit for bit (the same configurations at the same times),
/// and the smoothness of q̈ by second differences, which for the constant-acceleration
/// integrator (`q⁺ = q + Δt q̇ + ½Δt² q̈`) is the mean of two consecutive commanded q̈:
/// `q_{k+1} − 2q_k + q_{k−1} = ½Δt² (q̈_{k−1} + q̈_k)`.
#[test]
fn own_run_read_back_from_its_files_gives_its_figures() {
    let (profile, robot) = g1();
    let kp = builtin_motion("humanoid3d_walk")
        .and_then(|m| m.keypoints(DEFAULT_MAX_GAP))
        .expect("walk");
    let s = KeypointSettings::default();
    let run = retarget_keypoints(&profile, &kp, None, &s).expect("run");
    let own = run.quality.fidelity.clone().expect("fidelity");
    let file = TrainingTrajectory::from_keypoint_run(&robot, &run, s.dt, &[], 1.0 / s.dt)
        .expect("training trajectory");
    let csv = read_trajectory_csv(&file.csv(), "motion.csv").expect("csv");
    let npz = read_trajectory_npz(&file.npz().expect("npz"), "motion.npz").expect("npz");
    let e = evaluate_trajectory(&profile, &robot, &kp, &csv, s.dt).expect("evaluate csv");
    assert!(!e.resampled);
    assert_eq!(e.frames, run.trajectory.len());
    let f = &e.fidelity;
    assert_eq!(f.ticks, own.ticks);
    assert_eq!(f.scale, own.scale);
    assert_eq!(f.heading_deg, own.heading_deg);
    assert_eq!(f.keypoint_mean_cm, own.keypoint_mean_cm);
    assert_eq!(f.points, own.points);
    assert_eq!(f.posture, own.posture);
    assert_eq!(f.contacts, own.contacts);
    // The NPZ holds the same numbers.
    let from_npz = evaluate_trajectory(&profile, &robot, &kp, &npz, s.dt).expect("evaluate npz");
    assert_eq!(from_npz.fidelity, e.fidelity);
    // Smoothness: the run's commanded joint q̈, averaged in pairs.
    let nb = robot.base_nv();
    let n = run.accelerations.len();
    let mean: Vec<Vec<f64>> = run
        .accelerations
        .windows(2)
        .take(n - 2)
        .map(|w| {
            (nb..robot.nv())
                .map(|i| 0.5 * (w[0][i] + w[1][i]))
                .collect()
        })
        .collect();
    let (body, centres, support) = super::super::measured_body(&robot, &profile).expect("body");
    let expected = super::super::measure_fidelity(
        &robot,
        (&body, &centres),
        &support,
        &kp,
        (&run.times, &run.trajectory, &mean),
        s.dt,
    )
    .expect("expected")
    .smoothness;
    let got = f.smoothness;
    for (name, a, b) in [
        ("jerk_rms", got.jerk_rms, expected.jerk_rms),
        ("jerk_max", got.jerk_max, expected.jerk_max),
        ("flip_max", got.flip_max, expected.flip_max),
    ] {
        assert!(
            (a - b).abs() <= FD_ROUNDING * b.abs().max(1.0),
            "{name}: {a} from positions, {b} from the commanded q̈"
        );
    }
    assert_eq!(got.reversal_share, expected.reversal_share);
    // Averaging in pairs hides chatter that alternates tick by tick: never more reversals.
    assert!(got.reversal_share <= own.smoothness.reversal_share + FD_ROUNDING);
}

/// Ticks of the synthetic G1 trajectory \[–\] and its period \[s\].
const TICKS: usize = 200;
const DT: f64 = 0.005;
/// The alternating joint's amplitude \[rad\] and the elbows' q̈ \[rad/s²\].
const ALTERNATE: f64 = 1e-4;
const ELBOW_QDD: f64 = 1.0;

/// G1 standing still on a fixed base at `base` (legs straight), both elbows bending at a
/// constant q̈ of [`ELBOW_QDD`], the waist yaw alternating ±[`ALTERNATE`] tick by tick:
/// configurations q on [`TICKS`] ticks of [`DT`].
fn synthetic(robot: &Robot, base: [f64; 3]) -> Vec<Vec<f64>> {
    let names = robot.dof_names()[robot.base_nv()..].to_vec();
    (0..TICKS)
        .map(|k| {
            let t = k as f64 * DT;
            let mut q = vec![base[0], base[1], base[2], 0.0, 0.0, 0.0, 1.0];
            q.extend(names.iter().map(|n| match n.as_str() {
                "left_elbow_joint" | "right_elbow_joint" => 0.3 + 0.5 * ELBOW_QDD * t * t,
                "waist_yaw_joint" => ALTERNATE * if k % 2 == 0 { 1.0 } else { -1.0 },
                _ => 0.0,
            }));
            q
        })
        .collect()
}

/// The CSV of configurations `qs` at times `k · period` for every `every`-th tick: columns
/// `time`, the joints in reverse order, then `qw qx qy qz x y z` (names, not order, count).
fn csv_of(robot: &Robot, qs: &[Vec<f64>], every: usize) -> String {
    let names = robot.dof_names()[robot.base_nv()..].to_vec();
    let mut s = String::from("time");
    for n in names.iter().rev() {
        s.push(',');
        s.push_str(n);
    }
    s.push_str(",qw,qx,qy,qz,x,y,z\n");
    for (k, q) in qs.iter().enumerate().step_by(every) {
        s.push_str(&format!("{}", k as f64 * DT));
        for v in q[7..].iter().rev() {
            s.push_str(&format!(",{v}"));
        }
        for i in [6, 3, 4, 5, 0, 1, 2] {
            s.push_str(&format!(",{}", q[i]));
        }
        s.push('\n');
    }
    s
}

/// The person whose joint centres are `x` per frame (frames every [`DT`]), with the pelvis at
/// the hips' middle.
fn person(frames: &[[Vector3<f64>; 12]]) -> Keypoints {
    let mut points = vec![BodyPoint::Pelvis];
    points.extend(JOINT_CENTRES);
    points.sort_by_key(|p| BodyPoint::ALL.iter().position(|a| a == p));
    let at = |x: &[Vector3<f64>; 12], p: BodyPoint| {
        x[JOINT_CENTRES.iter().position(|q| *q == p).unwrap_or(0)]
    };
    let mut positions = Vec::new();
    for x in frames {
        for p in &points {
            positions.push(match p {
                BodyPoint::Pelvis => 0.5 * (at(x, BodyPoint::LeftHip) + at(x, BodyPoint::RightHip)),
                _ => at(x, *p),
            });
        }
    }
    Keypoints {
        source: "synthetic".into(),
        points,
        times: (0..frames.len()).map(|f| DT * f as f64).collect(),
        positions,
        orientations: None,
        units: UnitsDecision {
            unit: LengthUnit::Metres,
            automatic: false,
            standing_height: None,
        },
        up: UpDecision {
            up: UpAxis::Z,
            automatic: false,
            measured_on: Measured::RestPose,
        },
        filled_gaps: Vec::new(),
    }
}

/// The robot's own joint centres replayed as the person, with both wrists 5 cm higher: the
/// scale is 1 (the legs do not move), the heading 0 (the horizontal parts agree), the wrists'
/// errors 5 cm on every tick and the other points' 0, so the mean is 2 · 5 / 13 cm; the knees,
/// trunk lean and hip height agree. The still feet slip 0 mm over the person's contacts (both
/// feet down the whole clip: 2 windows). q̈ by second differences: the waist yaw's is
/// ∓4A/Δt² tick by tick (A = [`ALTERNATE`]), reversing on every tick, the elbows' constant:
/// the reversal share is 1/29 (one joint of G1's 29), the largest flip 4A/Δt² = 16 rad/s²,
/// the largest jerk 8A/Δt³ = 6400 rad/s³. A base 1 cm higher raises the lowest sole and the
/// sole height over the contacts by 10 mm and leaves the rest; 5 cm sideways changes nothing.
#[test]
fn the_robots_own_points_with_raised_wrists_give_the_hand_computed_figures() {
    let (profile, robot) = g1();
    let qs = synthetic(&robot, [0.0, 0.0, 0.8]);
    let (body, centres, support) = super::super::measured_body(&robot, &profile).expect("body");
    let samples = robot_samples(&robot, &centres, body.feet, &support, &qs).expect("samples");
    let raise = Vector3::new(0.0, 0.0, 0.05);
    let frames: Vec<[Vector3<f64>; 12]> = samples
        .iter()
        .map(|s| {
            let mut x = s.centres;
            for (p, c) in JOINT_CENTRES.iter().zip(x.iter_mut()) {
                if matches!(p, BodyPoint::LeftWrist | BodyPoint::RightWrist) {
                    *c += raise;
                }
            }
            x
        })
        .collect();
    let kp = person(&frames);
    let t = read_trajectory_csv(&csv_of(&robot, &qs, 1), "synthetic.csv").expect("csv");
    let e = evaluate_trajectory(&profile, &robot, &kp, &t, DT).expect("evaluate");
    assert!(!e.resampled);
    let f = &e.fidelity;
    assert_eq!(f.ticks, TICKS);
    assert!((f.scale - 1.0).abs() < 1e-12, "scale {}", f.scale);
    assert!(f.heading_deg.abs() < 1e-9, "heading {}", f.heading_deg);
    for p in &f.points {
        let expected = if p.point.ends_with("wrist") { 5.0 } else { 0.0 };
        assert!(
            (p.mean_cm - expected).abs() < CM_ROUNDING && (p.max_cm - expected).abs() < CM_ROUNDING,
            "{}: mean {} max {} cm, expected {expected}",
            p.point,
            p.mean_cm,
            p.max_cm
        );
    }
    assert!((f.keypoint_mean_cm - 10.0 / 13.0).abs() < CM_ROUNDING);
    for p in &f.posture {
        if !p.name.ends_with("elbow") {
            assert!(
                p.difference_p90.abs() < 1e-6,
                "{}: {} apart",
                p.name,
                p.difference_p90
            );
        }
    }
    assert_eq!(f.contacts.windows, 2);
    assert!(f.contacts.slip_max_mm < 1e-9, "{}", f.contacts.slip_max_mm);
    let sm = f.smoothness;
    let flip = 4.0 * ALTERNATE / (DT * DT);
    assert!(
        (sm.reversal_share - 1.0 / 29.0).abs() < 1e-12,
        "{}",
        sm.reversal_share
    );
    assert!(
        (sm.flip_max - flip).abs() < FD_ROUNDING * flip,
        "{}",
        sm.flip_max
    );
    assert!((sm.jerk_max - 2.0 * flip / DT).abs() < FD_ROUNDING * flip / DT);
    // Moved base: 1 cm up, then 5 cm sideways.
    for (shift, dz) in [([0.0, 0.0, 0.81], 10.0), ([0.0, 0.05, 0.8], 0.0)] {
        let moved = read_trajectory_csv(&csv_of(&robot, &synthetic(&robot, shift), 1), "moved")
            .expect("csv");
        let g = evaluate_trajectory(&profile, &robot, &kp, &moved, DT)
            .expect("evaluate")
            .fidelity;
        let mm = 1e-6;
        assert!((g.contacts.lowest_sole_mm - f.contacts.lowest_sole_mm - dz).abs() < mm);
        assert!((g.contacts.height_max_mm - f.contacts.height_max_mm - dz).abs() < mm);
        assert!((g.keypoint_mean_cm - f.keypoint_mean_cm).abs() < CM_ROUNDING);
        assert!(g.contacts.slip_max_mm < 1e-9);
    }
}

/// Every 4th tick (50 Hz) evaluated at 200 Hz is resampled by splines: nearly the figures of
/// the 200 Hz file (within [`RESAMPLE_CM`]); the spline's q̈ is linear between frames, so its
/// change reverses at frames only (the natural ends make the elbows' q̈ ripple there): a
/// reversal share of at most 50/200.
#[test]
fn a_trajectory_at_another_rate_is_resampled() {
    let (profile, robot) = g1();
    let qs = synthetic(&robot, [0.0, 0.0, 0.8]);
    let (body, centres, support) = super::super::measured_body(&robot, &profile).expect("body");
    let samples = robot_samples(&robot, &centres, body.feet, &support, &qs).expect("samples");
    let kp = person(&samples.iter().map(|s| s.centres).collect::<Vec<_>>());
    let slow = read_trajectory_csv(&csv_of(&robot, &qs, 4), "50hz.csv").expect("csv");
    let e = evaluate_trajectory(&profile, &robot, &kp, &slow, DT).expect("evaluate");
    assert!(e.resampled);
    assert!((e.input_rate_hz - 50.0).abs() < 1e-9);
    assert!(e.smoothness_note.contains("resampled"));
    // 0 ... 0.98 s at 200 Hz.
    assert_eq!(e.fidelity.ticks, 197);
    assert!(
        e.fidelity.keypoint_mean_cm < RESAMPLE_CM,
        "{}",
        e.fidelity.keypoint_mean_cm
    );
    // q̈ of a spline is linear between frames: its change reverses at frames only.
    let share = e.fidelity.smoothness.reversal_share;
    assert!(
        share > 0.0 && share <= e.input_rate_hz / e.rate_hz,
        "{share}"
    );
}

/// The readers' and the evaluation's errors name what is wrong.
#[test]
fn bad_trajectories_are_named_errors() {
    let (profile, robot) = g1();
    let qs = synthetic(&robot, [0.0, 0.0, 0.8]);
    let good = csv_of(&robot, &qs[..5], 1);
    let kp = {
        let (body, centres, support) = super::super::measured_body(&robot, &profile).expect("body");
        let s = robot_samples(&robot, &centres, body.feet, &support, &qs).expect("samples");
        person(&s.iter().map(|s| s.centres).collect::<Vec<_>>())
    };
    let eval = |text: &str| {
        read_trajectory_csv(text, "bad.csv")
            .and_then(|t| evaluate_trajectory(&profile, &robot, &kp, &t, DT))
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    assert_eq!(eval(&good), Ok(()));
    // A joint missing, and one the robot lacks.
    let renamed = good.replacen("left_knee_joint", "left_knee", 1);
    let err = eval(&renamed).unwrap_err();
    assert!(
        err.contains("left_knee_joint have no column") && err.contains("left_knee are no joint"),
        "{err}"
    );
    let missing = |col: &str| {
        let lines: Vec<String> = good
            .lines()
            .map(|l| {
                let header: Vec<&str> = good.lines().next().unwrap_or("").split(',').collect();
                let drop = header.iter().position(|h| *h == col).unwrap_or(usize::MAX);
                l.split(',')
                    .enumerate()
                    .filter(|(i, _)| *i != drop)
                    .map(|(_, v)| v)
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .collect();
        lines.join("\n")
    };
    let err = eval(&missing("waist_yaw_joint")).unwrap_err();
    assert!(err.contains("waist_yaw_joint have no column"), "{err}");
    let err = eval(&missing("qz")).unwrap_err();
    assert!(err.contains("missing: qz"), "{err}");
    let err = eval(&missing("time")).unwrap_err();
    assert!(err.contains("no time column"), "{err}");
    // Without any base column the floating base is missing.
    let no_base = ["qw", "qx", "qy", "qz", "x", "y"]
        .iter()
        .fold(missing("z"), |text, c| {
            let header: Vec<&str> = text.lines().next().unwrap_or("").split(',').collect();
            let drop = header.iter().position(|h| h == c).unwrap_or(usize::MAX);
            text.lines()
                .map(|l| {
                    l.split(',')
                        .enumerate()
                        .filter(|(i, _)| *i != drop)
                        .map(|(_, v)| v)
                        .collect::<Vec<_>>()
                        .join(",")
                })
                .collect::<Vec<_>>()
                .join("\n")
        });
    let err = eval(&no_base).unwrap_err();
    assert!(err.contains("floating base"), "{err}");
    // Rows: a short one, a word, a repeated time, too few frames.
    let lines: Vec<&str> = good.lines().collect();
    let err = eval(&format!("{}\n{}\n0.1,2\n", lines[0], lines[1])).unwrap_err();
    assert!(
        err.contains("bad.csv:3") && err.contains("values, expected"),
        "{err}"
    );
    let err = eval(&good.replacen("0.3", "abc", 1)).unwrap_err();
    assert!(err.contains("`abc` is not a number"), "{err}");
    let err = eval(&[lines[0], lines[1], lines[1], lines[2]].join("\n")).unwrap_err();
    assert!(err.contains("strictly increasing"), "{err}");
    let err = eval(&[lines[0], lines[1], lines[2]].join("\n")).unwrap_err();
    assert!(err.contains("at least 3"), "{err}");
    let err = eval(&format!("{}\ntime\n", lines[0])).unwrap_err();
    assert!(err.contains("values, expected"), "{err}");
    let dup = good.replacen("qw", "time", 1);
    let err = eval(&dup).unwrap_err();
    assert!(err.contains("appears twice"), "{err}");
}

/// NPZ: arrays read back as written, stored or deflated; a corrupted member, a truncated
/// archive and a missing array are named errors.
#[test]
fn npz_reading_round_trips_and_names_bad_archives() {
    let arrays = vec![
        NpyArray::f64("time", vec![3], vec![0.0, 0.1, 0.2]),
        NpyArray::strings("joint_names", vec!["a".into(), "bé".into()]),
        NpyArray::f64("joint_pos", vec![3, 2], vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
    ];
    let bytes = npz_bytes(&arrays).expect("npz");
    assert_eq!(
        crate::batch::read_npz(&bytes, "x.npz").expect("read"),
        arrays
    );
    let t = read_trajectory_npz(&bytes, "x.npz").expect("trajectory");
    assert_eq!(t.joint_names, vec!["a".to_string(), "bé".to_string()]);
    assert_eq!(
        t.joints,
        vec![vec![1.0, 2.0], vec![3.0, 4.0], vec![5.0, 6.0]]
    );
    assert!(t.base.is_none());
    // Deflated members (numpy.savez_compressed) read the same.
    let deflated = {
        use std::io::Write;
        let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        for a in &arrays {
            zip.start_file(format!("{}.npy", a.name), options)
                .expect("member");
            zip.write_all(&a.npy_bytes().expect("npy")).expect("write");
        }
        zip.finish().expect("zip").into_inner()
    };
    assert_eq!(
        crate::batch::read_npz(&deflated, "c.npz").expect("deflated"),
        arrays
    );
    // A byte of the first member's data flipped: its CRC-32 no longer matches (the member's
    // data is stored, so the value 1.0 of `time` is found as is).
    let mut corrupt = bytes.clone();
    let at = bytes
        .windows(8)
        .position(|w| w == 0.1_f64.to_le_bytes())
        .expect("0.1 in the stored data");
    corrupt[at] ^= 0xff;
    let err = crate::batch::read_npz(&corrupt, "k.npz")
        .unwrap_err()
        .to_string();
    assert!(err.contains("k.npz") && err.contains("`time`"), "{err}");
    // Cut short: the archive's directory (at its end) is missing.
    let err = crate::batch::read_npz(&bytes[..bytes.len() / 2], "h.npz")
        .unwrap_err()
        .to_string();
    assert!(err.contains("h.npz") && err.contains("cut short"), "{err}");
    let only_time =
        zip_stored(&[("time.npy".into(), arrays[0].npy_bytes().expect("npy"))]).expect("zip");
    let err = read_trajectory_npz(&only_time, "t.npz")
        .unwrap_err()
        .to_string();
    assert!(err.contains("no array `joint_names`"), "{err}");
}
