//! The quality figures of one retargeted clip, a flat record for the dataset report
//! ([`ClipQuality`]): on the keypoint route what [`RetargetQuality`] measures (keypoint errors,
//! foot slip, jerk, limit margins), on the joint route what the imitation run measures
//! ([`ImitateSummary`]); one number per quality, and on both the soles' penetration of the
//! ground ([`sole_penetration`]).
//!
//! Penetration: a sole is the rectangle `length × width` of its profile, centred `offset_x`
//! ahead of the foot frame and `ankle_height` below it (foot frame axes); its corner `c` (foot
//! frame) is at height `z = (T_foot · c)_z` in the world, the ground being `z = 0`. The depth of
//! a frame is `max(0, −min z)` over the corners of both soles; the clip's penetration is the
//! largest depth, and its share the fraction of frames whose depth exceeds
//! 0.1 mm.

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};
use serde::Serialize;

use crate::error::{Error, Result};
use crate::model::Robot;
use crate::profile::Foot;
use crate::retarget::{Fidelity, KeypointRun, RetargetQuality, KEYPOINT_LEVELS};
use crate::sim::{ImitateRun, ImitateSummary};

/// A sole corner deeper than this below the ground counts as penetrating in the share of frames
/// \[m\] (0.1 mm: above the rounding of the kinematics, below anything visible).
pub(crate) const PENETRATION_TOLERANCE: f64 = 1e-4;

/// How deep the soles went below the ground over a clip.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Penetration {
    /// Deepest sole corner below the ground \[m\] (0 when none went below).
    pub depth: f64,
    /// Share of the frames with a corner deeper than 0.1 mm \[–\].
    pub share: f64,
}

/// The penetration (module docs) of the soles `feet`, given the world poses of their foot
/// frames at every frame (`poses[f][i]` the pose of `feet[i]`'s frame at frame `f`). No frame
/// gives depth 0 and share 0.
pub fn sole_penetration<'a, I>(poses: I, feet: &[&Foot]) -> Penetration
where
    I: IntoIterator<Item = &'a [Isometry3<f64>]>,
{
    let (mut depth, mut below, mut n) = (0.0f64, 0usize, 0usize);
    for frame in poses {
        let mut lowest = f64::INFINITY;
        for (pose, foot) in frame.iter().zip(feet) {
            let s = &foot.sole;
            for (dx, dy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                let c = Point3::new(
                    s.offset_x + dx * s.length / 2.0,
                    dy * s.width / 2.0,
                    -foot.ankle_height,
                );
                lowest = lowest.min((pose * c).z);
            }
        }
        n += 1;
        let d = (-lowest).max(0.0);
        depth = depth.max(d);
        if d > PENETRATION_TOLERANCE {
            below += 1;
        }
    }
    Penetration {
        depth,
        share: if n == 0 { 0.0 } else { below as f64 / n as f64 },
    }
}

/// The penetration of `feet`'s soles over the recorded ticks of `run` (on `robot`), from the
/// link poses every tick records.
///
/// # Errors
/// [`Error::UnknownName`] for a foot frame the robot does not have; [`Error::DimensionMismatch`]
/// when a tick's link poses do not match the robot's links.
pub fn run_penetration(robot: &Robot, run: &ImitateRun, feet: &[&Foot]) -> Result<Penetration> {
    let frames = feet
        .iter()
        .map(|f| robot.frame_id(&f.frame).map(|id| &robot.frames()[id.0]))
        .collect::<Result<Vec<_>>>()?;
    let nl = robot.links().len();
    let mut poses = Vec::with_capacity(run.steps.len() * feet.len());
    for st in &run.steps {
        for (what, got) in [
            ("positions", st.links.len()),
            ("orientations", st.link_rotations.len()),
        ] {
            if got != nl {
                return Err(Error::DimensionMismatch {
                    what: format!("link {what} of a recorded tick"),
                    expected: nl,
                    got,
                });
            }
        }
        for fr in &frames {
            let (p, r) = (st.links[fr.link], st.link_rotations[fr.link]);
            let link = Isometry3::from_parts(
                Translation3::new(p[0], p[1], p[2]),
                UnitQuaternion::from_quaternion(Quaternion::new(r[3], r[0], r[1], r[2])),
            );
            poses.push(link * fr.offset);
        }
    }
    Ok(sole_penetration(poses.chunks(feet.len().max(1)), feet))
}

