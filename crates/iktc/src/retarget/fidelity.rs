//! Fidelity figures: the robot measured against the captured person with definitions that do
//! not depend on how the run was planned (no intermediate target, no contact of the robot's
//! own, no frame chosen for tracking). Any route's trajectory can be measured this way.
//!
//! Per control tick `k` at clip time `t_k` the person's points `p` are interpolated linearly
//! between the clip's frames; the robot's are its joint centres `x` ([`RobotJointCentres`]).
//!
//! * **Scale** `s = L_robot / L_person`, the legs' hip→knee→ankle length (mean of both legs):
//!   the robot's at q = 0, the person's the median over the clip's frames (the rest pose's for
//!   a rigid skeleton).
//! * **Keypoints**: hips, knees, ankles, shoulders, elbows, wrists and the neck (the middle of
//!   the shoulders). The person's, relative to the middle of their hips `m`, scaled and placed
//!   at the robot's hip middle `c`, turned by one heading `θ` for the whole clip:
//!   `x̂_k = c_k + R_z(θ) s (p_k − m_k)`, `θ` the least-squares fit over every point and tick
//!   (`θ = atan2(Σ d×b, Σ d·b)` over the horizontal parts of `d = s (p − m)` and `b = x − c`).
//!   Error `|x_k − x̂_k|`; mean and max per point; the clip's figure is the mean of the points'
//!   means.
//! * **Contacts** (the person's): a foot is down on frame `f` when its ankle is within
//!   [`CONTACT_HEIGHT`] of that ankle's lowest height over the clip and moves slower than
//!   [`CONTACT_SPEED`] horizontally; runs of at least two frames are the contact windows. Per
//!   window: the robot ankle centre's horizontal **slip** (the largest distance between two of
//!   its positions in the window) and its sole's lowest corner height (**contact height**: the
//!   foot should be on the ground). The window of the largest slip is reported with the
//!   person's own ankle's slip there (scaled by `s`) and the robot sole's height range, so
//!   that a slip the person made too can be told from one the robot added. **Lowest sole**: the lowest sole corner on any tick.
//!   **Skating**: ticks on which a sole's lowest corner is within [`SKATE_HEIGHT`] of the
//!   floor while the sole's centre moves faster than [`SKATE_SPEED`] horizontally.
//! * **Posture**, per tick, robot against scaled person: knee and elbow flexion
//!   (`π − ∠(proximal, joint, distal)`), trunk lean (the angle of `neck − m` from vertical),
//!   hip height (hip middle above the ankles' mean height; the person's times `s`).
//!   Reported: the person's and the robot's medians, the median signed difference and the
//!   90th percentile of the absolute difference.
//! * **Smoothness** of the joints' commanded q̈: RMS and largest jerk, the share of the ticks
//!   whose change of q̈ reverses ([`crate::sim::DofSmoothness`]), and the largest sign flip,
//!   `min(|q̈_{k−1}|, |q̈_k|)` over the ticks where q̈ changes sign.
//! * **Verdict**: every figure against [`FidelityLimits`]; the failures named.

use nalgebra::{Point3, Rotation3, Vector3};
use serde::Serialize;

use super::centres::{RobotJointCentres, JOINT_CENTRES};
use crate::error::{Error, Result};
use crate::model::{FrameId, Kinematics, Robot, State};
use crate::motion::{BodyPoint, Keypoints};
use crate::sim::imitate::SupportSettings;
use crate::sim::{percentile, DofSmoothness};

/// An ankle within this height of its lowest over the clip can be on the ground \[m\] (the
/// person's scale).
pub const CONTACT_HEIGHT: f64 = 0.03;
/// ... and slower than this horizontally \[m/s\] (the person's scale).
pub const CONTACT_SPEED: f64 = 0.2;
/// A sole whose lowest corner is within this of the floor is on it for skating \[m\].
pub const SKATE_HEIGHT: f64 = 0.005;
/// A sole on the floor moving faster than this horizontally skates \[m/s\].
pub const SKATE_SPEED: f64 = 0.1;

