//! Human keypoints scaled to the robot, segment by segment.
//!
//! Alignment: the clip is turned about the vertical so that the subject faces +x at the first
//! frame and moved so that its first pelvis is above the origin and its lowest ankle at z = 0:
//! `a(p) = R_z(−ψ₀) (p − (o_x, o_y, g))`, with `ψ₀ = atan2(l_y, l_x) − π/2` the heading of the
//! hip axis `l = p_lhip − p_rhip` at frame 0, `o` the first pelvis and `g` the lowest ankle
//! height of the clip \[m\].
//!
//! Scaling: the pelvis by the leg ratio `s_leg = L_robot / L_human` (hip–knee plus
//! knee–ankle lengths), horizontally `p'_pelvis,xy = s_leg a(p_pelvis)_xy`, vertically from the
//! middle of the hips (where the legs start, on both bodies):
//! `p'_pelvis,z = h_a + s_leg a(p_hips)_z + (r_pelvis − r_hips)_z` with `h_a` the robot's ankle
//! height above its sole and `r_hips` the middle of the robot's hips in its start posture; every
//! other point from its parent along the
//! segment tree (pelvis → hip → knee → ankle → toe, pelvis → shoulder → elbow → wrist,
//! pelvis → head, chest, neck): `p'_c = p'_p + s_pc (a(p_c) − a(p_p))` with
//! `s_pc = |r_c − r_p| / median_t |p_c(t) − p_p(t)|`, `r` the robot's points in its start
//! posture. A segment without robot points takes its parent segment's ratio (toe: the shank's;
//! chest, neck: the head's, else the leg's). With [`LimbScaling::Leg`] for the hands
//! the wrists are then placed from the middle of the hips by the leg ratio instead, `p'_wrist =
//! p'_m + s_leg (a(p_wrist) − a(m))` with `m` the middle of the human hips and `p'_m =
//! (s_leg a(m)_xy, h_a + s_leg a(m)_z)` its scaled counterpart (so that
//! `p'_wrist = s_leg a(p_wrist) + h_a ẑ`): where the hands are relative to the body is kept,
//! not the forearm's direction. With [`LimbScaling::Leg`] for the feet the ankles are placed
//! the same way, `p'_ankle = s_leg a(p_ankle) + h_a ẑ` (a foot at the clip's lowest ankle
//! height has its sole on the ground), and each toe moves with its ankle (`p'_toe +=
//! p'_ankle,leg − p'_ankle,segments`): the person's stance width, not the robot's hip width.

use nalgebra::{Rotation3, Vector3};

use super::body::RobotBody;
use super::LimbScaling;
use crate::error::{Error, Result};
use crate::model::{Kinematics, Robot};
use crate::motion::{BodyPoint, Keypoints};

use BodyPoint as B;

/// The segment tree, parents before children.
pub(crate) const SEGMENTS: [(BodyPoint, BodyPoint); 17] = [
    (B::Pelvis, B::LeftHip),
    (B::LeftHip, B::LeftKnee),
    (B::LeftKnee, B::LeftAnkle),
    (B::LeftAnkle, B::LeftToe),
    (B::Pelvis, B::RightHip),
    (B::RightHip, B::RightKnee),
    (B::RightKnee, B::RightAnkle),
    (B::RightAnkle, B::RightToe),
    (B::Pelvis, B::Head),
    (B::Pelvis, B::Chest),
    (B::Pelvis, B::Neck),
    (B::Pelvis, B::LeftShoulder),
    (B::LeftShoulder, B::LeftElbow),
    (B::LeftElbow, B::LeftWrist),
    (B::Pelvis, B::RightShoulder),
    (B::RightShoulder, B::RightElbow),
    (B::RightElbow, B::RightWrist),
];

/// How the clip was aligned and scaled (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Scaling {
    /// Heading of the subject at frame 0, ψ₀ \[rad\].
    pub heading: f64,
    /// The lowest ankle height of the clip, g \[m\] (file frame, after units and up axis).
    pub ground: f64,
    /// The leg ratio s_leg \[–\].
    pub leg: f64,
    /// The ratio of every segment present (parent, child, ratio \[–\]).
    pub segments: Vec<(BodyPoint, BodyPoint, f64)>,
}

