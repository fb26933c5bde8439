//! The humanoid walks while it imitates (Section 5.3 with the paper's own walking pattern for
//! the legs, and the damping controller of Section 4 in the loop).
//!
//! Per tick of Δt:
//!
//! 1. the walking pattern ([`crate::walk::WalkingPattern`]) gives both feet (pose, twist,
//!    acceleration), the COM by preview control, the ZMP reference and the support phase;
//! 2. the damping controller ([`crate::balance::BalanceController`]) reads the measured ZMP
//!    deviation of the simulated robot in the local frame of Figure 11 (SSP: at the stance
//!    foot; DSP: between the feet) and returns the COM offset Δc = l (u − u_ref), rotated to
//!    world axes; the COM task's reference is the pattern's COM plus Δc;
//! 3. the IK tick of the imitation ([`ImitationController`]): feet, COM, pelvis attitude and
//!    height, upper-body joints from the clip, under the joint box;
//! 4. the simulated robot: per plane an IPCJ with the robot's COM height as its length, the
//!    sensor lag, a true delay line and sensor noise ([`crate::balance::SimPlant`]), driven by
//!    the commanded COM's deviation from the pattern (u = deviation / l) and giving the measured
//!    ZMP deviation; its compliance switches with the support phase; a push is a force impulse
//!    on the COM.
//!
//! The simulated robot is the compliance dynamics about the nominal motion: the measured ZMP is
//! the pattern's cart-table ZMP plus the IPCJ's output. This is the model the controller is
//! designed on (the four synthetic cases of [`CaseParams::synthetic`] with the pendulum length
//! set to the robot's COM height), with a true delay instead of its Padé term.

use std::time::Instant;

use nalgebra::{
    Isometry3, Quaternion, Rotation2, Translation3, UnitQuaternion, Vector2, Vector3, Vector6,
};
use serde::Serialize;

use super::health::{HealthMonitor, HealthReport, Verdict};
use super::imitate::{check_state_finite, link_frames, ImitateConfig, ImitationController};
use super::margins::{dof_margins, held_limit, median, percentile, JointMargin};
use super::walk_plants::WalkPlants;
use crate::balance::{
    analyse_response, BalanceController, BalanceSettings, CaseParams, FullModelParams,
    ResponseSettings, SupportPhase,
};
use crate::controller::FrameHandle;
use crate::error::{Error, Result};
use crate::model::{FrameId, Kinematics, Robot, State};
use crate::motion::RobotReferences;
use crate::resources::MAX_ZMP_PASSES;
use crate::task::{ComReference, FrameReference};
use crate::walk::{
    link_masses, multibody_zmp, smoothstep, FootState, FootstepPlan, Phase, PreviewSettings, Side,
    SupportPolygon, WalkSample, WalkSettings, WalkingPattern,
};

/// How far inside the support polygon the ZMP correction brings the plan's ZMP \[m\]
/// ([`WalkingController::correct_zmp`]): a quarter of G1's 5 cm sole width, above the
/// measured ZMP's lag of a few millimetres behind the plan's in MuJoCo.
pub(crate) const ZMP_CORRECTION_MARGIN: f64 = 0.005;

/// A push on the COM during the walk.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Push {
    /// When \[s\].
    pub time: f64,
    /// Horizontal impulse (world x, y) \[N·s\].
    pub impulse: [f64; 2],
}

/// Settings of the walking imitation.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkImitateConfig {
    /// The imitation (stack, solver, bounds, narrowed joints, posture, soles).
    pub imitate: ImitateConfig,
    /// Number of footsteps (the last one closes the feet side by side).
    pub steps: usize,
    /// Step length along x \[m\]; 0 steps in place.
    pub step_length: f64,
    /// Walking timing and swing height; the foot separation and the sole size are taken from
    /// the robot's initial stance and [`ImitateConfig::support`].
    pub walk: WalkSettings,
    /// Preview control; the COM height is taken from the robot's initial COM.
    pub preview: PreviewSettings,
    /// Whether the damping controller is in the loop.
    pub damping: bool,
    /// The damping controller's design (poles, observer, hand-over).
    pub balance: BalanceSettings,
    /// The four compliance cases (their pendulum length is replaced by the COM height).
    pub cases: CaseParams,
    /// An optional push.
    pub push: Option<Push>,
    /// Standard deviation of the ZMP sensor noise \[m\].
    pub noise_std: f64,
    /// Seed of the sensor noise.
    pub seed: u64,
    /// The initial difference between the robot's COM and the pattern's is blended out over
    /// this time \[s\] (quintic, zero rate and acceleration at both ends).
    pub com_blend_time: f64,
    /// Most passes of the ZMP correction of the COM reference
    /// ([`WalkingController::correct_zmp_passes`]: fewer run once a pass stops improving); 0
    /// plans on the cart-table alone (the paper's pattern, the default). At most
    /// [`MAX_ZMP_PASSES`].
    pub zmp_passes: usize,
}

impl WalkImitateConfig {
    /// The default run on JVRC-1: the imitation defaults, 4 steps of 0.1 m (0.6 s single
    /// support, 0.1 s double support, 0.8 s initial and final double support, 4 cm swing), the
    /// damping controller on, a forward push of 5 N·s at 2.15 s (single support), 1 mm noise.
    pub fn jvrc1() -> Result<Self> {
        Ok(Self {
            imitate: ImitateConfig::jvrc1(),
            steps: 4,
            step_length: 0.1,
            walk: WalkSettings {
                ssp_duration: 0.6,
                dsp_duration: 0.1,
                initial_dsp_duration: 0.8,
                final_dsp_duration: 0.8,
                swing_height: 0.04,
                ..WalkSettings::default()
            },
            preview: PreviewSettings::default(),
            damping: true,
            balance: BalanceSettings::default(),
            cases: CaseParams::synthetic()?,
            push: Some(Push {
                time: 2.15,
                impulse: [5.0, 0.0],
            }),
            noise_std: 1e-3,
            seed: 7,
            com_blend_time: 0.5,
            zmp_passes: 0,
        })
    }
}

