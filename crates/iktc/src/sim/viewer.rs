//! The data a 3D viewer plays for an imitation or walking run (Fig. 21): the robot's links, the
//! captured skeleton beside it, the COM, the support polygon, the joints on a limit and, for a
//! walk, the footsteps and support phases. Plain data (serialisable); the page that plays it
//! is the CLI's.

use serde::Serialize;

use crate::error::Result;
use crate::model::Robot;
use crate::motion::Clip;
use crate::sim::experiment::Experiment;
use crate::sim::{ImitateRun, WalkRun};
use crate::walk::{sole_corners, Phase, Pose2, Side};

/// Where the captured skeleton stands in the viewer: this far along +y (the robot's left) of
/// the robot \[m\].
pub const SKELETON_OFFSET: f64 = 1.2;

/// Time between two viewer frames \[s\] (the run's ticks are decimated to it).
pub(crate) const FRAME_PERIOD: f64 = 0.02;

/// A stick figure: segments between points, and the points of every frame.
#[derive(Debug, Clone, Serialize)]
pub struct Figure3d {
    /// Name shown in the legend.
    pub name: String,
    /// Pairs of point indices joined by a segment.
    pub segments: Vec<[usize; 2]>,
    /// Points of every frame \[m\], world axes (z up).
    pub frames: Vec<Vec<[f32; 3]>>,
}

/// Everything the viewer plays.
#[derive(Debug, Clone, Serialize)]
pub struct ViewerData {
    /// Page title.
    pub title: String,
    /// Time between frames \[s\].
    pub dt: f64,
    /// The robot.
    pub robot: Figure3d,
    /// The captured skeleton (drawn beside the robot).
    pub skeleton: Figure3d,
    /// COM of every frame \[m\].
    pub com: Vec<[f32; 3]>,
    /// Support polygon \[m\] (counter-clockwise, on the ground).
    pub support: Vec<[f32; 3]>,
    /// Per frame: indices of robot segments whose joint sits on a limit.
    pub on_limit: Vec<Vec<usize>>,
    /// Per frame: names of the joints on a limit.
    pub on_limit_names: Vec<Vec<String>>,
    /// Walking: the support polygon of every frame (replaces `support` when not empty).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub support_frames: Vec<Vec<[f32; 3]>>,
    /// Walking: the footsteps' sole outlines \[m\].
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub footsteps: Vec<Vec<[f32; 3]>>,
    /// Walking: the support phase of every frame.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub phases: Vec<String>,
    /// Orientation of every robot link at every frame, unit quaternion (x, y, z, w); put in
    /// the page with the meshes ([`ViewerData::attach_meshes`]).
    #[serde(skip)]
    pub robot_rotations: Vec<Vec<[f32; 4]>>,
    /// The robot's meshes and link orientations; without them the page draws the stick
    /// figure.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub meshes: Option<crate::sim::viewer_mesh::ViewerMeshes>,
}

/// How the skeleton's root moves in the viewer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RootMotion {
    /// Pinned beside the robot: the root's horizontal motion is removed at every frame (the
    /// robot imitates standing and does not follow the clip's stepping).
    Pinned,
    /// The root moves as captured, from where it starts (the robot walks too).
    Free,
}

pub(crate) fn point(p: &[f64; 3]) -> [f32; 3] {
    [p[0] as f32, p[1] as f32, p[2] as f32]
}

pub(crate) fn quat(q: &[f64; 4]) -> [f32; 4] {
    q.map(|x| x as f32)
}

/// Ticks between viewer frames for a control period `dt` \[s\].
pub(crate) fn stride(dt: f64) -> usize {
    ((FRAME_PERIOD / dt).round() as usize).max(1)
}

/// The robot's stick figure (a segment per joint, parent link to child link), no frames yet.
pub(crate) fn robot_figure(robot: &Robot) -> Figure3d {
    Figure3d {
        name: robot.name().into(),
        segments: robot.joints().iter().map(|j| [j.parent, j.child]).collect(),
        frames: Vec::new(),
    }
}

/// The skeleton's stick figure at the run times `times` \[s\] (clamped to the clip's end), in the
/// robot's world axes (the map's basis), [`SKELETON_OFFSET`] to the robot's left.
fn skeleton_figure(e: &Experiment, times: &[f64], root: RootMotion) -> Result<Figure3d> {
    let clip: &Clip = &e.clip;
    let sk = clip.skeleton();
    let b = e.map.basis;
    let t0 = clip.times().first().copied().unwrap_or(0.0);
    let end = clip.times().last().copied().unwrap_or(0.0);
    let first = clip
        .frame(0)
        .map(|p| b * p.root_position)
        .unwrap_or_default();
    let mut frames = Vec::with_capacity(times.len());
    for &t in times {
        let pose = clip.sample((t0 + t).min(end))?;
        let anchor = match root {
            RootMotion::Pinned => b * pose.root_position,
            RootMotion::Free => first,
        };
        let pts = sk.world_positions(&pose)?;
        frames.push(
            pts.iter()
                .map(|p| {
                    let q = b * p;
                    [
                        (q.x - anchor.x) as f32,
                        (q.y - anchor.y + SKELETON_OFFSET) as f32,
                        q.z as f32,
                    ]
                })
                .collect(),
        );
    }
    Ok(Figure3d {
        name: clip.name().into(),
        segments: sk
            .joints()
            .iter()
            .enumerate()
            .filter_map(|(i, j)| j.parent.map(|p| [p, i]))
            .collect(),
        frames,
    })
}