/// A limit margin up to this counts as the limit kept \[rad, rad/s, rad/s²\]: the rounding of
/// the margins' own arithmetic (the in-step peak of a joint resting on its limit).
pub(crate) const MARGIN_ROUNDING: f64 = 1e-9;

/// The penetration of `feet`'s soles over recorded configurations `qs` of `robot` (each of
/// length `nq`), by the forward kinematics of each.
///
/// # Errors
/// [`Error::UnknownName`] for a foot frame the robot does not have; [`Error::DimensionMismatch`]
/// for a configuration whose length is not `nq`; those of the kinematics (a non-finite
/// configuration).
pub fn trajectory_penetration(
    robot: &Robot,
    qs: &[Vec<f64>],
    feet: &[&Foot],
) -> Result<Penetration> {
    let ids = feet
        .iter()
        .map(|f| robot.frame_id(&f.frame))
        .collect::<Result<Vec<_>>>()?;
    let mut state = crate::model::State::neutral(robot);
    let mut kin = crate::model::Kinematics::new(robot, &state)?;
    let mut poses = Vec::with_capacity(qs.len() * feet.len());
    for q in qs {
        if q.len() != robot.nq() {
            return Err(Error::DimensionMismatch {
                what: "a recorded configuration".into(),
                expected: robot.nq(),
                got: q.len(),
            });
        }
        state.q.copy_from_slice(q);
        kin.update(robot, &state)?;
        for id in &ids {
            poses.push(kin.frame_pose(robot, *id)?);
        }
    }
    Ok(sole_penetration(poses.chunks(feet.len().max(1)), feet))
}

/// One clip's quality figures (the `figures` of its `quality.json`), by route.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
// One value per clip, written once: the size of the keypoint figures costs nothing.
#[allow(clippy::large_enum_variant)]
pub enum ClipQuality {
    /// Keypoint retargeting ([`crate::retarget::retarget_keypoints`]).
    Keypoints(KeypointFigures),
    /// The joint-angle route ([`crate::sim::Experiment::imitate`]).
    Joints(JointFigures),
}

impl ClipQuality {
    /// The soles' penetration these figures hold.
    pub fn penetration(&self) -> Penetration {
        match self {
            Self::Keypoints(f) => Penetration {
                depth: f.penetration,
                share: f.penetration_share,
            },
            Self::Joints(f) => Penetration {
                depth: f.penetration,
                share: f.penetration_share,
            },
        }
    }

    /// Whether the clip passed its checks (see each route's `healthy`).
    pub fn healthy(&self) -> bool {
        match self {
            Self::Keypoints(f) => f.healthy,
            Self::Joints(f) => f.healthy,
        }
    }
}

