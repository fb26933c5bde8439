//! Tests of the neutral figures against hand-computed values.

use super::*;
use crate::motion::{LengthUnit, Measured, UnitsDecision, UpAxis, UpDecision};

use BodyPoint as B;

/// A standing person, metres, z up, facing +x: hips 0.9 m up, legs of 0.45 + 0.45 m
/// (straight), shoulders 1.4 m up, arms hanging (elbow 0.3 m, wrist 0.55 m below the
/// shoulder), in [`JOINT_CENTRES`] order.
fn standing() -> [Vector3<f64>; 12] {
    let v = Vector3::new;
    [
        v(0.0, 0.1, 0.9),
        v(0.0, 0.1, 0.45),
        v(0.0, 0.1, 0.0),
        v(0.0, -0.1, 0.9),
        v(0.0, -0.1, 0.45),
        v(0.0, -0.1, 0.0),
        v(0.0, 0.2, 1.4),
        v(0.0, 0.2, 1.1),
        v(0.0, 0.2, 0.85),
        v(0.0, -0.2, 1.4),
        v(0.0, -0.2, 1.1),
        v(0.0, -0.2, 0.85),
    ]
}

/// Keypoints of `frames` (one per 0.1 s) with the pelvis at the hips' middle.
fn person(frames: &[[Vector3<f64>; 12]]) -> Keypoints {
    let mut points = vec![B::Pelvis];
    points.extend(JOINT_CENTRES);
    points.sort_by_key(|p| B::ALL.iter().position(|a| a == p));
    let mut positions = Vec::new();
    for x in frames {
        for p in &points {
            positions.push(match p {
                B::Pelvis => hip_middle(x),
                _ => x[ix(*p)],
            });
        }
    }
    Keypoints {
        source: "synthetic".into(),
        points,
        times: (0..frames.len()).map(|f| 0.1 * f as f64).collect(),
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

/// A robot sample with centres `x`, soles on the floor under the ankles.
fn sample(x: [Vector3<f64>; 12]) -> RobotSample {
    let (l, r) = (x[ix(B::LeftAnkle)], x[ix(B::RightAnkle)]);
    RobotSample {
        centres: x,
        sole_lowest: [l.z, r.z],
        sole_centre: [l, r],
    }
}

/// The person turned by `yaw` about z, scaled by `s` and moved by `t`.
fn placed(x: &[Vector3<f64>; 12], yaw: f64, s: f64, t: Vector3<f64>) -> [Vector3<f64>; 12] {
    let r = Rotation3::from_axis_angle(&Vector3::z_axis(), yaw);
    x.map(|p| r * (s * p) + t)
}

fn run(kp: &Keypoints, robot: &[RobotSample], robot_leg: f64, qdd: &[Vec<f64>]) -> Fidelity {
    let times: Vec<f64> = (0..robot.len()).map(|k| 0.1 * k as f64).collect();
    fidelity(
        &FidelityInput {
            person: kp,
            times: &times,
            robot,
            robot_leg,
            qdd,
            dt: 0.1,
        },
        &FidelityLimits::default(),
    )
}

/// A robot that is the person scaled by its leg ratio, turned and moved has no keypoint
/// error, the heading of the turn, the scale of the legs, and the person's posture.
#[test]
fn a_scaled_turned_copy_of_the_person_has_no_error() {
    let body = standing();
    let kp = person(&[body; 3]);
    let (s, yaw) = (0.8, 0.4);
    let robot: Vec<RobotSample> = (0..3)
        .map(|k| {
            sample(placed(
                &body,
                yaw,
                s,
                Vector3::new(0.5 * k as f64, 1.0, 0.0),
            ))
        })
        .collect();
    let f = run(&kp, &robot, s * 0.9, &vec![vec![0.0]; 3]);
    assert!((f.scale - s).abs() < 1e-12, "{}", f.scale);
    assert!(
        (f.heading_deg - yaw.to_degrees()).abs() < 1e-9,
        "{}",
        f.heading_deg
    );
    assert!(f.keypoint_mean_cm < 1e-9, "{}", f.keypoint_mean_cm);
    assert_eq!(f.points.len(), 13);
    for p in &f.posture {
        assert!(p.difference_p90.abs() < 1e-6, "{p:?}");
    }
    // The standing person: straight knees and elbows, no lean, hips 0.9 m above the ankles.
    let by = |n: &str| f.posture.iter().find(|p| p.name == n).unwrap().clone();
    assert!(by("left_knee").person_median.abs() < 1e-6);
    assert!(by("trunk_lean").person_median.abs() < 1e-6);
    assert!((by("hip_height").person_median - 100.0 * s * 0.9).abs() < 1e-9);
}

/// A wrist 5 cm too low on every tick: that point's mean and max are 5 cm, the clip's mean
/// is 5/13 cm (thirteen points, the neck one of them); a vertical offset leaves the
/// heading fit (horizontal) at 0.
#[test]
fn one_point_off_counts_in_its_own_figure_and_the_mean() {
    let body = standing();
    let kp = person(&[body; 2]);
    let mut off = body;
    off[ix(B::LeftWrist)].z -= 0.05;
    let f = run(&kp, &[sample(off), sample(off)], 0.9, &vec![vec![0.0]; 2]);
    assert!(f.heading_deg.abs() < 1e-12, "{}", f.heading_deg);
    let wrist = f.points.iter().find(|p| p.point == "left_wrist").unwrap();
    assert!((wrist.mean_cm - 5.0).abs() < 1e-9, "{wrist:?}");
    assert!((wrist.max_cm - 5.0).abs() < 1e-9, "{wrist:?}");
    assert!(
        (f.keypoint_mean_cm - 5.0 / 13.0).abs() < 1e-9,
        "{}",
        f.keypoint_mean_cm
    );
    // Off across the body instead, the single fitted heading turns every point a little:
    // the fit does not hide the error, it spreads less than all of it onto the others.
    let mut across = body;
    across[ix(B::LeftWrist)].x += 0.05;
    let g = run(
        &kp,
        &[sample(across), sample(across)],
        0.9,
        &vec![vec![0.0]; 2],
    );
    assert!(g.heading_deg.abs() > 0.1, "{}", g.heading_deg);
    assert!(g.keypoint_mean_cm > 5.0 / 13.0, "{}", g.keypoint_mean_cm);
}

/// Knee flexion by hand: the shank at a right angle to the thigh is 90°; a trunk tilted
/// forward so that the neck is 0.5 m ahead of and 0.5 m above the hips leans 45°.
#[test]
fn flexion_and_lean_by_hand() {
    let mut x = standing();
    x[ix(B::LeftAnkle)] = Vector3::new(0.45, 0.1, 0.45);
    x[ix(B::LeftShoulder)] = Vector3::new(0.5, 0.2, 1.4);
    x[ix(B::RightShoulder)] = Vector3::new(0.5, -0.2, 1.4);
    let p = posture(&x);
    assert!((p[0] - 90.0).abs() < 1e-9, "{}", p[0]);
    assert!(p[1].abs() < 1e-9, "{}", p[1]);
    assert!((p[4] - 45.0).abs() < 1e-9, "{}", p[4]);
    // Hip height above the ankles' mean (0.45 and 0): 0.9 − 0.225.
    assert!((p[5] - 0.675).abs() < 1e-12, "{}", p[5]);
}

/// The person stands still on both feet for four frames then lifts the left foot 10 cm:
/// the left window is frames 0–3 (inclusive). A robot whose left ankle slides 2 cm along
/// x over that window slips 20 mm; its sole 7 mm above the floor there counts as the
/// contact height, and its sliding sole on the floor (≤ 5 mm) skates.
#[test]
fn contacts_slip_height_and_skating_by_hand() {
    let body = standing();
    let mut lifted = body;
    lifted[ix(B::LeftAnkle)].z += 0.1;
    let frames = [body, body, body, body, lifted, lifted];
    let kp = person(&frames);
    let windows = person_contacts(&kp);
    assert_eq!(windows[0], vec![(0, 3)]);
    assert_eq!(windows[1], vec![(0, 5)]);
    let robot: Vec<RobotSample> = frames
        .iter()
        .enumerate()
        .map(|(k, x)| {
            let mut r = sample(*x);
            let d = Vector3::new(0.02 * (k.min(3) as f64) / 3.0, 0.0, 0.0);
            r.centres[ix(B::LeftAnkle)] += d;
            r.sole_centre[0] += d;
            r.sole_lowest[0] = if k < 4 { 0.007 } else { 0.1 };
            r
        })
        .collect();
    let f = run(&kp, &robot, 0.9, &vec![vec![0.0]; 6]);
    let c = &f.contacts;
    assert_eq!(c.windows, 2);
    assert!((c.slip_max_mm - 20.0).abs() < 1e-9, "{c:?}");
    // The worst window is the left foot's, frames 0–3 (0–0.3 s); the person stood still there.
    let w = c.worst_slip.as_ref().expect("a window");
    assert_eq!(w.foot, "left");
    assert_eq!((w.start_s, w.end_s), (0.0, 0.30000000000000004));
    assert!(
        (w.robot_mm - 20.0).abs() < 1e-9 && w.person_mm.abs() < 1e-12,
        "{w:?}"
    );
    assert!((w.sole_mm[0] - 7.0).abs() < 1e-9 && (w.sole_mm[1] - 7.0).abs() < 1e-9);
    assert!(f.failures.is_empty() || !f.failures.iter().any(|m| m.contains("slip")));
    assert!((c.height_max_mm - 7.0).abs() < 1e-9, "{c:?}");
    assert!(c.lowest_sole_mm.abs() < 1e-9, "{c:?}");
    // The left sole is 7 mm up: not on the floor, so no skating at all.
    assert_eq!(c.skate_share, 0.0);
    // Brought down to 4 mm, its 6.7 mm steps per 0.1 s tick (0.067 m/s) are under
    // 0.1 m/s: still no skating; three times as fast, three ticks of twelve skate.
    let mut low = robot.clone();
    for r in &mut low {
        r.sole_lowest[0] = 0.004;
    }
    assert_eq!(
        run(&kp, &low, 0.9, &vec![vec![0.0]; 6])
            .contacts
            .skate_share,
        0.0
    );
    let mut fast = robot.clone();
    for (k, r) in fast.iter_mut().enumerate() {
        r.sole_lowest[0] = 0.004;
        r.sole_centre[0].x = 0.06 * (k.min(3) as f64) / 3.0;
    }
    let g = run(&kp, &fast, 0.9, &vec![vec![0.0]; 6]);
    assert!(
        (g.contacts.skate_share - 3.0 / 12.0).abs() < 1e-12,
        "{:?}",
        g.contacts
    );
    assert!((g.contacts.skate_distance_m - 0.06).abs() < 1e-12);
}

/// The person's left leg slides 5 cm along x over its window (frames 0–3, 0.167 m/s: still
/// a contact; the lifted frames' shorter legs leave the median, 0.9 m, and so the scale) and the robot's, at half the person's size (leg 0.45 m against 0.9 m), slides
/// 60 mm: the worst window reports the person's slide scaled, 25 mm, beside the robot's 60 mm,
/// and the verdict's slip failure names the foot, the window and both.
#[test]
fn the_worst_slip_window_shows_the_persons_own_slide() {
    let body = standing();
    let frames: Vec<[Vector3<f64>; 12]> = (0..6)
        .map(|k| {
            let mut x = body;
            // The whole left leg moves, so that its length (and the scale) stays exact.
            for p in [B::LeftHip, B::LeftKnee, B::LeftAnkle] {
                x[ix(p)].x += 0.05 * (k.min(3) as f64) / 3.0;
            }
            if k >= 4 {
                x[ix(B::LeftAnkle)].z += 0.1;
            }
            x
        })
        .collect();
    let kp = person(&frames);
    assert_eq!(person_contacts(&kp)[0], vec![(0, 3)]);
    let robot: Vec<RobotSample> = frames
        .iter()
        .enumerate()
        .map(|(k, x)| {
            let mut r = sample(x.map(|p| 0.5 * p));
            r.centres[ix(B::LeftAnkle)].x = 0.06 * (k.min(3) as f64) / 3.0;
            r
        })
        .collect();
    let f = run(&kp, &robot, 0.45, &vec![vec![0.0]; 6]);
    let w = f.contacts.worst_slip.as_ref().expect("a window");
    assert_eq!(w.foot, "left");
    assert!((w.robot_mm - 60.0).abs() < 1e-9, "{w:?}");
    assert!((w.person_mm - 25.0).abs() < 1e-9, "{w:?}");
    let why = f
        .failures
        .iter()
        .find(|m| m.contains("slip"))
        .expect("a slip failure");
    assert!(
        why.contains("left foot") && why.contains("0.00–0.30 s") && why.contains("25 mm"),
        "{why}"
    );
}

/// q̈ of one joint 10, −30, 20, 20 rad/s²: flips of 10 and 20 (min of the two sides), the
/// change −40, +50, 0 reverses once over the two ticks that can (share 1/2); jerk by hand
/// at Δt = 0.1 s: 400, 500, 0 rad/s³.
#[test]
fn smoothness_by_hand() {
    let qdd = [vec![10.0], vec![-30.0], vec![20.0], vec![20.0]];
    let s = smoothness(&qdd, 0.1);
    assert_eq!(s.flip_max, 20.0);
    assert!((s.reversal_share - 0.5).abs() < 1e-12, "{s:?}");
    assert!((s.jerk_max - 500.0).abs() < 1e-9);
    let rms = ((400.0f64.powi(2) + 500.0f64.powi(2)) / 3.0).sqrt();
    assert!((s.jerk_rms - rms).abs() < 1e-9, "{s:?}");
}

/// The verdict names what fails: a crouched robot (knees bent 90° where the person's are
/// straight) fails on the knees and on the keypoints, and says so.
#[test]
fn the_verdict_names_each_failure() {
    let body = standing();
    let kp = person(&[body; 2]);
    let mut crouch = body;
    for (k, a) in [(B::LeftKnee, B::LeftAnkle), (B::RightKnee, B::RightAnkle)] {
        crouch[ix(k)].x += 0.45;
        crouch[ix(k)].z += 0.45;
        crouch[ix(a)] = crouch[ix(k)] - Vector3::new(0.0, 0.0, 0.45);
    }
    let f = run(
        &kp,
        &[sample(crouch), sample(crouch)],
        0.9,
        &vec![vec![0.0]; 2],
    );
    assert!(!f.healthy);
    assert!(
        f.failures.iter().any(|m| m.starts_with("left_knee")),
        "{:?}",
        f.failures
    );
    assert!(
        f.failures.iter().any(|m| m.starts_with("hip_height")),
        "{:?}",
        f.failures
    );
    let fine = run(&kp, &[sample(body), sample(body)], 0.9, &vec![vec![0.0]; 2]);
    assert!(fine.healthy, "{:?}", fine.failures);
}