/// Thresholds of the verdict ([`Fidelity::healthy`], [`Fidelity::failures`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FidelityLimits {
    /// Largest mean keypoint error \[cm\].
    pub keypoint_cm: f64,
    /// Largest difference of the medians of knee flexion, elbow flexion and trunk lean \[deg\].
    pub posture_deg: f64,
    /// Largest median difference of the hip height \[cm\].
    pub hip_height_cm: f64,
    /// Largest slip over the person's contacts \[mm\].
    pub slip_mm: f64,
    /// Largest height of a sole over the person's contacts \[mm\].
    pub contact_height_mm: f64,
    /// Deepest a sole may go below the floor \[mm\].
    pub below_floor_mm: f64,
    /// Largest share of the ticks a foot skates \[–\].
    pub skate_share: f64,
    /// Largest share of the ticks whose change of q̈ reverses \[–\].
    pub reversal_share: f64,
    /// Largest tick-to-tick sign flip of a joint's q̈ \[rad/s²\].
    pub flip: f64,
}

impl Default for FidelityLimits {
    /// A person would call the run wrong beyond these: 12 cm mean error (a forearm's width
    /// past the person's pose on every point), 15° of posture (a visibly bent or leaning body
    /// the person does not have), 8 cm of hip height, 50 mm of slip (a visible skid), a foot
    /// 30 mm above the floor where the person's is down, 5 mm into the floor, 5 % of the
    /// time skating, 10 % of the ticks reversing q̈'s change (a servo hears the chatter), a
    /// 100 rad/s² flip of q̈ in one tick.
    fn default() -> Self {
        Self {
            keypoint_cm: 12.0,
            posture_deg: 15.0,
            hip_height_cm: 8.0,
            slip_mm: 50.0,
            contact_height_mm: 30.0,
            below_floor_mm: 5.0,
            skate_share: 0.05,
            reversal_share: 0.10,
            flip: 100.0,
        }
    }
}

/// Position error of one point \[cm\].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NeutralPointError {
    /// The point (`neck` for the middle of the shoulders).
    pub point: String,
    /// Mean over the ticks \[cm\].
    pub mean_cm: f64,
    /// Largest \[cm\].
    pub max_cm: f64,
}

/// One posture angle or height, the robot against the scaled person.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PostureFigure {
    /// `left_knee`, `right_knee`, `left_elbow`, `right_elbow` (flexion \[deg\]), `trunk_lean`
    /// \[deg\] or `hip_height` \[cm\].
    pub name: String,
    /// The person's median \[deg or cm\].
    pub person_median: f64,
    /// The robot's median \[deg or cm\].
    pub robot_median: f64,
    /// Median of robot − person per tick \[deg or cm\].
    pub difference_median: f64,
    /// 90th percentile of |robot − person| \[deg or cm\].
    pub difference_p90: f64,
}

/// The figures of the person's contact windows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactFigures {
    /// Contact windows over both feet.
    pub windows: usize,
    /// Share of the foot-ticks in a window \[–\].
    pub share: f64,
    /// Largest slip of the robot's ankle centre in a window \[mm\].
    pub slip_max_mm: f64,
    /// Mean over the windows of their slip \[mm\].
    pub slip_mean_mm: f64,
    /// Highest lowest sole corner in a window \[mm\].
    pub height_max_mm: f64,
    /// Lowest sole corner on any tick \[mm\] (negative: below the floor).
    pub lowest_sole_mm: f64,
    /// Share of the foot-ticks that skate \[–\].
    pub skate_share: f64,
    /// Horizontal distance skated, both feet \[m\].
    pub skate_distance_m: f64,
    /// The window of the largest slip (`None`: no window), to see where and whether the
    /// person's own foot moved there too.
    pub worst_slip: Option<SlipWindow>,
}

/// One contact window of the person's, where the robot's foot slipped most.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SlipWindow {
    /// `"left"` or `"right"`.
    pub foot: &'static str,
    /// Clip time of the window's first and last frame \[s\].
    pub start_s: f64,
    /// ... and last frame \[s\].
    pub end_s: f64,
    /// The robot ankle centre's slip there (the figure `slip_max_mm`) \[mm\].
    pub robot_mm: f64,
    /// The person's own ankle's slip over the window's frames, scaled to the robot by the
    /// legs' ratio (module documentation) \[mm\]: near `robot_mm` where the person's foot slid
    /// too, near 0 where only the robot's moved.
    pub person_mm: f64,
    /// Lowest and highest of the robot's lowest sole corner in the window \[mm\]: a sole well
    /// above the floor means the robot's foot was still (or already) in the air.
    pub sole_mm: [f64; 2],
}

