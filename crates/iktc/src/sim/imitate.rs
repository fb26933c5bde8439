//! The humanoid imitation experiment of Section 5.3: a retargeted captured motion tracked by a
//! floating-base humanoid under joint position, velocity and acceleration limits.
//!
//! Task stack (Table 1, priority order; sizes from the model, JVRC-1: 12, 2, 3, 1, 20, n = 38):
//! 1. both feet, 6D each, held at their initial poses (one level);
//! 2. COM in the horizontal plane, held over the centre of the support polygon;
//! 3. pelvis attitude (retargeted from the clip's root orientation);
//! 4. pelvis height (initial height + the retargeted root height change);
//! 5. upper-body joints (retargeted joint trajectories).
//!
//! One control tick ([`ImitationController::tick`]): kinematics → references → task
//! linearisation → acceleration box (narrowed joint ranges) → solve (IKTC, GF or clamp) →
//! constant-acceleration integration. The tick allocates nothing.

mod record;
mod support;

pub(crate) use record::{check_state_finite, link_frames};
pub use record::{run_imitate, ImitateRun, ImitateStep, ImitateSummary, JointMargin, LevelSummary};
pub use support::{sole_pose, support_polygon, SupportSettings};

use nalgebra::{DVector, Isometry3, Translation3, UnitQuaternion, Vector3, Vector6};

use super::health::HealthSettings;
use crate::controller::{
    ComHandle, Controller, ControllerBuilder, ControllerSettings, FrameHandle, JointsHandle,
};
use crate::error::{check_dim, Error, Result};
use crate::limits::{
    AccelerationBox, BoundMethod, JointLimits, NarrowedJoint, OutsideLimits, ViableSettings,
};
use crate::model::{Kinematics, Robot, State};
use crate::motion::RobotReferences;
use crate::resources::RunLimits;
use crate::solver::{Method, SolveReport, SolverSettings};
use crate::task::{Axes, ComReference, FrameReference, Gains, TaskEquation};

/// Names of the five levels, in priority order.
pub const LEVEL_NAMES: [&str; 5] = [
    "feet",
    "com_xy",
    "pelvis_attitude",
    "pelvis_height",
    "upper_body",
];

/// Settings of the imitation run.
#[derive(Debug, Clone, PartialEq)]
pub struct ImitateConfig {
    /// Solver (IKTC by default).
    pub method: Method,
    /// Joint bounds (default: quiet, with the soft approach to the range ends at the tasks' rate
    /// √k_p, [`ViableSettings::approach_rate`]).
    pub bounds: BoundMethod,
    /// Control period Δt \[s\]; must equal the references' period.
    pub dt: f64,
    /// Range of Δt and largest tick count ([`RunLimits`]).
    pub run_limits: RunLimits,
    /// CLIK gains of every task (default k_p = 100 s⁻², k_v = 20 s⁻¹, critically damped).
    pub gains: Gains,
    /// Frames of the feet (6D tasks, one level).
    pub feet: Vec<String>,
    /// Frame of the pelvis (attitude and height tasks).
    pub pelvis: String,
    /// Initial joint angles \[rad\] of joints not driven by the references (a standing
    /// posture with bent knees); the driven ones start at their first reference.
    pub initial_posture: Vec<(String, f64)>,
    /// Joint ranges narrowed (applied to the bounds and to the margins).
    pub narrow: Vec<NarrowedJoint>,
    /// Joint references are clamped into the (narrowed) range shrunk by this margin \[rad\]
    /// before the run (their rate and acceleration set to 0 where clamped): a reference outside
    /// the range only makes its task push into the limit.
    /// Larger margins keep the joints further from their limits at the price of fidelity.
    pub reference_margin: f64,
    /// The COM reference moves from the initial COM to the centre of the support polygon in
    /// this time \[s\] (quintic blend, zero rate and acceleration at both ends), then stays.
    /// Shorter blends ask more of the COM task at the start; 0 jumps.
    pub com_settle_time: f64,
    /// For solvers that report no corrected level (GF, clamp), a level counts as corrected at a
    /// tick when `‖J_i q̈ − h_i‖` exceeds this \[task unit/s²\] (reports only). Larger values
    /// ignore small sacrifices; smaller ones flag rounding.
    pub corrected_tolerance: f64,
    /// Foot soles and the support polygon.
    pub support: SupportSettings,
    /// A joint within this distance of a position limit counts as sitting on it \[rad\]
    /// (reports and viewer only). Larger values flag joints earlier.
    pub on_limit_position: f64,
    /// A joint whose |q̇| or |q̈| is above `(1 − fraction)` times its limit counts as sitting on
    /// it \[–\] (reports and viewer only).
    pub on_limit_fraction: f64,
    /// Solver settings.
    pub solver: SolverSettings,
    /// The run's checks (feet held, state finite, ZMP inside the support polygon) and whether
    /// a failed one stops the run ([`crate::sim::health`]).
    pub health: HealthSettings,
    /// Cut-off \[Hz\] of the zero-phase low-pass ([`crate::motion::lowpass`]) applied to the
    /// retargeted joint angles and pelvis height and angles at the clip's rate, before they
    /// are clamped into the ranges and differentiated into references (default
    /// [`IMITATE_SMOOTHING`], 6 Hz; `None`: as captured; a cut-off at or above the clip's
    /// Nyquist frequency leaves them too).
    pub smoothing: Option<f64>,
}

