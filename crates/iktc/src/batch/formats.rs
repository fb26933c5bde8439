//! A retargeted clip ([`TrainingTrajectory`]) in the files other training pipelines load as
//! they are ([`MotionFormat`]): iktc's own CSV and NPZ, GMR's motion pickle, the CSV of the
//! LAFAN1 retargeting dataset, and the motion NPZ mjlab / BeyondMimic trackers train from.
//!
//! Notation: T frames at the trajectory's rate `fps` \[Hz\], frame j at `j / fps` s from the
//! clip's start; n the robot's active joints in its joint order (the trajectory's
//! `joint_names`, e.g. the 29 joints of the G1 in Unitree's order: left leg, right leg, waist,
//! left arm, right arm; locked joints are not written); B the bodies of [`body_links`]. The
//! world is z-up, lengths in \[m\], angles in \[rad\].
//!
//! ## `gmr`: `motion_gmr.pkl`, GMR's robot motion pickle
//!
//! A Python `dict` pickled with protocol 4, as GMR's `scripts/*_to_robot*.py` save it and its
//! `general_motion_retargeting.load_robot_motion` (used by `scripts/vis_robot_motion.py`)
//! reads it; arrays are NumPy arrays (written as described in [`super::pickle`], loadable with
//! NumPy 1.x and 2.x):
//!
//! | key | type, shape | content |
//! |---|---|---|
//! | `fps` | `int` (a `float` if the rate is not whole) | frame rate \[Hz\] |
//! | `root_pos` | `float64` (T, 3) | base (root link) position, world \[m\] |
//! | `root_rot` | `float64` (T, 4) | base orientation, unit quaternion **x, y, z, w** |
//! | `dof_pos` | `float64` (T, n) | joint positions \[rad\], the robot's joint order |
//! | `local_body_pos` | `float32` (T, B, 3) | body origins in the root frame \[m\] |
//! | `link_body_list` | `list` of B `str` | the bodies' names |
//!
//! `local_body_pos` is GMR's: the forward kinematics of the frame's joint positions with the
//! root at the origin, not rotated; that is `R_rootᵀ (p_body − p_root)`, the body's origin in
//! the root link's frame (the root's own row is zero). GMR's loader turns `root_rot` to
//! w, x, y, z for MuJoCo's `qpos`.
//!
//! ## `lafan-csv`: `motion_lafan.csv`, the LAFAN1 retargeting dataset's CSV
//!
//! One row per frame, no header, comma-separated: base position x, y, z \[m\], base
//! orientation quaternion **x, y, z, w**, then the n joint positions \[rad\] in the robot's
//! joint order (7 + n columns; 36 for the G1). The dataset is at 30 Hz; this file is at the
//! output rate, which the reader must be told (BeyondMimic's and mjlab's `csv_to_npz.py
//! --input_fps`). Read with `numpy.loadtxt(path, delimiter=",")`.
//!
//! ## `mjlab`: `motion_mjlab.npz`, the motion NPZ of mjlab / BeyondMimic
//!
//! The arrays mjlab's `csv_to_npz.py` saves and its tracking task's `MotionLoader` reads (the
//! BeyondMimic tracker ported to MuJoCo), all `float64` here (the loader converts them to
//! `float32`), every quantity of the world frame. BeyondMimic's Isaac Lab original
//! (`whole_body_tracking`) reads the same keys, but its joint and body axes follow Isaac Lab's
//! breadth-first order, not this file's MuJoCo order:
//!
//! | key | shape | content |
//! |---|---|---|
//! | `fps` | (1,) | frame rate \[Hz\] |
//! | `joint_pos` | (T, n) | joint positions \[rad\], the robot's joint order |
//! | `joint_vel` | (T, n) | joint rates \[rad/s\] |
//! | `body_pos_w` | (T, B, 3) | body origins, world \[m\] |
//! | `body_quat_w` | (T, B, 4) | body orientations, unit quaternion **w, x, y, z** |
//! | `body_lin_vel_w` | (T, B, 3) | velocity of the body origins, world axes \[m/s\] |
//! | `body_ang_vel_w` | (T, B, 3) | angular velocity of the bodies, world axes \[rad/s\] |
//! | `joint_names` | (n,) | joint names (not read by the loader) |
//! | `body_names` | (B,) | body names (not read by the loader) |
//!
//! The loader picks its tracked bodies by their index in the simulated robot's body list,
//! so the body axis must follow that list: [`body_links`] is the list MuJoCo builds from the
//! robot's URDF (fixed links merged into their parents), which for the G1 is pelvis, then the
//! link each of the 29 joints moves, in the joint order. Velocities are the kinematics' (the
//! frame Jacobians times the interpolated q̇: [`Kinematics::frame_velocity`]), not finite
//! differences; the base's twist enters as recorded (in the base's axes) and comes out in
//! world axes, as `body_link_lin_vel_w` / `body_link_ang_vel_w` of the simulator.
//!
//! ## `csv`, `npz`: iktc's own `motion.csv`, `motion.npz`
//!
//! [`TrainingTrajectory::csv`] and [`TrainingTrajectory::npz`].

