//! `iktc imitate --retarget keypoints` (the default): the clip's body keypoints scaled to the
//! robot and tracked by the keypoint stack ([`iktc::retarget`]), with the quality figures of the
//! joint route on the same clip beside them.

use std::path::Path;

use anyhow::{Context, Result};
use iktc::batch::{posture_references, Posture};
use iktc::motion::{Keypoints, MotionFormat, BUILTIN_CLIP_NAMES, DEFAULT_MAX_GAP};
use iktc::profile::RobotProfile;
use iktc::retarget::{
    builtin_motion, joint_route_quality, retarget_keypoints, KeypointRun, KeypointSettings,
    LimbScaling, RetargetQuality,
};
use iktc::sim::ImitateConfig;

/// Which retargeting `iktc imitate` runs.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum RetargetArg {
    /// Body keypoints scaled to the robot, tracked by a strict-priority stack.
    Keypoints,
    /// The paper's joint-angle route: captured rotations decomposed onto the robot's joints.
    Joints,
}

/// Where the keypoint route places the hands' or the feet's references
/// ([`iktc::retarget::LimbScaling`]).
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LimbArg {
    /// From the middle of the hips by the leg ratio: the hands (feet) where the captured
    /// person's are relative to the pelvis, scaled as a whole (hands that meet still meet; the
    /// feet keep the person's stance width).
    #[default]
    Leg,
    /// Along the limb, each segment at the robot's length: the captured limb's direction.
    Segments,
}

impl From<LimbArg> for LimbScaling {
    fn from(a: LimbArg) -> Self {
        match a {
            LimbArg::Leg => LimbScaling::Leg,
            LimbArg::Segments => LimbScaling::Segments,
        }
    }
}

/// `--max-slide`: a length \[m\] or `none`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaxSlide(pub Option<f64>);

fn parse_max_slide(s: &str) -> Result<MaxSlide, String> {
    if s.eq_ignore_ascii_case("none") {
        return Ok(MaxSlide(None));
    }
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(MaxSlide(Some(v))),
        _ => Err(format!(
            "`{s}`: expected a length > 0 [m] (human scale) or `none`"
        )),
    }
}

/// Options of the keypoint retargeting (`iktc imitate`, `iktc retarget`).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct KeypointArgs {
    /// Standing imitation: the feet and the pelvis held at the robot's start pose for the whole
    /// clip, the COM over the middle of the soles, and only the clip's upper body imitated,
    /// relative to its pelvis (torso orientation, elbows, hands).
    #[arg(long)]
    pub standing: bool,
    /// Low-pass the captured motion at this cut-off [Hz] before it is differentiated into the
    /// tasks' references (zero-phase Butterworth, forward and backward): the body points of
    /// the keypoint route, the joint angles and pelvis height and angles of the joint route
    /// (and of the keypoint route's posture references). Removes the capture's frame-rate
    /// noise from the reference accelerations (6 Hz is biomechanics' usual choice for
    /// walking). Default: 6 Hz on the joint route, none on the keypoint route.
    #[arg(long, value_name = "HZ", conflicts_with = "no_smoothing")]
    pub smoothing: Option<f64>,
    /// The motion as captured, not low-passed, on either route.
    #[arg(long)]
    pub no_smoothing: bool,
    /// Where the keypoint route places the hands' references (default: leg).
    #[arg(long, value_enum)]
    pub hands: Option<LimbArg>,
    /// Where the keypoint route places the feet's references (default: leg, the person's
    /// stance width; segments: along the legs from the robot's hips).
    #[arg(long, value_enum)]
    pub foot_scaling: Option<LimbArg>,
    /// Keep the COM over the support polygon of the feet on the ground (a level above the
    /// pelvis and torso): a static balance the captured person does not keep, which the robot
    /// then keeps with its arms and loses the person's pose for (default off; standing
    /// imitation always balances).
    #[arg(long)]
    pub balance: bool,
    /// Also measure the static reach: per tick sampled every 0.05 s, the least mean keypoint
    /// error of a posture within the joint ranges alone (no feet, balance or rates), beside
    /// the run's own on the same ticks. What the robot's body cannot do is about the reach;
    /// the rest is what the retargeting gives up. About doubles the run's time.
    #[arg(long)]
    pub reach: bool,
    /// Hold every stance foot at its yaw: a foot the captured person turns on (more than 0.35
    /// rad over a stance) does not pivot about its sole's centre, the legs take the turn.
    #[arg(long)]
    pub no_pivot: bool,
    /// Where no joint map gives the posture level its joint angles, follow the person's
    /// posture fitted to the directions of their arms and trunk instead of holding the
    /// robot's start posture there: closer to the person's shape, the feet land less exactly.
    #[arg(long)]
    pub posture_fit: bool,
    /// Largest share of a leg's length (hip–knee plus knee–ankle) the pelvis height may ask
    /// of it, in (0, 1] (default 0.95): the pelvis is lowered instead. Larger values follow a
    /// person's straight knees closer and land the feet less exactly.
    #[arg(long, value_name = "SHARE")]
    pub max_leg_extension: Option<f64>,
    /// A stance over which the captured ankle slides further than this [m, human scale] is
    /// split into steps: the robot lifts the foot and sets it down where the captured foot has
    /// slid, instead of holding it behind. `none` holds every stance.
    #[arg(long, value_name = "M", value_parser = parse_max_slide)]
    pub max_slide: Option<MaxSlide>,
}