/// One recorded tick.
#[derive(Debug, Clone, Serialize)]
pub struct WalkStep {
    /// Time \[s\].
    pub t: f64,
    /// The support phase (with the stance foot in single support).
    pub phase: Phase,
    /// ZMP reference of the pattern (world) \[m\].
    pub zmp_reference: [f64; 2],
    /// ZMP of the pattern's cart-table model (world) \[m\].
    pub zmp_model: [f64; 2],
    /// Measured ZMP of the simulated robot (world) \[m\].
    pub zmp_measured: [f64; 2],
    /// Signed distance of the measured ZMP inside the support polygon \[m\] (negative: outside).
    pub zmp_margin: f64,
    /// Measured ZMP deviation in the local frame (x̃, ỹ) \[m\].
    pub zmp_deviation: [f64; 2],
    /// The pattern's COM (world) \[m\].
    pub com_pattern: [f64; 2],
    /// The COM reference given to the IK (pattern, blend and Δc) \[m\].
    pub com_reference: [f64; 2],
    /// The commanded COM (the IK's robot) \[m\].
    pub com: [f64; 3],
    /// The damping controller's offset Δc (world) \[m\].
    pub com_offset: [f64; 2],
    /// Left and right ankle references (world) \[m\].
    pub feet_reference: [[f64; 3]; 2],
    /// Left and right ankles achieved (world) \[m\].
    pub feet: [[f64; 3]; 2],
    /// The pattern's support polygon (world, counter-clockwise) \[m\]: the stance sole, or
    /// the hull of both soles ([`WalkingPattern::support_polygon_into`]).
    #[serde(skip)]
    pub support: Vec<[f64; 2]>,
    /// Level (0-based) IKTC corrected from; `None` without correction.
    pub corrected_from: Option<usize>,
    /// QPs this tick.
    pub qp_solves: usize,
    /// Tick time: pattern sample, damping controller and IK \[µs\].
    pub tick_us: f64,
    /// World positions of every link \[m\] (for the viewer).
    #[serde(skip)]
    pub links: Vec<[f64; 3]>,
    /// Orientation of every link in the world, unit quaternion (x, y, z, w) (for the viewer's
    /// meshes).
    #[serde(skip)]
    pub link_rotations: Vec<[f64; 4]>,
    /// Dof positions (joint angles; 0 for the base) \[rad\].
    #[serde(skip)]
    pub q: Vec<f64>,
    /// Dof velocities.
    #[serde(skip)]
    pub qd: Vec<f64>,
    /// Dof accelerations.
    #[serde(skip)]
    pub qdd: Vec<f64>,
}

/// The run's summary.
#[derive(Debug, Clone, Serialize)]
pub struct WalkSummary {
    /// Whether the damping controller was in the loop.
    pub damping: bool,
    /// The soft approach's rate \[1/s\] as used at the run's Δt (0 without it), as in
    /// [`ImitateSummary::approach_rate`](crate::sim::ImitateSummary).
    pub approach_rate: f64,
    /// Cut-off of the low-pass applied to the clip \[Hz\] (`None`: as captured).
    pub smoothing_hz: Option<f64>,
    /// Footsteps.
    pub steps: usize,
    /// Duration \[s\].
    pub duration: f64,
    /// Smallest signed distance of the measured ZMP inside the support polygon \[m\].
    pub min_zmp_margin: f64,
    /// The measured ZMP stayed inside the support polygon at every tick.
    pub zmp_inside: bool,
    /// Single-support ticks where the ZMP of the commanded motion itself (the links' masses
    /// and inertias, [`multibody_zmp`]) is outside the pattern's support polygon, or the body
    /// falls faster than gravity: no plant can follow the plan there without tipping, what
    /// the pattern's cart-table model does not see (the upper body's own motion).
    pub plan_zmp_outside_single: usize,
    /// The same in double support.
    pub plan_zmp_outside_double: usize,
    /// Smallest signed distance of the commanded motion's ZMP inside the support polygon \[m\]
    /// (−∞ where the body falls faster than gravity).
    pub plan_zmp_min_margin: f64,
    /// Per pass of the ZMP correction run ([`WalkingController::correct_zmp_passes`]), the
    /// largest move `|Δp|` it asked of the plan's ZMP \[m\] (empty without correction).
    pub zmp_corrections: Vec<f64>,
    /// Largest horizontal error of a stance foot's ankle against its reference \[m\].
    pub max_stance_foot_error: f64,
    /// Largest horizontal drift of a stance foot within one stance interval \[m\].
    pub max_stance_foot_slip: f64,
    /// Worst signed margins over all joints (position \[rad\], velocity \[rad/s\],
    /// acceleration \[rad/s²\]); ≤ 0: no limit exceeded.
    pub worst_margins: [f64; 3],
    /// Margins of every joint (narrowed ranges).
    pub margins: Vec<JointMargin>,
    /// The response to the push, in both horizontal directions; absent (`None`, left out
    /// of the JSON) without a push.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub push: Option<WalkPushSummary>,
    /// The run's checks: feet on their references, state finite, measured ZMP inside the
    /// support polygon.
    pub health: HealthReport,
    /// Ticks whose correction started above the lowest level.
    pub climbed_ticks: usize,
    /// Ticks with any correction.
    pub corrected_ticks: usize,
    /// How often the corrected level changed between consecutive corrected ticks.
    pub level_switches: crate::sim::LevelSwitches,
    /// Smoothness of the commanded q̈ of every joint (jerk, sign reversals of its change).
    pub smoothness: Vec<crate::sim::JointSmoothness>,
    /// The worst of `smoothness` over the joints.
    pub smoothness_worst: crate::sim::DofSmoothness,
    /// Median tick time \[µs\].
    pub tick_median_us: f64,
    /// 99th percentile tick time \[µs\].
    pub tick_p99_us: f64,
}

/// The response of the measured ZMP deviation along one horizontal axis of the local frame
/// of Figure 11 after a push ([`analyse_response`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PushAxisMetrics {
    /// Largest |deviation| after the push \[m\].
    pub peak: f64,
    /// Time of the peak after the push \[s\].
    pub peak_time: f64,
    /// Time after the push from which the deviation stays in its settling band \[s\];
    /// absent (left out of the JSON) if it never settles within the run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub settling_time: Option<f64>,
    /// Damping ratio of the fitted dominant mode \[–\]; absent (left out of the JSON) when
    /// the peak stays within the noise floor (`noise_sigmas` standard deviations of the
    /// sensor noise): there is no response to fit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping_ratio: Option<f64>,
    /// Natural frequency of the fitted mode \[rad/s\]; absent as the damping ratio.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub natural_frequency: Option<f64>,
}