/// Smoothness of the joints' commanded accelerations.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SmoothnessFigures {
    /// RMS jerk over joints and ticks \[rad/s³\].
    pub jerk_rms: f64,
    /// Largest jerk \[rad/s³\].
    pub jerk_max: f64,
    /// Share of the ticks whose change of q̈ reverses, over joints \[–\].
    pub reversal_share: f64,
    /// Largest sign flip of q̈ between two ticks \[rad/s²\].
    pub flip_max: f64,
}

/// The fidelity figures of one run (module documentation).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fidelity {
    /// Ticks measured.
    pub ticks: usize,
    /// The scale s \[–\].
    pub scale: f64,
    /// The fitted heading θ \[deg\].
    pub heading_deg: f64,
    /// Mean of the points' mean errors \[cm\].
    pub keypoint_mean_cm: f64,
    /// Per point.
    pub points: Vec<NeutralPointError>,
    /// Knees, elbows, trunk lean, hip height.
    pub posture: Vec<PostureFigure>,
    /// Over the person's contacts.
    pub contacts: ContactFigures,
    /// Of the joints' q̈.
    pub smoothness: SmoothnessFigures,
    /// Every failed check, in words (empty: healthy).
    pub failures: Vec<String>,
    /// No check failed.
    pub healthy: bool,
}

/// The robot's side of one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotSample {
    /// Joint centres in [`JOINT_CENTRES`] order \[m\], world.
    pub centres: [Vector3<f64>; 12],
    /// Per foot (left, right): the lowest sole corner's height \[m\].
    pub sole_lowest: [f64; 2],
    /// Per foot: the sole centre \[m\], world.
    pub sole_centre: [Vector3<f64>; 2],
}

/// What the figures are computed from.
#[derive(Debug, Clone, Copy)]
pub struct FidelityInput<'a> {
    /// The captured person.
    pub person: &'a Keypoints,
    /// Clip time of every tick \[s\].
    pub times: &'a [f64],
    /// The robot on every tick.
    pub robot: &'a [RobotSample],
    /// The robot's leg length hip→knee→ankle at q = 0, mean of both legs \[m\].
    pub robot_leg: f64,
    /// The joints' commanded q̈ on every tick (active joints) \[rad/s²\].
    pub qdd: &'a [Vec<f64>],
    /// Control period \[s\].
    pub dt: f64,
}

/// Index of a body point in [`JOINT_CENTRES`].
fn ix(p: BodyPoint) -> usize {
    JOINT_CENTRES.iter().position(|q| *q == p).unwrap_or(0)
}

/// The person's points at time `t`, in [`JOINT_CENTRES`] order, linearly interpolated
/// (`None`: a point missing).
fn person_at(kp: &Keypoints, t: f64) -> Option<[Vector3<f64>; 12]> {
    let n = kp.frame_count();
    if n == 0 {
        return None;
    }
    let i = kp.times.partition_point(|x| *x <= t);
    let (a, b, w) = if i == 0 {
        (0, 0, 0.0)
    } else if i >= n {
        (n - 1, n - 1, 0.0)
    } else {
        let (ta, tb) = (kp.times[i - 1], kp.times[i]);
        let w = if tb > ta { (t - ta) / (tb - ta) } else { 0.0 };
        (i - 1, i, w)
    };
    let mut out = [Vector3::zeros(); 12];
    for (o, p) in out.iter_mut().zip(JOINT_CENTRES) {
        let (pa, pb) = (kp.position(a, p)?, kp.position(b, p)?);
        *o = pa + (pb - pa) * w;
    }
    Some(out)
}

