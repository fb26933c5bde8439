//! Tests of the plan: a pivoting foot, standing imitation, smoothing, the COM reference's
//! offset, the neutral targets at the middle of the hips, and the toe's yaw.

use super::*;
use crate::profile::RobotProfile;
use crate::retarget::contacts::PIVOT_TURN;
use crate::sim::ImitateConfig;

/// The plans of `clip` on `robot` as the keypoint route builds them, with and without
/// `standing`, and the robot's start kinematics and body.
fn plans(robot: &str, clip: &str) -> (Robot, Kinematics, RobotBody, SupportSettings, Plan, Plan) {
    plans_with(robot, clip, &KeypointSettings::default())
}

fn plans_with(
    robot: &str,
    clip: &str,
    s: &KeypointSettings,
) -> (Robot, Kinematics, RobotBody, SupportSettings, Plan, Plan) {
    let profile = RobotProfile::builtin(robot).unwrap();
    let robot = profile.robot().unwrap();
    let cfg = profile.imitate_config(ImitateConfig::default()).unwrap();
    let names = super::super::frame_names(&profile, &cfg).unwrap();
    let mut kin = Kinematics::new(&robot, &crate::model::State::neutral(&robot)).unwrap();
    let body = RobotBody::find(&robot, &kin, &names).unwrap();
    let state = profile.standing_state(&robot).unwrap();
    kin.update(&robot, &state).unwrap();
    let kp = super::super::builtin_motion(clip)
        .unwrap()
        .keypoints(crate::motion::DEFAULT_MAX_GAP)
        .unwrap();
    let scaled = super::super::scale::scale_clip(
        &robot,
        &kin,
        &body,
        &kp,
        cfg.support.ankle_height,
        s.hands,
        s.feet,
    )
    .unwrap();
    let posture = super::super::posture_tracks(&robot, &state, None, s.posture_margin).unwrap();
    let on = PlanRobot {
        robot: &robot,
        start: &state,
        kin: &kin,
        body: &body,
        support: &cfg.support,
        posture: &posture,
    };
    let free = plan(&on, &kp, &scaled, s).unwrap();
    let standing = KeypointSettings {
        standing: true,
        ..s.clone()
    };
    let held = plan(&on, &kp, &scaled, &standing).unwrap();
    (robot, kin, body, cfg.support, free, held)
}

/// `humanoid3d_dance_a` spins on its feet: with the default a foot's yaw turns by more
/// than [`PIVOT_TURN`] over one of its stances (0.96 rad on G1), about its sole's centre,
/// which stays where the
/// stance holds it; with `pivot_turn: None` every stance holds the foot's yaw. Either way
/// the sole's centre is constant in every stance, and a pivoting foot turns no faster
/// than [`PIVOT_RATE`] there.
#[test]
fn a_spinning_foot_pivots_about_its_sole_centre_unless_asked_to_hold() {
    let planted = KeypointSettings {
        pivot_turn: None,
        ..KeypointSettings::default()
    };
    let (.., support, free, _) = plans("g1", "humanoid3d_dance_a");
    let (.., held, _) = plans_with("g1", "humanoid3d_dance_a", &planted);
    let s = Vector3::new(support.sole_offset_x, 0.0, -support.ankle_height);
    let centre = |f: &PoseRef| f.position.position + f.rotation * s;
    let yaw = |f: &PoseRef| {
        (f.rotation * Vector3::x())
            .y
            .atan2((f.rotation * Vector3::x()).x)
    };
    // Rounding of a held value carried through a rotation and back [m], [rad].
    let tol = 1e-12;
    let dt = KeypointSettings::default().dt;
    let mut largest_turn: f64 = 0.0;
    for (plan, pivots) in [(&free, true), (&held, false)] {
        for i in 0..2 {
            for (a, b) in runs(&plan.contact[i]) {
                let f = &plan.feet[i];
                for k in a + 1..b {
                    assert!((centre(&f[k]) - centre(&f[a])).norm() < tol, "{i} {k}");
                    let step = f[k].rotation.angle_to(&f[k - 1].rotation);
                    if pivots {
                        assert!(step <= PIVOT_RATE * dt + tol, "{i} {k}: {step}");
                    } else {
                        assert!(step < tol, "{i} {k}: {step}");
                    }
                }
                if pivots {
                    let turn = f[a..b]
                        .iter()
                        .map(|p| (yaw(p) - yaw(&f[a])).abs())
                        .fold(0.0, f64::max);
                    largest_turn = largest_turn.max(turn);
                }
            }
        }
    }
    assert!(largest_turn > PIVOT_TURN, "{largest_turn}");
}