/// The response to a push during the walk.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WalkPushSummary {
    /// The push.
    pub push: Push,
    /// Along the local x̃ axis (forward).
    pub x: PushAxisMetrics,
    /// Along the local ỹ axis (left).
    pub y: PushAxisMetrics,
    /// Smallest signed distance of the measured ZMP inside the support polygon from the
    /// push on \[m\].
    pub zmp_min_margin: f64,
    /// Largest distance of the measured ZMP outside the support polygon from the push on
    /// \[m\] (0: it stayed inside).
    pub zmp_excursion: f64,
}

/// A whole run.
#[derive(Debug, Clone, Serialize)]
pub struct WalkRun {
    /// Every tick.
    pub steps: Vec<WalkStep>,
    /// The footsteps (foot, world x \[m\], y \[m\], yaw \[rad\]), initial feet first.
    pub footsteps: Vec<(Side, [f64; 3])>,
    /// The phase intervals (start, end \[s\], phase).
    pub phases: Vec<(f64, f64, Phase)>,
    /// Summary.
    pub summary: WalkSummary,
}

fn with_length(m: &FullModelParams, l: f64) -> FullModelParams {
    let mut m = *m;
    m.ipcj.length = l;
    m
}

fn ankle_reference(
    foot: &FootState,
    offset: &Vector3<f64>,
    origin: &Vector2<f64>,
) -> FrameReference {
    let a = foot.offset(offset);
    let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a.yaw);
    let tw = a.twist();
    let ac = a.acceleration();
    FrameReference {
        pose: Isometry3::from_parts(
            Translation3::new(
                a.position.x + origin.x,
                a.position.y + origin.y,
                a.position.z,
            ),
            rotation,
        ),
        velocity: Vector6::from_row_slice(&tw),
        acceleration: Vector6::from_row_slice(&ac),
    }
}

/// Checks the settings [`WalkingController::new`] needs before anything is built: the
/// preview's period equal to the control period \[s\], two feet, and the ZMP passes within
/// [`MAX_ZMP_PASSES`].
fn check_walk_settings(cfg: &WalkImitateConfig) -> Result<()> {
    let dt = cfg.imitate.dt;
    if (cfg.preview.dt - dt).abs() > 1e-12 {
        return Err(Error::InvalidSetting {
            name: "preview.dt".into(),
            value: cfg.preview.dt.to_string(),
            expected: format!("the control period {dt} s"),
        });
    }
    if cfg.imitate.feet.len() != 2 {
        return Err(Error::InvalidSetting {
            name: "imitate.feet".into(),
            value: cfg.imitate.feet.join(","),
            expected: "two feet: right, then left".into(),
        });
    }
    if cfg.zmp_passes > MAX_ZMP_PASSES {
        return Err(Error::InvalidSetting {
            name: "zmp_passes (CLI --zmp-passes)".into(),
            value: cfg.zmp_passes.to_string(),
            expected: format!("at most {MAX_ZMP_PASSES} passes (resources::MAX_ZMP_PASSES)"),
        });
    }
    Ok(())
}

/// The footstep plan (in place when `step_length` is 0, else forward) and its walking pattern,
/// the pattern's duration \[s\] checked against the run limits.
fn plan_walk(
    cfg: &WalkImitateConfig,
    walk: &WalkSettings,
    preview: &PreviewSettings,
) -> Result<(FootstepPlan, WalkingPattern)> {
    let dt = cfg.imitate.dt;
    let plan = if cfg.step_length == 0.0 {
        FootstepPlan::in_place(cfg.steps, walk)?
    } else {
        FootstepPlan::forward(cfg.steps, cfg.step_length, walk)?
    };
    let pattern = WalkingPattern::new(&plan, walk, preview)?;
    cfg.imitate
        .run_limits
        .ticks("the walk", pattern.duration(), dt)?;
    Ok((plan, pattern))
}

/// The four cases with the pendulum length set to `l` \[m\].
fn cases_with_length(cases: &CaseParams, l: f64) -> CaseParams {
    CaseParams {
        xz_ssp: with_length(&cases.xz_ssp, l),
        xz_dsp: with_length(&cases.xz_dsp, l),
        yz_ssp: with_length(&cases.yz_ssp, l),
        yz_dsp: with_length(&cases.yz_dsp, l),
    }
}

/// What one tick of the [`WalkingController`] decided.
#[derive(Debug, Clone, Copy)]
pub struct WalkTick {
    /// The pattern at this tick (pattern frame: add [`WalkingController::origin`] for world).
    pub sample: WalkSample,
    /// The support phase.
    pub phase: SupportPhase,
    /// Yaw of the local frame of Figure 11 \[rad\].
    pub local_yaw: f64,
    /// The damping controller's COM offset Δc, world axes \[m\].
    pub com_offset: Vector2<f64>,
    /// The COM reference given to the IK, world \[m\].
    pub com_reference: Vector2<f64>,
    /// The nominal COM (pattern and initial blend, without Δc), world \[m\].
    pub com_nominal: Vector2<f64>,
    /// Level (0-based) IKTC corrected from; `None` without correction.
    pub corrected_from: Option<usize>,
    /// QPs this tick.
    pub qp_solves: usize,
}

/// The walking imitation's control loop — walking pattern, damping controller and the IK of
/// the imitation — sized once; [`WalkingController::tick`] allocates nothing.
#[derive(Debug, Clone)]
pub struct WalkingController {
    ctl: ImitationController,
    plan: FootstepPlan,
    pattern: WalkingPattern,
    bal: BalanceController,
    cases: CaseParams,
    damping: bool,
    dt: f64,
    origin: Vector2<f64>,
    ankle_offset: Vector3<f64>,
    com0: Vector3<f64>,
    blend0: Vector2<f64>,
    com_blend_time: f64,
    /// The handles of the right and left foot tasks.
    feet: [FrameHandle; 2],
    /// Their references of the last tick (right, left).
    feet_refs: [FrameReference; 2],
    dc_prev: Vector2<f64>,
    dcd_prev: Vector2<f64>,
    /// Whether Δc's rate and acceleration are fed forward to the COM task.
    offset_feedforward: bool,
    /// The ground plane's height \[m\] (the soles at the start).
    ground: f64,
    /// Per tick, the multibody correction of the COM reference, world x then y, each
    /// (position \[m\], rate \[m/s\], acceleration \[m/s²\]); empty without correction.
    com_correction: Vec<[[f64; 3]; 2]>,
    /// Per ZMP correction pass, the largest move it asked of the ZMP \[m\].
    zmp_corrections: Vec<f64>,
}

