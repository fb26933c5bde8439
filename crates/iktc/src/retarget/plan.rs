//! The references of every task at the control rate, computed once before the run.
//!
//! The scaled points ([`super::scale`]) are interpolated at the tick times by natural cubic
//! splines ([`CubicSpline`]); the feet are held in stance ([`super::contacts`]); the COM
//! reference is the scaled pelvis' ground projection plus the robot's own horizontal offset of
//! its COM from its pelvis in the posture asked of it at that tick ([`super::com`]: G1's COM is
//! 4.1 cm ahead of its pelvis standing; held over the pelvis, its torso's orientation missed
//! the clip's by a mean 29–43° on the shared clips, with the start posture's offset by
//! 10–31°), pulled into the support polygon of the
//! feet on the ground (shrunk by `com_margin`), then smoothed by two passes of a centred moving
//! average of `com_smoothing` \[s\]; orientations come from the points: the pelvis frame from
//! the hip axis and the vertical leaned toward the trunk's direction by
//! [`KeypointSettings::pelvis_lean`](super::KeypointSettings::pelvis_lean), the torso frame from the shoulder axis and the hips-to-
//! shoulders direction (`y` along the axis, `z` the other direction made orthogonal to it,
//! `x = y × z`), each times the constant rotation that maps the same construction on the robot
//! in its start posture onto the robot's frame. Where a leg would have to stretch beyond its
//! reach `r` to reach its foot's reference, the pelvis and the points above it are lowered by
//! `δz = −√(r² − |d_xy|²) − d_z` (`d` from the robot's hip, placed by the pelvis reference
//! and heading, to the ankle's reference), the largest over both legs, spread over
//! `com_smoothing` by a running maximum and the same moving averages. The reach is
//! `max_leg_extension` of the leg's length (hip–knee `t` plus knee–ankle `s`, the robot's),
//! and, for a foot the person has on the ground, at most the hip-to-ankle distance the
//! person's knee angle `α` (between thigh and shank, π straight) gives the robot's leg,
//! `√(t² + s² − 2ts cos α)` ([`leg_reach`]): the robot's stance knee bends at least as the
//! person's. A swing leg's knee is the swing foot's and the posture's to bend (bounding it
//! too lowered G1's hips under its swing legs). Rates and accelerations are central
//! differences of the sampled references (`ẋ_k = (x_{k+1} − x_{k−1}) / 2Δt`, angular rates
//! from `log(R_{k+1} R_{k−1}ᵀ) / 2Δt`).

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3, Vector6};

use super::body::RobotBody;
use super::com;
use super::contacts::{
    detect, hold, hold_turning, moving_average, quintic, remove_short, runs, split_slides,
    PIVOT_RATE, PIVOT_SMOOTHING,
};
use super::scale::ScaledClip;
use super::tracker::PostureTracks;
use super::{KeypointSettings, SupportArea};
use crate::error::{Error, Result};
use crate::model::{Kinematics, Robot, State};
use crate::motion::{lowpass_track, BodyPoint, CubicSpline, Keypoints};
use crate::sim::imitate::{sole_pose, SupportSettings};
use crate::task::{ComReference, FrameReference};
use crate::walk::{Pose2, SupportPolygon};

/// References of one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PointRef {
    pub position: Vector3<f64>,
    pub velocity: Vector3<f64>,
    pub acceleration: Vector3<f64>,
}

impl PointRef {
    pub fn frame(&self, hold: bool) -> FrameReference {
        let z = Vector3::zeros();
        let (v, a) = if hold {
            (z, z)
        } else {
            (self.velocity, self.acceleration)
        };
        FrameReference {
            pose: Isometry3::from_parts(
                Translation3::from(self.position),
                UnitQuaternion::identity(),
            ),
            velocity: Vector6::new(v.x, v.y, v.z, 0.0, 0.0, 0.0),
            acceleration: Vector6::new(a.x, a.y, a.z, 0.0, 0.0, 0.0),
        }
    }
}

/// A pose reference of one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PoseRef {
    pub position: PointRef,
    pub rotation: UnitQuaternion<f64>,
    pub angular_velocity: Vector3<f64>,
    pub angular_acceleration: Vector3<f64>,
}

impl PoseRef {
    pub fn frame(&self, hold: bool) -> FrameReference {
        let mut r = self.position.frame(hold);
        r.pose.rotation = self.rotation;
        if !hold {
            let (w, a) = (self.angular_velocity, self.angular_acceleration);
            r.velocity.fixed_rows_mut::<3>(3).copy_from(&w);
            r.acceleration.fixed_rows_mut::<3>(3).copy_from(&a);
        }
        r
    }
}

