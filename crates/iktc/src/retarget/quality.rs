//! Quality figures of a retargeted motion, the same for the keypoint route and the joint route.
//!
//! Per tick `k` of the clip (after any settling), from the robot's state:
//! * position error of each body point the robot has: `|x_k − (x_m,k + s_leg (a(p_k) −
//!   a(m_k)))|` \[m\], the human point scaled by the leg ratio and placed at the middle of the
//!   robot's hips (`m` the middle of the human hips, `x_m` of the robot's; the aligned clip
//!   `a`, [`super::scale`]); mean and max per point, reported in cm. The hip joint centres are
//!   the landmarks of the pelvis both bodies have, where a rig's root and a robot's pelvis
//!   frame differ (DeepMimic's root is at its hips, CMU's above them, G1's pelvis frame 10 cm
//!   above its hips, JVRC-1's at them): aligned at those, G1's hips missed the clip's by a
//!   rigid 10.3 cm on the DeepMimic clips, which no motion of the robot changes. The pelvis
//!   point is the alignment point, the middle of the hips on both bodies: its error is 0 by
//!   construction and it counts in the mean as such (its placement is measured by the hips,
//!   its orientation below);
//! * orientation error of the pelvis and the torso frames against the references built from the
//!   points ([`super::plan`]): the angle of `R_ref R_robotᵀ` \[rad\], mean and max, in degrees;
//! * stance-foot slip: for each stance run of a foot (on the keypoint route the robot's stance,
//!   from the foot's landing to the clip's lift-off; on the joint route the clip's contacts), the
//!   largest horizontal distance of the sole centre from where it was at the run's first tick
//!   \[m\], in mm;
//! * foot below the ground: the largest depth below z = 0 of any sole corner \[m\], in mm;
//! * foot floating: over the ticks on which the clip has a foot on the ground, the largest
//!   height of that foot's lowest sole corner above z = 0, in mm, and the share of those
//!   foot-ticks on which it is above [`FLOAT_HEIGHT`];
//! * optionally, the static reach of the body points ([`super::reach`]);
//! * joint jerk `(q̈_k − q̈_{k−1}) / Δt` of the active joints \[rad/s³\]: RMS over joints and
//!   ticks, and max ([`DofSmoothness`]); and the share of its square summed over joints and
//!   ticks that falls on the ticks where the joint limits shaped the command: tick k counts
//!   when the solver corrected the prioritized solution into the box on tick k or k − 1
//!   (IKTC's correction began, went on, moved to another level or ended there);
//! * the worst limit margins ([`dof_margins`]): positive means a limit was exceeded.

use nalgebra::{Point3, UnitQuaternion, Vector3};
use serde::Serialize;

use super::body::RobotBody;
use super::plan::Plan;
use crate::error::Result;
use crate::model::{Kinematics, Robot, State};
use crate::motion::BodyPoint;
use crate::sim::imitate::SupportSettings;
use crate::sim::{dof_margins, DofSmoothness};

/// Position error of one body point \[cm\].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointError {
    /// The body point.
    pub point: String,
    /// Mean over the ticks \[cm\].
    pub mean_cm: f64,
    /// Largest \[cm\].
    pub max_cm: f64,
}

/// Orientation error of one frame \[deg\].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationError {
    /// `pelvis` or `torso`.
    pub frame: String,
    /// Mean over the ticks \[deg\].
    pub mean_deg: f64,
    /// Largest \[deg\].
    pub max_deg: f64,
}

/// A joint counts as on a position limit in [`RetargetQuality::on_limit`] within this of it
/// \[rad\] or \[m\] (1 mrad, 0.06°): the viable bounds bring a joint to its limit along a
/// braking curve, so it spends ticks a hair's breadth short of it rather than exactly on it.
pub const LIMIT_BAND: f64 = 1e-3;

/// A joint that spends ticks on one of its position limits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointOnLimit {
    /// The joint's name.
    pub joint: String,
    /// Share of the ticks on which its position is within [`LIMIT_BAND`] of its lower or upper
    /// limit \[–\].
    pub share: f64,
}

/// A foot the clip has on the ground counts as floating in [`RetargetQuality::float_share`] when
/// its lowest sole corner is higher than this above the ground \[m\] (1 cm: ten times the
/// landing rule's rounding, half its `land_height`).
pub const FLOAT_HEIGHT: f64 = 0.01;