/// Leg length hip→knee→ankle, mean of both legs, of the points `x` (in [`JOINT_CENTRES`]
/// order) \[m\].
pub fn leg_length(x: &[Vector3<f64>; 12]) -> f64 {
    let side = |h: BodyPoint, k: BodyPoint, a: BodyPoint| {
        (x[ix(h)] - x[ix(k)]).norm() + (x[ix(k)] - x[ix(a)]).norm()
    };
    0.5 * (side(
        BodyPoint::LeftHip,
        BodyPoint::LeftKnee,
        BodyPoint::LeftAnkle,
    ) + side(
        BodyPoint::RightHip,
        BodyPoint::RightKnee,
        BodyPoint::RightAnkle,
    ))
}

fn hip_middle(x: &[Vector3<f64>; 12]) -> Vector3<f64> {
    0.5 * (x[ix(BodyPoint::LeftHip)] + x[ix(BodyPoint::RightHip)])
}

fn neck(x: &[Vector3<f64>; 12]) -> Vector3<f64> {
    0.5 * (x[ix(BodyPoint::LeftShoulder)] + x[ix(BodyPoint::RightShoulder)])
}

/// The thirteen points (twelve centres and the neck) relative to the hip middle.
fn relative(x: &[Vector3<f64>; 12]) -> [Vector3<f64>; 13] {
    let m = hip_middle(x);
    let mut out = [Vector3::zeros(); 13];
    for (o, p) in out.iter_mut().zip(x) {
        *o = p - m;
    }
    out[12] = neck(x) - m;
    out
}

/// Flexion at `b` of the chain a–b–c \[deg\]: 0 straight.
fn flexion(a: Vector3<f64>, b: Vector3<f64>, c: Vector3<f64>) -> f64 {
    let (u, v) = (a - b, c - b);
    let cos = u.dot(&v) / (u.norm() * v.norm()).max(f64::MIN_POSITIVE);
    180.0 - cos.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Posture measures of one body: left/right knee, left/right elbow flexion \[deg\], trunk
/// lean \[deg\], hip height above the ankles \[m\].
fn posture(x: &[Vector3<f64>; 12]) -> [f64; 6] {
    use BodyPoint as B;
    let p = |b| x[ix(b)];
    let m = hip_middle(x);
    let up = neck(x) - m;
    let lean = (up.z / up.norm().max(f64::MIN_POSITIVE))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    let ankles = 0.5 * (p(B::LeftAnkle).z + p(B::RightAnkle).z);
    [
        flexion(p(B::LeftHip), p(B::LeftKnee), p(B::LeftAnkle)),
        flexion(p(B::RightHip), p(B::RightKnee), p(B::RightAnkle)),
        flexion(p(B::LeftShoulder), p(B::LeftElbow), p(B::LeftWrist)),
        flexion(p(B::RightShoulder), p(B::RightElbow), p(B::RightWrist)),
        lean,
        m.z - ankles,
    ]
}

/// The person's contact windows per foot (left, right) on their frames: inclusive ranges of
/// frames (module documentation).
pub fn person_contacts(kp: &Keypoints) -> [Vec<(usize, usize)>; 2] {
    let mut out = [Vec::new(), Vec::new()];
    for (side, ankle) in [BodyPoint::LeftAnkle, BodyPoint::RightAnkle]
        .into_iter()
        .enumerate()
    {
        let n = kp.frame_count();
        let pos: Vec<Vector3<f64>> = (0..n).filter_map(|f| kp.position(f, ankle)).collect();
        if pos.len() != n || n < 2 {
            continue;
        }
        let lowest = pos.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        let down: Vec<bool> = (0..n)
            .map(|f| {
                let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
                let dt = kp.times[b] - kp.times[a];
                let speed = if dt > 0.0 {
                    (pos[b] - pos[a]).xy().norm() / dt
                } else {
                    0.0
                };
                pos[f].z - lowest <= CONTACT_HEIGHT && speed < CONTACT_SPEED
            })
            .collect();
        let mut f = 0;
        while f < n {
            if down[f] {
                let start = f;
                while f + 1 < n && down[f + 1] {
                    f += 1;
                }
                if f > start {
                    out[side].push((start, f));
                }
            }
            f += 1;
        }
    }
    out
}

/// The fidelity figures of `input` against `limits` (module documentation).
pub fn fidelity(input: &FidelityInput, limits: &FidelityLimits) -> Fidelity {
    let kp = input.person;
    let scale = person_scale(input);
    let persons: Vec<Option<[Vector3<f64>; 12]>> =
        input.times.iter().map(|t| person_at(kp, *t)).collect();
    let heading = fit_heading(input, &persons, scale);
    let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), heading);
    let names: Vec<String> = JOINT_CENTRES
        .iter()
        .map(|p| p.name().to_string())
        .chain(["neck".to_string()])
        .collect();
    let mut sums = [(0.0, 0.0_f64); 13];
    let mut measured = 0usize;
    let mut post: [Vec<(f64, f64)>; 6] = Default::default();
    for (r, p) in input.robot.iter().zip(&persons) {
        let Some(p) = p else { continue };
        measured += 1;
        for ((s, d), b) in sums.iter_mut().zip(relative(p)).zip(relative(&r.centres)) {
            let e = (b - rot * (scale * d)).norm();
            s.0 += e;
            s.1 = s.1.max(e);
        }
        let (pp, rp) = (posture(p), posture(&r.centres));
        for (i, v) in post.iter_mut().enumerate() {
            let person = if i == 5 { scale * pp[i] } else { pp[i] };
            v.push((person, rp[i]));
        }
    }
    let n = measured.max(1) as f64;
    let points: Vec<NeutralPointError> = names
        .iter()
        .zip(sums)
        .map(|(name, (s, m))| NeutralPointError {
            point: name.clone(),
            mean_cm: 100.0 * s / n,
            max_cm: 100.0 * m,
        })
        .collect();
    let keypoint_mean_cm = points.iter().map(|p| p.mean_cm).sum::<f64>() / points.len() as f64;
    let posture = posture_figures(&post);
    let contacts = contact_figures(input, scale);
    let smoothness = smoothness(input.qdd, input.dt);
    let mut f = Fidelity {
        ticks: measured,
        scale,
        heading_deg: heading.to_degrees(),
        keypoint_mean_cm,
        points,
        posture,
        contacts,
        smoothness,
        failures: Vec::new(),
        healthy: true,
    };
    f.failures = verdict(&f, limits);
    f.healthy = f.failures.is_empty();
    f
}