/// Every task's references at every tick, the contacts, and the human points for the quality
/// figures.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    pub ticks: usize,
    /// Feet (left, right) per tick.
    pub feet: [Vec<PoseRef>; 2],
    /// Feet on the ground per tick (left, right).
    pub contact: [Vec<bool>; 2],
    /// Per foot and tick, the weight of the offset latched at the foot's last touch-down
    /// (the tracker's closed-loop hold) and its first and second time derivatives \[–\],
    /// \[1/s\], \[1/s²\]: 1 in stance, `1 − s(τ)` over the swing to the next stance (the
    /// swing's progress `τ`, [`quintic`]), 1 after the last stance, 0 before the first.
    pub latch_weight: [Vec<[f64; 3]>; 2],
    pub com: Vec<ComReference>,
    pub pelvis: Vec<PoseRef>,
    pub torso: Vec<PoseRef>,
    /// The tracked points (hands, elbows, head) and their references per tick.
    pub points: Vec<(BodyPoint, Vec<PointRef>)>,
    /// Per tick, per point of the robot body: `s_leg (a(p) − a(m))` \[m\], the neutral target
    /// relative to the middle of the robot's hips, with `m = (p_lhip + p_rhip) / 2` the middle of
    /// the human hips. The hip joint centres are the pelvis's anatomical landmarks both bodies
    /// have; a rig's root and a robot's pelvis frame are not (DeepMimic's root is at hip height,
    /// CMU's several centimetres above, G1's pelvis frame 10 cm above its hips, JVRC-1's at them).
    /// The pelvis point is that middle on both bodies (the alignment point: its target is 0).
    pub neutral: Vec<Vec<(BodyPoint, Vector3<f64>)>>,
}

/// The distance from hip to ankle \[m\] of a leg with a thigh of `thigh` and a shank of
/// `shank` \[m\] whose knee's inner angle is `angle` \[rad\] (π for a straight leg), by the
/// law of cosines: `√(t² + s² − 2ts cos α)`.
pub(crate) fn leg_reach(thigh: f64, shank: f64, angle: f64) -> f64 {
    (thigh * thigh + shank * shank - 2.0 * thigh * shank * angle.cos())
        .max(0.0)
        .sqrt()
}

fn finite_differences(x: &[Vector3<f64>], dt: f64) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let n = x.len();
    let diff = |x: &[Vector3<f64>]| -> Vec<Vector3<f64>> {
        (0..n)
            .map(|k| {
                if n < 3 || k == 0 || k + 1 == n {
                    Vector3::zeros()
                } else {
                    (x[k + 1] - x[k - 1]) / (2.0 * dt)
                }
            })
            .collect()
    };
    let v = diff(x);
    let a = diff(&v);
    (v, a)
}

fn point_refs(x: Vec<Vector3<f64>>, dt: f64) -> Vec<PointRef> {
    let (v, a) = finite_differences(&x, dt);
    x.into_iter()
        .zip(v.into_iter().zip(a))
        .map(|(position, (velocity, acceleration))| PointRef {
            position,
            velocity,
            acceleration,
        })
        .collect()
}

fn pose_refs(x: Vec<Vector3<f64>>, r: Vec<UnitQuaternion<f64>>, dt: f64) -> Vec<PoseRef> {
    let n = r.len();
    let w: Vec<Vector3<f64>> = (0..n)
        .map(|k| {
            if n < 3 || k == 0 || k + 1 == n {
                Vector3::zeros()
            } else {
                (r[k + 1] * r[k - 1].inverse()).scaled_axis() / (2.0 * dt)
            }
        })
        .collect();
    let (_, wd) = finite_differences(&w, dt);
    let wd: Vec<Vector3<f64>> = (0..n)
        .map(|k| {
            if n < 3 || k == 0 || k + 1 == n {
                Vector3::zeros()
            } else {
                (w[k + 1] - w[k - 1]) / (2.0 * dt)
            }
        })
        .zip(wd)
        .map(|(a, _)| a)
        .collect();
    point_refs(x, dt)
        .into_iter()
        .zip(r.into_iter().zip(w.into_iter().zip(wd)))
        .map(|(position, (rotation, (w, a)))| PoseRef {
            position,
            rotation,
            angular_velocity: w,
            angular_acceleration: a,
        })
        .collect()
}

/// The frame with `y` along `axis` and `z` along `up` made orthogonal to it.
fn frame_from(axis: Vector3<f64>, up: Vector3<f64>) -> UnitQuaternion<f64> {
    let y = axis.try_normalize(1e-12).unwrap_or_else(Vector3::y);
    let z = (up - y * y.dot(&up))
        .try_normalize(1e-12)
        .unwrap_or_else(Vector3::z);
    let x = y.cross(&z);
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(Matrix3::from_columns(
        &[x, y, z],
    )))
}

/// The pelvis frame of hips `lh`, `rh` under shoulders `ls`, `rs`: `y` along the hip axis,
/// `z` along `(1 − a) ẑ + a t̂` made orthogonal to it, `t̂` the trunk's direction from the
/// hips' middle to the shoulders' and `a` = `trunk` (0: upright, 1: the whole trunk lean).
fn pelvis_frame(
    lh: Vector3<f64>,
    rh: Vector3<f64>,
    ls: Vector3<f64>,
    rs: Vector3<f64>,
    trunk: f64,
) -> UnitQuaternion<f64> {
    let t = (0.5 * (ls + rs) - 0.5 * (lh + rh))
        .try_normalize(1e-12)
        .unwrap_or_else(Vector3::z);
    frame_from(lh - rh, (1.0 - trunk) * Vector3::z() + trunk * t)
}

fn torso_frame(
    ls: Vector3<f64>,
    rs: Vector3<f64>,
    lh: Vector3<f64>,
    rh: Vector3<f64>,
) -> UnitQuaternion<f64> {
    frame_from(ls - rs, 0.5 * (ls + rs) - 0.5 * (lh + rh))
}