impl WalkingController {
    /// Builds the imitation controller, the walking pattern (feet and COM of the robot's
    /// initial stance, COM height as the cart-table height) and the damping controller (the
    /// four cases with the COM height as pendulum length).
    pub fn new(robot: &Robot, refs: &RobotReferences, cfg: &WalkImitateConfig) -> Result<Self> {
        let dt = cfg.imitate.dt;
        check_walk_settings(cfg)?;
        // Before the footsteps are planned: the walk lasts at least steps × ssp_duration.
        cfg.imitate.run_limits.ticks(
            "the walk",
            cfg.steps as f64 * cfg.walk.ssp_duration.max(0.0),
            dt,
        )?;
        let ctl = ImitationController::new(robot, refs, &cfg.imitate)?;
        // The imitation lists the right foot first, then the left.
        let (r0, l0) = (ctl.feet0()[0], ctl.feet0()[1]);
        let feet = [ctl.tasks().feet[0], ctl.tasks().feet[1]];
        let support = cfg.imitate.support;
        // The pattern plans the soles' centres: `sole_offset_x` ahead of each ankle along its
        // foot's x axis (the sole of the imitation's support polygon).
        let sole_centre = |ankle: &Isometry3<f64>| {
            let r = ankle.rotation * Vector3::new(support.sole_offset_x, 0.0, 0.0);
            Vector2::new(ankle.translation.x + r.x, ankle.translation.y + r.y)
        };
        let (rs, ls) = (sole_centre(&r0), sole_centre(&l0));
        let origin = Vector2::new(0.5 * (rs.x + ls.x), 0.5 * (rs.y + ls.y));
        // The ankle from the sole centre, foot axes.
        let ankle_offset = Vector3::new(
            -support.sole_offset_x,
            0.0,
            r0.translation.z.min(l0.translation.z),
        );
        let com0 = ctl.kinematics().com();
        let walk = WalkSettings {
            foot_separation: (ls.y - rs.y).abs(),
            sole_length: support.sole_length,
            sole_width: support.sole_width,
            ..cfg.walk
        };
        let preview = PreviewSettings {
            com_height: com0.z,
            dt,
            ..cfg.preview
        };
        let (plan, pattern) = plan_walk(cfg, &walk, &preview)?;
        let cases = cases_with_length(&cfg.cases, com0.z);
        let bal = BalanceController::new(&cases, &cfg.balance, SupportPhase::Double)?;
        let s0 = pattern.sample(0.0)?;
        let blend0 = Vector2::new(
            com0.x - origin.x - s0.com.position.x,
            com0.y - origin.y - s0.com.position.y,
        );
        let ground = r0.translation.z.min(l0.translation.z) - support.ankle_height;
        let mut wc = Self {
            feet_refs: [FrameReference::hold(r0), FrameReference::hold(l0)],
            feet,
            ctl,
            plan,
            pattern,
            bal,
            cases,
            damping: cfg.damping,
            dt,
            origin,
            ankle_offset,
            com0,
            blend0,
            com_blend_time: cfg.com_blend_time,
            dc_prev: Vector2::zeros(),
            dcd_prev: Vector2::zeros(),
            offset_feedforward: true,
            ground,
            com_correction: Vec::new(),
            zmp_corrections: Vec::new(),
        };
        wc.correct_zmp_passes(cfg.zmp_passes)?;
        Ok(wc)
    }

    /// One pass of the ZMP correction, after the second stage of Kajita et al. 2003 but only
    /// where the plan is infeasible. A copy of this controller runs the whole walk without the
    /// damping controller; the ZMP of its links' motion `p_mb` ([`multibody_zmp`]) is taken,
    /// tick by tick, against the pattern's support polygon: where it is less than
    /// 5 mm inside (or outside), `Δp` is the shortest move along the
    /// segment to the pattern's ZMP reference `p_target` that brings it that far inside,
    /// elsewhere 0. The COM that the preview controller makes the cart-table follow for `Δp`
    /// is added to the COM reference (with its rate and acceleration): moving the cart-table's
    /// COM by Δc moves its ZMP by Δp, and the links' ZMP responds to the COM as the cart-table's
    /// does as far as the upper body's own motion is unchanged. `p_target` is the cart-table
    /// ZMP of the COM the controller asks for: the pattern's plus the blend of the initial
    /// offset, `b − (z_c/g) b̈`. A plan already inside by the margin is left as it is. Returns
    /// the largest `|Δp|` \[m\] of this pass (also in
    /// [`WalkingController::zmp_corrections`]). Allocates (once per pass, not per tick).
    pub fn correct_zmp(&mut self) -> Result<f64> {
        let n = self.ticks();
        let mut sim = self.clone();
        sim.damping = false;
        let mut poses = Vec::with_capacity(n);
        let mut target = Vec::with_capacity(n);
        let (zc, g) = (
            self.com0.z - self.ground,
            self.pattern.controller().settings().gravity,
        );
        for k in 0..n {
            let wt = sim.tick(k, [0.0, 0.0])?;
            poses.push(sim.ctl.kinematics().link_poses().to_vec());
            let t = k as f64 * self.dt;
            let (s, _, sdd) = smoothstep(0.0, self.com_blend_time, t);
            let blend = self.blend0 * (1.0 - s) + self.blend0 * (zc / g) * sdd;
            let m = wt.sample.zmp_model;
            target.push([m.0 + self.origin.x + blend.x, m.1 + self.origin.y + blend.y]);
            sim.integrate()?;
        }
        let zmp = multibody_zmp(
            &link_masses(self.ctl.controller().robot()),
            &poses,
            self.dt,
            self.ground,
            g,
        )?;
        let mut polygon = SupportPolygon::default();
        let mut dx = vec![0.0; n];
        let mut dy = vec![0.0; n];
        for k in 0..n {
            // A tick where the body falls faster than gravity has no ZMP to move.
            let Some(p) = zmp[k] else { continue };
            self.pattern
                .support_polygon_into(k as f64 * self.dt, &mut polygon)?;
            let local = (p[0] - self.origin.x, p[1] - self.origin.y);
            let r = (target[k][0] - self.origin.x, target[k][1] - self.origin.y);
            let q = polygon.pull_towards(local, r, ZMP_CORRECTION_MARGIN);
            dx[k] = q.0 - local.0;
            dy[k] = q.1 - local.1;
        }
        let residual = dx
            .iter()
            .zip(&dy)
            .map(|(x, y)| x.hypot(*y))
            .fold(0.0, f64::max);
        let ctrl = self.pattern.controller();
        let (cx, cy) = (ctrl.track(&dx)?, ctrl.track(&dy)?);
        if self.com_correction.len() != n {
            self.com_correction = vec![[[0.0; 3]; 2]; n];
        }
        for (c, (sx, sy)) in self.com_correction.iter_mut().zip(cx.iter().zip(&cy)) {
            for (axis, sample) in c.iter_mut().zip([sx, sy]) {
                for (v, d) in axis.iter_mut().zip(sample.state.iter()) {
                    *v += d;
                }
            }
        }
        self.zmp_corrections.push(residual);
        Ok(residual)
    }