/// Standing: feet, pelvis and COM are constant at the robot's start, both feet on the ground
/// throughout; every tracked point is the free plan's point moved by X₀ X_k⁻¹ (recomputed
/// here from the free plan's pelvis as a rotation and a translation, not as an isometry
/// product) and the torso keeps its orientation relative to the pelvis.
#[test]
fn standing_holds_feet_and_pelvis_and_carries_the_upper_body_on_the_pelvis() {
    for (robot_name, clip) in [("g1", "humanoid3d_dance_b"), ("jvrc1", "humanoid3d_punch")] {
        let (robot, kin, body, support, free, held) = plans(robot_name, clip);
        assert_eq!(free.ticks, held.ticks);
        let x0 = kin.frame_pose(&robot, body.pelvis).unwrap();
        // A pose read back from the kinematics and stored: exact up to rounding.
        let tol = 1e-12;
        for k in 0..held.ticks {
            let p = &held.pelvis[k];
            assert!((p.position.position - x0.translation.vector).norm() < tol);
            assert!(p.rotation.angle_to(&x0.rotation) < tol);
            assert!(p.position.velocity.norm() < tol && p.angular_velocity.norm() < tol);
            for i in 0..2 {
                assert!(held.contact[i][k], "{robot_name}: foot {i} off at tick {k}");
                let f0 = kin.frame_pose(&robot, body.feet[i]).unwrap();
                assert!((held.feet[i][k].position.position - f0.translation.vector).norm() < tol);
            }
            assert!((held.com[k].position - held.com[0].position).norm() < tol);
            // The pelvis pose the free plan gives at tick k.
            let (xk, rk) = (free.pelvis[k].position.position, free.pelvis[k].rotation);
            for ((pf, rf), (ph, rh)) in free.points.iter().zip(&held.points) {
                assert_eq!(pf, ph);
                let expected =
                    x0.rotation * (rk.inverse() * (rf[k].position - xk)) + x0.translation.vector;
                assert!(
                    (rh[k].position - expected).norm() < 1e-9,
                    "{robot_name} {pf} tick {k}: {} vs {expected}",
                    rh[k].position
                );
            }
            let rel_free = rk.inverse() * free.torso[k].rotation;
            let rel_held = x0.rotation.inverse() * held.torso[k].rotation;
            assert!(
                rel_free.angle_to(&rel_held) < 1e-9,
                "{robot_name} torso tick {k}"
            );
        }
        // The COM over the middle of the soles: inside the support polygon of both feet.
        let soles: Vec<_> = (0..2)
            .map(|i| {
                let f0 = kin.frame_pose(&robot, body.feet[i]).unwrap();
                sole_pose(&f0, &support)
            })
            .collect();
        let mut polygon = SupportPolygon::default();
        polygon.set_hull_of_soles(
            &soles[0],
            &soles[1],
            support.sole_length,
            support.sole_width,
        );
        let c = held.com[0].position;
        assert!(
            polygon.margin((c.x, c.y)) > 0.0,
            "{robot_name}: COM {c} outside"
        );
        // The upper body does move.
        let (_, hand) = &held.points[0];
        let travel = hand
            .iter()
            .map(|r| (r.position - hand[0].position).norm())
            .fold(0.0, f64::max);
        assert!(travel > 0.1, "{robot_name}: the hand moves {travel} m");
    }
}

/// Share of ticks where the change of a reference acceleration reverses its sign.
fn reversals(a: &[f64]) -> f64 {
    let d: Vec<f64> = a.windows(2).map(|w| w[1] - w[0]).collect();
    let n = d.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
    n as f64 / (d.len() - 1) as f64
}

/// The low-pass takes the capture's frame-rate noise out of the references' accelerations:
/// as captured (60 Hz, cubic splines), the change of the wrists' and elbows' reference
/// acceleration reverses its sign on 21–23 % of the 200 Hz ticks (at the frames); low-passed
/// at 6 Hz, on 5–6 %. The references move by at most 2.1 cm (the dance's fastest arm
/// motions, at the cut-off).
#[test]
fn smoothing_takes_the_frame_rate_noise_out_of_the_references() {
    let raw = plans_with("jvrc1", "humanoid3d_dance_b", &KeypointSettings::default()).4;
    let s = KeypointSettings {
        smoothing: Some(6.0),
        ..KeypointSettings::default()
    };
    let smooth = plans_with("jvrc1", "humanoid3d_dance_b", &s).4;
    for ((p, r), (_, f)) in raw.points.iter().zip(&smooth.points) {
        let (mut rr, mut rf, mut moved) = (0.0_f64, 0.0_f64, 0.0_f64);
        for axis in 0..3 {
            let ar: Vec<f64> = r.iter().map(|x| x.acceleration[axis]).collect();
            let af: Vec<f64> = f.iter().map(|x| x.acceleration[axis]).collect();
            rr = rr.max(reversals(&ar));
            rf = rf.max(reversals(&af));
        }
        for (a, b) in r.iter().zip(f) {
            moved = moved.max((a.position - b.position).norm());
        }
        assert!(rr > 0.15, "{p}: as captured {rr}");
        assert!(rf < 0.1, "{p}: low-passed {rf}");
        assert!(moved < 0.03, "{p}: moved {moved} m");
    }
}