impl ImitateConfig {
    /// The defaults for JVRC-1: IKTC, quiet bounds with the soft approach to the range ends at
    /// the tasks' rate √k_p = 10 /s (a limit is approached no faster than a task converges, and
    /// the command changes smoothly as it starts to bind), a hold of [`IMITATE_LEVEL_HOLD`]
    /// ticks on the corrected level (a joint pushed into a limit rests on it and the corrected
    /// level does not flicker; `BoundMethod::viable()` and a hold of 1 are Algorithm 2 as
    /// printed with the discrete-time bounds), the clip low-passed at [`IMITATE_SMOOTHING`], Δt = 5 ms, feet `r_ankle` and `l_ankle`,
    /// pelvis `PELVIS_S`, hip pitch −0.4, knee 0.8, ankle pitch −0.4 rad, L_KNEE narrowed to
    /// \[0.55, 0.95\] rad and L_HIP_R to \[−0.05, 0.05\] rad (so that the pelvis height and
    /// attitude tasks get corrected, as in Fig. 20), reference margin 0.05 rad.
    pub fn jvrc1() -> Self {
        let mut posture = Vec::new();
        for side in ["R", "L"] {
            posture.push((format!("{side}_HIP_P"), -0.4));
            posture.push((format!("{side}_KNEE"), 0.8));
            posture.push((format!("{side}_ANKLE_P"), -0.4));
        }
        let gains = Gains {
            kp: 100.0,
            kv: 20.0,
        };
        Self {
            method: Method::Iktc,
            bounds: BoundMethod::Quiet(ViableSettings {
                approach_rate: gains.kp.sqrt(),
                ..ViableSettings::default()
            }),
            dt: 0.005,
            run_limits: RunLimits::default(),
            gains,
            feet: vec!["r_ankle".into(), "l_ankle".into()],
            pelvis: "PELVIS_S".into(),
            initial_posture: posture,
            narrow: vec![
                NarrowedJoint {
                    joint: "L_KNEE".into(),
                    lower: 0.55,
                    upper: 0.95,
                },
                NarrowedJoint {
                    joint: "L_HIP_R".into(),
                    lower: -0.05,
                    upper: 0.05,
                },
            ],
            reference_margin: 0.05,
            com_settle_time: 0.5,
            corrected_tolerance: 1e-3,
            support: SupportSettings::default(),
            on_limit_position: 2e-3,
            on_limit_fraction: 0.01,
            solver: SolverSettings {
                level_hold: IMITATE_LEVEL_HOLD,
                ..SolverSettings::default()
            },
            health: HealthSettings::default(),
            smoothing: Some(IMITATE_SMOOTHING),
        }
    }

