//! `iktc model ROBOT`: what a model contains, and its kinematics at a given configuration.

use std::path::PathBuf;

use anyhow::{Context, Result};
use iktc::model::{BaseKind, JointRole, Kinematics, Robot, State, StateConfig};
use nalgebra::{DMatrix, Isometry3};
use serde::Serialize;

use crate::robot_arg::{load_robot, RobotOptions};

/// Arguments of `iktc model`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A built-in robot (jvrc1, g1, planar3r), a robot profile (.toml) or a URDF file.
    pub robot: String,
    #[command(flatten)]
    pub robot_options: RobotOptions,
    /// Print JSON instead of text (schema in the user guide, book/src/cli.md).
    #[arg(long)]
    pub json: bool,
    /// A configuration file (JSON or TOML): joint values by name, base pose, velocities.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Also output the Jacobian and drift of these frames (with --config; repeatable).
    #[arg(long = "jacobian", value_delimiter = ',')]
    pub jacobians: Vec<String>,
    /// Also output the COM Jacobian and drift (with --config).
    #[arg(long)]
    pub com_jacobian: bool,
}

#[derive(Serialize)]
struct JointOut {
    name: String,
    r#type: &'static str,
    q_index: usize,
    v_index: usize,
    #[serde(serialize_with = "unbounded")]
    lower: f64,
    #[serde(serialize_with = "unbounded")]
    upper: f64,
    #[serde(serialize_with = "unbounded")]
    velocity: f64,
    #[serde(serialize_with = "unbounded")]
    acceleration: f64,
    #[serde(serialize_with = "unbounded")]
    effort: f64,
}

/// An unbounded limit (±∞) is written as `null`; NaN stays a number, for the output check to
/// refuse.
fn unbounded<S: serde::Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    if v.is_infinite() {
        s.serialize_none()
    } else {
        s.serialize_f64(*v)
    }
}

#[derive(Serialize)]
struct Summary {
    name: String,
    base: BaseKind,
    nq: usize,
    nv: usize,
    total_mass: f64,
    com_neutral: [f64; 3],
    joints: Vec<JointOut>,
    locked: Vec<(String, f64)>,
    mimic: Vec<Mimic>,
    frames: Vec<String>,
    /// What the description has that is accepted but worth a word (e.g. URDF `effort="0"`).
    warnings: Vec<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    state: Option<StateOut>,
}

#[derive(Serialize)]
struct Mimic {
    name: String,
    master: String,
    multiplier: f64,
    offset: f64,
}

#[derive(Serialize)]
struct PoseOut {
    name: String,
    position: [f64; 3],
    orientation: [f64; 4],
}

#[derive(Serialize)]
struct JacobianOut {
    frame: String,
    /// 6 rows (vx, vy, vz, wx, wy, wz), nv columns.
    jacobian: Vec<Vec<f64>>,
    drift: Vec<f64>,
    velocity: Vec<f64>,
}

#[derive(Serialize)]
struct StateOut {
    q: Vec<f64>,
    qd: Vec<f64>,
    links: Vec<PoseOut>,
    com: [f64; 3],
    com_velocity: [f64; 3],
    #[serde(skip_serializing_if = "Vec::is_empty")]
    jacobians: Vec<JacobianOut>,
    #[serde(skip_serializing_if = "Option::is_none")]
    com_jacobian: Option<JacobianOut>,
}

fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|r| m.row(r).iter().copied().collect())
        .collect()
}

fn pose_out(name: &str, t: &Isometry3<f64>) -> PoseOut {
    let q = t.rotation.coords;
    PoseOut {
        name: name.into(),
        position: t.translation.vector.into(),
        orientation: [q[0], q[1], q[2], q[3]],
    }
}

/// Reads a config file, JSON or TOML by extension, and the state it describes on `robot`.
pub fn state_from_file(robot: &Robot, path: &std::path::Path) -> Result<State> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let name = path.display().to_string();
    let cfg = if path.extension().and_then(|e| e.to_str()) == Some("toml") {
        StateConfig::from_toml_str(&text, &name)?
    } else {
        StateConfig::from_json_str(&text, &name)?
    };
    Ok(cfg.state(robot)?)
}