    /// Up to `passes` passes of [`WalkingController::correct_zmp`], stopping at the first
    /// that finds the plan inside the margin (`|Δp|` = 0) or whose `|Δp|` is not smaller
    /// than the pass before: the correction of that earlier pass made the plan's ZMP worse
    /// (the links' ZMP does not respond to the COM exactly as the cart-table's does, and
    /// repeated corrections then overshoot), so it is undone; so is one whose plan's
    /// simulation fails. On G1 walking with DeepMimic's `dance_b` (`tests/walk_imitate.rs`)
    /// `|Δp|` went 0.446, 0.339, then 0.470 m: the second pass's correction was undone and
    /// the passes ended there. The kept correction is the
    /// one whose plan had the smallest `|Δp|` measured. Returns the passes run.
    pub fn correct_zmp_passes(&mut self, passes: usize) -> Result<usize> {
        // (|Δp| of the plan before a pass, the COM correction before that pass).
        let mut last: Option<(f64, Vec<[[f64; 3]; 2]>)> = None;
        for pass in 0..passes {
            let before = self.com_correction.clone();
            let measured = self.correct_zmp();
            if let Some((previous, undo)) = last.take() {
                // A plan whose simulation fails (q̈ not finite) is worse too.
                if measured.as_ref().map_or(true, |r| *r >= previous) {
                    self.com_correction = undo;
                    return Ok(pass + 1);
                }
            }
            let residual = measured?;
            if residual == 0.0 {
                return Ok(pass + 1);
            }
            last = Some((residual, before));
        }
        Ok(passes)
    }

    /// Per ZMP correction pass, the largest move `|Δp|` it asked of the ZMP \[m\] (empty
    /// without correction; a pass that found the plan feasible reports 0).
    pub fn zmp_corrections(&self) -> &[f64] {
        &self.zmp_corrections
    }

    /// Whether the damping controller's COM offset Δc reaches the COM task with its backward
    /// differences (rate, acceleration) fed forward (the default: the commanded COM follows Δc
    /// within a tick) or as a position alone (the COM task's CLIK then follows it through its
    /// second-order response, as in an identification that sweeps the COM reference).
    pub fn set_offset_feedforward(&mut self, on: bool) {
        self.offset_feedforward = on;
    }

    /// Ticks in the walk (its duration over Δt, plus one).
    pub fn ticks(&self) -> usize {
        (self.pattern.duration() / self.dt).round() as usize + 1
    }

    /// The walking pattern (its own frame; see [`WalkingController::origin`]).
    pub fn pattern(&self) -> &WalkingPattern {
        &self.pattern
    }

    /// The footstep plan.
    pub fn plan(&self) -> &FootstepPlan {
        &self.plan
    }

    /// World position of the pattern's origin (between the initial sole centres) \[m\].
    pub fn origin(&self) -> Vector2<f64> {
        self.origin
    }

    /// The four compliance cases with the pendulum length set to the COM height.
    pub fn cases(&self) -> &CaseParams {
        &self.cases
    }

    /// Pendulum length: the initial COM height \[m\].
    pub fn pendulum_length(&self) -> f64 {
        self.com0.z
    }

    /// The imitation's controller (state, kinematics, solver report, limits).
    pub fn imitation(&self) -> &ImitationController {
        &self.ctl
    }

    /// The feet references of the last tick (left, right).
    pub fn feet_references(&self) -> [FrameReference; 2] {
        [self.feet_refs[1], self.feet_refs[0]]
    }

    /// One control tick at index `k` with the measured ZMP deviation `zmp` (x̃, ỹ in the local
    /// frame of Figure 11) \[m\]: pattern sample, damping controller, COM and feet references,
    /// IK solve. q̈ is then in the imitation controller, applied by
    /// [`WalkingController::integrate`]. Allocates nothing.
    pub fn tick(&mut self, k: usize, zmp: [f64; 2]) -> Result<WalkTick> {
        let dt = self.dt;
        let t = k as f64 * dt;
        let s = self.pattern.sample(t)?;
        let phase = match s.phase {
            Phase::DoubleSupport => SupportPhase::Double,
            Phase::SingleSupport { .. } => SupportPhase::Single,
        };
        // Local frame of Figure 11: yaw of the stance foot (SSP) or of both feet (DSP).
        let yaw = match s.phase {
            Phase::DoubleSupport => 0.5 * (s.left.yaw + s.right.yaw),
            Phase::SingleSupport { stance } => s.foot(stance).yaw,
        };
        let rot = Rotation2::new(yaw);
        let offset_world = if self.damping {
            let out = self.bal.step(phase, [0.0, 0.0], zmp)?;
            rot * Vector2::new(out.com_offset[0], out.com_offset[1])
        } else {
            Vector2::zeros()
        };
        // COM reference: pattern + blend of the initial offset + Δc, with Δc's backward
        // differences fed forward so that the commanded COM follows it within a tick.
        // The blend is 1 − s(t) of the quintic smoothstep over the blend time.
        let (s_blend, sd_blend, sdd_blend) = smoothstep(0.0, self.com_blend_time, t);
        let (b, bd, bdd) = (1.0 - s_blend, -sd_blend, -sdd_blend);
        let (origin, blend0) = (self.origin, self.blend0);
        let cp = s.com.position;
        let corr = self.com_correction.get(k).copied().unwrap_or([[0.0; 3]; 2]);
        let nominal =
            Vector2::new(cp.x + origin.x + corr[0][0], cp.y + origin.y + corr[1][0]) + blend0 * b;
        let cref = nominal + offset_world;
        let dcd = (offset_world - self.dc_prev) / dt;
        let dcdd = (dcd - self.dcd_prev) / dt;
        self.dc_prev = offset_world;
        self.dcd_prev = dcd;
        let (dcd, dcdd) = if self.offset_feedforward {
            (dcd, dcdd)
        } else {
            (Vector2::zeros(), Vector2::zeros())
        };
        self.ctl.set_com_override(Some(ComReference {
            position: Vector3::new(cref.x, cref.y, self.com0.z),
            velocity: Vector3::new(
                s.com.velocity.x + blend0.x * bd + dcd.x + corr[0][1],
                s.com.velocity.y + blend0.y * bd + dcd.y + corr[1][1],
                0.0,
            ),
            acceleration: Vector3::new(
                s.com.acceleration.x + blend0.x * bdd + dcdd.x + corr[0][2],
                s.com.acceleration.y + blend0.y * bdd + dcdd.y + corr[1][2],
                0.0,
            ),
        }));
        self.feet_refs[0] = ankle_reference(&s.right, &self.ankle_offset, &origin);
        self.feet_refs[1] = ankle_reference(&s.left, &self.ankle_offset, &origin);
        for (h, r) in self.feet.iter().zip(&self.feet_refs) {
            self.ctl.controller_mut().set_frame_reference(*h, *r)?;
        }
        let rep = self.ctl.tick(k)?;
        Ok(WalkTick {
            sample: s,
            phase,
            local_yaw: yaw,
            com_offset: offset_world,
            com_reference: cref,
            com_nominal: nominal,
            corrected_from: rep.corrected_from,
            qp_solves: rep.qp_solves,
        })
    }

