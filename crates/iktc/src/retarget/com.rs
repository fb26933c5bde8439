//! The COM reference's offset from the pelvis: where the robot's COM is, relative to its
//! pelvis, in the posture it is asked for.
//!
//! ## Method
//!
//! The COM reference ([`super::plan`]) is the scaled pelvis's ground projection plus `d_k`, the
//! robot's own horizontal offset of its COM from its pelvis frame at tick k, with every active
//! joint at its posture reference (the joint route's where given, else the start posture) and
//! the pelvis frame at its orientation reference:
//!
//! `d_k = c(q_k) − p(q_k)` with its vertical component set to 0,
//!
//! `c` the COM and `p` the pelvis frame's origin in the world (a difference does not depend on
//! where the robot is, so the base is placed with the pelvis frame at the origin, turned to
//! its reference orientation, and `d_k` is the COM's horizontal position). Standing as at its start, `d_k` is the start
//! posture's offset turned with the pelvis (G1's COM 4.1 cm ahead of its pelvis frame); where
//! the captured person bends (a bow, a reach, a crouch), the robot's own masses move its COM
//! from its pelvis as the posture moves them, and the legs are not asked to hold a COM where
//! the robot, so posed, does not have it. `book/src/retarget-defaults.md` compares this
//! offset with the start posture's offset turned with the clip's heading throughout, and
//! with none.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::tracker::PostureTracks;
use crate::error::Result;
use crate::model::{FrameId, Kinematics, Robot, State};