/// The support polygon of `soles` (sole centres and headings, each `length` × `width` \[m\]):
/// one sole's rectangle or the hull of two; `None` without a sole.
pub(crate) fn soles_polygon(soles: &[Pose2], length: f64, width: f64) -> Option<SupportPolygon> {
    let mut polygon = SupportPolygon::default();
    match soles {
        [a] => polygon.set_sole(a, length, width),
        [a, b] => polygon.set_hull_of_soles(a, b, length, width),
        _ => return None,
    }
    Some(polygon)
}

/// Pulls `p` into `polygon` until its margin is at least `margin` \[m\], along the segment to the
/// polygon's vertex centroid (bisection).
pub(crate) fn pull_inside(polygon: &SupportPolygon, p: (f64, f64), margin: f64) -> (f64, f64) {
    let v = polygon.vertices();
    let n = v.len().max(1) as f64;
    let c = v
        .iter()
        .fold((0.0, 0.0), |a, q| (a.0 + q.0 / n, a.1 + q.1 / n));
    polygon.pull_towards(p, c, margin)
}

/// The robot a plan is made for: its model, its start state and the kinematics at it, its
/// body frames and feet, and its posture references per tick.
pub(crate) struct PlanRobot<'a> {
    pub robot: &'a Robot,
    pub start: &'a State,
    pub kin: &'a Kinematics,
    pub body: &'a RobotBody,
    pub support: &'a SupportSettings,
    pub posture: &'a PostureTracks,
}

/// The plan of a run (see the module documentation).
pub(crate) fn plan(
    r: &PlanRobot,
    kp: &Keypoints,
    clip: &ScaledClip,
    s: &KeypointSettings,
) -> Result<Plan> {
    let frames = kp.frame_count();
    let (t0, t1) = (kp.times[0], kp.times[frames - 1]);
    let ticks = s
        .run_limits
        .ticks(&format!("`{}`", kp.source), t1 - t0, s.dt)?
        + 1;
    let times: Vec<f64> = (0..ticks).map(|k| (t0 + k as f64 * s.dt).min(t1)).collect();
    let tr = Tracks::sample(kp, clip, s, &times)?;
    let contact = contact_ticks(&tr, clip, s, &times)?;
    let pelvis_x = tr.get(BodyPoint::Pelvis)?;
    let (lh, rh) = (tr.get(BodyPoint::LeftHip)?, tr.get(BodyPoint::RightHip)?);
    let heading: Vec<f64> = unwrap(
        (0..ticks)
            .map(|k| {
                let l = lh[k] - rh[k];
                l.y.atan2(l.x) - std::f64::consts::FRAC_PI_2
            })
            .collect(),
    );
    let feet = foot_refs(r, &tr, s, &contact, &heading, ticks)?;
    let start = StartPoints::of(r, &tr)?;
    let pelvis_rot = pelvis_rotations(r, &tr, s, &start, lh, rh, ticks)?;
    let com = com_refs(r, s, &contact, &feet, pelvis_x, &pelvis_rot, ticks)?;
    let drop = leg_drops(r, &tr, s, &contact, &feet, pelvis_x, &heading, ticks)?;
    let lowered = lowering(&drop, s, ticks);
    let pelvis_x: Vec<Vector3<f64>> = pelvis_x.iter().zip(&lowered).map(|(p, d)| p - d).collect();
    let pelvis = pose_refs(pelvis_x, pelvis_rot, s.dt);
    let torso = torso_refs(r, &tr, s, &start, lh, rh, ticks)?;
    let points = point_tracks(r.body, &tr, &lowered, s.dt);
    let neutral = neutral_points(r.body, &tr, clip, ticks)?;
    let latch_weight = [
        latch_weights(&contact[0], s.dt),
        latch_weights(&contact[1], s.dt),
    ];
    let mut plan = Plan {
        ticks,
        feet,
        contact,
        latch_weight,
        com,
        pelvis,
        torso,
        points,
        neutral,
    };
    if s.standing {
        hold_stance(&mut plan, r.robot, r.kin, r.body, r.support, s.dt)?;
    }
    Ok(plan)
}

/// The ankle and toe points of the feet (left, right).
const SIDES: [(BodyPoint, BodyPoint); 2] = [
    (BodyPoint::LeftAnkle, BodyPoint::LeftToe),
    (BodyPoint::RightAnkle, BodyPoint::RightToe),
];

/// The clip's points sampled at the tick times, and the lookups of the plan's steps.
struct Tracks<'a> {
    kp: &'a Keypoints,
    /// Per body point of `kp`, the scaled points (low-passed, when asked) per tick \[m\].
    scaled: Vec<Option<Vec<Vector3<f64>>>>,
    /// Per body point of `kp`, the aligned points per tick \[m\].
    aligned: Vec<Option<Vec<Vector3<f64>>>>,
}