    /// Checks the numbers.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, value: f64, expected: &str| Error::InvalidSetting {
            name: name.into(),
            value: value.to_string(),
            expected: expected.into(),
        };
        self.run_limits.check_dt("dt", self.dt)?;
        crate::motion::check_smoothing(self.smoothing)?;
        if !(self.reference_margin.is_finite() && self.reference_margin >= 0.0) {
            return Err(bad(
                "reference_margin",
                self.reference_margin,
                "a finite margin >= 0 [rad]",
            ));
        }
        for n in &self.narrow {
            n.validate(&format!("narrowed range of {}", n.joint))?;
        }
        if !(self.com_settle_time.is_finite() && self.com_settle_time >= 0.0) {
            return Err(bad(
                "com_settle_time",
                self.com_settle_time,
                "a finite time >= 0 [s]",
            ));
        }
        if !(self.corrected_tolerance.is_finite() && self.corrected_tolerance > 0.0) {
            return Err(bad(
                "corrected_tolerance",
                self.corrected_tolerance,
                "a finite tolerance > 0 [task unit/s²]",
            ));
        }
        if !(self.on_limit_position.is_finite() && self.on_limit_position >= 0.0) {
            return Err(bad(
                "on_limit_position",
                self.on_limit_position,
                "a finite distance >= 0 [rad]",
            ));
        }
        if !(self.on_limit_fraction.is_finite() && (0.0..1.0).contains(&self.on_limit_fraction)) {
            return Err(bad(
                "on_limit_fraction",
                self.on_limit_fraction,
                "a fraction in [0, 1)",
            ));
        }
        if self.feet.is_empty() {
            return Err(Error::InvalidSetting {
                name: "feet".into(),
                value: "none".into(),
                expected: "at least one foot frame".into(),
            });
        }
        self.gains.validate()?;
        self.bounds.validate()?;
        self.support.validate()?;
        self.health.validate()?;
        self.solver.validate()
    }
}

/// The hold on IKTC's corrected level in the imitation's defaults \[ticks\]
/// ([`SolverSettings::level_hold`]). On the default clip with the quiet bounds a level change
/// is undone at the next tick 13 times with no hold and 3 times with 4 ticks. A longer hold
/// corrects the held levels longer than needed: with 5 ticks the COM of the default run strays
/// 3 cm from its reference while a lower level is corrected (1 cm with 4), and keypoint
/// retargeting of CMU 131_02 on G1 loses the pelvis orientation (123°); with 3 the walk of
/// `tests/walk_imitate.rs` without the damping controller puts its ZMP 0.2 mm outside the
/// support polygon for one tick.
pub const IMITATE_LEVEL_HOLD: usize = 4;

/// The cut-off of the low-pass applied to captured motion in the imitation's defaults \[Hz\]
/// ([`ImitateConfig::smoothing`]): 6 Hz, the cut-off customary for filtering captured human
/// movement in biomechanics (most of its power lies below it; D. A. Winter, *Biomechanics and
/// Motor Control of Human Movement*), which takes out the frame-rate zigzag of the clips.
pub const IMITATE_SMOOTHING: f64 = 6.0;

impl Default for ImitateConfig {
    fn default() -> Self {
        Self::jvrc1()
    }
}

/// The references of a run: `clip` retargeted with `map` ([`retarget_joint_angles`]), the joint samples
/// clamped into their (narrowed) ranges shrunk by `cfg.reference_margin` *before* the
/// interpolation (so the tracked references stay C²; the controller's own clamp then only trims
/// the splines' small overshoots), and resampled at `cfg.dt` ([`Retargeted::resample`]).
///
/// [`retarget_joint_angles`]: crate::motion::retarget_joint_angles
/// [`Retargeted::resample`]: crate::motion::Retargeted::resample
pub fn imitation_references(
    robot: &Robot,
    clip: &crate::motion::Clip,
    map: &crate::motion::RetargetMap,
    cfg: &ImitateConfig,
) -> Result<RobotReferences> {
    cfg.validate()?;
    let mut r = crate::motion::retarget_joint_angles(clip, robot, map)?;
    if let Some(fc) = cfg.smoothing {
        let low = |x: &[f64]| crate::motion::lowpass_track(x, &r.times, fc);
        let joints = r
            .joint_angles
            .iter()
            .map(|t| low(t))
            .collect::<Result<_>>()?;
        let height = low(&r.pelvis_height)?;
        let [a0, a1, a2] = &r.pelvis_angles;
        let angles = [low(a0)?, low(a1)?, low(a2)?];
        r.joint_angles = joints;
        r.pelvis_height = height;
        r.pelvis_angles = angles;
    }
    r.clamp_to_limits(robot, cfg.reference_margin)?;
    for n in &cfg.narrow {
        let (lo, hi) = crate::motion::shrunk_range(n.lower, n.upper, cfg.reference_margin);
        for (name, track) in r.joint_names.iter().zip(r.joint_angles.iter_mut()) {
            if *name == n.joint {
                for v in track.iter_mut() {
                    *v = v.clamp(lo, hi);
                }
            }
        }
    }
    r.resample_with(cfg.dt, &cfg.run_limits)
}