impl KeypointArgs {
    /// Gives `cfg` the `--smoothing` (both routes use it; without it the joint route keeps
    /// `cfg`'s default, [`iktc::sim::IMITATE_SMOOTHING`], and the keypoint route none),
    /// `--no-smoothing`, and refuses the keypoint route's options (`--standing`, `--hands`,
    /// `--foot-scaling`, `--balance`, `--reach`, …) on the joint route.
    pub fn apply(&self, route: RetargetArg, cfg: &mut ImitateConfig) -> Result<()> {
        if route == RetargetArg::Joints && self.standing {
            anyhow::bail!("--standing applies to --retarget keypoints only");
        }
        if route == RetargetArg::Joints && self.hands.is_some() {
            anyhow::bail!("--hands applies to --retarget keypoints only");
        }
        if route == RetargetArg::Joints && self.foot_scaling.is_some() {
            anyhow::bail!("--foot-scaling applies to --retarget keypoints only");
        }
        if route == RetargetArg::Joints && self.balance {
            anyhow::bail!("--balance applies to --retarget keypoints only");
        }
        if route == RetargetArg::Joints && self.reach {
            anyhow::bail!("--reach applies to --retarget keypoints only");
        }
        if route == RetargetArg::Joints && self.no_pivot {
            anyhow::bail!("--no-pivot applies to --retarget keypoints only");
        }
        if route == RetargetArg::Joints && self.posture_fit {
            anyhow::bail!("--posture-fit applies to --retarget keypoints only");
        }
        if route == RetargetArg::Joints && self.max_leg_extension.is_some() {
            anyhow::bail!("--max-leg-extension applies to --retarget keypoints only");
        }
        if route == RetargetArg::Joints && self.max_slide.is_some() {
            anyhow::bail!("--max-slide applies to --retarget keypoints only");
        }
        cfg.smoothing = match (self.no_smoothing, self.smoothing, route) {
            (true, _, _) => None,
            (false, Some(hz), _) => Some(hz),
            (false, None, RetargetArg::Joints) => cfg.smoothing,
            (false, None, RetargetArg::Keypoints) => None,
        };
        Ok(())
    }
}

/// The keypoint retargeting's settings: the imitation's solver, period and tick limit from
/// `cfg`, `bounds`, and the keypoint options `k`.
pub fn keypoint_settings(
    cfg: &ImitateConfig,
    bounds: iktc::limits::BoundMethod,
    k: &KeypointArgs,
) -> KeypointSettings {
    KeypointSettings {
        method: cfg.method,
        bounds,
        dt: cfg.dt,
        run_limits: cfg.run_limits,
        standing: k.standing,
        smoothing: if k.no_smoothing { None } else { k.smoothing },
        hands: k.hands.unwrap_or_default().into(),
        feet: k.foot_scaling.unwrap_or_default().into(),
        balance: k.balance,
        reach: k.reach,
        posture_fit: k.posture_fit,
        max_leg_extension: k
            .max_leg_extension
            .unwrap_or(iktc::retarget::MAX_LEG_EXTENSION),
        pivot_turn: if k.no_pivot {
            None
        } else {
            KeypointSettings::default().pivot_turn
        },
        max_slide: match k.max_slide {
            Some(MaxSlide(m)) => m,
            None => KeypointSettings::default().max_slide,
        },
        ..KeypointSettings::default()
    }
}

/// The keypoints of `spec` (a built-in clip or a motion file) and, for a skeleton, its clip in
/// metres, Z up, with its format.
fn load(
    spec: &str,
    options: &crate::cmd_map::MotionArgs,
) -> Result<(Keypoints, Option<(iktc::motion::Clip, MotionFormat)>)> {
    let motion = if BUILTIN_CLIP_NAMES.contains(&spec) {
        builtin_motion(spec)?
    } else {
        crate::cmd_map::load(Path::new(spec), options, None)?
    };
    let kp = motion
        .keypoints(DEFAULT_MAX_GAP)
        .with_context(|| format!("the body points of `{spec}`"))?;
    let clip = motion.clip().transpose()?.map(|c| (c, motion.format));
    Ok((kp, clip))
}