/// The quality figures of a keypoint retargeting, flat, in SI units.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KeypointFigures {
    /// `keypoints`.
    pub route: &'static str,
    /// Duration of the recorded run \[s\].
    pub duration: f64,
    /// Control ticks recorded.
    pub ticks: usize,
    /// Every joint limit kept (position, velocity and acceleration margins at most
    /// 10⁻⁹) and every neutral figure within its limit
    /// ([`crate::retarget::FidelityLimits`]); `failures` says what failed.
    pub healthy: bool,
    /// What made the clip unhealthy, in words (empty if healthy).
    pub failures: Vec<String>,
    /// The neutral mean keypoint error: the robot's joint centres against the captured
    /// person's, scaled by the leg and placed at the robot's hips \[m\]
    /// ([`crate::retarget::fidelity`]).
    pub neutral_keypoint_error: f64,
    /// Largest slip of a robot ankle over the person's contacts \[m\].
    pub contact_slip: f64,
    /// Highest a sole is above the floor over the person's contacts \[m\].
    pub contact_height: f64,
    /// Lowest sole corner \[m\] (negative: below the floor).
    pub lowest_sole: f64,
    /// Share of the foot-ticks on which a sole skates on the floor \[–\].
    pub skate_share: f64,
    /// Median knee flexion, robot − person, mean of both knees \[rad\].
    pub knee_flexion_gap: f64,
    /// Median elbow flexion, robot − person, mean of both elbows \[rad\].
    pub elbow_flexion_gap: f64,
    /// Median trunk lean, robot − person \[rad\].
    pub trunk_lean_gap: f64,
    /// Median hip height above the ankles, robot − scaled person \[m\].
    pub hip_height_gap: f64,
    /// Share of the ticks whose change of q̈ reverses, over joints \[–\].
    pub reversal_share: f64,
    /// Largest sign flip of a joint's q̈ between two ticks \[rad/s²\].
    pub flip_max: f64,
    /// The tool's own tracking error: the mean over its tracked body points of each point's
    /// mean position error against its own scaled targets \[m\] (the pelvis counts as 0).
    pub mean_keypoint_error: f64,
    /// Largest position error of any body point \[m\].
    pub max_keypoint_error: f64,
    /// The body point with the largest mean error.
    pub worst_keypoint: String,
    /// Largest orientation error of the pelvis or torso \[rad\].
    pub max_orientation_error: f64,
    /// Largest stance-foot slip \[m\].
    pub foot_slip: f64,
    /// Worst signed position margin over the joints \[rad\] (positive: a limit exceeded).
    pub worst_position_margin: f64,
    /// Worst signed velocity margin \[rad/s\].
    pub worst_velocity_margin: f64,
    /// Worst signed acceleration margin \[rad/s²\].
    pub worst_acceleration_margin: f64,
    /// RMS joint jerk over joints and ticks \[rad/s³\].
    pub rms_jerk: f64,
    /// Largest joint jerk \[rad/s³\].
    pub max_jerk: f64,
    /// Share of the squared joint jerk on the ticks the solver corrected into the box and the
    /// ticks after them \[–\] ([`crate::retarget::RetargetQuality::jerk_limit_share`]).
    pub jerk_limit_share: f64,
    /// Share of the ticks solved by GF because IKTC's answer left the box \[–\].
    pub fallback_share: f64,
    /// Share of the ticks solved by GF to keep the feet's levels (stance, floor) more exactly
    /// \[–\].
    pub stance_gf_share: f64,
    /// Ratio of the robot's leg length to the captured person's \[–\].
    pub leg_ratio: f64,
    /// Median tick time \[µs\] (wall clock, noisy).
    pub tick_median_us: f64,
    /// Highest a foot floats while the clip has it on the ground \[m\]
    /// ([`RetargetQuality::float_mm`]).
    pub foot_float: f64,
    /// Share of the clip's foot-contact ticks with the foot's lowest sole corner more than
    /// [`crate::retarget::FLOAT_HEIGHT`] above the ground \[–\] ([`RetargetQuality::float_share`]).
    pub foot_float_share: f64,
    /// Deepest sole corner below the ground \[m\] ([`sole_penetration`]).
    pub penetration: f64,
    /// Share of the ticks with a sole corner deeper than 0.1 mm \[–\].
    pub penetration_share: f64,
    /// Share of the ticks on which IKTC sacrificed the feet's, the COM's or the pelvis and
    /// torso's level (the first five of [`KEYPOINT_LEVELS`]) to keep the joint limits \[–\]:
    /// the body could not take the clip's stance, pelvis pose or trunk
    /// ([`KeypointRun::sacrificed`]).
    pub body_sacrificed_share: f64,
    /// The level IKTC sacrificed on the most ticks (empty if none).
    pub most_sacrificed: String,
    /// The joint on a position limit on the most ticks (empty if none touches one;
    /// [`RetargetQuality::on_limit`]).
    pub most_on_limit: String,
    /// The share of the ticks that joint is on its limit \[–\] (0 if none).
    pub most_on_limit_share: f64,
    /// The static reach where it was asked for ([`crate::retarget::KeypointSettings::reach`]): the least mean
    /// keypoint error of a posture within the joint ranges alone, over the ticks sampled
    /// every 0.05 s ([`RetargetQuality::reach_cm`]); `null` otherwise.
    pub reach_keypoint_error: Option<f64>,
    /// The balanced reach beside the static reach: the least mean keypoint error of a posture
    /// that also keeps the clip's feet where the run has them and the COM over their soles
    /// \[m\] ([`RetargetQuality::balanced_reach_cm`]); `null` without the reach.
    pub balanced_reach_keypoint_error: Option<f64>,
    /// The run's mean keypoint error over the same sampled ticks \[m\]; `null` without the
    /// reach.
    pub reach_run_keypoint_error: Option<f64>,
    /// How far the robot's body takes the person's shape: the RMS angle between the person's
    /// segment directions and the fitted posture's \[rad\] ([`RetargetQuality::posture_fit_deg`]);
    /// `null` where the posture was not fitted.
    pub posture_fit_error: Option<f64>,
}