/// The aligned clip `a(p)` and its scaled points, frame-major like [`Keypoints::positions`].
#[derive(Debug, Clone)]
pub(crate) struct ScaledClip {
    pub scaling: Scaling,
    pub aligned: Vec<Vector3<f64>>,
    pub scaled: Vec<Vector3<f64>>,
}

fn index(kp: &Keypoints, p: BodyPoint) -> Option<usize> {
    kp.points.iter().position(|q| *q == p)
}

fn required(kp: &Keypoints, p: BodyPoint) -> Result<usize> {
    index(kp, p).ok_or_else(|| Error::UnknownName {
        kind: "body point (missing from the keypoints)",
        name: format!("{p}` in `{}", kp.source),
        valid: kp.points.iter().map(|q| q.name().to_string()).collect(),
    })
}

/// Aligns and scales `kp` onto the robot whose body points are `body` at the kinematics `kin`
/// (start posture); `ankle_height` is the robot's ankle above its sole \[m\]; `hands` places
/// the wrists and `feet` the ankles and toes.
pub(crate) fn scale_clip(
    robot: &Robot,
    kin: &Kinematics,
    body: &RobotBody,
    kp: &Keypoints,
    ankle_height: f64,
    hands: LimbScaling,
    feet: LimbScaling,
) -> Result<ScaledClip> {
    let n = kp.points.len();
    let frames = kp.frame_count();
    if frames == 0 || kp.positions.len() != frames * n {
        return Err(Error::InsufficientData {
            what: format!("keypoints of `{}`", kp.source),
            message: format!(
                "{frames} frames and {} positions for {n} points",
                kp.positions.len()
            ),
        });
    }
    let at = |f: usize, k: usize| kp.positions[f * n + k];
    let pelvis = required(kp, B::Pelvis)?;
    let (lh, rh) = (required(kp, B::LeftHip)?, required(kp, B::RightHip)?);
    let (la, ra) = (required(kp, B::LeftAnkle)?, required(kp, B::RightAnkle)?);
    let left = at(0, lh) - at(0, rh);
    let heading = left.y.atan2(left.x) - std::f64::consts::FRAC_PI_2;
    let ground = (0..frames)
        .map(|f| at(f, la).z.min(at(f, ra).z))
        .fold(f64::INFINITY, f64::min);
    let o = at(0, pelvis);
    let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), -heading);
    let origin = Vector3::new(o.x, o.y, ground);
    let aligned: Vec<Vector3<f64>> = kp.positions.iter().map(|p| rot * (p - origin)).collect();
    let rp = RobotPoints { robot, kin, body };
    let (lk, rk) = (required(kp, B::LeftKnee)?, required(kp, B::RightKnee)?);
    let leg = leg_ratio(&rp, kp, [(lh, lk, la), (rh, rk, ra)])?;
    let segments = segment_ratios(&rp, kp, leg)?;
    let robot_hips = match (rp.at(B::LeftHip)?, rp.at(B::RightHip)?, rp.at(B::Pelvis)?) {
        (Some(l), Some(r), Some(p)) => p.z - 0.5 * (l.z + r.z),
        _ => 0.0,
    };
    let scaled = ScaleFrames {
        kp,
        aligned: &aligned,
        leg,
        segments: &segments,
        ankle_height,
        robot_hips,
        ids: [pelvis, lh, rh, la, ra],
    }
    .scaled(hands, feet);
    Ok(ScaledClip {
        scaling: Scaling {
            heading,
            ground,
            leg,
            segments,
        },
        aligned,
        scaled,
    })
}

/// The robot's body points in its start posture.
struct RobotPoints<'a> {
    robot: &'a Robot,
    kin: &'a Kinematics,
    body: &'a RobotBody,
}

impl RobotPoints<'_> {
    /// The position \[m\] of the robot's frame of `p`, if it has one.
    fn at(&self, p: BodyPoint) -> Result<Option<Vector3<f64>>> {
        match self.body.frame_of(p) {
            Some(f) => Ok(Some(self.kin.frame_pose(self.robot, f)?.translation.vector)),
            None => Ok(None),
        }
    }
}