    /// Applies the last q̈ over Δt.
    pub fn integrate(&mut self) -> Result<()> {
        self.ctl.integrate()
    }
}

/// Runs the walking imitation on the simulated compliant robot, each tick checked by a
/// [`HealthMonitor`] with the imitation's [`ImitateConfig::health`]: each foot's ankle
/// (position \[m\] and rotation \[rad\]) against its reference from the walking pattern, the
/// state and the measured ZMP finite, and the measured ZMP inside the pattern's support
/// polygon ([`WalkingPattern::support_polygon_into`]).
///
/// Errors: bad settings or references, and [`Error::RunFailed`] when a check fails (unless
/// [`crate::sim::HealthSettings::keep_going`]; see [`crate::sim::health`]).
pub fn run_walk_imitate(
    robot: &Robot,
    refs: &RobotReferences,
    cfg: &WalkImitateConfig,
) -> Result<WalkRun> {
    let dt = cfg.imitate.dt;
    let mut wc = WalkingController::new(robot, refs, cfg)?;
    let feet_ids = cfg
        .imitate
        .feet
        .iter()
        .map(|f| robot.frame_id(f))
        .collect::<Result<Vec<_>>>()?;
    let origin = wc.origin();
    let mut plants = WalkPlants::new(&wc, robot.total_mass(), cfg)?;
    let n = wc.ticks();
    let mut steps = Vec::with_capacity(n);
    let mut polygon = SupportPolygon::default();
    let mut health = HealthMonitor::new(cfg.imitate.health)?;
    let dof_names = robot.dof_names();
    for k in 0..n {
        let t = k as f64 * dt;
        // Measured ZMP deviation of the simulated robot, local frame.
        let dev = plants.measure();
        let start = Instant::now();
        let wt = wc.tick(k, dev)?;
        let tick_us = start.elapsed().as_secs_f64() * 1e6;
        let s = &wt.sample;
        let rot = Rotation2::new(wt.local_yaw);
        let ctl = wc.imitation();
        let kin = ctl.kinematics();
        let com = kin.com();
        plants.step(k, &wc, &wt)?;
        // Record.
        let zdev = rot * Vector2::new(dev[0], dev[1]);
        let zm = (
            s.zmp_model.0 + origin.x + zdev.x,
            s.zmp_model.1 + origin.y + zdev.y,
        );
        if check_state_finite(
            &mut health,
            t,
            &dof_names,
            ctl,
            &com,
            &[("measured ZMP [m]", &[zm.0, zm.1])],
        )? == Verdict::Stop
        {
            break;
        }
        wc.pattern().support_polygon_into(t, &mut polygon)?;
        let zmp_margin = polygon.margin((zm.0 - origin.x, zm.1 - origin.y));
        let frefs = wc.feet_references();
        let feet = check_feet(robot, cfg, kin, &mut health, t, &feet_ids, &frefs)?;
        health.check_support(
            t,
            &polygon,
            (zm.0 - origin.x, zm.1 - origin.y),
            "measured ZMP",
            "world axes, origin between the initial sole centres",
        )?;
        health.end_tick();
        let measured = TickMeasure {
            t,
            com,
            zmp_measured: zm,
            zmp_margin,
            zmp_deviation: dev,
            tick_us,
            feet,
        };
        steps.push(walk_step(&wt, ctl, origin, &polygon, &frefs, measured));
        wc.integrate()?;
    }
    finish_walk_run(robot, cfg, &wc, steps, health.report())
}

/// Checks each foot's ankle (right, then left) against its reference at time `t` \[s\]:
/// position error \[m\] and rotation error \[rad\]; returns the ankles' positions \[m\] in the
/// order of the references (left, right).
fn check_feet(
    robot: &Robot,
    cfg: &WalkImitateConfig,
    kin: &Kinematics,
    health: &mut HealthMonitor,
    t: f64,
    feet_ids: &[FrameId],
    frefs: &[FrameReference; 2],
) -> Result<[[f64; 3]; 2]> {
    let mut feet = [[0.0; 3]; 2];
    for ((slot, id), (r, name)) in feet.iter_mut().zip([feet_ids[1], feet_ids[0]]).zip(
        frefs
            .iter()
            .zip([&cfg.imitate.feet[1], &cfg.imitate.feet[0]]),
    ) {
        let pose = kin.frame_pose(robot, id)?;
        let p = pose.translation.vector;
        *slot = [p.x, p.y, p.z];
        health.check_foot(
            t,
            name,
            (p - r.pose.translation.vector).norm(),
            pose.rotation.angle_to(&r.pose.rotation),
        )?;
    }
    Ok(feet)
}

