//! Turning a `ROBOT` argument (a built-in name or a URDF path) into a model.

use std::path::Path;

use anyhow::{Context, Result};
use iktc::model::{builtin_robot, jvrc1, BaseKind, ModelOptions, Robot, BUILTIN_ROBOTS};

/// Options shared by every command that loads a robot.
#[derive(clap::Args, Debug, Clone)]
pub struct RobotOptions {
    /// Give a URDF a floating base (built-in robots have their own: jvrc1 floating, planar3r fixed).
    #[arg(long)]
    pub floating: bool,
    /// Lock a joint at a value [rad or m]: NAME=VALUE (repeatable, or comma-separated).
    #[arg(long = "lock", value_delimiter = ',')]
    pub lock: Vec<String>,
    /// Acceleration limit of a joint [rad/s² or m/s²]: NAME=VALUE (repeatable, or comma-separated).
    #[arg(long = "accel", value_delimiter = ',')]
    pub accel: Vec<String>,
    /// Default acceleration limit as a multiple of the velocity limit [1/s].
    #[arg(long, default_value_t = 10.0)]
    pub accel_per_velocity: f64,
}

fn parse_pairs(what: &str, items: &[String]) -> Result<Vec<(String, f64)>> {
    items
        .iter()
        .map(|s| {
            let (n, v) = s
                .split_once('=')
                .with_context(|| format!("{what} `{s}`: expected NAME=VALUE"))?;
            let v: f64 = v
                .trim()
                .parse()
                .with_context(|| format!("{what} `{s}`: `{v}` is not a number"))?;
            Ok((n.trim().to_string(), v))
        })
        .collect()
}

/// Loads a built-in robot by name or a URDF file by path.
pub fn load_robot(spec: &str, o: &RobotOptions) -> Result<Robot> {
    let options = ModelOptions {
        base: if o.floating {
            BaseKind::Floating
        } else {
            BaseKind::Fixed
        },
        locked: parse_pairs("--lock", &o.lock)?,
        acceleration_limits: parse_pairs("--accel", &o.accel)?,
        acceleration_per_velocity: o.accel_per_velocity,
        ..Default::default()
    };
    if BUILTIN_ROBOTS.contains(&spec) {
        if spec == "jvrc1" {
            return Ok(jvrc1(&options)?);
        }
        if !o.lock.is_empty() || !o.accel.is_empty() {
            anyhow::bail!("--lock and --accel apply to jvrc1 and URDF files, not to `{spec}`");
        }
        return Ok(builtin_robot(spec)?);
    }
    let path = Path::new(spec);
    if !path.exists() {
        anyhow::bail!(
            "`{spec}` is neither a built-in robot ({}) nor an existing URDF file",
            BUILTIN_ROBOTS.join(", ")
        );
    }
    let robot = Robot::from_urdf_file(path, &options).with_context(|| format!("loading {spec}"))?;
    for w in robot.warnings() {
        eprintln!("warning: {w}");
    }
    Ok(robot)
}