use super::npz::{npz_bytes, NpyArray};
use super::pickle::{pickle_dict, PyDtype, PyValue};
use super::training::TrainingTrajectory;
use crate::error::{Error, Result};
use crate::model::{BaseKind, FrameId, JointKind, Kinematics, Robot, State};

/// A file a retargeted clip can be written as (see the module docs for each layout).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MotionFormat {
    /// iktc's CSV (`motion.csv`, [`TrainingTrajectory::csv`]).
    Csv,
    /// iktc's NPZ (`motion.npz`, [`TrainingTrajectory::npz`]).
    Npz,
    /// GMR's motion pickle (`motion_gmr.pkl`).
    Gmr,
    /// The LAFAN1 retargeting dataset's CSV (`motion_lafan.csv`).
    LafanCsv,
    /// mjlab / BeyondMimic's motion NPZ (`motion_mjlab.npz`).
    Mjlab,
}

impl MotionFormat {
    /// Every format, in the order [`Self::name`] lists them.
    pub const ALL: [MotionFormat; 5] = [
        MotionFormat::Csv,
        MotionFormat::Npz,
        MotionFormat::Gmr,
        MotionFormat::LafanCsv,
        MotionFormat::Mjlab,
    ];

    /// The formats written when none is chosen: iktc's CSV and NPZ.
    pub const DEFAULT: [MotionFormat; 2] = [MotionFormat::Csv, MotionFormat::Npz];