/// Per tick, `d_k` of the module documentation \[m\]: the robot's COM from its `pelvis` frame,
/// horizontal, with the joints at `posture` (per tick; a track shorter than the ticks holds its
/// last value) and the pelvis frame turned to `pelvis_rot[k]`, one tick per entry of
/// `pelvis_rot`. `start` places the base relative to the pelvis frame. Errors: a posture joint
/// the robot does not have.
pub(crate) fn com_offsets(
    robot: &Robot,
    start: &State,
    pelvis: FrameId,
    pelvis_rot: &[UnitQuaternion<f64>],
    posture: &PostureTracks,
) -> Result<Vec<Vector3<f64>>> {
    let mut state = start.clone();
    let mut kin = Kinematics::new(robot, &state)?;
    let base_in_pelvis = kin.frame_pose(robot, pelvis)?.inverse() * state.base_pose(robot);
    let joints: Vec<usize> = posture
        .0
        .iter()
        .map(|name| robot.joint_q_index(name))
        .collect::<Result<_>>()?;
    let mut offsets = Vec::with_capacity(pelvis_rot.len());
    for (k, rot) in pelvis_rot.iter().enumerate() {
        for (iq, [position, ..]) in joints.iter().zip(&posture.1) {
            if let Some(v) = position.get(k).or(position.last()) {
                state.q[*iq] = *v;
            }
        }
        // The pelvis frame at the origin: the COM is its offset.
        let pelvis_pose = Isometry3::from_parts(Translation3::identity(), *rot);
        state.set_base_pose(robot, &(pelvis_pose * base_in_pelvis))?;
        kin.update(robot, &state)?;
        let mut d = kin.com();
        d.z = 0.0;
        offsets.push(d);
    }
    Ok(offsets)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::RobotProfile;
    use crate::sim::ImitateConfig;

    /// G1, its pelvis frame and its start state, as the keypoint route sets them up.
    fn g1() -> (Robot, FrameId, State) {
        let profile = RobotProfile::builtin("g1").unwrap();
        let robot = profile.robot().unwrap();
        let cfg = profile.imitate_config(ImitateConfig::default()).unwrap();
        let names = super::super::frame_names(&profile, &cfg).unwrap();
        let kin = Kinematics::new(&robot, &State::neutral(&robot)).unwrap();
        let body = super::super::body::RobotBody::find(&robot, &kin, &names).unwrap();
        let start = profile.standing_state(&robot).unwrap();
        (robot, body.pelvis, start)
    }

    /// The posture tracks of one joint held at `value` (rad) and every other at the start.
    fn tracks(robot: &Robot, start: &State, joint: &str, value: &[f64]) -> PostureTracks {
        let mut t = super::super::posture_tracks(robot, start, None, 0.0).unwrap();
        let j = t.0.iter().position(|n| n == joint).unwrap();
        t.1[j][0] = value.to_vec();
        t
    }

    /// Rounding of a COM summed over about thirty bodies at metre scale \[m\].
    const TOL: f64 = 1e-12;

    /// At the start posture and orientation the offset is the start's own COM offset from the
    /// pelvis frame, computed directly (the start turned by 0.4 rad and moved, so that the
    /// base's placement matters); turned about the vertical with the pelvis, it turns with it;
    /// bending the waist forward (G1's `waist_pitch_joint`, positive pitch leans the torso
    /// forward) carries it forward, by more than 2 cm at 0.5 rad.
    #[test]
    fn the_offset_follows_the_posture_and_turns_with_the_pelvis() {
        let (robot, pelvis, mut start) = g1();
        let turned = Isometry3::new(Vector3::new(1.0, -2.0, 0.8), Vector3::new(0.0, 0.0, 0.4));
        start.set_base_pose(&robot, &turned).unwrap();
        let kin = Kinematics::new(&robot, &start).unwrap();
        let p0 = kin.frame_pose(&robot, pelvis).unwrap();
        let mut direct = kin.com() - p0.translation.vector;
        direct.z = 0.0;
        let yaw = UnitQuaternion::from_euler_angles(0.0, 0.0, 0.7);
        let rots = [p0.rotation, yaw * p0.rotation];
        let standing = super::super::posture_tracks(&robot, &start, None, 0.0).unwrap();
        let d = com_offsets(&robot, &start, pelvis, &rots, &standing).unwrap();
        assert!((d[0] - direct).norm() < TOL, "{} against {direct}", d[0]);
        assert!(
            (d[1] - yaw * direct).norm() < TOL,
            "{} against {}",
            d[1],
            yaw * direct
        );
        assert!(
            direct.norm() > 0.03,
            "G1's COM 4 cm ahead of its pelvis: {direct}"
        );
        // Forward is the pelvis frame's x axis at the start.
        let forward = p0.rotation * Vector3::x();
        let bent = tracks(&robot, &start, "waist_pitch_joint", &[0.0, 0.5]);
        let d = com_offsets(&robot, &start, pelvis, &[p0.rotation, p0.rotation], &bent).unwrap();
        let ahead = (d[1] - d[0]).dot(&forward);
        assert!(ahead > 0.02, "{ahead} m");
        assert!(d.iter().all(|v| v.z == 0.0));
    }

    /// Any frame can stand for the pelvis, one away from the base too: G1's torso frame (above
    /// the waist joints) at its start orientation gives the COM's offset from it, computed
    /// directly.
    #[test]
    fn a_frame_away_from_the_base_gives_the_offset_from_it() {
        let (robot, _, start) = g1();
        let torso = robot.frame_id("torso_link").unwrap();
        let kin = Kinematics::new(&robot, &start).unwrap();
        let t0 = kin.frame_pose(&robot, torso).unwrap();
        let mut direct = kin.com() - t0.translation.vector;
        direct.z = 0.0;
        let standing = super::super::posture_tracks(&robot, &start, None, 0.0).unwrap();
        let d = com_offsets(&robot, &start, torso, &[t0.rotation], &standing).unwrap();
        assert!((d[0] - direct).norm() < TOL, "{} against {direct}", d[0]);
    }

    /// A track shorter than the ticks holds its last value: the ticks after its end have the
    /// offset of its last posture.
    #[test]
    fn a_short_track_holds_its_last_posture() {
        let (robot, pelvis, start) = g1();
        let r = Kinematics::new(&robot, &start)
            .unwrap()
            .frame_pose(&robot, pelvis)
            .unwrap()
            .rotation;
        let bent = tracks(&robot, &start, "waist_pitch_joint", &[0.0, 0.4]);
        let d = com_offsets(&robot, &start, pelvis, &[r; 4], &bent).unwrap();
        assert!((d[0] - d[1]).norm() > 0.01);
        assert_eq!(d[1], d[2]);
        assert_eq!(d[2], d[3]);
    }

    /// A posture joint the robot does not have is an error naming it.
    #[test]
    fn an_unknown_posture_joint_is_an_error() {
        let (robot, pelvis, start) = g1();
        let mut t = super::super::posture_tracks(&robot, &start, None, 0.0).unwrap();
        t.0[0] = "no_such_joint".into();
        let e = com_offsets(&robot, &start, pelvis, &[UnitQuaternion::identity()], &t)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no_such_joint"), "{e}");
    }
}
