//! `iktc model ROBOT`: what a model contains, and its kinematics at a given configuration.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{Context, Result};
use iktc::model::{BaseKind, JointRole, Kinematics, Robot, State};
use nalgebra::{DMatrix, Isometry3, Quaternion, Translation3, UnitQuaternion};
use serde::{Deserialize, Serialize};

use crate::robot_arg::{load_robot, RobotOptions};

/// Arguments of `iktc model`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A built-in robot (jvrc1, g1, planar3r), a robot profile (.toml) or a URDF file.
    pub robot: String,
    #[command(flatten)]
    pub robot_options: RobotOptions,
    /// Print JSON instead of text (schema in the README).
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

/// The `--config` file.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct ConfigFile {
    /// Joint positions \[rad or m\] by name; missing joints stay at the neutral value.
    #[serde(default)]
    pub joints: BTreeMap<String, f64>,
    /// Floating-base pose.
    pub base: Option<BasePose>,
    /// Joint rates \[rad/s or m/s\] by name.
    #[serde(default)]
    pub velocities: BTreeMap<String, f64>,
    /// Base body twist (vx, vy, vz \[m/s\], wx, wy, wz \[rad/s\], base axes).
    pub base_velocity: Option<[f64; 6]>,
}

/// A base pose in a config file.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct BasePose {
    /// Position \[m\].
    pub position: [f64; 3],
    /// Unit quaternion (x, y, z, w).
    #[serde(default = "identity_quat")]
    pub orientation: [f64; 4],
}