/// The quality figures of one run (see the module documentation).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RetargetQuality {
    /// `keypoints` or `joints`.
    pub route: String,
    /// Ticks measured.
    pub ticks: usize,
    /// Per body point, in [`BodyPoint::ALL`] order.
    pub points: Vec<PointError>,
    /// Mean of the per-point means \[cm\].
    pub mean_cm: f64,
    /// Orientation errors.
    pub orientations: Vec<OrientationError>,
    /// Largest stance-foot slip \[mm\].
    pub slip_mm: f64,
    /// Deepest sole corner below the ground \[mm\] (0 if never below).
    pub below_ground_mm: f64,
    /// Highest a foot floats while the clip has it on the ground: the largest height of its
    /// lowest sole corner above z = 0 over the clip's foot-contact ticks \[mm\] (0 if it never
    /// rises; a foot the robot cannot bring down, or does not land, shows here).
    pub float_mm: f64,
    /// Share of the clip's foot-contact ticks (per foot) on which the foot's lowest sole corner
    /// is more than [`FLOAT_HEIGHT`] above the ground \[–\].
    pub float_share: f64,
    /// Ticks with at least one foot on the ground (per the clip's contacts).
    pub stance_ticks: usize,
    /// RMS joint jerk \[rad/s³\].
    pub jerk_rms: f64,
    /// Largest joint jerk \[rad/s³\].
    pub jerk_max: f64,
    /// Share of the squared joint jerk (summed over the active joints and ticks) on the ticks
    /// where the box shaped the command: a tick on which the solver corrected the prioritized
    /// solution, or the tick after one (where the correction ends) \[–\]; 0 without jerk or
    /// without a corrected tick. Near 1 with the
    /// viable or quiet bounds alone, the jerk is the joint limits' (the soft approach to the
    /// range ends smooths it, and then shapes most ticks itself); near 0, the references' or
    /// the contacts'.
    pub jerk_limit_share: f64,
    /// Worst position margin \[rad\] (positive: a limit exceeded by that much).
    pub position_margin: f64,
    /// Worst velocity margin \[rad/s\].
    pub velocity_margin: f64,
    /// Worst acceleration margin \[rad/s²\].
    pub acceleration_margin: f64,
    /// The joints on a position limit on at least one tick, the most often first (ties in the
    /// robot's joint order). A joint that rides its limit through much of a clip is where the
    /// robot's body stops following the captured one, and a long stay on a limit of a leg's yaw
    /// or roll is a leg on a branch the person's was not.
    pub on_limit: Vec<JointOnLimit>,
    /// The static reach, where asked for ([`super::KeypointSettings::reach`]): the least mean
    /// body point error found per tick by a posture within the joint ranges alone, averaged
    /// over the ticks sampled every 0.05 s \[cm\] ([`super::reach`]). The robot's
    /// body cannot do better than about this; the rest of [`RetargetQuality::mean_cm`] is what
    /// the retargeting gives up for its feet, balance and smoothness.
    pub reach_cm: Option<f64>,
    /// The balanced reach, where asked for with the static reach: the same descent keeping
    /// the feet the clip has on the ground where the run has them and the COM over their
    /// soles, averaged over the same ticks \[cm\] ([`super::reach`], balanced reach). The rest
    /// of [`RetargetQuality::mean_cm`] is what the run gives up to its rates, priorities and
    /// references.
    pub balanced_reach_cm: Option<f64>,
    /// How far the robot's body can take the person's shape: the angle between the person's
    /// segment directions and the fitted posture's, root mean square over the fit's samples
    /// and segments \[°\] ([`super::fit`]); `None` where the posture was not fitted (a joint
    /// map's references, standing imitation, [`super::KeypointSettings::posture_fit`] off).
    pub posture_fit_deg: Option<f64>,
    /// The run's own mean body point error over the same sampled ticks \[cm\], beside
    /// [`RetargetQuality::reach_cm`].
    pub reach_run_cm: Option<f64>,
    /// The neutral figures: the robot's joint centres against the captured person, contacts
    /// from the person, posture, smoothness and the verdict ([`super::fidelity`]). `None`
    /// only from [`QualityRecorder::finish`] alone; every route fills it.
    pub fidelity: Option<super::Fidelity>,
}