impl<'a> Tracks<'a> {
    /// Splines through the scaled (low-passed, when asked) and aligned points, at `times` \[s\].
    fn sample(
        kp: &'a Keypoints,
        clip: &ScaledClip,
        s: &KeypointSettings,
        times: &[f64],
    ) -> Result<Self> {
        let n = kp.points.len();
        let mut scaled: Vec<Option<Vec<Vector3<f64>>>> = vec![None; n];
        let mut aligned: Vec<Option<Vec<Vector3<f64>>>> = vec![None; n];
        for k in 0..n {
            scaled[k] = Some(sample_point(kp, times, &clip.scaled, k, s.smoothing)?);
            aligned[k] = Some(sample_point(kp, times, &clip.aligned, k, None)?);
        }
        Ok(Tracks {
            kp,
            scaled,
            aligned,
        })
    }

    /// The index of `p` among the keypoints' points.
    fn idx(&self, p: BodyPoint) -> Option<usize> {
        self.kp.points.iter().position(|q| *q == p)
    }

    /// The scaled track of `p`, if the keypoints have it.
    fn track(&self, p: BodyPoint) -> Option<&Vec<Vector3<f64>>> {
        self.idx(p).and_then(|k| self.scaled[k].as_ref())
    }

    /// The error of a body point missing from the keypoints.
    fn missing(&self, p: BodyPoint) -> Error {
        Error::UnknownName {
            kind: "body point (missing from the keypoints)",
            name: format!("{p}` in `{}", self.kp.source),
            valid: self
                .kp
                .points
                .iter()
                .map(|q| q.name().to_string())
                .collect(),
        }
    }

    /// The scaled track of `p`, or the error of its absence.
    fn get(&self, p: BodyPoint) -> Result<&Vec<Vector3<f64>>> {
        self.track(p).ok_or_else(|| self.missing(p))
    }

    /// The position \[m\] of the robot's frame of `p` in its start posture.
    fn at_start(&self, r: &PlanRobot, p: BodyPoint) -> Result<Vector3<f64>> {
        let f = r.body.frame_of(p).ok_or_else(|| self.missing(p))?;
        Ok(r.kin.frame_pose(r.robot, f)?.translation.vector)
    }
}

/// Point `k` of `data` (frame-major) at `times` \[s\] by a cubic spline, low-passed at
/// `smoothing` \[Hz\] when given.
fn sample_point(
    kp: &Keypoints,
    times: &[f64],
    data: &[Vector3<f64>],
    k: usize,
    smoothing: Option<f64>,
) -> Result<Vec<Vector3<f64>>> {
    let n = kp.points.len();
    let frames = kp.frame_count();
    let ticks = times.len();
    let mut out = vec![Vector3::zeros(); ticks];
    let mut column = vec![0.0; ticks];
    if frames == 1 {
        out.iter_mut().for_each(|o| *o = data[k]);
        return Ok(out);
    }
    for axis in 0..3 {
        let mut y: Vec<f64> = (0..frames).map(|f| data[f * n + k][axis]).collect();
        if let Some(fc) = smoothing {
            y = lowpass_track(&y, &kp.times, fc)?;
        }
        CubicSpline::new(&kp.times, &y)?.values_at(times, &mut column)?;
        for (o, v) in out.iter_mut().zip(&column) {
            o[axis] = *v;
        }
    }
    Ok(out)
}

/// The source frame nearest to time `t` \[s\] (the earlier one on a tie).
fn nearest_frame(times: &[f64], t: f64) -> usize {
    let frames = times.len();
    let f = times.partition_point(|x| *x < t);
    if f == 0 {
        0
    } else if f >= frames {
        frames - 1
    } else if t - times[f - 1] < times[f] - t {
        f - 1
    } else {
        f
    }
}

/// Contacts at the source rate, on the aligned clip, then per tick (nearest frame).
fn contact_ticks(
    tr: &Tracks,
    clip: &ScaledClip,
    s: &KeypointSettings,
    times: &[f64],
) -> Result<[Vec<bool>; 2]> {
    let kp = tr.kp;
    let n = kp.points.len();
    let frames = kp.frame_count();
    let (t0, t1) = (kp.times[0], kp.times[frames - 1]);
    let rate_dt = if frames > 1 {
        (t1 - t0) / (frames - 1) as f64
    } else {
        s.dt
    };
    let min_len = (s.min_phase / rate_dt).round() as usize;
    let column =
        |k: usize| -> Vec<Vector3<f64>> { (0..frames).map(|f| clip.aligned[f * n + k]).collect() };
    let toe_ground = SIDES
        .iter()
        .filter_map(|(_, t)| tr.idx(*t))
        .flat_map(|k| (0..frames).map(move |f| (k, f)))
        .map(|(k, f)| clip.aligned[f * n + k].z)
        .fold(f64::INFINITY, f64::min);
    let mut contact: [Vec<bool>; 2] = [Vec::new(), Vec::new()];
    for (i, (a, t)) in SIDES.iter().enumerate() {
        let ankle = column(tr.idx(*a).ok_or_else(|| tr.missing(*a))?);
        let toe = tr.idx(*t).map(column);
        let mut c = detect(
            &kp.times,
            &ankle,
            toe.as_deref(),
            [0.0, toe_ground],
            s.contact_height,
            s.contact_speed,
        );
        remove_short(&mut c, false, min_len);
        remove_short(&mut c, true, min_len);
        if let Some(d) = s.max_slide {
            split_slides(&mut c, &ankle, d, min_len);
        }
        contact[i] = times
            .iter()
            .map(|t| c[nearest_frame(&kp.times, *t)])
            .collect();
    }
    Ok(contact)
}