impl KeypointFigures {
    /// The figures of a keypoint run recorded every `dt` \[s\], with the soles' penetration
    /// `p`.
    pub fn from_run(run: &KeypointRun, dt: f64, p: Penetration) -> Self {
        let q: &RetargetQuality = &run.quality;
        let ticks = q.ticks.max(1) as f64;
        let worst = q
            .points
            .iter()
            .max_by(|a, b| a.mean_cm.total_cmp(&b.mean_cm));
        let failures = keypoint_failures(q);
        let fid = q.fidelity.as_ref();
        let gap = |names: &[&str]| posture_gap(fid, names);
        let c = fid.map(|f| &f.contacts);
        Self {
            route: "keypoints",
            duration: run.times.len() as f64 * dt,
            ticks: q.ticks,
            healthy: failures.is_empty(),
            failures,
            neutral_keypoint_error: fid.map_or(f64::NAN, |f| f.keypoint_mean_cm / 100.0),
            contact_slip: c.map_or(f64::NAN, |c| c.slip_max_mm / 1000.0),
            contact_height: c.map_or(f64::NAN, |c| c.height_max_mm / 1000.0),
            lowest_sole: c.map_or(f64::NAN, |c| c.lowest_sole_mm / 1000.0),
            skate_share: c.map_or(f64::NAN, |c| c.skate_share),
            knee_flexion_gap: gap(&["left_knee", "right_knee"]).to_radians(),
            elbow_flexion_gap: gap(&["left_elbow", "right_elbow"]).to_radians(),
            trunk_lean_gap: gap(&["trunk_lean"]).to_radians(),
            hip_height_gap: gap(&["hip_height"]) / 100.0,
            reversal_share: fid.map_or(f64::NAN, |f| f.smoothness.reversal_share),
            flip_max: fid.map_or(f64::NAN, |f| f.smoothness.flip_max),
            mean_keypoint_error: q.mean_cm / 100.0,
            max_keypoint_error: q.points.iter().map(|e| e.max_cm).fold(0.0, f64::max) / 100.0,
            worst_keypoint: worst.map_or_else(String::new, |e| e.point.clone()),
            max_orientation_error: q
                .orientations
                .iter()
                .map(|o| o.max_deg)
                .fold(0.0, f64::max)
                .to_radians(),
            foot_slip: q.slip_mm / 1000.0,
            foot_float: q.float_mm / 1000.0,
            foot_float_share: q.float_share,
            worst_position_margin: q.position_margin,
            worst_velocity_margin: q.velocity_margin,
            worst_acceleration_margin: q.acceleration_margin,
            rms_jerk: q.jerk_rms,
            max_jerk: q.jerk_max,
            jerk_limit_share: q.jerk_limit_share,
            fallback_share: run.fallback_ticks as f64 / ticks,
            stance_gf_share: run.stance_gf_ticks as f64 / ticks,
            leg_ratio: run.scaling.leg,
            tick_median_us: run.tick_median_us,
            penetration: p.depth,
            penetration_share: p.share,
            body_sacrificed_share: KEYPOINT_LEVELS[..5]
                .iter()
                .map(|l| run.sacrificed.of(l))
                .sum::<usize>() as f64
                / ticks,
            most_sacrificed: most_sacrificed(run),
            most_on_limit: q
                .on_limit
                .first()
                .map_or_else(String::new, |j| j.joint.clone()),
            most_on_limit_share: q.on_limit.first().map_or(0.0, |j| j.share),
            reach_keypoint_error: q.reach_cm.map(|c| c / 100.0),
            balanced_reach_keypoint_error: q.balanced_reach_cm.map(|c| c / 100.0),
            reach_run_keypoint_error: q.reach_run_cm.map(|c| c / 100.0),
            posture_fit_error: q.posture_fit_deg.map(f64::to_radians),
        }
    }
}