/// Records the ticks of a run and gives its [`RetargetQuality`]. Allocates during `record`
/// (it keeps the trajectory); not for the control loop's hot path.
#[derive(Debug, Clone)]
pub struct QualityRecorder {
    route: String,
    dt: f64,
    sums: Vec<(BodyPoint, f64, f64)>,
    orient: [(f64, f64); 2],
    slip: f64,
    below: f64,
    /// Highest lowest-corner over contact ticks \[m\], contact foot-ticks, floating ones.
    float: (f64, usize, usize),
    stance_start: [Option<Vector3<f64>>; 2],
    stance_ticks: usize,
    ticks: usize,
    q: Vec<Vec<f64>>,
    qd: Vec<Vec<f64>>,
    qdd: Vec<Vec<f64>>,
    /// Per recorded tick: whether the solver corrected it into the box.
    corrected: Vec<bool>,
    pos: Vec<f64>,
}

impl QualityRecorder {
    pub(crate) fn new(route: &str, body: &RobotBody, dt: f64) -> Self {
        Self {
            route: route.into(),
            dt,
            sums: body.points.iter().map(|(p, _)| (*p, 0.0, 0.0)).collect(),
            orient: [(0.0, 0.0); 2],
            slip: 0.0,
            below: 0.0,
            float: (0.0, 0, 0),
            stance_start: [None, None],
            stance_ticks: 0,
            ticks: 0,
            q: Vec::new(),
            qd: Vec::new(),
            qdd: Vec::new(),
            corrected: Vec::new(),
            pos: Vec::new(),
        }
    }