/// Feet: x, y (of the sole's centre) and yaw held in stance (the yaw followed where the foot
/// pivots), z on the ground in stance; `heading` per tick \[rad\].
fn foot_refs(
    r: &PlanRobot,
    tr: &Tracks,
    s: &KeypointSettings,
    contact: &[Vec<bool>; 2],
    heading: &[f64],
    ticks: usize,
) -> Result<[Vec<PoseRef>; 2]> {
    let (robot, kin, body, support) = (r.robot, r.kin, r.body, r.support);
    let h_a = support.ankle_height;
    let mut feet: [Vec<PoseRef>; 2] = [Vec::new(), Vec::new()];
    let pivot_half = (0.5 * PIVOT_SMOOTHING / s.dt).round() as usize;
    for (i, (a, t)) in SIDES.iter().enumerate() {
        let ankle = tr.get(*a)?;
        let foot0 = kin.frame_pose(robot, body.feet[i])?;
        // The toe's yaw where it gives one, else the heading; relative to the first tick.
        let raw = tr
            .track(*t)
            .and_then(|toe| {
                let dirs: Vec<Vector3<f64>> = (0..ticks).map(|k| toe[k] - ankle[k]).collect();
                foot_yaw(&dirs, heading)
            })
            .unwrap_or_else(|| heading.to_vec());
        let yaw: Vec<f64> = raw.iter().map(|y| y - raw[0]).collect();
        // The sole's centre is held (x, y), and a pivoting foot turns about it: the ankle's
        // track is carried to the sole's centre with the captured yaw and back with the
        // held one.
        let mut w = yaw.clone();
        match s.pivot_turn {
            Some(turn) => hold_turning(&mut w, &contact[i], turn, pivot_half, PIVOT_RATE * s.dt),
            None => hold(&mut w, &contact[i], None),
        }
        let s0 = foot0.rotation * Vector3::new(support.sole_offset_x, 0.0, 0.0);
        let sole = |psi: f64| UnitQuaternion::from_euler_angles(0.0, 0.0, psi) * s0;
        let mut x: Vec<f64> = (0..ticks).map(|k| ankle[k].x + sole(yaw[k]).x).collect();
        let mut y: Vec<f64> = (0..ticks).map(|k| ankle[k].y + sole(yaw[k]).y).collect();
        let mut z: Vec<f64> = ankle.iter().map(|p| p.z).collect();
        hold(&mut x, &contact[i], None);
        hold(&mut y, &contact[i], None);
        hold(&mut z, &contact[i], Some(h_a));
        let pos: Vec<Vector3<f64>> = (0..ticks)
            .map(|k| {
                let s = sole(w[k]);
                Vector3::new(x[k] - s.x, y[k] - s.y, z[k].max(h_a))
            })
            .collect();
        let rot: Vec<UnitQuaternion<f64>> = w
            .iter()
            .map(|yaw| UnitQuaternion::from_euler_angles(0.0, 0.0, *yaw) * foot0.rotation)
            .collect();
        feet[i] = pose_refs(pos, rot, s.dt);
    }
    Ok(feet)
}

/// The robot's hips and shoulders in its start posture \[m\].
struct StartPoints {
    lh: Vector3<f64>,
    rh: Vector3<f64>,
    ls: Vector3<f64>,
    rs: Vector3<f64>,
}

impl StartPoints {
    /// The robot's hips and shoulders at its start.
    fn of(r: &PlanRobot, tr: &Tracks) -> Result<Self> {
        let (lh, rh) = (
            tr.at_start(r, BodyPoint::LeftHip)?,
            tr.at_start(r, BodyPoint::RightHip)?,
        );
        let (ls, rs) = (
            tr.at_start(r, BodyPoint::LeftShoulder)?,
            tr.at_start(r, BodyPoint::RightShoulder)?,
        );
        Ok(StartPoints { lh, rh, ls, rs })
    }
}

/// Pelvis orientations per tick, from the same construction on the robot at its start.
fn pelvis_rotations(
    r: &PlanRobot,
    tr: &Tracks,
    s: &KeypointSettings,
    start: &StartPoints,
    lh: &[Vector3<f64>],
    rh: &[Vector3<f64>],
    ticks: usize,
) -> Result<Vec<UnitQuaternion<f64>>> {
    let trunk = s.pelvis_lean;
    let (sl, sr) = (
        tr.get(BodyPoint::LeftShoulder)?,
        tr.get(BodyPoint::RightShoulder)?,
    );
    let c_pelvis = pelvis_frame(start.lh, start.rh, start.ls, start.rs, trunk).inverse()
        * r.kin.frame_pose(r.robot, r.body.pelvis)?.rotation;
    Ok((0..ticks)
        .map(|k| pelvis_frame(lh[k], rh[k], sl[k], sr[k], trunk) * c_pelvis)
        .collect())
}