/// Runs the keypoint retargeting of `spec` on `profile` with the imitation's solver, period and
/// tick limit from `cfg` and `bounds`, compares it with the joint route where `map` (`--map`),
/// else the profile's map for the clip's format, fits the clip (its angles are then the
/// posture level's references too), prints both and writes `keypoints_summary.json` and
/// `keypoints_trajectory.csv` to `out`.
pub fn run(
    profile: &RobotProfile,
    spec: &str,
    options: &crate::cmd_map::MotionArgs,
    cfg: &ImitateConfig,
    (bounds, map): (
        iktc::limits::BoundMethod,
        Option<&iktc::motion::RetargetMap>,
    ),
    keypoint_args: &KeypointArgs,
    out: &Path,
) -> Result<()> {
    let (kp, clip) = load(spec, options)?;
    crate::outln!("{}", kp.summary())?;
    let settings = keypoint_settings(cfg, bounds, keypoint_args);
    let robot = profile.robot()?;
    let posture = match &clip {
        Some((clip, format)) => {
            posture_references(&robot, profile, clip, *format, map, cfg, settings.smoothing)?
        }
        None => Posture::Start("the motion has no skeleton".into()),
    };
    if let Posture::Start(_) = &posture {
        crate::outln!(
            "joint route: not run; posture level: {}",
            posture.describe()
        )?;
    }
    let refs = posture.references();
    let run = retarget_keypoints(profile, &kp, refs, &settings)?;
    let joints = match refs {
        Some(r) => Some(joint_route_quality(profile, &kp, r, &settings)?),
        None => None,
    };
    print(&run, joints.as_ref())?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let summary = serde_json::json!({
        "source": kp.source,
        "leg_ratio": run.scaling.leg,
        "gf_ticks": run.fallback_ticks,
        "stance_gf_ticks": run.stance_gf_ticks,
        "tick_median_us": run.tick_median_us,
        "sacrificed": run.sacrificed,
        "settle_sacrificed": run.settle_sacrificed,
        "standing": settings.standing,
        "smoothing_hz": settings.smoothing,
        "keypoints": run.quality,
        "joints": joints,
    });
    let path = out.join("keypoints_summary.json");
    std::fs::write(&path, serde_json::to_string_pretty(&summary)?)
        .with_context(|| format!("writing {}", path.display()))?;
    let mut csv = String::from("t");
    for n in robot.dof_names().iter().skip(robot.base_nv()) {
        csv.push(',');
        csv.push_str(n);
    }
    csv.push('\n');
    let nq = robot.nq() - robot.n_active();
    for (t, q) in run.times.iter().zip(&run.trajectory) {
        csv.push_str(&format!("{t:.4}"));
        for v in &q[nq..] {
            csv.push_str(&format!(",{v:.6}"));
        }
        csv.push('\n');
    }
    let path = out.join("keypoints_trajectory.csv");
    std::fs::write(&path, csv).with_context(|| format!("writing {}", path.display()))?;
    let mut viewer = iktc::retarget::keypoint_viewer(&robot, &kp, &run, cfg.dt)?;
    let meshes = crate::viewer::robot_meshes(profile);
    crate::viewer::attach(&mut viewer, &robot, meshes.as_ref())?;
    crate::viewer::write_viewer(&out.join("viewer.html"), &viewer)?;
    crate::outln!(
        "wrote keypoints_summary.json, keypoints_trajectory.csv and viewer.html to {}",
        out.display()
    )?;
    Ok(())
}

/// The summary lists this many joints on a position limit, the most often first.
const ON_LIMIT_LISTED: usize = 3;

/// Prints the keypoint run's quality beside the joint route's (`joints`, when it ran).
fn print(run: &KeypointRun, joints: Option<&RetargetQuality>) -> std::io::Result<()> {
    let k = &run.quality;
    print_header(run, joints)?;
    print_points(k, joints)?;
    print_contacts_and_limits(k, joints)?;
    crate::outln!("(mean / max; jerk in rad/s³, and its square's share on the ticks the solver corrected into the joint limits' box and the ticks after them; margins position [rad], velocity [rad/s], acceleration [rad/s²], positive = a limit exceeded)")
}