    /// The format's name on the command line (`--format`).
    pub fn name(self) -> &'static str {
        match self {
            MotionFormat::Csv => "csv",
            MotionFormat::Npz => "npz",
            MotionFormat::Gmr => "gmr",
            MotionFormat::LafanCsv => "lafan-csv",
            MotionFormat::Mjlab => "mjlab",
        }
    }

    /// The file name a clip's folder holds it under.
    pub fn file_name(self) -> &'static str {
        match self {
            MotionFormat::Csv => "motion.csv",
            MotionFormat::Npz => "motion.npz",
            MotionFormat::Gmr => "motion_gmr.pkl",
            MotionFormat::LafanCsv => "motion_lafan.csv",
            MotionFormat::Mjlab => "motion_mjlab.npz",
        }
    }

    /// The format called `name`.
    ///
    /// Errors: [`Error::UnknownName`] listing the valid names.
    pub fn parse(name: &str) -> Result<Self> {
        let name = name.trim();
        Self::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| Error::UnknownName {
                kind: "output format",
                name: name.into(),
                valid: Self::ALL.iter().map(|f| f.name().to_string()).collect(),
            })
    }

    /// The formats of `specs`, each a name or a comma-separated list of names, without
    /// repeats, in the order first given; [`Self::DEFAULT`] when `specs` is empty.
    ///
    /// Errors: [`Error::UnknownName`] for a name that is no format (an empty one included).
    pub fn parse_list<S: AsRef<str>>(specs: &[S]) -> Result<Vec<Self>> {
        if specs.is_empty() {
            return Ok(Self::DEFAULT.to_vec());
        }
        let mut out = Vec::new();
        for spec in specs {
            for name in spec.as_ref().split(',') {
                let f = Self::parse(name)?;
                if !out.contains(&f) {
                    out.push(f);
                }
            }
        }
        Ok(out)
    }

    /// The file's bytes for the clip `traj` of `robot`.
    ///
    /// Errors: those of [`TrainingTrajectory::npz`], [`gmr_pickle`] and [`mjlab_npz`].
    pub fn encode(self, robot: &Robot, traj: &TrainingTrajectory) -> Result<Vec<u8>> {
        match self {
            MotionFormat::Csv => Ok(traj.csv().into_bytes()),
            MotionFormat::Npz => traj.npz(),
            MotionFormat::Gmr => gmr_pickle(robot, traj),
            MotionFormat::LafanCsv => Ok(lafan_csv(traj).into_bytes()),
            MotionFormat::Mjlab => mjlab_npz(robot, traj),
        }
    }
}

impl std::str::FromStr for MotionFormat {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        Self::parse(s)
    }
}

/// The robot's bodies as MuJoCo lists those of its URDF (fixed links merged into their
/// parents): the root link, then the child link of every joint that is not fixed, depth-first
/// from the root in the robot's joint order (locked and mimic joints still move a body of
/// their own).
pub fn body_links(robot: &Robot) -> Vec<String> {
    let links = robot.links();
    std::iter::once(robot.root_link())
        .chain(
            robot
                .joints()
                .iter()
                .filter(|j| !matches!(j.kind, JointKind::Fixed))
                .map(|j| j.child),
        )
        .map(|i| links[i].name.clone())
        .collect()
}

/// The world poses and velocities of some bodies over a trajectory, from the kinematics of
/// each frame's configuration and velocity.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyMotion {
    /// Body names (links or frames of the robot).
    pub names: Vec<String>,
    /// Origins in the world \[m\], per frame, per body.
    pub pos_w: Vec<Vec<[f64; 3]>>,
    /// Origins in the root link's frame \[m\] (`R_rootᵀ (p − p_root)`), per frame, per body.
    pub pos_root: Vec<Vec<[f64; 3]>>,
    /// Orientations in the world, unit quaternions (w, x, y, z), per frame, per body.
    pub quat_w_wxyz: Vec<Vec<[f64; 4]>>,
    /// Velocities of the origins, world axes \[m/s\] (J q̇), per frame, per body.
    pub lin_vel_w: Vec<Vec<[f64; 3]>>,
    /// Angular velocities, world axes \[rad/s\] (J q̇), per frame, per body.
    pub ang_vel_w: Vec<Vec<[f64; 3]>>,
}