/// The median over the frames of `kp` of the distance \[m\] between its points `a` and `b`.
fn human_length(kp: &Keypoints, a: usize, b: usize) -> f64 {
    let n = kp.points.len();
    let frames = kp.frame_count();
    let at = |f: usize, k: usize| kp.positions[f * n + k];
    let mut d: Vec<f64> = (0..frames).map(|f| (at(f, b) - at(f, a)).norm()).collect();
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

/// The leg ratio: the robot's leg length over the person's (hip–knee plus knee–ankle, the
/// medians), the mean over the legs both have; `legs` are the (hip, knee, ankle) indices of
/// the left and right legs in `kp`.
fn leg_ratio(r: &RobotPoints, kp: &Keypoints, legs: [(usize, usize, usize); 2]) -> Result<f64> {
    let [(lh, lk, la), (rh, rk, ra)] = legs;
    let mut legs = Vec::new();
    for (h, k, a, ph, pk, pa) in [
        (lh, lk, la, B::LeftHip, B::LeftKnee, B::LeftAnkle),
        (rh, rk, ra, B::RightHip, B::RightKnee, B::RightAnkle),
    ] {
        let (Some(rh), Some(rk), Some(ra)) = (r.at(ph)?, r.at(pk)?, r.at(pa)?) else {
            continue;
        };
        let human = human_length(kp, h, k) + human_length(kp, k, a);
        if human > 0.0 {
            legs.push(((rk - rh).norm() + (ra - rk).norm()) / human);
        }
    }
    if legs.is_empty() {
        return Err(Error::InsufficientData {
            what: format!("leg lengths of `{}`", kp.source),
            message: "the hips, knees and ankles coincide in every frame".into(),
        });
    }
    Ok(legs.iter().sum::<f64>() / legs.len() as f64)
}

/// The ratio of each segment of [`SEGMENTS`] `kp` has: the robot's length over the
/// person's, or where the robot lacks a point, the knee's (toes), the head's (chest, neck) or
/// the `leg` ratio.
fn segment_ratios(
    r: &RobotPoints,
    kp: &Keypoints,
    leg: f64,
) -> Result<Vec<(BodyPoint, BodyPoint, f64)>> {
    let ratio = |pa: BodyPoint, pb: BodyPoint, a: usize, b: usize| -> Result<Option<f64>> {
        let (Some(ra), Some(rb)) = (r.at(pa)?, r.at(pb)?) else {
            return Ok(None);
        };
        let h = human_length(kp, a, b);
        Ok((h > 0.0).then(|| (rb - ra).norm() / h))
    };
    let mut segments: Vec<(BodyPoint, BodyPoint, f64)> = Vec::new();
    for (pa, pb) in SEGMENTS {
        let (Some(a), Some(b)) = (index(kp, pa), index(kp, pb)) else {
            continue;
        };
        let fallback = match pb {
            B::LeftToe | B::RightToe => {
                let knee = if pb == B::LeftToe {
                    B::LeftKnee
                } else {
                    B::RightKnee
                };
                segments.iter().find(|s| s.0 == knee).map_or(leg, |s| s.2)
            }
            B::Chest | B::Neck => segments
                .iter()
                .find(|s| s.1 == B::Head)
                .map_or(leg, |s| s.2),
            _ => leg,
        };
        let r = ratio(pa, pb, a, b)?.unwrap_or(fallback);
        segments.push((pa, pb, r));
    }
    Ok(segments)
}

/// What the scaled points of every frame are made from.
struct ScaleFrames<'a> {
    kp: &'a Keypoints,
    /// The aligned points, frame-major \[m\].
    aligned: &'a [Vector3<f64>],
    /// The leg ratio \[–\].
    leg: f64,
    segments: &'a [(BodyPoint, BodyPoint, f64)],
    /// The robot's ankle above its sole \[m\].
    ankle_height: f64,
    /// The robot's pelvis above the middle of its hips \[m\].
    robot_hips: f64,
    /// The indices in `kp` of the pelvis, left and right hips, left and right ankles.
    ids: [usize; 5],
}