/// The scale of the person onto the robot \[–\]: the robot's leg over the median of the
/// person's (1 without a person's leg).
fn person_scale(input: &FidelityInput) -> f64 {
    let kp = input.person;
    let person_leg = {
        let mut legs: Vec<f64> = (0..kp.frame_count())
            .filter_map(|f| person_at(kp, kp.times[f]))
            .map(|x| leg_length(&x))
            .collect();
        legs.retain(|l| l.is_finite());
        percentile(&legs, 0.5)
    };
    if person_leg > 0.0 {
        input.robot_leg / person_leg
    } else {
        1.0
    }
}

/// The heading fit \[rad\] over every point and tick of the scaled person `persons` (per
/// tick) onto the robot's joint centres.
fn fit_heading(input: &FidelityInput, persons: &[Option<[Vector3<f64>; 12]>], scale: f64) -> f64 {
    let (mut cross, mut dot) = (0.0, 0.0);
    for (r, p) in input.robot.iter().zip(persons) {
        let Some(p) = p else { continue };
        for (d, b) in relative(p).iter().zip(relative(&r.centres)) {
            cross += scale * (d.x * b.y - d.y * b.x);
            dot += scale * (d.x * b.x + d.y * b.y);
        }
    }
    cross.atan2(dot)
}

/// The posture figures from the (person, robot) values per tick of the knees, elbows \[°\],
/// trunk lean \[°\] and hip height \[m\] (in cm in the figures).
fn posture_figures(post: &[Vec<(f64, f64)>; 6]) -> Vec<PostureFigure> {
    let posture_names = [
        "left_knee",
        "right_knee",
        "left_elbow",
        "right_elbow",
        "trunk_lean",
        "hip_height",
    ];
    posture_names
        .iter()
        .zip(post)
        .enumerate()
        .map(|(i, (name, v))| {
            let unit = if i == 5 { 100.0 } else { 1.0 };
            let person: Vec<f64> = v.iter().map(|x| unit * x.0).collect();
            let robot: Vec<f64> = v.iter().map(|x| unit * x.1).collect();
            let diff: Vec<f64> = v.iter().map(|x| unit * (x.1 - x.0)).collect();
            let abs: Vec<f64> = diff.iter().map(|d| d.abs()).collect();
            PostureFigure {
                name: (*name).into(),
                person_median: percentile(&person, 0.5),
                robot_median: percentile(&robot, 0.5),
                difference_median: percentile(&diff, 0.5),
                difference_p90: percentile(&abs, 0.9),
            }
        })
        .collect()
}