/// The handles of the tasks of Table 1 in an imitation's [`Controller`].
#[derive(Debug, Clone)]
pub struct ImitationTasks {
    /// The feet, 6D each, in the order of [`ImitateConfig::feet`] (level 1).
    pub feet: Vec<FrameHandle>,
    /// The COM in the horizontal plane (level 2).
    pub com: ComHandle,
    /// The pelvis attitude (level 3).
    pub pelvis_attitude: FrameHandle,
    /// The pelvis height (level 4).
    pub pelvis_height: FrameHandle,
    /// The upper-body joints, one row per reference joint (level 5).
    pub upper_body: JointsHandle,
}

/// Clamps the joint references into the (narrowed) ranges shrunk by `margin` \[rad\]; a
/// clamped sample's rate and acceleration become 0.
fn clamp_joint_references(
    robot: &Robot,
    limits: &JointLimits,
    refs: &mut RobotReferences,
    margin: f64,
) -> Result<()> {
    for (name, track) in refs.joint_names.iter().zip(refs.joints.iter_mut()) {
        let v = robot.joint_v_index(name)?;
        if let Some(d) = limits.get(v) {
            let (lo, hi) = crate::motion::shrunk_range(d.position_min, d.position_max, margin);
            for (p, (v, a)) in track
                .position
                .iter_mut()
                .zip(track.velocity.iter_mut().zip(track.acceleration.iter_mut()))
            {
                if *p < lo || *p > hi {
                    *p = p.clamp(lo, hi);
                    *v = 0.0;
                    *a = 0.0;
                }
            }
        }
    }
    Ok(())
}

/// The initial state: the neutral posture with `cfg.initial_posture` and the first joint
/// references; refused when outside the (narrowed) limits unless recovery was asked for.
fn initial_state(
    robot: &Robot,
    cfg: &ImitateConfig,
    refs: &RobotReferences,
    limits: &JointLimits,
) -> Result<State> {
    let mut state = State::neutral(robot);
    for (name, value) in &cfg.initial_posture {
        state.set_joint(robot, name, *value)?;
    }
    for (name, track) in refs.joint_names.iter().zip(&refs.joints) {
        if let Some(p) = track.position.first() {
            state.set_joint(robot, name, *p)?;
        }
    }
    // A start outside the (narrowed) limits is refused unless recovery was asked for.
    let mut pos = vec![0.0; robot.nv()];
    if cfg.bounds.outside_limits() == OutsideLimits::Error {
        state.dof_positions(robot, &mut pos)?;
        limits.check_state(&pos, state.qd.as_slice())?;
    }
    Ok(state)
}

/// Places the base so that the lowest foot frame is `ankle_height` \[m\] above z = 0; returns
/// the kinematics of the placed state and the feet's poses.
fn stand_on_ground(
    robot: &Robot,
    cfg: &ImitateConfig,
    state: &mut State,
) -> Result<(Kinematics, Vec<Isometry3<f64>>)> {
    let mut kin = Kinematics::new(robot, state)?;
    let feet_ids = cfg
        .feet
        .iter()
        .map(|f| robot.frame_id(f))
        .collect::<Result<Vec<_>>>()?;
    let lowest = feet_ids
        .iter()
        .map(|f| kin.frame_pose(robot, *f).map(|p| p.translation.z))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    let mut base = state.base_pose(robot);
    base.translation.vector.z += cfg.support.ankle_height - lowest;
    state.set_base_pose(robot, &base)?;
    kin.update(robot, state)?;
    let feet0 = feet_ids
        .iter()
        .map(|f| kin.frame_pose(robot, *f))
        .collect::<Result<Vec<_>>>()?;
    Ok((kin, feet0))
}

