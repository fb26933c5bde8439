//! The 3D viewer data of a keypoint retargeting run: the robot's links at every viewer frame,
//! the captured body points beside it (aligned on the first frame's pelvis and scaled by the
//! leg ratio), the COM, and the joints on a position limit.

use nalgebra::Vector3;

use crate::error::Result;
use crate::limits::JointLimits;
use crate::model::{Kinematics, Robot, State};
use crate::motion::{BodyPoint, Keypoints};
use crate::sim::viewer::{
    point, quat, robot_figure, stride, Figure3d, ViewerData, SKELETON_OFFSET,
};

use super::KeypointRun;

/// A joint closer than this to an end of its position range counts as on the limit in the
/// viewer \[rad\] or \[m\] (far above the rounding of the integration, far below a visible
/// distance).
pub(crate) const ON_LIMIT: f64 = 1e-6;

/// The body-point segments drawn for the captured person (those whose two ends exist).
const SEGMENTS: [(BodyPoint, BodyPoint); 17] = {
    use BodyPoint::*;
    [
        (Pelvis, LeftHip),
        (Pelvis, RightHip),
        (LeftHip, LeftKnee),
        (RightHip, RightKnee),
        (LeftKnee, LeftAnkle),
        (RightKnee, RightAnkle),
        (LeftAnkle, LeftToe),
        (RightAnkle, RightToe),
        (Pelvis, Chest),
        (Chest, Neck),
        (Neck, Head),
        (Chest, LeftShoulder),
        (Chest, RightShoulder),
        (LeftShoulder, LeftElbow),
        (RightShoulder, RightElbow),
        (LeftElbow, LeftWrist),
        (RightElbow, RightWrist),
    ]
};

/// The viewer data of `run` (a keypoint retargeting of `kp` onto `robot` at the control period
/// `dt` \[s\]), decimated to 0.02 s.
///
/// # Errors
/// The kinematics' errors for a configuration of the wrong size or with a non-finite entry.
pub fn keypoint_viewer(
    robot: &Robot,
    kp: &Keypoints,
    run: &KeypointRun,
    dt: f64,
) -> Result<ViewerData> {
    let stride = stride(dt);
    let limits = JointLimits::from_robot(robot)?;
    let names = robot.dof_names();
    let joint_of_dof: Vec<Option<usize>> = names
        .iter()
        .map(|n| robot.joints().iter().position(|j| &j.name == n))
        .collect();
    let (base_nv, nq, n_active) = (robot.base_nv(), robot.nq(), robot.n_active());
    let mut state = State::neutral(robot);
    let mut kin = Kinematics::new(robot, &state)?;
    let mut figure = robot_figure(robot);
    let (mut com, mut on_limit, mut on_limit_names, mut times, mut rotations) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (t, q) in run.times.iter().zip(&run.trajectory).step_by(stride) {
        state.q.copy_from_slice(q);
        kin.update(robot, &state)?;
        figure.frames.push(
            kin.link_poses()
                .iter()
                .map(|p| point(&p.translation.vector.into()))
                .collect(),
        );
        rotations.push(
            kin.link_poses()
                .iter()
                .map(|p| quat(&p.rotation.coords.into()))
                .collect(),
        );
        com.push(point(&kin.com().into()));
        let mut idx = Vec::new();
        let mut nm = Vec::new();
        for (j, &x) in q[nq - n_active..].iter().enumerate() {
            let d = base_nv + j;
            let Some(l) = limits.get(d) else { continue };
            if x >= l.position_max - ON_LIMIT || x <= l.position_min + ON_LIMIT {
                if let Some(Some(ji)) = joint_of_dof.get(d) {
                    idx.push(*ji);
                }
                if let Some(n) = names.get(d) {
                    nm.push(n.clone());
                }
            }
        }
        on_limit.push(idx);
        on_limit_names.push(nm);
        times.push(*t);
    }
    Ok(ViewerData {
        title: format!(
            "{} retargeting {} (body keypoints)",
            robot.name(),
            kp.source
        ),
        dt: dt * stride as f64,
        robot: figure,
        skeleton: person(kp, run, &times),
        com,
        support: Vec::new(),
        on_limit,
        on_limit_names,
        support_frames: Vec::new(),
        footsteps: Vec::new(),
        phases: Vec::new(),
        robot_rotations: rotations,
        meshes: None,
    })
}

/// The captured points at the times `times` \[s\] (nearest frame), their pelvis at frame 0
/// moved to the origin, scaled by the leg ratio, [`SKELETON_OFFSET`] to the robot's left.
fn person(kp: &Keypoints, run: &KeypointRun, times: &[f64]) -> Figure3d {
    let n = kp.points.len();
    let at = |p: BodyPoint| kp.points.iter().position(|q| *q == p);
    let origin = at(BodyPoint::Pelvis)
        .and_then(|i| kp.positions.get(i).copied())
        .unwrap_or_else(Vector3::zeros);
    let s = run.scaling.leg;
    let t0 = kp.times.first().copied().unwrap_or(0.0);
    let mut frames = Vec::with_capacity(times.len());
    for &t in times {
        let f = kp
            .times
            .partition_point(|&x| x < t0 + t)
            .min(kp.frame_count().saturating_sub(1));
        let pts = kp.positions.get(f * n..(f + 1) * n).unwrap_or(&[]);
        frames.push(
            pts.iter()
                .map(|p| {
                    let d = (p - origin) * s;
                    [d.x as f32, (d.y + SKELETON_OFFSET) as f32, (p.z * s) as f32]
                })
                .collect(),
        );
    }
    let segments = SEGMENTS
        .iter()
        .filter_map(|(a, b)| Some([at(*a)?, at(*b)?]))
        .collect();
    Figure3d {
        name: kp.source.clone(),
        segments,
        frames,
    }
}