impl BodyMotion {
    /// The motion of `bodies` (link or frame names of `robot`) over `traj`: at each frame, the
    /// robot at the base pose and joint positions of the frame, moving at its base twist (base
    /// axes) and joint rates.
    ///
    /// Errors: [`Error::InvalidSetting`] when `traj`'s joints are not `robot`'s active joints
    /// in its order, [`Error::DimensionMismatch`] for a frame of the wrong width,
    /// [`Error::UnknownName`] for a body the robot lacks, and those of
    /// [`Kinematics::update`] (a non-finite value, a quaternion that is not unit).
    pub fn new(robot: &Robot, traj: &TrainingTrajectory, bodies: &[String]) -> Result<Self> {
        let active = check_joint_order(robot, traj)?;
        let ids = bodies
            .iter()
            .map(|b| robot.frame_id(b))
            .collect::<Result<Vec<FrameId>>>()?;
        let n = traj.len();
        let nj = active.len();
        let floating = robot.base() == BaseKind::Floating;
        let (nqb, nvb) = (robot.base_nq(), robot.base_nv());
        let mut state = State::neutral(robot);
        let mut kin = Kinematics::new(robot, &state)?;
        let mut out = Self {
            names: bodies.to_vec(),
            pos_w: Vec::with_capacity(n),
            pos_root: Vec::with_capacity(n),
            quat_w_wxyz: Vec::with_capacity(n),
            lin_vel_w: Vec::with_capacity(n),
            ang_vel_w: Vec::with_capacity(n),
        };
        for j in 0..n {
            check_frame_width(traj, j, nj)?;
            let q = state.q.as_mut_slice();
            let qd = state.qd.as_mut_slice();
            if floating {
                q[..3].copy_from_slice(&traj.base_pos[j]);
                q[3..7].copy_from_slice(&traj.base_quat_xyzw[j]);
                qd[..3].copy_from_slice(&traj.base_lin_vel[j]);
                qd[3..6].copy_from_slice(&traj.base_ang_vel[j]);
            }
            q[nqb..].copy_from_slice(&traj.joint_pos[j]);
            qd[nvb..].copy_from_slice(&traj.joint_vel[j]);
            kin.update(robot, &state)?;
            let root =
                *kin.link_pose(robot.root_link())
                    .ok_or_else(|| Error::InsufficientData {
                        what: "body motion".into(),
                        message: "the robot has no root link".into(),
                    })?;
            let (mut pw, mut pr, mut qw) = (Vec::new(), Vec::new(), Vec::new());
            let (mut vw, mut ww) = (Vec::new(), Vec::new());
            for id in &ids {
                let pose = kin.frame_pose(robot, *id)?;
                let p = pose.translation.vector;
                let local = root.inverse_transform_point(&nalgebra::Point3::from(p));
                let r = pose.rotation;
                let v = kin.frame_velocity(robot, *id)?;
                pw.push([p.x, p.y, p.z]);
                pr.push([local.x, local.y, local.z]);
                qw.push([r.w, r.i, r.j, r.k]);
                vw.push([v[0], v[1], v[2]]);
                ww.push([v[3], v[4], v[5]]);
            }
            out.pos_w.push(pw);
            out.pos_root.push(pr);
            out.quat_w_wxyz.push(qw);
            out.lin_vel_w.push(vw);
            out.ang_vel_w.push(ww);
        }
        Ok(out)
    }
}

/// The robot's active joints, checked to be `traj`'s joints in the same order.
fn check_joint_order<'a>(robot: &'a Robot, traj: &TrainingTrajectory) -> Result<Vec<&'a str>> {
    let active: Vec<&str> = robot.active_joints().map(|j| j.name.as_str()).collect();
    if traj
        .joint_names
        .iter()
        .map(String::as_str)
        .ne(active.iter().copied())
    {
        return Err(Error::InvalidSetting {
            name: "the trajectory's joints".into(),
            value: traj.joint_names.join(", "),
            expected: format!(
                "the robot `{}`'s active joints in its order ({})",
                robot.name(),
                active.join(", ")
            ),
        });
    }
    Ok(active)
}

/// Checks that frame `j` of `traj` has `nj` joint positions and `nj` joint rates.
fn check_frame_width(traj: &TrainingTrajectory, j: usize, nj: usize) -> Result<()> {
    for (what, got) in [
        ("joint positions of a frame", traj.joint_pos[j].len()),
        ("joint rates of a frame", traj.joint_vel[j].len()),
    ] {
        if got != nj {
            return Err(Error::DimensionMismatch {
                what: what.into(),
                expected: nj,
                got,
            });
        }
    }
    Ok(())
}

fn flat<const K: usize>(rows: &[Vec<[f64; K]>]) -> Vec<f64> {
    rows.iter().flatten().flatten().copied().collect()
}