/// The viewer data of a standing imitation: robot, skeleton pinned beside it, COM, the
/// support polygon, and the joints on a limit at every frame.
pub fn imitation_viewer(r: &ImitateRun, e: &Experiment) -> Result<ViewerData> {
    let robot = &e.robot;
    let stride = stride(r.summary.dt);
    let joint_of_dof: Vec<Option<usize>> = (0..robot.nv())
        .map(|d| {
            let name = r.dof_names.get(d)?;
            robot.joints().iter().position(|j| &j.name == name)
        })
        .collect();
    let mut figure = robot_figure(&e.robot);
    let (mut com, mut on_limit, mut on_limit_names, mut times, mut rotations) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for st in r.steps.iter().step_by(stride) {
        figure.frames.push(st.links.iter().map(point).collect());
        rotations.push(st.link_rotations.iter().map(quat).collect());
        com.push(point(&st.com));
        on_limit.push(
            st.on_limit
                .iter()
                .filter_map(|d| joint_of_dof.get(*d).copied().flatten())
                .collect(),
        );
        on_limit_names.push(
            st.on_limit
                .iter()
                .filter_map(|d| r.dof_names.get(*d).cloned())
                .collect(),
        );
        times.push(st.t);
    }
    Ok(ViewerData {
        title: format!(
            "{} imitating {} ({} / {} bounds)",
            robot.name(),
            e.clip.name(),
            r.summary.solver.to_uppercase(),
            r.summary.bounds
        ),
        dt: r.summary.dt * stride as f64,
        robot: figure,
        skeleton: skeleton_figure(e, &times, RootMotion::Pinned)?,
        com,
        support: r.support.iter().map(point).collect(),
        on_limit,
        on_limit_names,
        support_frames: Vec::new(),
        footsteps: Vec::new(),
        phases: Vec::new(),
        robot_rotations: rotations,
        meshes: None,
    })
}

/// The outline of a sole `length` × `width` \[m\] centred at the footstep `p` (x, y \[m\],
/// yaw \[rad\]), counter-clockwise, on the ground ([`sole_corners`]).
fn sole_outline(p: &[f64; 3], length: f64, width: f64) -> Vec<[f32; 3]> {
    sole_corners(&Pose2::new(p[0], p[1], p[2]), length, width)
        .iter()
        .map(|(x, y)| [*x as f32, *y as f32, 0.0])
        .collect()
}

/// The viewer data of a walk: robot, skeleton walking beside it, COM, the footsteps' soles,
/// the support polygon ([`WalkStep::support`](crate::sim::WalkStep::support)) and the support
/// phase of every frame. `dt` is the control period \[s\], `sole_size` the sole's length and
/// width \[m\].
pub fn walking_viewer(
    r: &WalkRun,
    e: &Experiment,
    dt: f64,
    sole_size: [f64; 2],
) -> Result<ViewerData> {
    let stride = stride(dt);
    let [length, width] = sole_size;
    let mut figure = robot_figure(&e.robot);
    let (mut com, mut support_frames, mut phases, mut times, mut rotations) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for st in r.steps.iter().step_by(stride) {
        figure.frames.push(st.links.iter().map(point).collect());
        rotations.push(st.link_rotations.iter().map(quat).collect());
        com.push(point(&st.com));
        times.push(st.t);
        let poly: Vec<[f32; 3]> = st
            .support
            .iter()
            .map(|p| [p[0] as f32, p[1] as f32, 0.0])
            .collect();
        support_frames.push(poly);
        phases.push(
            match st.phase {
                Phase::SingleSupport { stance: Side::Left } => "single (left foot)",
                Phase::SingleSupport {
                    stance: Side::Right,
                } => "single (right foot)",
                Phase::DoubleSupport => "double",
            }
            .to_string(),
        );
    }
    let n = figure.frames.len();
    Ok(ViewerData {
        title: format!(
            "{} walking while imitating {} (damping controller {})",
            e.robot.name(),
            e.clip.name(),
            if r.summary.damping { "on" } else { "off" }
        ),
        dt: dt * stride as f64,
        robot: figure,
        skeleton: skeleton_figure(e, &times, RootMotion::Free)?,
        com,
        support: Vec::new(),
        on_limit: vec![Vec::new(); n],
        on_limit_names: vec![Vec::new(); n],
        support_frames,
        footsteps: r
            .footsteps
            .iter()
            .map(|(_, p)| sole_outline(p, length, width))
            .collect(),
        phases,
        robot_rotations: rotations,
        meshes: None,
    })
}