fn identity_quat() -> [f64; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

#[derive(Serialize)]
struct JointOut {
    name: String,
    r#type: &'static str,
    q_index: usize,
    v_index: usize,
    lower: f64,
    upper: f64,
    velocity: f64,
    acceleration: f64,
    effort: f64,
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

/// Builds a state from a config file.
pub fn state_from_config(robot: &Robot, cfg: &ConfigFile) -> Result<State> {
    let mut s = State::neutral(robot);
    for (n, v) in &cfg.joints {
        s.set_joint(robot, n, *v)?;
    }
    if let Some(b) = &cfg.base {
        let [x, y, z, w] = b.orientation;
        let q = Quaternion::new(w, x, y, z);
        let n = q.norm();
        if !(n.is_finite() && (n - 1.0).abs() < iktc::model::QUATERNION_NORM_TOLERANCE) {
            anyhow::bail!(
                "base orientation {:?} is not a unit quaternion (x, y, z, w): norm {n}",
                b.orientation
            );
        }
        let pose = Isometry3::from_parts(
            Translation3::new(b.position[0], b.position[1], b.position[2]),
            UnitQuaternion::from_quaternion(q),
        );
        s.set_base_pose(robot, &pose)?;
    }
    for (n, v) in &cfg.velocities {
        iktc::error::check_finite(|| format!("velocity of `{n}`"), *v)?;
        s.qd[robot.joint_v_index(n)?] = *v;
    }
    if let Some(v) = cfg.base_velocity {
        if robot.base() != BaseKind::Floating {
            anyhow::bail!("base_velocity given, but the robot has a fixed base");
        }
        iktc::error::check_all_finite("base_velocity", &v)?;
        for (k, x) in v.iter().enumerate() {
            s.qd[k] = *x;
        }
    }
    s.validate(robot)?;
    Ok(s)
}

/// Reads a config file, JSON or TOML by extension.
pub fn read_config(path: &std::path::Path) -> Result<ConfigFile> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    if path.extension().and_then(|e| e.to_str()) == Some("toml") {
        toml::from_str(&text).with_context(|| format!("parsing {} as TOML", path.display()))
    } else {
        serde_json::from_str(&text).with_context(|| format!("parsing {} as JSON", path.display()))
    }
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
    let names: Vec<String> = robot.joints().iter().map(|j| j.name.clone()).collect();
    let active_names: Vec<String> = robot.active_joints().map(|j| j.name.clone()).collect();
    let summary_joints = robot
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
        .collect();
    let _ = names;
    let mut summary = Summary {
        name: robot.name().into(),
        base: robot.base(),
        nq: robot.nq(),
        nv: robot.nv(),
        total_mass: robot.total_mass(),
        com_neutral: kin0.com().into(),
        joints: summary_joints,
        locked: robot
            .joints()
            .iter()
            .filter_map(|j| match j.role {
                JointRole::Locked { value } => Some((j.name.clone(), value)),
                _ => None,
            })
            .collect(),
        mimic: robot
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
            .collect(),
        frames: robot.frames().iter().map(|f| f.name.clone()).collect(),
        state: None,
    };
    if let Some(path) = &a.config {
        let cfg = read_config(path)?;
        let s = state_from_config(&robot, &cfg)?;
        let kin = Kinematics::new(&robot, &s)?;
        let mut jacobians = Vec::new();
        let mut j6 = DMatrix::zeros(6, robot.nv());
        for f in &a.jacobians {
            let id = robot.frame_id(f)?;
            kin.frame_jacobian(&robot, id, &mut j6)?;
            jacobians.push(JacobianOut {
                frame: f.clone(),
                jacobian: rows(&j6),
                drift: kin.frame_drift(&robot, id)?.iter().copied().collect(),
                velocity: kin.frame_velocity(&robot, id)?.iter().copied().collect(),
            });
        }
        let com_jacobian = if a.com_jacobian {
            let mut j3 = DMatrix::zeros(3, robot.nv());
            kin.com_jacobian(&robot, &mut j3)?;
            Some(JacobianOut {
                frame: "com".into(),
                jacobian: rows(&j3),
                drift: kin.com_drift().iter().copied().collect(),
                velocity: kin.com_velocity().iter().copied().collect(),
            })
        } else {
            None
        };
        summary.state = Some(StateOut {
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
        });
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_text(&summary);
    }
    Ok(())
}

fn fmt_lim(v: f64) -> String {
    if v.is_infinite() {
        "-".into()
    } else {
        format!("{v:.4}")
    }
}

fn print_text(s: &Summary) {
    println!(
        "robot {}: {:?} base, nq = {}, nv = {}",
        s.name, s.base, s.nq, s.nv
    );
    println!(
        "total mass {:.3} kg; COM at the neutral pose ({:.4}, {:.4}, {:.4}) m",
        s.total_mass, s.com_neutral[0], s.com_neutral[1], s.com_neutral[2]
    );
    println!();
    println!(
        "{:>4} {:>4}  {:<16} {:<10} {:>9} {:>9} {:>9} {:>10}",
        "q", "v", "joint", "type", "lower", "upper", "vel max", "acc max"
    );
    for j in &s.joints {
        println!(
            "{:>4} {:>4}  {:<16} {:<10} {:>9} {:>9} {:>9} {:>10}",
            j.q_index,
            j.v_index,
            j.name,
            j.r#type,
            fmt_lim(j.lower),
            fmt_lim(j.upper),
            fmt_lim(j.velocity),
            fmt_lim(j.acceleration)
        );
    }
    println!("(units: rad, rad/s, rad/s² for revolute joints; m, m/s, m/s² for prismatic; - = unbounded)");
    if !s.locked.is_empty() {
        println!();
        println!(
            "locked: {}",
            s.locked
                .iter()
                .map(|(n, v)| format!("{n}={v}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    if !s.mimic.is_empty() {
        println!(
            "mimic (followed): {}",
            s.mimic
                .iter()
                .map(|m| format!("{} = {}·{} + {}", m.name, m.multiplier, m.master, m.offset))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    if let Some(st) = &s.state {
        println!();
        println!(
            "at the configuration given: COM ({:.4}, {:.4}, {:.4}) m",
            st.com[0], st.com[1], st.com[2]
        );
        for l in &st.links {
            println!("  {:<20} p = ({:>8.4}, {:>8.4}, {:>8.4})  q(xyzw) = ({:>7.4}, {:>7.4}, {:>7.4}, {:>7.4})", l.name, l.position[0], l.position[1], l.position[2], l.orientation[0], l.orientation[1], l.orientation[2], l.orientation[3]);
        }
        for j in st.jacobians.iter().chain(st.com_jacobian.iter()) {
            println!(
                "Jacobian of {} (rows vx vy vz wx wy wz, world axes):",
                j.frame
            );
            for r in &j.jacobian {
                println!(
                    "  {}",
                    r.iter()
                        .map(|v| format!("{v:>8.4}"))
                        .collect::<Vec<_>>()
                        .join(" ")
                );
            }
            println!("  drift J̇q̇ = {:?}", j.drift);
        }
    }
}