/// COM over the support polygon of the feet on the ground: the scaled pelvis plus the
/// robot's own COM offset from its pelvis in the posture asked of it ([`com`]), smoothed.
fn com_refs(
    r: &PlanRobot,
    s: &KeypointSettings,
    contact: &[Vec<bool>; 2],
    feet: &[Vec<PoseRef>; 2],
    pelvis_x: &[Vector3<f64>],
    pelvis_rot: &[UnitQuaternion<f64>],
    ticks: usize,
) -> Result<Vec<ComReference>> {
    let support = r.support;
    let com_offset = com::com_offsets(r.robot, r.start, r.body.pelvis, pelvis_rot, r.posture)?;
    let mut com: Vec<Vector3<f64>> = Vec::with_capacity(ticks);
    for k in 0..ticks {
        let any = contact[0][k] || contact[1][k];
        let on: Vec<Isometry3<f64>> = (0..2)
            .filter(|i| match s.support_area {
                SupportArea::Stance => contact[*i][k],
                SupportArea::BothFeet => any,
            })
            .map(|i| {
                Isometry3::from_parts(
                    Translation3::from(feet[i][k].position.position),
                    feet[i][k].rotation,
                )
            })
            .collect();
        let c = pelvis_x[k] + com_offset[k];
        let p = (c.x, c.y);
        let (l, w) = (support.sole_length, support.sole_width);
        let soles: Vec<Pose2> = on.iter().map(|a| sole_pose(a, support)).collect();
        let q = match soles_polygon(&soles, l, w) {
            Some(polygon) => pull_inside(&polygon, p, s.com_margin),
            None => p,
        };
        com.push(Vector3::new(q.0, q.1, 0.0));
    }
    let half = (0.5 * s.com_smoothing / s.dt).round() as usize;
    moving_average(&mut com, half);
    moving_average(&mut com, half);
    Ok(point_refs(com, s.dt)
        .into_iter()
        .map(|r| ComReference {
            position: r.position,
            velocity: r.velocity,
            acceleration: r.acceleration,
        })
        .collect())
}

