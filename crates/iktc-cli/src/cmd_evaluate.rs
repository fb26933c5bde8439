//! `iktc evaluate`: the neutral fidelity figures ([`iktc::retarget::fidelity`]) of a robot
//! trajectory made by any tool (iktc's `motion.csv` / `motion.npz`, or a plain CSV: `time`,
//! base `x y z qw qx qy qz`, then one column per joint) against the captured motion it
//! retargets ([`iktc::retarget::evaluate_trajectory`]).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use iktc::motion::{load_motion, DEFAULT_MAX_GAP};
use iktc::retarget::{
    evaluate_trajectory, read_trajectory_csv, read_trajectory_npz, RobotTrajectory,
    TrajectoryEvaluation,
};
use serde::Serialize;

use crate::robot_arg::{resolve_robot, RobotOptions};

/// Arguments of `iktc evaluate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The captured motion the trajectory retargets (.bvh, .amc, .c3d, DeepMimic), read as
    /// `iktc retarget` reads it.
    #[arg(value_name = "MOTION")]
    pub motion: PathBuf,
    /// Robot: a built-in profile (jvrc1, g1) or a robot profile (.toml); its feet, pelvis and
    /// hands give the measured points.
    #[arg(long)]
    pub robot: String,
    /// The robot's trajectory: .npz (iktc's motion.npz) or CSV with a header: `time` (or
    /// `t`) [s], the base pose `x y z qw qx qy qz` (or `base_x ... base_qz`, any order)
    /// [m], then one column per joint named as the robot's joints [rad].
    #[arg(long)]
    pub trajectory: PathBuf,
    /// Evaluation rate [Hz] (default: the control rate of `iktc retarget`, 1/0.005 s). A
    /// trajectory at another rate is resampled by natural cubic splines; the smoothness
    /// figures (q̈ by second differences) depend on this rate.
    #[arg(long)]
    pub rate: Option<f64>,
    #[command(flatten)]
    pub motion_options: crate::cmd_map::MotionArgs,
    /// Write the figures as JSON here.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// The control period `iktc retarget` uses by default \[s\] (its `--dt`).
const DEFAULT_PERIOD: f64 = 0.005;

/// `quality.json` of `iktc evaluate`.
#[derive(Serialize)]
struct Output<'a> {
    motion: String,
    trajectory: String,
    robot: &'a str,
    #[serde(flatten)]
    evaluation: &'a TrajectoryEvaluation,
}

/// Runs `iktc evaluate`.
pub fn run(a: &Args) -> Result<()> {
    let rate = match a.rate {
        Some(r) => iktc::resources::check_output_rate("--rate", r)?,
        None => 1.0 / DEFAULT_PERIOD,
    };
    let resolved = resolve_robot(&a.robot, &RobotOptions::default(), None)?;
    let profile = resolved
        .profile
        .as_ref()
        .context("`planar3r` has no profile: evaluate needs a humanoid's profile")?;
    let motion = load_motion(&a.motion, &a.motion_options.options()?)
        .with_context(|| format!("reading the motion {}", a.motion.display()))?;
    let kp = motion.keypoints(DEFAULT_MAX_GAP)?;
    let source = a.trajectory.display().to_string();
    let trajectory = read_trajectory(&a.trajectory, &source)?;
    let e = evaluate_trajectory(profile, &resolved.robot, &kp, &trajectory, 1.0 / rate)?;
    print_evaluation(&e)?;
    if let Some(out) = &a.out {
        let o = Output {
            motion: a.motion.display().to_string(),
            trajectory: source,
            robot: &a.robot,
            evaluation: &e,
        };
        let json = crate::finite::to_json("evaluation", &o)?;
        std::fs::write(out, json).with_context(|| format!("writing {}", out.display()))?;
    }
    Ok(())
}

/// Reads the robot trajectory at `path` (named `source` in errors): NPZ by extension or
/// content, CSV otherwise.
fn read_trajectory(path: &Path, source: &str) -> Result<RobotTrajectory> {
    let bytes = std::fs::read(path).with_context(|| format!("reading the trajectory {source}"))?;
    let is_npz = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npz"))
        || bytes.starts_with(b"PK\x03\x04");
    Ok(if is_npz {
        read_trajectory_npz(&bytes, source)?
    } else {
        let text = String::from_utf8(bytes)
            .map_err(|_| anyhow::anyhow!("{source}: not UTF-8 text (a CSV was expected)"))?;
        read_trajectory_csv(&text, source)?
    })
}

/// Prints the evaluation: rates [Hz], keypoint error [cm], posture, contacts [mm], smoothness
/// and the verdict.
fn print_evaluation(e: &TrajectoryEvaluation) -> Result<()> {
    let f = &e.fidelity;
    crate::outln!(
        "{} frames at {:.3} Hz evaluated at {:.3} Hz{}; {}",
        e.frames,
        e.input_rate_hz,
        e.rate_hz,
        if e.resampled { " (resampled)" } else { "" },
        e.smoothness_note
    )?;
    crate::outln!(
        "mean keypoint error {:.2} cm (scale {:.3}, heading {:.1}°)",
        f.keypoint_mean_cm,
        f.scale,
        f.heading_deg
    )?;
    for p in &f.posture {
        crate::outln!(
            "  {:<12} robot median {:7.2}  person {:7.2}  difference median {:7.2}  p90 {:7.2}",
            p.name,
            p.robot_median,
            p.person_median,
            p.difference_median,
            p.difference_p90
        )?;
    }
    let c = &f.contacts;
    crate::outln!(
        "contacts: {} windows, slip mean {:.1} mm max {:.1} mm, sole height max {:.1} mm, lowest sole {:.1} mm, skating {:.1} %",
        c.windows,
        c.slip_mean_mm,
        c.slip_max_mm,
        c.height_max_mm,
        c.lowest_sole_mm,
        100.0 * c.skate_share
    )?;
    let s = &f.smoothness;
    crate::outln!(
        "smoothness: jerk RMS {:.1} max {:.1} rad/s³, reversal share {:.3}, largest flip {:.1} rad/s²",
        s.jerk_rms,
        s.jerk_max,
        s.reversal_share,
        s.flip_max
    )?;
    if f.healthy {
        crate::outln!("verdict: healthy")?;
    } else {
        crate::outln!("verdict: {}", f.failures.join("; "))?;
    }
    Ok(())
}