/// What keeps a keypoint run from being healthy: each joint limit exceeded by more than
/// rounding (position, velocity, acceleration margins), then the neutral figures' failures,
/// or their absence.
fn keypoint_failures(q: &RetargetQuality) -> Vec<String> {
    let margins = [q.position_margin, q.velocity_margin, q.acceleration_margin];
    let mut failures: Vec<String> = ["position", "velocity", "acceleration"]
        .iter()
        .zip(margins)
        .filter(|(_, m)| m.is_nan() || *m > MARGIN_ROUNDING)
        .map(|(what, m)| format!("a joint's {what} limit exceeded by {m:.3e}"))
        .collect();
    match q.fidelity.as_ref() {
        Some(f) => failures.extend(f.failures.iter().cloned()),
        None => failures.push("no neutral figures".into()),
    }
    failures
}

/// The mean over the posture figures `names` of the robot's median minus the person's (the
/// figures' unit: ° for angles, cm for heights); 0 without neutral figures.
fn posture_gap(fid: Option<&Fidelity>, names: &[&str]) -> f64 {
    let v: Vec<f64> = fid
        .map(|f| {
            f.posture
                .iter()
                .filter(|p| names.contains(&p.name.as_str()))
                .map(|p| p.robot_median - p.person_median)
                .collect()
        })
        .unwrap_or_default();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The level sacrificed on the most ticks (empty if none was).
fn most_sacrificed(run: &KeypointRun) -> String {
    run.sacrificed
        .levels
        .iter()
        .filter(|(_, n)| *n > 0)
        .max_by_key(|(_, n)| *n)
        .map_or_else(String::new, |(l, _)| l.clone())
}

/// The quality figures of a joint-route imitation, flat.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointFigures {
    /// `joints`.
    pub route: &'static str,
    /// Duration of the run \[s\].
    pub duration: f64,
    /// Control ticks run.
    pub ticks: usize,
    /// All run checks passed (feet held, state finite, COM over the support polygon).
    pub healthy: bool,
    /// Ticks on which a run check failed.
    pub failed_ticks: usize,
    /// RMS tracking error of the feet level ‖x_d − x‖ \[m, rad mixed\].
    pub rms_error_feet: f64,
    /// RMS tracking error of the COM x-y level \[m\].
    pub rms_error_com: f64,
    /// RMS tracking error of the pelvis attitude \[rad\].
    pub rms_error_pelvis_attitude: f64,
    /// RMS tracking error of the pelvis height \[m\].
    pub rms_error_pelvis_height: f64,
    /// RMS tracking error of the upper-body joints \[rad\].
    pub rms_error_upper_body: f64,
    /// Largest tracking error of the upper-body joints \[rad\].
    pub max_error_upper_body: f64,
    /// Foot slip: largest foot position drift from its held pose \[m\].
    pub foot_slip: f64,
    /// Largest foot rotation drift \[rad\].
    pub foot_rotation_slip: f64,
    /// Worst signed position margin over the joints \[rad\] (positive: a limit exceeded).
    pub worst_position_margin: f64,
    /// Worst signed velocity margin \[rad/s\].
    pub worst_velocity_margin: f64,
    /// Worst signed acceleration margin \[rad/s²\].
    pub worst_acceleration_margin: f64,
    /// Share of the ticks with a joint on its position limit \[–\].
    pub position_binding_share: f64,
    /// Smallest distance of the COM's ground projection inside the support polygon \[m\].
    pub com_min_margin: f64,
    /// Largest RMS commanded jerk over the joints \[rad/s³\].
    pub max_rms_jerk: f64,
    /// Joint with that largest RMS jerk.
    pub jerkiest_joint: String,
    /// Share of the ticks with a fallback (empty box, nothing to correct) \[–\].
    pub fallback_share: f64,
    /// Median tick time \[µs\] (wall clock, noisy).
    pub tick_median_us: f64,
    /// Deepest sole corner below the ground \[m\] ([`sole_penetration`]; 0 until
    /// [`JointFigures::with_penetration`]).
    pub penetration: f64,
    /// Share of the ticks with a sole corner deeper than 0.1 mm \[–\].
    pub penetration_share: f64,
}