/// What one tick of [`run_walk_imitate`] measured beside the controller's state: time \[s\],
/// the COM before the plants' step \[m\], measured ZMP (world axes) \[m\], its support margin \[m\], the plant's ZMP deviation (local
/// frame) \[m\], the tick's wall-clock time \[µs\] and the ankles' positions \[m\].
struct TickMeasure {
    t: f64,
    com: Vector3<f64>,
    zmp_measured: (f64, f64),
    zmp_margin: f64,
    zmp_deviation: [f64; 2],
    tick_us: f64,
    feet: [[f64; 3]; 2],
}

/// The recorded [`WalkStep`] of one tick: the pattern's sample and the controller's state,
/// shifted from the pattern's frame to world axes by `origin` \[m\].
fn walk_step(
    wt: &WalkTick,
    ctl: &ImitationController,
    origin: Vector2<f64>,
    polygon: &SupportPolygon,
    frefs: &[FrameReference; 2],
    m: TickMeasure,
) -> WalkStep {
    let s = &wt.sample;
    let kin = ctl.kinematics();
    let com = m.com;
    let (links, link_rotations) = link_frames(kin);
    let state: &State = ctl.state();
    let fr = |r: &FrameReference| {
        let p = r.pose.translation.vector;
        [p.x, p.y, p.z]
    };
    WalkStep {
        t: m.t,
        phase: s.phase,
        zmp_reference: [s.zmp_reference.0 + origin.x, s.zmp_reference.1 + origin.y],
        zmp_model: [s.zmp_model.0 + origin.x, s.zmp_model.1 + origin.y],
        zmp_measured: [m.zmp_measured.0, m.zmp_measured.1],
        zmp_margin: m.zmp_margin,
        zmp_deviation: m.zmp_deviation,
        com_pattern: [wt.com_nominal.x, wt.com_nominal.y],
        com_reference: [wt.com_reference.x, wt.com_reference.y],
        com: [com.x, com.y, com.z],
        com_offset: [wt.com_offset.x, wt.com_offset.y],
        feet_reference: [fr(&frefs[0]), fr(&frefs[1])],
        feet: m.feet,
        support: polygon
            .vertices()
            .iter()
            .map(|(x, y)| [x + origin.x, y + origin.y])
            .collect(),
        corrected_from: wt.corrected_from,
        qp_solves: wt.qp_solves,
        tick_us: m.tick_us,
        links,
        link_rotations,
        q: ctl.dof_positions().to_vec(),
        qd: state.qd.as_slice().to_vec(),
        qdd: ctl.qdd().as_slice().to_vec(),
    }
}

/// The footstep list of `plan` in world axes (shifted by `origin` \[m\]): the initial left and
/// right feet, then the steps; each `[x, y, yaw]` \[m, m, rad\].
fn world_footsteps(plan: &FootstepPlan, origin: Vector2<f64>) -> Vec<(Side, [f64; 3])> {
    let mut v = vec![
        (
            Side::Left,
            [
                plan.initial(Side::Left).x + origin.x,
                plan.initial(Side::Left).y + origin.y,
                plan.initial(Side::Left).yaw,
            ],
        ),
        (
            Side::Right,
            [
                plan.initial(Side::Right).x + origin.x,
                plan.initial(Side::Right).y + origin.y,
                plan.initial(Side::Right).yaw,
            ],
        ),
    ];
    for f in plan.steps() {
        v.push((
            f.side,
            [f.pose.x + origin.x, f.pose.y + origin.y, f.pose.yaw],
        ));
    }
    v
}

/// The [`WalkRun`] of the recorded `steps`: the world footsteps, the pattern's phases and the
/// summary (with the plan's ZMP figures and the controller's ZMP corrections).
fn finish_walk_run(
    robot: &Robot,
    cfg: &WalkImitateConfig,
    wc: &WalkingController,
    steps: Vec<WalkStep>,
    health: HealthReport,
) -> Result<WalkRun> {
    let origin = wc.origin();
    let plan = wc.plan();
    let pattern = wc.pattern();
    let ctl = wc.imitation();
    let footsteps = world_footsteps(plan, origin);
    let phases = pattern
        .timeline()
        .phases()
        .iter()
        .map(|p| (p.start, p.end, p.phase))
        .collect();
    let plan_zmp = plan_zmp_figures(robot, cfg, pattern, origin, &steps)?;
    let mut summary = summarize(
        robot,
        cfg,
        ctl,
        &steps,
        pattern.duration(),
        health,
        plan_zmp,
    )?;
    summary.zmp_corrections = wc.zmp_corrections().to_vec();
    Ok(WalkRun {
        steps,
        footsteps,
        phases,
        summary,
    })
}

/// The ZMP of the commanded motion ([`multibody_zmp`] of the recorded links' poses, the ground
/// at the soles' start height) against the pattern's support polygon of each tick: (ticks
/// outside in single support, in double support, the smallest margin \[m\]). A tick where the
/// body falls faster than gravity counts as outside.
fn plan_zmp_figures(
    robot: &Robot,
    cfg: &WalkImitateConfig,
    pattern: &WalkingPattern,
    origin: Vector2<f64>,
    steps: &[WalkStep],
) -> Result<(usize, usize, f64)> {
    if steps.len() < 3 {
        return Ok((0, 0, f64::NAN));
    }
    let poses: Vec<Vec<Isometry3<f64>>> = steps
        .iter()
        .map(|s| {
            s.links
                .iter()
                .zip(&s.link_rotations)
                .map(|(p, r)| {
                    Isometry3::from_parts(
                        Translation3::new(p[0], p[1], p[2]),
                        UnitQuaternion::new_normalize(Quaternion::new(r[3], r[0], r[1], r[2])),
                    )
                })
                .collect()
        })
        .collect();
    let ground = steps[0].feet[0][2].min(steps[0].feet[1][2]) - cfg.imitate.support.ankle_height;
    let zmp = multibody_zmp(
        &link_masses(robot),
        &poses,
        cfg.imitate.dt,
        ground,
        cfg.preview.gravity,
    )?;
    let mut polygon = SupportPolygon::default();
    let (mut single, mut double, mut worst) = (0, 0, f64::INFINITY);
    for (s, p) in steps.iter().zip(&zmp) {
        pattern.support_polygon_into(s.t, &mut polygon)?;
        let m = p.map_or(f64::NEG_INFINITY, |p| {
            polygon.margin((p[0] - origin.x, p[1] - origin.y))
        });
        if m < 0.0 {
            match s.phase {
                Phase::SingleSupport { .. } => single += 1,
                Phase::DoubleSupport => double += 1,
            }
        }
        worst = worst.min(m);
    }
    Ok((single, double, worst))
}