impl ScaleFrames<'_> {
    /// The scaled points, frame-major \[m\]: the pelvis, then each segment from its parent,
    /// then the ankles (with `feet`) and wrists (with `hands`) by the leg ratio.
    fn scaled(&self, hands: LimbScaling, feet: LimbScaling) -> Vec<Vector3<f64>> {
        let (kp, aligned, leg) = (self.kp, self.aligned, self.leg);
        let [pelvis, lh, rh, la, ra] = self.ids;
        let n = kp.points.len();
        let frames = kp.frame_count();
        let mut scaled = vec![Vector3::zeros(); aligned.len()];
        let wrists = [index(kp, B::LeftWrist), index(kp, B::RightWrist)];
        let ankles = [(la, index(kp, B::LeftToe)), (ra, index(kp, B::RightToe))];
        // p'_m + s_leg (a(p) − a(m)) with p'_m = (s_leg a(m)_xy, h_a + s_leg a(m)_z), i.e.
        // s_leg a(p) + h_a ẑ: a point placed from the middle of the hips by the leg ratio.
        let by_leg = |i: usize| leg * aligned[i] + Vector3::new(0.0, 0.0, self.ankle_height);
        for f in 0..frames {
            let row = f * n;
            let hips = 0.5 * (aligned[row + lh] + aligned[row + rh]);
            let p = leg * aligned[row + pelvis];
            scaled[row + pelvis] =
                Vector3::new(p.x, p.y, self.ankle_height + leg * hips.z + self.robot_hips);
            for &(pa, pb, r) in self.segments {
                if let (Some(a), Some(b)) = (index(kp, pa), index(kp, pb)) {
                    scaled[row + b] = scaled[row + a] + r * (aligned[row + b] - aligned[row + a]);
                }
            }
            if feet == LimbScaling::Leg {
                // The ankle by the leg ratio; the toe keeps its offset from the ankle.
                for (a, toe) in ankles {
                    let moved = by_leg(row + a);
                    let shift = moved - scaled[row + a];
                    scaled[row + a] = moved;
                    if let Some(t) = toe {
                        scaled[row + t] += shift;
                    }
                }
            }
            if hands == LimbScaling::Leg {
                for w in wrists.iter().flatten() {
                    scaled[row + w] = by_leg(row + w);
                }
            }
        }
        scaled
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::RobotProfile;

    /// The robot's ankle height above its sole in these tests \[m\].
    const ANKLE_HEIGHT: f64 = 0.035;

    /// `kp` scaled onto the robot with the hands and feet placed by `hands` and `feet`.
    fn scaled(
        robot: &Robot,
        kin: &Kinematics,
        body: &RobotBody,
        kp: &Keypoints,
        hands: LimbScaling,
        feet: LimbScaling,
    ) -> ScaledClip {
        scale_clip(robot, kin, body, kp, ANKLE_HEIGHT, hands, feet).unwrap()
    }

    /// G1 at its neutral posture, its body points, and the keypoints of a built-in clip.
    fn g1_and(clip: &str) -> (Robot, Kinematics, RobotBody, Keypoints) {
        let kp = super::super::builtin_motion(clip)
            .unwrap()
            .keypoints(crate::motion::DEFAULT_MAX_GAP)
            .unwrap();
        let profile = RobotProfile::builtin("g1").unwrap();
        let robot = profile.robot().unwrap();
        let cfg = profile
            .imitate_config(crate::sim::ImitateConfig::default())
            .unwrap();
        let names = super::super::frame_names(&profile, &cfg).unwrap();
        let state = crate::model::State::neutral(&robot);
        let kin = Kinematics::new(&robot, &state).unwrap();
        let body = RobotBody::find(&robot, &kin, &names).unwrap();
        (robot, kin, body, kp)
    }

    /// Every limb segment (thigh, shank, upper arm, forearm) comes out exactly as long as the
    /// robot's with the segment scaling of the hands: the clip's limbs are rigid, so their
    /// median length is their length in every frame. (Segments from the pelvis are not: the
    /// spine bends, and the pelvis is placed by the hips' height.) The pelvis starts above the
    /// origin.
    #[test]
    fn scaled_segments_have_the_robots_lengths() {
        let (robot, kin, body, kp) = g1_and("humanoid3d_punch");
        let c = scaled(
            &robot,
            &kin,
            &body,
            &kp,
            LimbScaling::Segments,
            LimbScaling::Segments,
        );
        let n = kp.points.len();
        let idx = |p: BodyPoint| kp.points.iter().position(|q| *q == p).unwrap();
        let mut checked = 0;
        for (pa, pb, _) in &c.scaling.segments {
            let (Some(fa), Some(fb)) = (body.frame_of(*pa), body.frame_of(*pb)) else {
                continue;
            };
            if *pa == BodyPoint::Pelvis {
                continue;
            }
            let robot_len = (kin.frame_pose(&robot, fb).unwrap().translation.vector
                - kin.frame_pose(&robot, fa).unwrap().translation.vector)
                .norm();
            for f in [0, kp.frame_count() / 2, kp.frame_count() - 1] {
                let d = (c.scaled[f * n + idx(*pb)] - c.scaled[f * n + idx(*pa)]).norm();
                assert!(
                    (d - robot_len).abs() < 1e-9,
                    "{pa}-{pb} frame {f}: {d} vs {robot_len}"
                );
            }
            checked += 1;
        }
        assert_eq!(checked, 8, "limb segments checked");
        let p0 = c.scaled[idx(BodyPoint::Pelvis)];
        assert!(p0.xy().norm() < 1e-12, "{p0}");
    }

    /// With the leg ratio for the hands, hands that meet in the clip meet on the robot (the
    /// captured wrists moved onto their midpoint in every frame: a clap), while along the
    /// arm's segments they miss each other by centimetres; every other point is placed alike
    /// by both.
    #[test]
    fn hands_that_meet_in_the_clip_meet_with_the_leg_ratio() {
        let (robot, kin, body, mut kp) = g1_and("humanoid3d_punch");
        let n = kp.points.len();
        let idx = |p: BodyPoint| kp.points.iter().position(|q| *q == p).unwrap();
        let (l, r) = (idx(BodyPoint::LeftWrist), idx(BodyPoint::RightWrist));
        for f in 0..kp.frame_count() {
            let mid = 0.5 * (kp.positions[f * n + l] + kp.positions[f * n + r]);
            kp.positions[f * n + l] = mid;
            kp.positions[f * n + r] = mid;
        }
        let leg = scaled(
            &robot,
            &kin,
            &body,
            &kp,
            LimbScaling::Leg,
            LimbScaling::Segments,
        );
        let seg = scaled(
            &robot,
            &kin,
            &body,
            &kp,
            LimbScaling::Segments,
            LimbScaling::Segments,
        );
        // Rounding of a few additions of decimetre-sized vectors \[m\].
        let tol = 1e-12;
        let mut apart: f64 = 0.0;
        for f in 0..kp.frame_count() {
            let gap = |c: &ScaledClip| (c.scaled[f * n + l] - c.scaled[f * n + r]).norm();
            assert!(gap(&leg) < tol, "frame {f}: {}", gap(&leg));
            apart = apart.max(gap(&seg));
            for k in (0..n).filter(|k| *k != l && *k != r) {
                assert_eq!(leg.scaled[f * n + k], seg.scaled[f * n + k], "point {k}");
            }
        }
        assert!(apart > 0.01, "the segments' hands at most {apart} m apart");
        // With the leg ratio, each hand is the captured hand's offset from the middle of the
        // hips, scaled by the leg ratio, from the middle of the hips' reference: the pelvis'
        // reference less the robot's pelvis height above its hips, horizontally the middle of
        // the human hips scaled by the leg ratio.
        let frame = |p: BodyPoint| {
            let f = body.frame_of(p).unwrap();
            kin.frame_pose(&robot, f).unwrap().translation.vector
        };
        let robot_above_hips = frame(BodyPoint::Pelvis).z
            - 0.5 * (frame(BodyPoint::LeftHip).z + frame(BodyPoint::RightHip).z);
        assert!(
            robot_above_hips > 0.05,
            "G1's pelvis frame {robot_above_hips} m above its hips"
        );
        let (pelvis, lh, rh) = (
            idx(BodyPoint::Pelvis),
            idx(BodyPoint::LeftHip),
            idx(BodyPoint::RightHip),
        );
        for f in 0..kp.frame_count() {
            let a = &leg.aligned;
            let m = 0.5 * (a[f * n + lh] + a[f * n + rh]);
            let mut scaled_m =
                leg.scaled[f * n + pelvis] - Vector3::new(0.0, 0.0, robot_above_hips);
            scaled_m.x = leg.scaling.leg * m.x;
            scaled_m.y = leg.scaling.leg * m.y;
            for w in [l, r] {
                let want = scaled_m + leg.scaling.leg * (a[f * n + w] - m);
                let got = leg.scaled[f * n + w];
                assert!((got - want).norm() < tol, "frame {f}: {got} vs {want}");
            }
        }
    }

    /// With the leg ratio for the feet, each ankle is the captured ankle's offset from the
    /// middle of the hips scaled by the leg ratio from the middle of the hips' reference, its
    /// height above the clip's lowest ankle scaled and raised by the robot's ankle height; the
    /// feet are as far apart as the person's, scaled; each toe keeps its offset from its
    /// ankle; every other point is placed as along the segments.
    #[test]
    fn feet_by_the_leg_ratio_keep_the_persons_stance() {
        let (robot, kin, body, kp) = g1_and("humanoid3d_walk");
        let n = kp.points.len();
        let idx = |p: BodyPoint| kp.points.iter().position(|q| *q == p).unwrap();
        let h_a = ANKLE_HEIGHT;
        let leg = scaled(
            &robot,
            &kin,
            &body,
            &kp,
            LimbScaling::Segments,
            LimbScaling::Leg,
        );
        let seg = scaled(
            &robot,
            &kin,
            &body,
            &kp,
            LimbScaling::Segments,
            LimbScaling::Segments,
        );
        let s = leg.scaling.leg;
        // Rounding of a few additions of metre-sized vectors \[m\].
        let tol = 1e-12;
        let ankles = [idx(BodyPoint::LeftAnkle), idx(BodyPoint::RightAnkle)];
        let find = |p: BodyPoint| kp.points.iter().position(|q| *q == p);
        // The DeepMimic skeleton has no toes: the ankles alone then.
        let toes = [find(BodyPoint::LeftToe), find(BodyPoint::RightToe)];
        let mut narrower: f64 = 0.0;
        for f in 0..kp.frame_count() {
            let a = &leg.aligned;
            for (ankle, toe) in ankles.into_iter().zip(toes) {
                let want = s * a[f * n + ankle] + Vector3::new(0.0, 0.0, h_a);
                let got = leg.scaled[f * n + ankle];
                assert!((got - want).norm() < tol, "frame {f}: {got} vs {want}");
                if let Some(toe) = toe {
                    let offset = |c: &ScaledClip| c.scaled[f * n + toe] - c.scaled[f * n + ankle];
                    assert!((offset(&leg) - offset(&seg)).norm() < tol, "frame {f}: toe");
                }
            }
            let width =
                |c: &ScaledClip| (c.scaled[f * n + ankles[0]] - c.scaled[f * n + ankles[1]]).norm();
            let person = (a[f * n + ankles[0]] - a[f * n + ankles[1]]).norm();
            assert!(
                (width(&leg) - s * person).abs() < tol,
                "frame {f}: stance width"
            );
            narrower = narrower.max(width(&seg) - width(&leg));
            for k in (0..n).filter(|k| !ankles.contains(k) && !toes.contains(&Some(*k))) {
                assert_eq!(leg.scaled[f * n + k], seg.scaled[f * n + k], "point {k}");
            }
        }
        // G1's hips are wider apart than the scaled person's: along the segments its feet
        // stand wider.
        assert!(
            narrower > 0.02,
            "the segments' stance at most {narrower} m wider"
        );
    }
}