impl JointFigures {
    /// The figures of a run's summary.
    pub fn from_summary(s: &ImitateSummary) -> Self {
        let rms = |i: usize| s.levels.get(i).map_or(0.0, |l| l.rms_error);
        let ticks = s.steps.max(1) as f64;
        let jerkiest = s
            .smoothness
            .iter()
            .max_by(|a, b| a.smoothness.rms_jerk.total_cmp(&b.smoothness.rms_jerk));
        Self {
            route: "joints",
            duration: s.duration,
            ticks: s.steps,
            healthy: s.health.healthy,
            failed_ticks: s.health.failed_ticks,
            rms_error_feet: rms(0),
            rms_error_com: rms(1),
            rms_error_pelvis_attitude: rms(2),
            rms_error_pelvis_height: rms(3),
            rms_error_upper_body: rms(4),
            max_error_upper_body: s.levels.get(4).map_or(0.0, |l| l.max_error),
            foot_slip: s.foot_drift,
            foot_rotation_slip: s.foot_rotation_drift,
            worst_position_margin: s.worst_position_margin,
            worst_velocity_margin: s.worst_velocity_margin,
            worst_acceleration_margin: s.worst_acceleration_margin,
            position_binding_share: s.position_binding_steps as f64 / ticks,
            com_min_margin: s.com_min_margin,
            max_rms_jerk: jerkiest.map_or(0.0, |j| j.smoothness.rms_jerk),
            jerkiest_joint: jerkiest.map_or_else(String::new, |j| j.joint.clone()),
            fallback_share: s.fallback_steps as f64 / ticks,
            tick_median_us: s.tick_median_us,
            penetration: 0.0,
            penetration_share: 0.0,
        }
    }