/// The contact figures of `input` (module documentation).
fn contact_figures(input: &FidelityInput, scale: f64) -> ContactFigures {
    let kp = input.person;
    let windows = person_contacts(kp);
    let ticks = input.robot.len();
    let mut in_window = [vec![false; ticks], vec![false; ticks]];
    let (mut count, mut slip_max, mut slip_sum, mut height_max) =
        (0usize, 0.0_f64, 0.0, f64::NEG_INFINITY);
    let mut worst: Option<SlipWindow> = None;
    for (side, ws) in windows.iter().enumerate() {
        for &(a, b) in ws {
            let (ta, tb) = (kp.times[a], kp.times[b]);
            let ks: Vec<usize> = (0..ticks)
                .filter(|k| input.times[*k] >= ta && input.times[*k] <= tb)
                .collect();
            if ks.is_empty() {
                continue;
            }
            count += 1;
            let ankle = ix(if side == 0 {
                BodyPoint::LeftAnkle
            } else {
                BodyPoint::RightAnkle
            });
            let mut slip = 0.0_f64;
            for (i, &k) in ks.iter().enumerate() {
                in_window[side][k] = true;
                height_max = height_max.max(input.robot[k].sole_lowest[side]);
                let x = input.robot[k].centres[ankle].xy();
                for &j in &ks[i + 1..] {
                    slip = slip.max((input.robot[j].centres[ankle].xy() - x).norm());
                }
            }
            if worst.as_ref().is_none_or(|w| 1000.0 * slip > w.robot_mm) {
                let person: Vec<Vector3<f64>> = (a..=b)
                    .filter_map(|f| kp.position(f, JOINT_CENTRES[ankle]))
                    .collect();
                let soles = ks.iter().map(|k| input.robot[*k].sole_lowest[side]);
                worst = Some(SlipWindow {
                    foot: if side == 0 { "left" } else { "right" },
                    start_s: ta,
                    end_s: tb,
                    robot_mm: 1000.0 * slip,
                    person_mm: 1000.0 * scale * horizontal_diameter(&person),
                    sole_mm: [
                        1000.0 * soles.clone().fold(f64::INFINITY, f64::min),
                        1000.0 * soles.fold(f64::NEG_INFINITY, f64::max),
                    ],
                });
            }
            slip_max = slip_max.max(slip);
            slip_sum += slip;
        }
    }
    let (lowest, skate, distance) = skating(input);
    let foot_ticks = (2 * ticks).max(1) as f64;
    let held = in_window.iter().flatten().filter(|b| **b).count();
    ContactFigures {
        windows: count,
        share: held as f64 / foot_ticks,
        slip_max_mm: 1000.0 * slip_max,
        slip_mean_mm: 1000.0 * slip_sum / count.max(1) as f64,
        height_max_mm: if count > 0 { 1000.0 * height_max } else { 0.0 },
        lowest_sole_mm: if ticks > 0 { 1000.0 * lowest } else { 0.0 },
        skate_share: skate as f64 / foot_ticks,
        skate_distance_m: distance,
        worst_slip: worst,
    }
}