    /// Records tick `k` of `plan`: the state at its start (`kin` updated at it) and the q̈ applied
    /// over it; `stance` says which feet are held on the ground (for the slip), `corrected`
    /// whether the solver corrected the tick into the box (IKTC's correction, or a fallback that
    /// answered instead of the prioritized solution; for [`RetargetQuality::jerk_limit_share`]).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record(
        &mut self,
        robot: &Robot,
        kin: &Kinematics,
        body: &RobotBody,
        plan: &Plan,
        support: &SupportSettings,
        (k, stance, corrected): (usize, [bool; 2], bool),
        state: &State,
        qdd: &[f64],
    ) -> Result<()> {
        let pelvis = kin.frame_pose(robot, body.pelvis)?;
        let hips = body.hips_middle(robot, kin)?;
        for ((p, sum, max), (f_p, f)) in self.sums.iter_mut().zip(&body.points) {
            debug_assert_eq!(p, f_p);
            let Some((_, rel)) = plan.neutral[k].iter().find(|(q, _)| q == p) else {
                continue;
            };
            let x = match p {
                BodyPoint::Pelvis => hips,
                _ => kin.frame_pose(robot, *f)?.translation.vector,
            };
            let e = (x - (hips + rel)).norm();
            *sum += e;
            *max = max.max(e);
        }
        let angle = |a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>| (a * b.inverse()).angle();
        let e = angle(&plan.pelvis[k].rotation, &pelvis.rotation);
        self.orient[0] = (self.orient[0].0 + e, self.orient[0].1.max(e));
        if let Some(t) = body.torso {
            let r = kin.frame_pose(robot, t)?.rotation;
            let e = angle(&plan.torso[k].rotation, &r);
            self.orient[1] = (self.orient[1].0 + e, self.orient[1].1.max(e));
        }
        let mut any = false;
        for (i, (held, f)) in stance.iter().zip(body.feet).enumerate() {
            let foot = kin.frame_pose(robot, f)?;
            let (hl, hw) = (0.5 * support.sole_length, 0.5 * support.sole_width);
            let mut lowest = f64::INFINITY;
            for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                let c = foot
                    * Point3::new(
                        support.sole_offset_x + sx * hl,
                        sy * hw,
                        -support.ankle_height,
                    );
                self.below = self.below.max(-c.z);
                lowest = lowest.min(c.z);
            }
            if plan.contact[i].get(k).copied().unwrap_or(false) {
                self.float.0 = self.float.0.max(lowest);
                self.float.1 += 1;
                self.float.2 += usize::from(lowest > FLOAT_HEIGHT);
            }
            let centre =
                (foot * Point3::new(support.sole_offset_x, 0.0, -support.ankle_height)).coords;
            if *held {
                any = true;
                let start = *self.stance_start[i].get_or_insert(centre);
                let d = (centre - start).xy().norm();
                self.slip = self.slip.max(d);
            } else {
                self.stance_start[i] = None;
            }
        }
        if any {
            self.stance_ticks += 1;
        }
        self.pos.resize(robot.nv(), 0.0);
        state.dof_positions(robot, &mut self.pos)?;
        let b = robot.base_nv();
        self.q.push(self.pos[b..].to_vec());
        self.qd.push(state.qd.as_slice()[b..].to_vec());
        self.qdd.push(qdd[b..].to_vec());
        self.corrected.push(corrected);
        self.ticks += 1;
        Ok(())
    }

    /// The figures of the ticks recorded.
    pub fn finish(&self, robot: &Robot) -> RetargetQuality {
        let n = self.ticks.max(1) as f64;
        let points: Vec<PointError> = self
            .sums
            .iter()
            .map(|(p, s, m)| PointError {
                point: p.name().into(),
                mean_cm: 100.0 * s / n,
                max_cm: 100.0 * m,
            })
            .collect();
        let mean_cm = points.iter().map(|p| p.mean_cm).sum::<f64>() / points.len().max(1) as f64;
        let orientations = self.orientation_errors(n);
        let JointFigures {
            sum_sq,
            count,
            jerk_max,
            pm,
            vm,
            am,
            on_limit,
        } = self.joint_figures(robot);
        RetargetQuality {
            route: self.route.clone(),
            ticks: self.ticks,
            points,
            mean_cm,
            orientations,
            slip_mm: 1000.0 * self.slip,
            below_ground_mm: 1000.0 * self.below.max(0.0),
            float_mm: 1000.0 * self.float.0,
            float_share: self.float.2 as f64 / self.float.1.max(1) as f64,
            stance_ticks: self.stance_ticks,
            jerk_rms: (sum_sq / count.max(1) as f64).sqrt(),
            jerk_max,
            jerk_limit_share: jerk_limit_share(&self.qdd, &self.corrected),
            position_margin: pm,
            velocity_margin: vm,
            acceleration_margin: am,
            on_limit,
            reach_cm: None,
            balanced_reach_cm: None,
            posture_fit_deg: None,
            reach_run_cm: None,
            fidelity: None,
        }
    }

    /// The pelvis' orientation error, and the torso's where one was recorded, over `n` ticks.
    fn orientation_errors(&self, n: f64) -> Vec<OrientationError> {
        let mut orientations = vec![OrientationError {
            frame: "pelvis".into(),
            mean_deg: self.orient[0].0 / n * 180.0 / std::f64::consts::PI,
            max_deg: self.orient[0].1.to_degrees(),
        }];
        if self.orient[1] != (0.0, 0.0) {
            orientations.push(OrientationError {
                frame: "torso".into(),
                mean_deg: self.orient[1].0 / n * 180.0 / std::f64::consts::PI,
                max_deg: self.orient[1].1.to_degrees(),
            });
        }
        orientations
    }

    /// The jerk, margin and on-limit figures of every active joint of `robot`.
    fn joint_figures(&self, robot: &Robot) -> JointFigures {
        let joints = robot.n_active();
        let (mut sum_sq, mut count, mut jerk_max) = (0.0, 0usize, 0.0_f64);
        let (mut pm, mut vm, mut am) = (f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        let mut on_limit = Vec::new();
        for (j, joint) in robot.active_joints().enumerate().take(joints) {
            let col = |rows: &[Vec<f64>]| -> Vec<f64> {
                rows.iter()
                    .map(|r| r.get(j).copied().unwrap_or(0.0))
                    .collect()
            };
            let (q, qd, qdd) = (col(&self.q), col(&self.qd), col(&self.qdd));
            let sm = DofSmoothness::of(&qdd, self.dt);
            let steps = qdd.len().saturating_sub(1);
            sum_sq += sm.rms_jerk * sm.rms_jerk * steps as f64;
            count += steps;
            jerk_max = jerk_max.max(sm.max_jerk);
            let (lo, hi) = (joint.limit.lower, joint.limit.upper);
            let on = q
                .iter()
                .filter(|x| **x <= lo + LIMIT_BAND || **x >= hi - LIMIT_BAND)
                .count();
            if on > 0 {
                on_limit.push(JointOnLimit {
                    joint: joint.name.clone(),
                    share: on as f64 / q.len().max(1) as f64,
                });
            }
            let m = dof_margins(j, &q, &qd, &qdd, self.dt, &joint.limit);
            pm = pm.max(m.position);
            vm = vm.max(m.velocity);
            am = am.max(m.acceleration);
        }
        // Stable: ties keep the robot's joint order.
        on_limit.sort_by(|a, b| b.share.total_cmp(&a.share));
        JointFigures {
            sum_sq,
            count,
            jerk_max,
            pm,
            vm,
            am,
            on_limit,
        }
    }
}