/// Legs within reach: per tick, how far \[m\] the pelvis must be lowered for both legs to
/// reach their feet's references.
#[allow(clippy::too_many_arguments)]
fn leg_drops(
    r: &PlanRobot,
    tr: &Tracks,
    s: &KeypointSettings,
    contact: &[Vec<bool>; 2],
    feet: &[Vec<PoseRef>; 2],
    pelvis_x: &[Vector3<f64>],
    heading: &[f64],
    ticks: usize,
) -> Result<Vec<f64>> {
    let (robot, kin, body) = (r.robot, r.kin, r.body);
    let aligned = &tr.aligned;
    let mut drop = vec![0.0; ticks];
    for (i, (hip, knee, ankle)) in [
        (
            BodyPoint::LeftHip,
            BodyPoint::LeftKnee,
            BodyPoint::LeftAnkle,
        ),
        (
            BodyPoint::RightHip,
            BodyPoint::RightKnee,
            BodyPoint::RightAnkle,
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let (h0, k0, a0) = (
            tr.at_start(r, hip)?,
            tr.at_start(r, knee)?,
            tr.at_start(r, ankle)?,
        );
        let (thigh, shank) = ((k0 - h0).norm(), (a0 - k0).norm());
        let cap = s.max_leg_extension * (thigh + shank);
        // The person's knee, as the angle between thigh and shank (π straight).
        let person = [tr.idx(hip), tr.idx(knee), tr.idx(ankle)];
        let offset = h0 - kin.frame_pose(robot, body.pelvis)?.translation.vector;
        for k in 0..ticks {
            let reach = match person {
                [Some(h), Some(n), Some(a)] if contact[i][k] => {
                    match (&aligned[h], &aligned[n], &aligned[a]) {
                        (Some(h), Some(n), Some(a)) => {
                            leg_reach(thigh, shank, (h[k] - n[k]).angle(&(a[k] - n[k]))).min(cap)
                        }
                        _ => cap,
                    }
                }
                _ => cap,
            };
            let turn = UnitQuaternion::from_euler_angles(0.0, 0.0, heading[k] - heading[0]);
            let d = feet[i][k].position.position - (pelvis_x[k] + turn * offset);
            let horizontal = d.xy().norm().min(reach);
            let need = -(reach * reach - horizontal * horizontal).sqrt() - d.z;
            drop[k] = f64::max(drop[k], need);
        }
    }
    Ok(drop)
}

/// The lowering \[m\] per tick of the pelvis and the points above it: the drops' running
/// maximum over `com_smoothing`, smoothed by two moving averages.
fn lowering(drop: &[f64], s: &KeypointSettings, ticks: usize) -> Vec<Vector3<f64>> {
    let half = (0.5 * s.com_smoothing / s.dt).round() as usize;
    let peak: Vec<f64> = (0..ticks)
        .map(|k| {
            drop[k.saturating_sub(half)..(k + half + 1).min(ticks)]
                .iter()
                .fold(0.0, |a: f64, b| a.max(*b))
        })
        .collect();
    let mut lowered: Vec<Vector3<f64>> = peak.iter().map(|d| Vector3::new(0.0, 0.0, *d)).collect();
    moving_average(&mut lowered, half);
    moving_average(&mut lowered, half);
    lowered
}

/// Torso orientations per tick, from the same construction on the robot at its start.
fn torso_refs(
    r: &PlanRobot,
    tr: &Tracks,
    s: &KeypointSettings,
    start: &StartPoints,
    lh: &[Vector3<f64>],
    rh: &[Vector3<f64>],
    ticks: usize,
) -> Result<Vec<PoseRef>> {
    let (ls, rs) = (
        tr.get(BodyPoint::LeftShoulder)?,
        tr.get(BodyPoint::RightShoulder)?,
    );
    let c_torso = match r.body.torso {
        Some(f) => {
            torso_frame(start.ls, start.rs, start.lh, start.rh).inverse()
                * r.kin.frame_pose(r.robot, f)?.rotation
        }
        None => UnitQuaternion::identity(),
    };
    let torso_rot: Vec<UnitQuaternion<f64>> = (0..ticks)
        .map(|k| torso_frame(ls[k], rs[k], lh[k], rh[k]) * c_torso)
        .collect();
    Ok(pose_refs(vec![Vector3::zeros(); ticks], torso_rot, s.dt))
}

/// Hands, elbows, head: the scaled points lowered by `lowered` \[m\] per tick.
fn point_tracks(
    body: &RobotBody,
    tr: &Tracks,
    lowered: &[Vector3<f64>],
    dt: f64,
) -> Vec<(BodyPoint, Vec<PointRef>)> {
    let mut points = Vec::new();
    for p in TRACKED {
        if body.frame_of(p).is_some() {
            if let Some(x) = tr.track(p) {
                let x = x.iter().zip(lowered).map(|(p, d)| p - d).collect();
                points.push((p, point_refs(x, dt)));
            }
        }
    }
    points
}

/// The neutral targets of one tick: per point of the robot body, relative to the middle of its
/// hips \[m\] (see `Plan::neutral`).
type NeutralTargets = Vec<(BodyPoint, Vector3<f64>)>;

/// Neutral targets: the aligned human points scaled by the leg ratio, placed at the middle
/// of the hips (the joint centres both bodies have; see `Plan::neutral`).
fn neutral_points(
    body: &RobotBody,
    tr: &Tracks,
    clip: &ScaledClip,
    ticks: usize,
) -> Result<Vec<NeutralTargets>> {
    let aligned = &tr.aligned;
    let hip_k = [
        tr.idx(BodyPoint::LeftHip)
            .ok_or_else(|| tr.missing(BodyPoint::LeftHip))?,
        tr.idx(BodyPoint::RightHip)
            .ok_or_else(|| tr.missing(BodyPoint::RightHip))?,
    ];
    let leg = clip.scaling.leg;
    Ok((0..ticks)
        .map(|k| {
            let (Some(l), Some(r)) = (&aligned[hip_k[0]], &aligned[hip_k[1]]) else {
                return Vec::new();
            };
            let o = 0.5 * (l[k] + r[k]);
            body.points
                .iter()
                .filter_map(|(p, _)| {
                    let a = aligned[tr.idx(*p)?].as_ref()?[k];
                    // The pelvis is the alignment point itself (see `Plan::neutral`).
                    let rel = match p {
                        BodyPoint::Pelvis => Vector3::zeros(),
                        _ => leg * (a - o),
                    };
                    Some((*p, rel))
                })
                .collect()
        })
        .collect())
}

/// Standing imitation ([`KeypointSettings::standing`]): the feet and the pelvis held at the
/// robot's start pose, both feet on the ground throughout, the COM over the midpoint of the
/// two soles' centres, and the upper body imitated relative to the clip's pelvis. With
/// `X_k = (x_k, R_k)` the pelvis reference the clip gives at tick k and `X₀` the robot's pelvis
/// at its start, every tracked point becomes `p′_k = X₀ X_k⁻¹ p_k` and the torso's orientation
/// `T′_k = R₀ R_k⁻¹ T_k`: what the clip's upper body does relative to its pelvis, placed on a
/// pelvis that does not move. Rates and accelerations are the finite differences of the new
/// references, as everywhere in the plan.
fn hold_stance(
    plan: &mut Plan,
    robot: &Robot,
    kin: &Kinematics,
    body: &RobotBody,
    support: &SupportSettings,
    dt: f64,
) -> Result<()> {
    let ticks = plan.ticks;
    let x0 = kin.frame_pose(robot, body.pelvis)?;
    let to_robot: Vec<Isometry3<f64>> = plan
        .pelvis
        .iter()
        .map(|p| {
            x0 * Isometry3::from_parts(Translation3::from(p.position.position), p.rotation)
                .inverse()
        })
        .collect();
    for (_, refs) in plan.points.iter_mut() {
        let x = refs
            .iter()
            .zip(&to_robot)
            .map(|(r, t)| t.transform_point(&r.position.into()).coords)
            .collect();
        *refs = point_refs(x, dt);
    }
    let torso = plan
        .torso
        .iter()
        .zip(&to_robot)
        .map(|(r, t)| t.rotation * r.rotation)
        .collect();
    plan.torso = pose_refs(vec![Vector3::zeros(); ticks], torso, dt);
    plan.pelvis = pose_refs(
        vec![x0.translation.vector; ticks],
        vec![x0.rotation; ticks],
        dt,
    );
    let mut middle = Vector3::zeros();
    for i in 0..2 {
        let f0 = kin.frame_pose(robot, body.feet[i])?;
        let sole = sole_pose(&f0, support);
        middle += 0.5 * Vector3::new(sole.x, sole.y, 0.0);
        plan.feet[i] = pose_refs(
            vec![f0.translation.vector; ticks],
            vec![f0.rotation; ticks],
            dt,
        );
        plan.contact[i] = vec![true; ticks];
        plan.latch_weight[i] = latch_weights(&plan.contact[i], dt);
    }
    plan.com = vec![
        ComReference {
            position: middle,
            velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
        };
        ticks
    ];
    Ok(())
}

/// The points tracked below the pelvis: hands (level 4), then elbows (level 5, with the torso's
/// orientation). The head is not tracked: on a robot whose head is fixed to the torso its
/// position and the torso's orientation make a rank-deficient level, which IKTC's correction
/// does not keep inside the box (seen on G1); its error is reported.
pub(crate) const TRACKED: [BodyPoint; 4] = [
    BodyPoint::LeftWrist,
    BodyPoint::RightWrist,
    BodyPoint::LeftElbow,
    BodyPoint::RightElbow,
];

/// [`Plan::latch_weight`] of one foot: `1 − s(τ)` and its derivatives `−s'(τ)/T`,
/// `−s''(τ)/T²` over a swing of `T` \[s\] (`s' = 30τ²(1 − τ)²`, `s'' = 60τ(1 − τ)(1 − 2τ)`).
fn latch_weights(contact: &[bool], dt: f64) -> Vec<[f64; 3]> {
    let n = contact.len();
    let stances = runs(contact);
    let mut w = vec![[0.0; 3]; n];
    for (i, &(s, e)) in stances.iter().enumerate() {
        w[s..e].iter_mut().for_each(|x| *x = [1.0, 0.0, 0.0]);
        let a = e - 1;
        match stances.get(i + 1) {
            Some(&(b, _)) => {
                let span = (b - a) as f64;
                let t = span * dt;
                for (k, x) in w.iter_mut().enumerate().take(b).skip(e) {
                    let tau = (k - a) as f64 / span;
                    let d1 = 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau);
                    let d2 = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau);
                    *x = [1.0 - quintic(tau), -d1 / t, -d2 / (t * t)];
                }
            }
            None => w[e..].iter_mut().for_each(|x| *x = [1.0, 0.0, 0.0]),
        }
    }
    w
}

