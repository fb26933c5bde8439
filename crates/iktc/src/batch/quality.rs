//! The quality figures of one retargeted clip, a flat record for the dataset report: what the
//! imitation run already measures ([`ImitateSummary`]), one number per quality, and the soles'
//! penetration of the ground ([`sole_penetration`]).
//!
//! Penetration: a sole is the rectangle `length × width` of its profile, centred `offset_x`
//! ahead of the foot frame and `ankle_height` below it (foot frame axes); its corner `c` (foot
//! frame) is at height `z = (T_foot · c)_z` in the world, the ground being `z = 0`. The depth of
//! a frame is `max(0, −min z)` over the corners of both soles; the clip's penetration is the
//! largest depth, and its share the fraction of frames whose depth exceeds
//! [`PENETRATION_TOLERANCE`].

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};
use serde::Serialize;

use crate::error::{Error, Result};
use crate::model::Robot;
use crate::profile::Foot;
use crate::sim::{ImitateRun, ImitateSummary};

/// A sole corner deeper than this below the ground counts as penetrating in the share of frames
/// \[m\] (0.1 mm: above the rounding of the kinematics, below anything visible).
pub const PENETRATION_TOLERANCE: f64 = 1e-4;

/// How deep the soles went below the ground over a clip.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Penetration {
    /// Deepest sole corner below the ground \[m\] (0 when none went below).
    pub depth: f64,
    /// Share of the frames with a corner deeper than [`PENETRATION_TOLERANCE`] \[–\].
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

/// One clip's quality figures (the `figures` of its `quality.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClipQuality {
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
    /// [`ClipQuality::with_penetration`]).
    pub penetration: f64,
    /// Share of the ticks with a sole corner deeper than [`PENETRATION_TOLERANCE`] \[–\].
    pub penetration_share: f64,
}

impl ClipQuality {
    /// The figures of a run's summary.
    pub fn from_summary(s: &ImitateSummary) -> Self {
        let rms = |i: usize| s.levels.get(i).map_or(0.0, |l| l.rms_error);
        let ticks = s.steps.max(1) as f64;
        let jerkiest = s
            .smoothness
            .iter()
            .max_by(|a, b| a.smoothness.rms_jerk.total_cmp(&b.smoothness.rms_jerk));
        Self {
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
        let b = BatchRetarget::from_profile(profile, ImitateConfig::default()).unwrap();
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data/motions/deepmimic/humanoid3d_walk.txt");
        let o = b.retarget(&path).unwrap();
        let feet = b.profile.feet.as_ref().unwrap();
        let feet = [&feet.left, &feet.right];
        let got = run_penetration(&b.robot, &o.run, &feet).unwrap();
        assert_eq!(o.quality.penetration, got.depth);
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
        for st in &o.run.steps {
            state.q.as_mut_slice()[..bq].copy_from_slice(&st.base[..bq]);
            state.q.as_mut_slice()[bq..].copy_from_slice(&st.q[bv..]);
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
        // Standing on held feet: the soles stay within a millimetre of the ground.
        assert!(got.depth < 1e-3, "{got:?}");
    }
}