fn flat_rows<const K: usize>(rows: &[[f64; K]]) -> Vec<f64> {
    rows.iter().flatten().copied().collect()
}

/// GMR's motion pickle of `traj` (a clip of `robot`), bodies [`body_links`]; see the module
/// docs for its keys.
///
/// Errors: those of [`BodyMotion::new`] and [`pickle_dict`].
pub fn gmr_pickle(robot: &Robot, traj: &TrainingTrajectory) -> Result<Vec<u8>> {
    let bodies = body_links(robot);
    let motion = BodyMotion::new(robot, traj, &bodies)?;
    let (t, n, b) = (traj.len(), traj.joint_names.len(), bodies.len());
    let fps = if traj.fps.fract() == 0.0 && traj.fps.abs() <= f64::from(i32::MAX) {
        PyValue::Int(traj.fps as i32)
    } else {
        PyValue::Float(traj.fps)
    };
    let f64s = |shape: Vec<usize>, data: Vec<f64>| PyValue::Array {
        dtype: PyDtype::F64,
        shape,
        data,
    };
    pickle_dict(&[
        ("fps", fps),
        ("root_pos", f64s(vec![t, 3], flat_rows(&traj.base_pos))),
        (
            "root_rot",
            f64s(vec![t, 4], flat_rows(&traj.base_quat_xyzw)),
        ),
        ("dof_pos", f64s(vec![t, n], traj.joint_pos.concat())),
        (
            "local_body_pos",
            PyValue::Array {
                dtype: PyDtype::F32,
                shape: vec![t, b, 3],
                data: flat(&motion.pos_root),
            },
        ),
        (
            "link_body_list",
            PyValue::List(bodies.into_iter().map(PyValue::Str).collect()),
        ),
    ])
}

/// The LAFAN1 retargeting dataset's CSV of `traj`: per frame, base x y z \[m\], quaternion
/// x y z w, joints \[rad\]; no header; numbers in Rust's shortest round-trip form.
pub fn lafan_csv(traj: &TrainingTrajectory) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    for j in 0..traj.len() {
        let row = traj.base_pos[j]
            .iter()
            .chain(&traj.base_quat_xyzw[j])
            .chain(&traj.joint_pos[j]);
        for (c, x) in row.enumerate() {
            if c > 0 {
                s.push(',');
            }
            // Writing into a String cannot fail.
            let _ = write!(s, "{x}");
        }
        s.push('\n');
    }
    s
}

/// mjlab / BeyondMimic's motion NPZ of `traj` (a clip of `robot`), bodies [`body_links`];
/// see the module docs for its arrays.
///
/// Errors: those of [`BodyMotion::new`] and [`npz_bytes`].
pub fn mjlab_npz(robot: &Robot, traj: &TrainingTrajectory) -> Result<Vec<u8>> {
    let bodies = body_links(robot);
    let m = BodyMotion::new(robot, traj, &bodies)?;
    let (t, n, b) = (traj.len(), traj.joint_names.len(), bodies.len());
    npz_bytes(&[
        NpyArray::f64("fps", vec![1], vec![traj.fps]),
        NpyArray::f64("joint_pos", vec![t, n], traj.joint_pos.concat()),
        NpyArray::f64("joint_vel", vec![t, n], traj.joint_vel.concat()),
        NpyArray::f64("body_pos_w", vec![t, b, 3], flat(&m.pos_w)),
        NpyArray::f64("body_quat_w", vec![t, b, 4], flat(&m.quat_w_wxyz)),
        NpyArray::f64("body_lin_vel_w", vec![t, b, 3], flat(&m.lin_vel_w)),
        NpyArray::f64("body_ang_vel_w", vec![t, b, 3], flat(&m.ang_vel_w)),
        NpyArray::strings("joint_names", traj.joint_names.clone()),
        NpyArray::strings("body_names", bodies),
    ])
}