/// The COM reference: over the centre of the initial feet's support polygon (the mean of its
/// corners), at the COM's height \[m\].
fn com_over_support(
    kin: &Kinematics,
    feet0: &[Isometry3<f64>],
    cfg: &ImitateConfig,
) -> Result<Vector3<f64>> {
    let polygon = support_polygon(feet0, &cfg.support)?;
    let corners = polygon.vertices();
    let centre = corners
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let count = corners.len().max(1) as f64;
    Ok(Vector3::new(
        centre.0 / count,
        centre.1 / count,
        kin.com().z,
    ))
}

/// The controller with the stack of Table 1, each task created holding where the robot stands.
fn build_stack(
    robot: &Robot,
    cfg: &ImitateConfig,
    state: &State,
    limits: JointLimits,
    refs: &RobotReferences,
) -> Result<(Controller, ImitationTasks)> {
    let mut b = ControllerBuilder::new(std::sync::Arc::new(robot.clone()), state)?;
    b.gains(cfg.gains)
        .limits(limits)
        .settings(ControllerSettings {
            method: cfg.method,
            bounds: cfg.bounds,
            solver: cfg.solver,
        });
    b.level(LEVEL_NAMES[0]);
    let feet = cfg
        .feet
        .iter()
        .map(|f| b.frame(f, Axes::ALL))
        .collect::<Result<Vec<_>>>()?;
    let com = b.level(LEVEL_NAMES[1]).com([true, true, false])?;
    let pelvis_attitude = b
        .level(LEVEL_NAMES[2])
        .frame(&cfg.pelvis, Axes::ORIENTATION)?;
    let pelvis_height = b.level(LEVEL_NAMES[3]).frame(&cfg.pelvis, Axes::Z)?;
    let names: Vec<&str> = refs.joint_names.iter().map(|s| s.as_str()).collect();
    let upper_body = b.level(LEVEL_NAMES[4]).joints(&names)?;
    Ok((
        b.build()?,
        ImitationTasks {
            feet,
            com,
            pelvis_attitude,
            pelvis_height,
            upper_body,
        },
    ))
}

/// The closed loop of one imitation run: a [`Controller`] with the stack of Table 1, its
/// references and its state, sized once.
#[derive(Debug, Clone)]
pub struct ImitationController {
    ctl: Controller,
    tasks: ImitationTasks,
    dt: f64,
    refs: RobotReferences,
    state: State,
    upper: [Vec<f64>; 3],
    pelvis0: Isometry3<f64>,
    feet0: Vec<Isometry3<f64>>,
    com_ref: Vector3<f64>,
    com_start: Vector3<f64>,
    com_settle_time: f64,
    com_override: Option<ComReference>,
    tick: usize,
}