/// The COM reference is the pelvis' ground projection plus the robot's own COM offset from
/// its pelvis frame in the posture asked of it (here the start posture, every tick) with
/// the pelvis frame at its orientation reference, wherever that lies inside the support
/// polygon (unsmoothed here, so it is compared tick by tick; elsewhere it is pulled to the
/// polygon's margin). The offset is computed here from the robot placed by the plan's
/// pelvis reference. On G1 it is about 4 cm: held over the pelvis instead, the reference
/// would match on no tick.
#[test]
fn the_com_reference_carries_the_robots_com_offset_from_its_pelvis() {
    let s = KeypointSettings {
        com_smoothing: 0.0,
        ..KeypointSettings::default()
    };
    let (robot, mut kin, body, _, free, _) = plans_with("g1", "humanoid3d_walk", &s);
    let profile = RobotProfile::builtin("g1").unwrap();
    let mut state = profile.standing_state(&robot).unwrap();
    let base_in_pelvis =
        kin.frame_pose(&robot, body.pelvis).unwrap().inverse() * state.base_pose(&robot);
    let (mut with, mut without) = (0, 0);
    for k in 0..free.ticks {
        let r = &free.pelvis[k];
        let pelvis = Isometry3::from_parts(Translation3::from(r.position.position), r.rotation);
        state
            .set_base_pose(&robot, &(pelvis * base_in_pelvis))
            .unwrap();
        kin.update(&robot, &state).unwrap();
        let placed = kin.frame_pose(&robot, body.pelvis).unwrap();
        // The robot placed by the reference: its pelvis frame is there.
        assert!((placed.translation.vector - r.position.position).norm() < 1e-9);
        let offset = kin.com() - placed.translation.vector;
        assert!(
            offset.xy().norm() > 0.03,
            "G1's offset at tick {k}: {offset}"
        );
        let p = r.position.position;
        let c = free.com[k].position;
        // A reference built from stored positions: equal up to rounding.
        if (c.xy() - (p + offset).xy()).norm() < 1e-9 {
            with += 1;
        }
        if (c.xy() - p.xy()).norm() < 1e-9 {
            without += 1;
        }
    }
    assert!(2 * with > free.ticks, "{with} of {} ticks", free.ticks);
    assert_eq!(without, 0);
}

/// The neutral targets are aligned at the middle of the hips: the two hips' targets are
/// opposite (their middle is the origin), and a robot whose body points sit exactly on
/// the targets, placed from the middle of its hips, scores zero error whichever of its
/// frames is taken for the pelvis; moved by 1 cm, every point scores 1 cm. The pelvis
/// frame's reference turned by 0.1 rad about the vertical scores 0.1 rad, in degrees, on
/// each of two ticks.
#[test]
fn the_keypoint_error_is_aligned_at_the_middle_of_the_hips() {
    use super::super::quality::QualityRecorder;
    let (robot, mut kin, body, support, free, _) = plans("g1", "humanoid3d_punch");
    // The robot turned and tilted, so that no frame is at the identity.
    let mut state = crate::model::State::neutral(&robot);
    let pose = Isometry3::new(Vector3::new(0.1, -0.2, 0.7), Vector3::new(0.2, -0.1, 0.6));
    state.set_base_pose(&robot, &pose).unwrap();
    kin.update(&robot, &state).unwrap();
    // Sums of decimetre-sized vectors, and one of 0.01 m \[m\].
    let tol = 1e-12;
    let k = free.ticks / 2;
    let target = |p: BodyPoint| free.neutral[k].iter().find(|(q, _)| *q == p).unwrap().1;
    let (l, r) = (target(BodyPoint::LeftHip), target(BodyPoint::RightHip));
    assert!((l + r).norm() < tol, "{l} {r}");
    assert!(l.norm() > 0.03, "half the hips' width: {l}");
    // A plan whose tick k is the robot's own points relative to its hip middle.
    let at = |p: BodyPoint| {
        let f = body.frame_of(p).unwrap();
        kin.frame_pose(&robot, f).unwrap().translation.vector
    };
    let middle = 0.5 * (at(BodyPoint::LeftHip) + at(BodyPoint::RightHip));
    let mut plan = free.clone();
    let shift = Vector3::new(0.0, 0.01, 0.0);
    for (p, rel) in plan.neutral[k].iter_mut() {
        if *p == BodyPoint::Pelvis {
            assert_eq!(*rel, Vector3::zeros(), "the pelvis is the alignment point");
            continue;
        }
        *rel = at(*p) - middle
            + if *p == BodyPoint::LeftHip || *p == BodyPoint::RightHip {
                Vector3::zeros()
            } else {
                shift
            };
    }
    let turn = 0.1;
    for t in [k, k + 1] {
        plan.neutral[t] = plan.neutral[k].clone();
        plan.pelvis[t].rotation = UnitQuaternion::from_euler_angles(0.0, 0.0, turn)
            * kin.frame_pose(&robot, body.pelvis).unwrap().rotation;
    }
    let qdd = vec![0.0; robot.nv()];
    let pelvis_frame = body.pelvis;
    for pelvis in [body.pelvis, body.torso.unwrap()] {
        let body = RobotBody {
            pelvis,
            ..body.clone()
        };
        let mut rec = QualityRecorder::new("keypoints", &body, 0.005);
        for t in [k, k + 1] {
            rec.record(
                &robot,
                &kin,
                &body,
                &plan,
                &support,
                (t, [false; 2], false),
                &state,
                &qdd,
            )
            .unwrap();
        }
        let q = rec.finish(&robot);
        if pelvis == pelvis_frame {
            let o = &q.orientations[0];
            assert_eq!(o.frame, "pelvis");
            assert!((o.mean_deg - turn.to_degrees()).abs() < 1e-9, "{o:?}");
            assert!((o.max_deg - turn.to_degrees()).abs() < 1e-9, "{o:?}");
        }
        for e in &q.points {
            let want = if e.point.ends_with("_hip") || e.point == "pelvis" {
                0.0
            } else {
                1.0
            };
            assert!(
                (e.mean_cm - want).abs() < 1e-9,
                "{}: {} cm",
                e.point,
                e.mean_cm
            );
        }
    }
}