/// Prints the run's ticks, solvers and sacrificed levels, and the table's column titles.
fn print_header(run: &KeypointRun, joints: Option<&RetargetQuality>) -> std::io::Result<()> {
    let k = &run.quality;
    crate::outln!(
        "keypoint retargeting: {} ticks, leg ratio {:.3}, {} ticks solved by GF (+{} for the feet), tick median {:.1} µs",
        k.ticks,
        run.scaling.leg,
        run.fallback_ticks,
        run.stance_gf_ticks,
        run.tick_median_us
    )?;
    crate::outln!(
        "levels sacrificed to the joint limits (ticks IKTC corrected from each): {} of {} ticks; while settling on the first frame: {} of {}",
        run.sacrificed.describe(),
        run.sacrificed.ticks,
        run.settle_sacrificed.describe(),
        run.settle_sacrificed.ticks
    )?;
    crate::outln!(
        "{:<16} {:>22} {:>22}",
        "",
        "keypoints",
        if joints.is_some() {
            "joints"
        } else {
            "joints (not run)"
        }
    )
}

/// Prints one row of the table: its name, the keypoint route's value `a`, the joint route's `b`.
fn row(name: &str, a: String, b: Option<String>) -> std::io::Result<()> {
    crate::outln!("{name:<16} {a:>22} {:>22}", b.unwrap_or_default())
}

/// Prints the position errors of the points [cm], the reaches [cm] and the orientation errors
/// of the frames [deg].
fn print_points(k: &RetargetQuality, joints: Option<&RetargetQuality>) -> std::io::Result<()> {
    for (i, p) in k.points.iter().enumerate() {
        let other = joints
            .and_then(|j| j.points.get(i))
            .map(|q| format!("{:.1} / {:.1} cm", q.mean_cm, q.max_cm));
        row(
            &p.point,
            format!("{:.1} / {:.1} cm", p.mean_cm, p.max_cm),
            other,
        )?;
    }
    row(
        "mean of points",
        format!("{:.2} cm", k.mean_cm),
        joints.map(|j| format!("{:.2} cm", j.mean_cm)),
    )?;
    if let (Some(reach), Some(run)) = (k.reach_cm, k.reach_run_cm) {
        row(
            "static reach",
            format!("{reach:.2} cm (run {run:.2})"),
            None,
        )?;
    }
    if let Some(balanced) = k.balanced_reach_cm {
        row(
            "balanced reach (feet, COM kept)",
            format!("{balanced:.2} cm"),
            None,
        )?;
    }
    for (i, o) in k.orientations.iter().enumerate() {
        let other = joints
            .and_then(|j| j.orientations.get(i))
            .map(|q| format!("{:.1} / {:.1}°", q.mean_deg, q.max_deg));
        row(
            &format!("{} (orient.)", o.frame),
            format!("{:.1} / {:.1}°", o.mean_deg, o.max_deg),
            other,
        )?;
    }
    Ok(())
}

/// The joints most often on a position limit with their share of the ticks, or "none".
fn on_limit_text(q: &RetargetQuality) -> String {
    if q.on_limit.is_empty() {
        return "none".into();
    }
    q.on_limit
        .iter()
        .take(ON_LIMIT_LISTED)
        .map(|j| format!("{} {:.0} %", j.joint, 100.0 * j.share))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Prints the feet's contact (slip, depth, floating [mm]), the joints on a limit, the jerk
/// [rad/s³] and the worst margins.
fn print_contacts_and_limits(
    k: &RetargetQuality,
    joints: Option<&RetargetQuality>,
) -> std::io::Result<()> {
    row(
        "stance slip",
        format!("{:.2} mm", k.slip_mm),
        joints.map(|j| format!("{:.2} mm", j.slip_mm)),
    )?;
    row(
        "below ground",
        format!("{:.2} mm", k.below_ground_mm),
        joints.map(|j| format!("{:.2} mm", j.below_ground_mm)),
    )?;
    row(
        "foot floating (max, share > 1 cm)",
        format!("{:.1} mm, {:.1} %", k.float_mm, 100.0 * k.float_share),
        joints.map(|j| format!("{:.1} mm, {:.1} %", j.float_mm, 100.0 * j.float_share)),
    )?;
    row(
        "on a position limit (ticks)",
        on_limit_text(k),
        joints.map(on_limit_text),
    )?;
    row(
        "jerk RMS / max",
        format!("{:.0} / {:.0}", k.jerk_rms, k.jerk_max),
        joints.map(|j| format!("{:.0} / {:.0}", j.jerk_rms, j.jerk_max)),
    )?;
    row(
        "jerk² where the limits bound",
        format!("{:.0} %", 100.0 * k.jerk_limit_share),
        joints.map(|j| format!("{:.0} %", 100.0 * j.jerk_limit_share)),
    )?;
    row(
        "worst margins",
        format!(
            "{:+.1e} {:+.1e} {:+.1e}",
            k.position_margin, k.velocity_margin, k.acceleration_margin
        ),
        joints.map(|j| {
            format!(
                "{:+.1e} {:+.1e} {:+.1e}",
                j.position_margin, j.velocity_margin, j.acceleration_margin
            )
        }),
    )
}