impl ImitationController {
    /// Builds the stack of Table 1 on `robot` for the references `refs` (one joint task row per
    /// reference joint), sets the initial state (posture, base placed so that the lowest sole is
    /// on z = 0), and holds the feet where they start and the COM over the centre of the support
    /// polygon.
    ///
    /// Errors: bad settings, unknown frames or joints, references whose period differs from
    /// `cfg.dt`, a narrowed range outside the joint's own, and
    /// [`Error::StateOutsideLimits`] for a start state (posture, first references) outside the
    /// (narrowed) limits unless `cfg.bounds` asks for [`OutsideLimits::Recover`].
    pub fn new(robot: &Robot, refs: &RobotReferences, cfg: &ImitateConfig) -> Result<Self> {
        cfg.validate()?;
        refs.validate()?;
        if (refs.dt - cfg.dt).abs() > 1e-12 * cfg.dt || refs.is_empty() {
            return Err(Error::InvalidSetting {
                name: "reference period".into(),
                value: format!("{} s, {} ticks", refs.dt, refs.len()),
                expected: format!("references resampled at dt = {} s", cfg.dt),
            });
        }
        let mut refs = refs.clone();
        // Limits, with the narrowed ranges.
        let limits = JointLimits::from_robot(robot)?.narrowed(&cfg.narrow)?;
        clamp_joint_references(robot, &limits, &mut refs, cfg.reference_margin)?;
        let mut state = initial_state(robot, cfg, &refs, &limits)?;
        let (kin, feet0) = stand_on_ground(robot, cfg, &mut state)?;
        let com_ref = com_over_support(&kin, &feet0, cfg)?;
        let com_start = kin.com();
        let pelvis_id = robot.frame_id(&cfg.pelvis)?;
        let pelvis0 = kin.frame_pose(robot, pelvis_id)?;
        let (ctl, tasks) = build_stack(robot, cfg, &state, limits, &refs)?;
        let m = refs.joint_names.len();
        Ok(Self {
            ctl,
            tasks,
            dt: cfg.dt,
            refs,
            state,
            upper: [vec![0.0; m], vec![0.0; m], vec![0.0; m]],
            pelvis0,
            feet0,
            com_ref,
            com_start,
            com_settle_time: cfg.com_settle_time,
            com_override: None,
            tick: 0,
        })
    }

    /// One control tick at reference index `k` (clamped to the last): kinematics, references,
    /// task linearisation, acceleration box, solve; q̈ is then available in
    /// [`ImitationController::qdd`] and not yet applied (see [`ImitationController::integrate`]).
    /// Allocates nothing.
    pub fn tick(&mut self, k: usize) -> Result<&SolveReport> {
        let k = k.min(self.refs.len().saturating_sub(1));
        self.tick = k;
        let r = &self.refs;
        let attitude = r.attitude.get(k).copied().unwrap_or_default() * self.pelvis0.rotation;
        let w = r.angular_velocity.get(k).copied().unwrap_or_default();
        let wd = r.angular_acceleration.get(k).copied().unwrap_or_default();
        let z = self.pelvis0.translation.z + r.height.position.get(k).copied().unwrap_or(0.0);
        let zd = r.height.velocity.get(k).copied().unwrap_or(0.0);
        let zdd = r.height.acceleration.get(k).copied().unwrap_or(0.0);
        for (i, t) in r.joints.iter().enumerate() {
            self.upper[0][i] = t.position.get(k).copied().unwrap_or(0.0);
            self.upper[1][i] = t.velocity.get(k).copied().unwrap_or(0.0);
            self.upper[2][i] = t.acceleration.get(k).copied().unwrap_or(0.0);
        }
        let com = match self.com_override {
            Some(c) => c,
            None => self.com_reference_at(k as f64 * self.dt),
        };
        let t = &self.tasks;
        self.ctl.set_com_reference(t.com, com)?;
        self.ctl.set_frame_reference(
            t.pelvis_attitude,
            FrameReference {
                pose: Isometry3::from_parts(self.pelvis0.translation, attitude),
                velocity: Vector6::new(0.0, 0.0, 0.0, w.x, w.y, w.z),
                acceleration: Vector6::new(0.0, 0.0, 0.0, wd.x, wd.y, wd.z),
            },
        )?;
        self.ctl.set_frame_reference(
            t.pelvis_height,
            FrameReference {
                pose: Isometry3::from_parts(
                    Translation3::new(self.pelvis0.translation.x, self.pelvis0.translation.y, z),
                    UnitQuaternion::identity(),
                ),
                velocity: Vector6::new(0.0, 0.0, zd, 0.0, 0.0, 0.0),
                acceleration: Vector6::new(0.0, 0.0, zdd, 0.0, 0.0, 0.0),
            },
        )?;
        self.ctl.set_joints_reference(
            t.upper_body,
            &self.upper[0],
            &self.upper[1],
            &self.upper[2],
        )?;
        self.ctl.prepare(&self.state, self.dt)?;
        self.ctl.solve()
    }