    /// These figures with the soles' penetration `p`.
    pub fn with_penetration(self, p: Penetration) -> Self {
        Self {
            penetration: p.depth,
            penetration_share: p.share,
            ..self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::BatchRetarget;
    use crate::model::{Kinematics, State};
    use crate::profile::{RobotProfile, Sole};
    use crate::sim::ImitateConfig;
    use nalgebra::{Isometry3, Vector3};

    fn foot() -> Foot {
        Foot {
            frame: "f".into(),
            ankle_height: 0.05,
            sole: Sole {
                length: 0.2,
                width: 0.1,
                offset_x: 0.02,
            },
        }
    }

    #[test]
    fn penetration_of_a_hand_made_trajectory() {
        let (f, h) = (foot(), 0.05);
        let at = |x: f64, z: f64| Isometry3::translation(x, 0.1, z);
        let theta: f64 = 0.1;
        // Yawed then pitched: the yaw does not change heights.
        let pitched = Isometry3::translation(0.3, -0.1, 0.06)
            * Isometry3::rotation(Vector3::z() * 0.7)
            * Isometry3::rotation(Vector3::y() * theta);
        let frames = [
            // On the ground but for 50 µm: in the depth, not in the share.
            [at(0.0, h - 5e-5), at(0.0, h)],
            // Left sole 1 cm deep.
            [at(0.1, h - 0.01), at(0.0, h)],
            // Right foot pitched toes down: the corner at x = offset + length/2 lowest,
            // z = 0.06 − x·sin θ − h·cos θ.
            [at(0.1, h), pitched],
            // Both lifted.
            [at(0.1, h + 0.02), at(0.0, h + 0.03)],
        ];
        let toe = 0.06 - 0.12 * theta.sin() - h * theta.cos();
        assert!(toe < -PENETRATION_TOLERANCE);
        let p = sole_penetration(frames.iter().map(|f| &f[..]), &[&f, &f]);
        assert!((p.depth - 0.01).abs() < 1e-12, "{}", p.depth);
        assert_eq!(p.share, 0.5);
        // Without the 1 cm frame the pitched toe is the deepest.
        let p = sole_penetration([&frames[0][..], &frames[2][..]], &[&f, &f]);
        assert!((p.depth + toe).abs() < 1e-12, "{} vs {}", p.depth, -toe);
        assert_eq!(p.share, 0.5);
        let none = sole_penetration(std::iter::empty(), &[&f]);
        assert_eq!((none.depth, none.share), (0.0, 0.0));
    }

    #[test]
    fn a_run_penetration_matches_the_kinematics_of_its_configurations() {
        let profile = RobotProfile::builtin("jvrc1").unwrap();
        let mut b = BatchRetarget::from_profile(profile, ImitateConfig::default()).unwrap();
        b.method = crate::batch::RetargetMethod::Joints;
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data/motions/deepmimic/humanoid3d_walk.txt");
        let o = b.retarget(&path).unwrap();
        let crate::batch::ClipRun::Joints { run, .. } = &o.run else {
            panic!("joint run")
        };
        let feet = b.profile.feet.as_ref().unwrap();
        let feet = [&feet.left, &feet.right];
        let got = run_penetration(&b.robot, run, &feet).unwrap();
        assert_eq!(o.quality.penetration().depth, got.depth);
        // Second method: the foot frames' poses from each tick's configuration.
        let robot = &b.robot;
        let ids: Vec<_> = feet
            .iter()
            .map(|f| robot.frame_id(&f.frame).unwrap())
            .collect();
        let mut state = State::neutral(robot);
        let mut kin = Kinematics::new(robot, &state).unwrap();
        let (bq, bv) = (robot.base_nq(), robot.base_nv());
        let mut poses = Vec::new();
        let mut qs = Vec::new();
        for st in &run.steps {
            state.q.as_mut_slice()[..bq].copy_from_slice(&st.base[..bq]);
            state.q.as_mut_slice()[bq..].copy_from_slice(&st.q[bv..]);
            qs.push(state.q.as_slice().to_vec());
            kin.update(robot, &state).unwrap();
            poses.push(
                ids.iter()
                    .map(|&id| kin.frame_pose(robot, id).unwrap())
                    .collect::<Vec<_>>(),
            );
        }
        let want = sole_penetration(poses.iter().map(|p| &p[..]), &feet);
        assert!((got.depth - want.depth).abs() < 1e-9, "{got:?} vs {want:?}");
        assert_eq!(got.share, want.share);
        // The configurations' own function gives the same.
        let from_q = trajectory_penetration(robot, &qs, &feet).unwrap();
        assert!((from_q.depth - want.depth).abs() < 1e-9, "{from_q:?}");
        assert_eq!(from_q.share, want.share);
        qs[1].pop();
        let e = trajectory_penetration(robot, &qs, &feet).unwrap_err();
        assert!(matches!(e, Error::DimensionMismatch { .. }), "{e}");
        // Standing on held feet: the soles stay within a millimetre of the ground.
        assert!(got.depth < 1e-3, "{got:?}");
    }
}