/// The toe's direction gives a foot's yaw only while its horizontal part is at least this
/// share of its length \[–\] (the foot pitched less than 45° from level): a foot pointing
/// down has an `atan2` of a short, noisy horizontal vector. At 0.5 (60°) G1's held feet
/// slipped 3.5 mm on CMU 131_01; at 0.7 1.2 mm, and the 51 Bandai Namco clips' figures are
/// within 0.1 cm of 0.5's.
pub(crate) const TOE_LEVEL: f64 = 0.7;

/// The toe's direction gives a foot's yaw only while it is within this of the pelvis heading
/// \[rad\] (90°): beyond, the foot points backwards because it is pitched past vertical (a
/// swing with the knee bent and the ankle extended), not because it is turned. Taken as a yaw
/// on a clip of Bandai Namco's dataset, both made a swing foot's reference spin by 250° in
/// 0.1 s.
pub(crate) const TOE_TWIST: f64 = std::f64::consts::FRAC_PI_2;

/// A foot's yaw per tick \[rad\] from the ankle-to-toe vectors `dirs` \[m\] and the pelvis
/// heading `heading` \[rad\] (unwrapped): `heading + τ`, the twist `τ` being the angle from
/// the heading to the vectors' horizontal part on the ticks where that gives a yaw
/// ([`TOE_LEVEL`], [`TOE_TWIST`]), linearly interpolated across the other ticks and held before
/// the first and after the last such tick; `None` if there is none.
pub(crate) fn foot_yaw(dirs: &[Vector3<f64>], heading: &[f64]) -> Option<Vec<f64>> {
    let good: Vec<(usize, f64)> = dirs
        .iter()
        .zip(heading)
        .enumerate()
        .filter_map(|(k, (d, h))| {
            let level = d.xy().norm();
            if level == 0.0 || level < TOE_LEVEL * d.norm() {
                return None;
            }
            let twist = crate::motion::wrap_to_pi(d.y.atan2(d.x) - h);
            (twist.abs() <= TOE_TWIST).then_some((k, twist))
        })
        .collect();
    let (last, end) = *good.last()?;
    let mut twist = vec![good[0].1; dirs.len()];
    twist[last..].fill(end);
    for pair in good.windows(2) {
        let ((a, ta), (b, tb)) = (pair[0], pair[1]);
        for (k, t) in twist.iter_mut().enumerate().take(b + 1).skip(a) {
            *t = ta + (tb - ta) * (k - a) as f64 / (b - a) as f64;
        }
    }
    Some(heading.iter().zip(&twist).map(|(h, t)| h + t).collect())
}

fn unwrap(mut a: Vec<f64>) -> Vec<f64> {
    for k in 1..a.len() {
        let d = crate::motion::wrap_to_pi(a[k] - a[k - 1]);
        a[k] = a[k - 1] + d;
    }
    a
}

#[cfg(test)]
#[path = "plan_tests.rs"]
mod tests;