/// The joints' figures of a run ([`QualityRecorder::finish`]).
struct JointFigures {
    /// The sum over the joints of the squared RMS jerk times the joint's steps \[rad²/s⁶\].
    sum_sq: f64,
    /// The steps summed over the joints.
    count: usize,
    /// The largest jerk \[rad/s³\].
    jerk_max: f64,
    /// The largest position, velocity and acceleration margins over the joints.
    pm: f64,
    vm: f64,
    am: f64,
    /// The joints that were within [`LIMIT_BAND`] of a limit, most of the time first.
    on_limit: Vec<JointOnLimit>,
}

/// [`RetargetQuality::jerk_limit_share`] of the joint accelerations `qdd` (one row per tick,
/// the active joints \[rad/s²\]), with `corrected[k]` whether tick k was corrected into the box
/// (missing entries: not corrected): the squared jerk of the steps k − 1 → k on which tick k
/// or k − 1 was corrected, over the squared jerk of every step. The period cancels in the
/// ratio: the squared changes of q̈ stand for the squared jerks.
pub(crate) fn jerk_limit_share(qdd: &[Vec<f64>], corrected: &[bool]) -> f64 {
    let at = |k: usize| corrected.get(k).copied().unwrap_or(false);
    let (mut limited, mut total) = (0.0, 0.0);
    for (k, pair) in qdd.windows(2).enumerate() {
        let squared: f64 = pair[1]
            .iter()
            .zip(&pair[0])
            .map(|(a, b)| (a - b).powi(2))
            .sum();
        total += squared;
        if at(k) || at(k + 1) {
            limited += squared;
        }
    }
    if total > 0.0 {
        limited / total
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::jerk_limit_share;

    /// By hand, one joint: q̈ = 0, 2, 2, 6 rad/s² changes by 2, 0, 4 (squares 4, 0, 16). With
    /// tick 2 corrected, the steps 1 → 2 and 2 → 3 count: 16 of 20.
    #[test]
    fn the_share_counts_the_steps_into_and_out_of_a_corrected_tick() {
        let qdd = [vec![0.0], vec![2.0], vec![2.0], vec![6.0]];
        let share = jerk_limit_share(&qdd, &[false, false, true, false]);
        assert!((share - 16.0 / 20.0).abs() < 1e-15, "{share}");
        // Tick 0 corrected: only the step 0 → 1 (4 of 20).
        let first = jerk_limit_share(&qdd, &[true]);
        assert!((first - 4.0 / 20.0).abs() < 1e-15, "{first}");
        // Every tick or none; missing entries are uncorrected.
        assert_eq!(jerk_limit_share(&qdd, &[true; 4]), 1.0);
        assert_eq!(jerk_limit_share(&qdd, &[]), 0.0);
    }

    /// Several joints add their squares; a run without jerk (or without a step) has share 0.
    #[test]
    fn the_share_sums_the_joints_and_is_zero_without_jerk() {
        // Joint a changes by 1, 1; joint b by 0, 3. Step 1 → 2 corrected: (1 + 9) / 11.
        let qdd = [vec![0.0, 0.0], vec![1.0, 0.0], vec![2.0, 3.0]];
        let share = jerk_limit_share(&qdd, &[false, false, true]);
        assert!((share - 10.0 / 11.0).abs() < 1e-15, "{share}");
        let still = vec![vec![0.5, -1.0]; 3];
        assert_eq!(jerk_limit_share(&still, &[true, true, true]), 0.0);
        assert_eq!(jerk_limit_share(&qdd[..1], &[true]), 0.0);
    }
}