    /// Replaces the references of the feet tasks (level 1), one per foot in the order of
    /// [`ImitateConfig::feet`]: a walking pattern moves the feet this way. Allocates nothing.
    pub fn set_feet_references(&mut self, refs: &[FrameReference]) -> Result<()> {
        if refs.len() != self.tasks.feet.len() {
            check_dim("feet references", self.tasks.feet.len(), refs.len())?;
        }
        for (h, r) in self.tasks.feet.iter().zip(refs) {
            self.ctl.set_frame_reference(*h, *r)?;
        }
        Ok(())
    }

    /// Overrides the COM reference of the next ticks (a walking pattern plus the damping
    /// controller's offset); `None` returns to the standing reference. Allocates nothing.
    pub fn set_com_override(&mut self, r: Option<ComReference>) {
        self.com_override = r;
    }

    /// Applies the last q̈ over Δt (constant acceleration).
    ///
    /// Errors: no tick solved since the last integration.
    pub fn integrate(&mut self) -> Result<()> {
        self.ctl.integrate(&mut self.state)
    }

    /// The controller (stack, equations, box, solver) with the tasks of Table 1.
    pub fn controller(&self) -> &Controller {
        &self.ctl
    }

    /// The controller, to set a task's reference or gains through [`Self::tasks`]; the tick
    /// overwrites every reference but the feet's.
    pub fn controller_mut(&mut self) -> &mut Controller {
        &mut self.ctl
    }

    /// The handles of the tasks of Table 1.
    pub fn tasks(&self) -> &ImitationTasks {
        &self.tasks
    }

    /// The state (at the start of the next tick once integrated).
    pub fn state(&self) -> &State {
        &self.state
    }

    /// Kinematics at the state of the last tick.
    pub fn kinematics(&self) -> &Kinematics {
        self.ctl.kinematics()
    }

    /// The task equations of the last tick (errors `x_d − x` per level).
    pub fn equations(&self) -> &[TaskEquation] {
        self.ctl.equations()
    }

    /// The acceleration box of the last tick.
    pub fn acceleration_box(&self) -> &AccelerationBox {
        self.ctl.bounds()
    }

    /// q̈ of the last tick \[rad/s²\] (base: \[m/s²\], \[rad/s²\]).
    pub fn qdd(&self) -> &DVector<f64> {
        self.ctl.qdd()
    }

    /// Dof positions of the last tick \[rad\] (base entries 0).
    pub fn dof_positions(&self) -> &[f64] {
        self.ctl.dof_positions()
    }

    /// The limits used (narrowed).
    pub fn limits(&self) -> &JointLimits {
        self.ctl.limits()
    }

    /// The references (joint references clamped into the ranges).
    pub fn references(&self) -> &RobotReferences {
        &self.refs
    }

    /// Initial foot poses (held).
    pub fn feet0(&self) -> &[Isometry3<f64>] {
        &self.feet0
    }

    /// Initial pelvis pose.
    pub fn pelvis0(&self) -> &Isometry3<f64> {
        &self.pelvis0
    }

    /// The COM reference once settled \[m\]: the centre of the support polygon (z unused).
    pub fn com_reference(&self) -> Vector3<f64> {
        self.com_ref
    }

    /// The COM reference at time `t` \[s\]: `c(t) = c_0 + s(τ) (c_∞ − c_0)` with
    /// `τ = t / T` clamped to \[0, 1\] and the quintic `s = 10τ³ − 15τ⁴ + 6τ⁵`
    /// ([`crate::walk::smoothstep`]).
    pub fn com_reference_at(&self, t: f64) -> ComReference {
        let d = self.com_ref - self.com_start;
        let (s, sd, sdd) = crate::walk::smoothstep(0.0, self.com_settle_time, t);
        ComReference {
            // Once settled, exactly the centre (not c_0 + (c_∞ − c_0), which may round).
            position: if s >= 1.0 {
                self.com_ref
            } else {
                self.com_start + d * s
            },
            velocity: d * sd,
            acceleration: d * sdd,
        }
    }

    /// The solver's report of the last tick.
    pub fn report(&self) -> &SolveReport {
        self.ctl.report()
    }

    /// Reference index of the last tick.
    pub fn tick_index(&self) -> usize {
        self.tick
    }

    /// Level sizes m_i in priority order.
    pub fn level_dims(&self) -> Vec<usize> {
        self.ctl.level_dims().collect()
    }
}