/// The lowest sole over the run \[m\], and the foot ticks that skate (a sole within
/// `SKATE_HEIGHT` of the ground moving faster than `SKATE_SPEED`) with the distance \[m\] they
/// cover.
fn skating(input: &FidelityInput) -> (f64, usize, f64) {
    let mut lowest = f64::INFINITY;
    let (mut skate, mut distance) = (0usize, 0.0);
    for (k, r) in input.robot.iter().enumerate() {
        for side in 0..2 {
            lowest = lowest.min(r.sole_lowest[side]);
            if k > 0 && r.sole_lowest[side] <= SKATE_HEIGHT {
                let step = (r.sole_centre[side] - input.robot[k - 1].sole_centre[side])
                    .xy()
                    .norm();
                if step > SKATE_SPEED * input.dt {
                    skate += 1;
                    distance += step;
                }
            }
        }
    }
    (lowest, skate, distance)
}

/// The largest horizontal distance between two of `points` \[m\] (0 for fewer than two).
fn horizontal_diameter(points: &[Vector3<f64>]) -> f64 {
    let mut d = 0.0_f64;
    for (i, p) in points.iter().enumerate() {
        for q in &points[i + 1..] {
            d = d.max((p - q).xy().norm());
        }
    }
    d
}

/// Smoothness of the per-tick joint accelerations `qdd` (rows: ticks; columns: joints).
fn smoothness(qdd: &[Vec<f64>], dt: f64) -> SmoothnessFigures {
    let joints = qdd.first().map_or(0, Vec::len);
    let (mut sum_sq, mut steps, mut jerk_max, mut rev, mut rev_n, mut flip) =
        (0.0, 0usize, 0.0_f64, 0.0, 0usize, 0.0_f64);
    for j in 0..joints {
        let col: Vec<f64> = qdd
            .iter()
            .map(|r| r.get(j).copied().unwrap_or(0.0))
            .collect();
        let s = DofSmoothness::of(&col, dt);
        let n = col.len().saturating_sub(1);
        sum_sq += s.rms_jerk * s.rms_jerk * n as f64;
        steps += n;
        jerk_max = jerk_max.max(s.max_jerk);
        let m = col.len().saturating_sub(2);
        rev += s.reversal_share * m as f64;
        rev_n += m;
        for w in col.windows(2) {
            if w[0] * w[1] < 0.0 {
                flip = flip.max(w[0].abs().min(w[1].abs()));
            }
        }
    }
    SmoothnessFigures {
        jerk_rms: (sum_sq / steps.max(1) as f64).sqrt(),
        jerk_max,
        reversal_share: rev / rev_n.max(1) as f64,
        flip_max: flip,
    }
}

/// The failed checks of `f` against `l`, in words.
fn verdict(f: &Fidelity, l: &FidelityLimits) -> Vec<String> {
    let mut out = Vec::new();
    if f.ticks == 0 {
        out.push("no tick could be compared with the person (a body point missing)".into());
        return out;
    }
    if exceeds(f.keypoint_mean_cm, l.keypoint_cm) {
        out.push(format!(
            "mean keypoint error {:.1} cm > {} cm",
            f.keypoint_mean_cm, l.keypoint_cm
        ));
    }
    posture_failures(f, l, &mut out);
    let checks = contact_and_smoothness_checks(f, l);
    out.extend(checks.into_iter().filter(|(ok, _)| !ok).map(|(_, m)| m));
    out
}

/// The posture figures whose medians are further apart than `l` allows, as messages onto `out`.
fn posture_failures(f: &Fidelity, l: &FidelityLimits, out: &mut Vec<String>) {
    for p in &f.posture {
        let gap = p.robot_median - p.person_median;
        let (limit, unit) = if p.name == "hip_height" {
            (l.hip_height_cm, "cm")
        } else {
            (l.posture_deg, "°")
        };
        if exceeds(gap.abs(), limit) {
            out.push(format!(
                "{}: robot median {:.1}{unit} against the person's {:.1}{unit} (more than {limit}{unit} apart)",
                p.name, p.robot_median, p.person_median
            ));
        }
    }
}