/// Runs `iktc model`.
pub fn run(a: &Args) -> Result<()> {
    let robot = load_robot(&a.robot, &a.robot_options)?;
    if a.config.is_none() && (!a.jacobians.is_empty() || a.com_jacobian) {
        anyhow::bail!(
            "--jacobian and --com-jacobian need --config (the configuration to evaluate them at)"
        );
    }
    let neutral = State::neutral(&robot);
    let kin0 = Kinematics::new(&robot, &neutral)?;
    let mut summary = Summary {
        name: robot.name().into(),
        base: robot.base(),
        nq: robot.nq(),
        nv: robot.nv(),
        total_mass: robot.total_mass(),
        com_neutral: kin0.com().into(),
        joints: joints_out(&robot),
        warnings: robot.warnings().to_vec(),
        locked: locked_out(&robot),
        mimic: mimic_out(&robot),
        frames: robot.frames().iter().map(|f| f.name.clone()).collect(),
        state: None,
    };
    if let Some(path) = &a.config {
        summary.state = Some(state_out(&robot, a, path)?);
    }
    if a.json {
        crate::outln!("{}", crate::finite::to_json("model summary", &summary)?)?;
    } else {
        print_text(&summary)?;
    }
    Ok(())
}

/// The active joints with their indices and limits.
fn joints_out(robot: &Robot) -> Vec<JointOut> {
    robot
        .active_joints()
        .enumerate()
        .map(|(i, j)| JointOut {
            name: j.name.clone(),
            r#type: if j.limit.lower.is_infinite() && j.kind.name() == "revolute" {
                "continuous"
            } else {
                j.kind.name()
            },
            q_index: robot.base_nq() + i,
            v_index: robot.base_nv() + i,
            lower: j.limit.lower,
            upper: j.limit.upper,
            velocity: j.limit.velocity,
            acceleration: j.limit.acceleration,
            effort: j.limit.effort,
        })
        .collect()
}

/// The locked joints and the values they are locked at.
fn locked_out(robot: &Robot) -> Vec<(String, f64)> {
    robot
        .joints()
        .iter()
        .filter_map(|j| match j.role {
            JointRole::Locked { value } => Some((j.name.clone(), value)),
            _ => None,
        })
        .collect()
}

/// The mimic joints and the active joints they follow.
fn mimic_out(robot: &Robot) -> Vec<Mimic> {
    let active_names: Vec<String> = robot.active_joints().map(|j| j.name.clone()).collect();
    robot
        .joints()
        .iter()
        .filter_map(|j| match j.role {
            JointRole::Mimic {
                master,
                multiplier,
                offset,
            } => Some(Mimic {
                name: j.name.clone(),
                master: active_names[master].clone(),
                multiplier,
                offset,
            }),
            _ => None,
        })
        .collect()
}

/// The kinematics at the configuration in the file `path`, with the Jacobians `a` asks for.
fn state_out(robot: &Robot, a: &Args, path: &std::path::Path) -> Result<StateOut> {
    let s = state_from_file(robot, path)?;
    let kin = Kinematics::new(robot, &s)?;
    let mut jacobians = Vec::new();
    let mut j6 = DMatrix::zeros(6, robot.nv());
    for f in &a.jacobians {
        let id = robot.frame_id(f)?;
        kin.frame_jacobian(robot, id, &mut j6)?;
        jacobians.push(JacobianOut {
            frame: f.clone(),
            jacobian: rows(&j6),
            drift: kin.frame_drift(robot, id)?.iter().copied().collect(),
            velocity: kin.frame_velocity(robot, id)?.iter().copied().collect(),
        });
    }
    let com_jacobian = if a.com_jacobian {
        let mut j3 = DMatrix::zeros(3, robot.nv());
        kin.com_jacobian(robot, &mut j3)?;
        Some(JacobianOut {
            frame: "com".into(),
            jacobian: rows(&j3),
            drift: kin.com_drift().iter().copied().collect(),
            velocity: kin.com_velocity().iter().copied().collect(),
        })
    } else {
        None
    };
    Ok(StateOut {
        q: s.q.iter().copied().collect(),
        qd: s.qd.iter().copied().collect(),
        links: robot
            .links()
            .iter()
            .zip(kin.link_poses())
            .map(|(l, t)| pose_out(&l.name, t))
            .collect(),
        com: kin.com().into(),
        com_velocity: kin.com_velocity().into(),
        jacobians,
        com_jacobian,
    })
}