/// A foot's yaw from its toe: where the toe points down (past [`TOE_LEVEL`]) or backwards
/// (past [`TOE_TWIST`] from the heading), the twist from the heading is interpolated between
/// the neighbouring ticks that give one, never the `atan2` of that tick; held at the ends.
#[test]
fn a_foot_pointing_down_or_backwards_gives_no_yaw() {
    let deg = f64::to_radians;
    // A heading turning by 5° a tick, the foot twisted 10° out, on the level.
    let heading: Vec<f64> = (0..8).map(|k| deg(5.0 * k as f64)).collect();
    let level = |k: usize, twist: f64| {
        let a = heading[k] + deg(twist);
        Vector3::new(a.cos(), a.sin(), -0.2)
    };
    let mut dirs: Vec<Vector3<f64>> = (0..8).map(|k| level(k, 10.0)).collect();
    dirs[0] = Vector3::new(0.05, 0.3, -1.0); // pointing down, horizontal part 30% of it
    dirs[3] = Vector3::new(0.2, -0.1, -1.0); // pointing down
    dirs[4] = -level(4, 10.0) + Vector3::new(0.0, 0.0, -0.4); // backwards
    dirs[7] = -level(7, 30.0) + Vector3::new(0.0, 0.0, -0.4); // backwards
    dirs[5] = level(5, 40.0);
    // A foot's length: the share of the horizontal part, not its length, decides.
    let dirs: Vec<Vector3<f64>> = dirs.iter().map(|d| 0.15 * d).collect();
    let yaw = foot_yaw(&dirs, &heading).unwrap();
    let twist: Vec<f64> = yaw
        .iter()
        .zip(&heading)
        .map(|(y, h)| (y - h).to_degrees())
        .collect();
    let expected = [10.0, 10.0, 10.0, 20.0, 30.0, 40.0, 10.0, 10.0];
    for (k, (t, e)) in twist.iter().zip(expected).enumerate() {
        assert!((t - e).abs() < 1e-9, "tick {k}: twist {t}°, expected {e}°");
    }
    // Unwrapped: a heading past ±180° carries the yaw with it.
    let heading: Vec<f64> = (0..4).map(|k| deg(170.0 + 10.0 * k as f64)).collect();
    let dirs: Vec<Vector3<f64>> = heading
        .iter()
        .map(|h| Vector3::new(h.cos(), h.sin(), 0.0))
        .collect();
    let yaw = foot_yaw(&dirs, &heading).unwrap();
    for (y, h) in yaw.iter().zip(&heading) {
        assert!((y - h).abs() < 1e-9);
    }
    // No tick gives a yaw.
    assert!(foot_yaw(&[Vector3::new(0.0, 0.0, -1.0)], &[0.0]).is_none());
}