/// The contact and smoothness checks of `f` against `l`: whether each passes, and its message.
fn contact_and_smoothness_checks(f: &Fidelity, l: &FidelityLimits) -> [(bool, String); 6] {
    let c = &f.contacts;
    [
        (
            !exceeds(c.slip_max_mm, l.slip_mm),
            format!(
                "foot slip over the person's contacts {:.0} mm > {} mm{}",
                c.slip_max_mm,
                l.slip_mm,
                c.worst_slip.as_ref().map_or(String::new(), |w| format!(
                    " ({} foot, {:.2}–{:.2} s; the person's ankle {:.0} mm there, scaled; the \
                     robot's sole {:.0} to {:.0} mm up)",
                    w.foot, w.start_s, w.end_s, w.person_mm, w.sole_mm[0], w.sole_mm[1]
                ))
            ),
        ),
        (
            !exceeds(c.height_max_mm, l.contact_height_mm),
            format!(
                "a sole {:.0} mm above the floor where the person's foot is down (> {} mm)",
                c.height_max_mm, l.contact_height_mm
            ),
        ),
        (
            !exceeds(-c.lowest_sole_mm, l.below_floor_mm),
            format!(
                "a sole {:.1} mm below the floor (> {} mm)",
                -c.lowest_sole_mm, l.below_floor_mm
            ),
        ),
        (
            !exceeds(c.skate_share, l.skate_share),
            format!(
                "feet skate on {:.1} % of the ticks (> {:.0} %)",
                100.0 * c.skate_share,
                100.0 * l.skate_share
            ),
        ),
        (
            !exceeds(f.smoothness.reversal_share, l.reversal_share),
            format!(
                "q̈'s change reverses on {:.1} % of the ticks (> {:.0} %)",
                100.0 * f.smoothness.reversal_share,
                100.0 * l.reversal_share
            ),
        ),
        (
            !exceeds(f.smoothness.flip_max, l.flip),
            format!(
                "a joint's q̈ flips sign by {:.0} rad/s² in one tick (> {} rad/s²)",
                f.smoothness.flip_max, l.flip
            ),
        ),
    ]
}

/// Whether `x` is above `limit` or not a number (a figure that cannot be computed fails).
fn exceeds(x: f64, limit: f64) -> bool {
    x.is_nan() || x > limit
}

/// The robot's side of every tick of `trajectory` (configurations q, one per tick): joint
/// centres and the soles of `feet` (left, right) as `support` describes them. Errors: a
/// configuration of the wrong length or not finite.
pub fn robot_samples(
    robot: &Robot,
    centres: &RobotJointCentres,
    feet: [FrameId; 2],
    support: &SupportSettings,
    trajectory: &[Vec<f64>],
) -> Result<Vec<RobotSample>> {
    let mut state = State::neutral(robot);
    let mut kin = Kinematics::new(robot, &state)?;
    let mut out = Vec::with_capacity(trajectory.len());
    let (hl, hw) = (0.5 * support.sole_length, 0.5 * support.sole_width);
    for q in trajectory {
        if q.len() != robot.nq() {
            return Err(Error::DimensionMismatch {
                what: "a trajectory's configuration".into(),
                expected: robot.nq(),
                got: q.len(),
            });
        }
        state.q.copy_from_slice(q);
        kin.update(robot, &state)?;
        let mut sample = RobotSample {
            centres: centres.at(&kin)?,
            sole_lowest: [f64::INFINITY; 2],
            sole_centre: [Vector3::zeros(); 2],
        };
        for (i, f) in feet.iter().enumerate() {
            let foot = kin.frame_pose(robot, *f)?;
            for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                let c = foot
                    * Point3::new(
                        support.sole_offset_x + sx * hl,
                        sy * hw,
                        -support.ankle_height,
                    );
                sample.sole_lowest[i] = sample.sole_lowest[i].min(c.z);
            }
            sample.sole_centre[i] =
                (foot * Point3::new(support.sole_offset_x, 0.0, -support.ankle_height)).coords;
        }
        out.push(sample);
    }
    Ok(out)
}

/// The robot's leg length hip→knee→ankle at q = 0 (its neutral state), mean of both legs
/// \[m\] ([`leg_length`] of its joint centres).
pub fn robot_leg(robot: &Robot, centres: &RobotJointCentres) -> Result<f64> {
    let kin = Kinematics::new(robot, &State::neutral(robot))?;
    Ok(leg_length(&centres.at(&kin)?))
}

#[cfg(test)]
#[path = "fidelity_tests.rs"]
mod tests;