/// A limit to four decimals, or "-" when unbounded.
fn fmt_lim(v: f64) -> String {
    if v.is_infinite() {
        "-".into()
    } else {
        format!("{v:.4}")
    }
}

/// Prints the summary as text.
fn print_text(s: &Summary) -> std::io::Result<()> {
    crate::outln!(
        "robot {}: {:?} base, nq = {}, nv = {}",
        s.name,
        s.base,
        s.nq,
        s.nv
    )?;
    for w in &s.warnings {
        crate::outln!("warning: {w}")?;
    }
    crate::outln!(
        "total mass {:.3} kg; COM at the neutral pose ({:.4}, {:.4}, {:.4}) m",
        s.total_mass,
        s.com_neutral[0],
        s.com_neutral[1],
        s.com_neutral[2]
    )?;
    crate::outln!()?;
    print_joints(&s.joints)?;
    print_roles(s)?;
    if let Some(st) = &s.state {
        print_state(st)?;
    }
    Ok(())
}

/// Prints the table of the active joints: indices, type and limits (rad or m, per s, per s²).
fn print_joints(joints: &[JointOut]) -> std::io::Result<()> {
    crate::outln!(
        "{:>4} {:>4}  {:<16} {:<10} {:>9} {:>9} {:>9} {:>10}",
        "q",
        "v",
        "joint",
        "type",
        "lower",
        "upper",
        "vel max",
        "acc max"
    )?;
    for j in joints {
        crate::outln!(
            "{:>4} {:>4}  {:<16} {:<10} {:>9} {:>9} {:>9} {:>10}",
            j.q_index,
            j.v_index,
            j.name,
            j.r#type,
            fmt_lim(j.lower),
            fmt_lim(j.upper),
            fmt_lim(j.velocity),
            fmt_lim(j.acceleration)
        )?;
    }
    crate::outln!("(units: rad, rad/s, rad/s² for revolute joints; m, m/s, m/s² for prismatic; - = unbounded)")
}

/// Prints the locked and the mimic joints, if any.
fn print_roles(s: &Summary) -> std::io::Result<()> {
    if !s.locked.is_empty() {
        crate::outln!()?;
        crate::outln!(
            "locked: {}",
            s.locked
                .iter()
                .map(|(n, v)| format!("{n}={v}"))
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }
    if !s.mimic.is_empty() {
        crate::outln!(
            "mimic (followed): {}",
            s.mimic
                .iter()
                .map(|m| format!("{} = {}·{} + {}", m.name, m.multiplier, m.master, m.offset))
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }
    Ok(())
}

/// Prints the kinematics at the configuration given: COM and link poses [m], Jacobians.
fn print_state(st: &StateOut) -> std::io::Result<()> {
    crate::outln!()?;
    crate::outln!(
        "at the configuration given: COM ({:.4}, {:.4}, {:.4}) m",
        st.com[0],
        st.com[1],
        st.com[2]
    )?;
    for l in &st.links {
        crate::outln!("  {:<20} p = ({:>8.4}, {:>8.4}, {:>8.4})  q(xyzw) = ({:>7.4}, {:>7.4}, {:>7.4}, {:>7.4})", l.name, l.position[0], l.position[1], l.position[2], l.orientation[0], l.orientation[1], l.orientation[2], l.orientation[3])?;
    }
    for j in st.jacobians.iter().chain(st.com_jacobian.iter()) {
        crate::outln!(
            "Jacobian of {} (rows vx vy vz wx wy wz, world axes):",
            j.frame
        )?;
        for r in &j.jacobian {
            crate::outln!(
                "  {}",
                r.iter()
                    .map(|v| format!("{v:>8.4}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            )?;
        }
        crate::outln!("  drift J̇q̇ = {:?}", j.drift)?;
    }
    Ok(())
}