/// Each actuated joint's margins to its limits over the recorded `steps` (period `dt` \[s\]),
/// and the worst position, velocity and acceleration margins.
fn joint_margins(
    robot: &Robot,
    ctl: &ImitationController,
    steps: &[WalkStep],
    dt: f64,
    names: &[String],
) -> (Vec<JointMargin>, [f64; 3]) {
    let mut margins = Vec::new();
    let mut worst = [f64::NEG_INFINITY; 3];
    for (d, lim) in ctl.limits().dofs().iter().enumerate().skip(robot.base_nv()) {
        let col = |f: &dyn Fn(&WalkStep) -> f64| steps.iter().map(f).collect::<Vec<f64>>();
        let limit = held_limit(lim, f64::INFINITY);
        let m = dof_margins(
            d,
            &col(&|s| s.q[d]),
            &col(&|s| s.qd[d]),
            &col(&|s| s.qdd[d]),
            dt,
            &limit,
        );
        worst[0] = worst[0].max(m.position);
        worst[1] = worst[1].max(m.velocity);
        worst[2] = worst[2].max(m.acceleration);
        margins.push(JointMargin::new(
            names.get(d).cloned().unwrap_or_default(),
            &m,
        ));
    }
    (margins, worst)
}

/// Stance feet over the recorded `steps`: the largest horizontal error against the reference
/// and the largest drift within a stance interval \[m\].
fn stance_feet_errors(steps: &[WalkStep]) -> (f64, f64) {
    let mut max_err = 0.0f64;
    let mut max_slip = 0.0f64;
    for (foot, side) in [Side::Left, Side::Right].into_iter().enumerate() {
        let mut anchor: Option<[f64; 3]> = None;
        for s in steps {
            let in_stance = match s.phase {
                Phase::DoubleSupport => true,
                Phase::SingleSupport { stance } => stance == side,
            };
            if in_stance {
                let (p, r) = (s.feet[foot], s.feet_reference[foot]);
                max_err = max_err.max(((p[0] - r[0]).powi(2) + (p[1] - r[1]).powi(2)).sqrt());
                match anchor {
                    None => anchor = Some(p),
                    Some(a) => {
                        max_slip =
                            max_slip.max(((p[0] - a[0]).powi(2) + (p[1] - a[1]).powi(2)).sqrt())
                    }
                }
            } else {
                anchor = None;
            }
        }
    }
    (max_err, max_slip)
}

#[allow(clippy::too_many_arguments)]
fn summarize(
    robot: &Robot,
    cfg: &WalkImitateConfig,
    ctl: &ImitationController,
    steps: &[WalkStep],
    duration: f64,
    health: HealthReport,
    plan_zmp: (usize, usize, f64),
) -> Result<WalkSummary> {
    let dt = cfg.imitate.dt;
    let names = robot.dof_names();
    let (margins, worst) = joint_margins(robot, ctl, steps, dt, &names);
    let (max_err, max_slip) = stance_feet_errors(steps);
    let min_margin = steps
        .iter()
        .map(|s| s.zmp_margin)
        .fold(f64::INFINITY, f64::min);
    let push = match cfg.push {
        Some(p) if steps.last().is_some_and(|s| s.t > p.time) => {
            Some(push_summary(steps, p, cfg.noise_std)?)
        }
        _ => None,
    };
    let ticks: Vec<f64> = steps.iter().map(|s| s.tick_us).collect();
    let nt = ctl.level_dims().len();
    let smoothness = crate::sim::smoothness::joints_smoothness(
        robot.base_nv()..robot.nv(),
        0..steps.len(),
        dt,
        |k, d| steps[k].qdd[d],
        |d| names.get(d).cloned().unwrap_or_default(),
    );
    Ok(WalkSummary {
        damping: cfg.damping,
        approach_rate: cfg.imitate.bounds.approach_rate_at(cfg.imitate.dt),
        smoothing_hz: cfg.imitate.smoothing,
        steps: cfg.steps,
        duration,
        min_zmp_margin: min_margin,
        zmp_inside: min_margin >= 0.0,
        plan_zmp_outside_single: plan_zmp.0,
        plan_zmp_outside_double: plan_zmp.1,
        plan_zmp_min_margin: plan_zmp.2,
        zmp_corrections: Vec::new(),
        max_stance_foot_error: max_err,
        max_stance_foot_slip: max_slip,
        worst_margins: worst,
        margins,
        push,
        health,
        climbed_ticks: steps
            .iter()
            .filter(|s| matches!(s.corrected_from, Some(l) if l + 1 < nt))
            .count(),
        corrected_ticks: steps.iter().filter(|s| s.corrected_from.is_some()).count(),
        level_switches: crate::sim::LevelSwitches::count(
            &steps.iter().map(|s| s.corrected_from).collect::<Vec<_>>(),
        ),
        smoothness_worst: crate::sim::smoothness::worst(&smoothness),
        smoothness,
        tick_median_us: median(&ticks),
        tick_p99_us: percentile(&ticks, 0.99),
    })
}

/// The response to push `p` along both axes of the local frame, and the ZMP's excursion
/// outside the support polygon from the push on.
fn push_summary(steps: &[WalkStep], p: Push, noise_std: f64) -> Result<WalkPushSummary> {
    let settings = ResponseSettings::default();
    let t: Vec<f64> = steps.iter().map(|s| s.t).collect();
    let axis = |i: usize| -> Result<PushAxisMetrics> {
        let y: Vec<f64> = steps.iter().map(|s| s.zmp_deviation[i]).collect();
        let m = analyse_response(&t, &y, p.time, noise_std, &settings)?;
        let fitted = m.peak > settings.noise_sigmas * noise_std;
        Ok(PushAxisMetrics {
            peak: m.peak,
            peak_time: m.peak_time,
            settling_time: m.settling_time,
            damping_ratio: fitted.then_some(m.damping_ratio),
            natural_frequency: fitted.then_some(m.natural_frequency),
        })
    };
    let zmp_min_margin = steps
        .iter()
        .filter(|s| s.t >= p.time)
        .map(|s| s.zmp_margin)
        .fold(f64::INFINITY, f64::min);
    Ok(WalkPushSummary {
        push: p,
        x: axis(0)?,
        y: axis(1)?,
        zmp_min_margin,
        zmp_excursion: (-zmp_min_margin).max(0.0),
    })
}
