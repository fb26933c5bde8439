//! Running the imitation experiment and recording it: steps and summary.

use std::time::Instant;

use nalgebra::{DMatrix, UnitQuaternion, Vector3};
use serde::Serialize;

use super::support::support_polygon;
use super::{ImitateConfig, ImitationController, LEVEL_NAMES};
use crate::error::Result;
use crate::limits::NarrowedJoint;
use crate::model::{FrameId, JointLimit, Kinematics, Robot};
use crate::motion::RobotReferences;
use crate::sim::health::{HealthMonitor, HealthReport, Verdict};
pub use crate::sim::margins::JointMargin;
use crate::sim::margins::{dof_margins, held_limit, median, percentile};
use crate::solver::{Fallback, Method};
use crate::walk::SupportPolygon;

/// One recorded tick (state at its start, command applied over it).
#[derive(Debug, Clone, Serialize)]
pub struct ImitateStep {
    /// Time \[s\].
    pub t: f64,
    /// Dof positions \[rad\] (base entries 0), nv entries.
    pub q: Vec<f64>,
    /// Pose of the root link in the world: position \[m\] then unit quaternion (x, y, z, w)
    /// (identity for a fixed base).
    pub base: [f64; 7],
    /// Dof rates \[rad/s\] (base: body twist \[m/s\], \[rad/s\]).
    pub qd: Vec<f64>,
    /// Commanded q̈ \[rad/s²\].
    pub qdd: Vec<f64>,
    /// Acceleration box, lower side \[rad/s²\].
    pub box_lower: Vec<f64>,
    /// Acceleration box, upper side \[rad/s²\].
    pub box_upper: Vec<f64>,
    /// ‖x_d − x‖ of each level (task units: \[m\] and \[rad\] mixed for the feet).
    pub level_error: [f64; 5],
    /// ‖J_i q̈ − h_i‖ of each level at the commanded q̈ \[task unit/s²\]: what the level lost
    /// at the acceleration level this tick (0 for a level the solution satisfies).
    pub level_residual: [f64; 5],
    /// ‖Δh_i‖ of each level's correction \[task unit/s²\].
    pub correction: [f64; 5],
    /// Highest-priority corrected level, 0-based; `None` without correction. IKTC's own
    /// report; for GF and clamp, the first level whose `‖J_i q̈ − h_i‖` exceeds
    /// [`ImitateConfig::corrected_tolerance`].
    pub corrected_from: Option<usize>,
    /// Largest foot position drift from the initial pose \[m\].
    pub foot_drift: f64,
    /// Largest foot orientation drift \[rad\].
    pub foot_rotation_drift: f64,
    /// COM \[m\].
    pub com: [f64; 3],
    /// Signed distance from the COM's ground projection to the support polygon's edge \[m\]
    /// (positive inside).
    pub com_margin: f64,
    /// ZMP of the commanded motion on the ground \[m\] (cart-table model, see
    /// [`run_imitate`]).
    pub zmp: [f64; 2],
    /// Signed distance from the ZMP to the support polygon's edge \[m\] (positive inside).
    pub zmp_margin: f64,
    /// Desired pelvis height \[m\].
    pub pelvis_height_desired: f64,
    /// Pelvis height \[m\].
    pub pelvis_height: f64,
    /// Desired pelvis (roll, pitch, yaw) \[rad\] (Z-Y-X angles).
    pub pelvis_rpy_desired: [f64; 3],
    /// Pelvis (roll, pitch, yaw) \[rad\].
    pub pelvis_rpy: [f64; 3],
    /// World positions of every link origin \[m\] (for the viewer).
    pub links: Vec<[f64; 3]>,
    /// Orientation of every link in the world, unit quaternion (x, y, z, w) (for the viewer's
    /// meshes).
    #[serde(skip)]
    pub link_rotations: Vec<[f64; 4]>,
    /// Dofs sitting on a position, velocity or acceleration limit.
    pub on_limit: Vec<usize>,
    /// QPs solved this tick.
    pub qp_solves: usize,
    /// Dofs with an empty box.
    pub empty_dofs: usize,
    /// Dofs being brought back into their range this tick
    /// ([`OutsideLimits::Recover`](crate::limits::OutsideLimits)).
    pub recovering: Vec<usize>,
    /// Whether a fallback was taken.
    pub fallback: bool,
    /// Which fallback, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fallback_kind: Option<Fallback>,
    /// Time of the tick (kinematics, tasks, bounds, solve) \[µs\].
    pub tick_us: f64,
}

/// Tracking of one level over the run.
#[derive(Debug, Clone, Serialize)]
pub struct LevelSummary {
    /// Level name.
    pub name: String,
    /// Rows m_i.
    pub dim: usize,
    /// Largest ‖x_d − x‖ \[task unit\].
    pub max_error: f64,
    /// RMS of ‖x_d − x‖ over the run.
    pub rms_error: f64,
    /// Ticks where this level was corrected.
    pub corrected_steps: usize,
    /// First and last time it was corrected \[s\]; absent (`None`, left out of the JSON)
    /// if it never was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub corrected_span: Option<[f64; 2]>,
}

/// The run's summary (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct ImitateSummary {
    /// Solver name.
    pub solver: String,
    /// Bound method.
    pub bounds: String,
    /// The soft approach's rate \[1/s\] ([`ViableSettings::approach_rate`](crate::limits::ViableSettings)),
    /// as used at the run's Δt (capped at `MAX_APPROACH_STEP/Δt`); 0 without it.
    pub approach_rate: f64,
    /// Cut-off of the low-pass applied to the clip \[Hz\] ([`ImitateConfig::smoothing`]); `None`:
    /// the clip as captured.
    pub smoothing_hz: Option<f64>,
    /// Δt \[s\].
    pub dt: f64,
    /// Duration \[s\].
    pub duration: f64,
    /// Ticks.
    pub steps: usize,
    /// n.
    pub nv: usize,
    /// Level sizes m_i.
    pub level_dims: Vec<usize>,
    /// Narrowed ranges.
    pub narrowed: Vec<NarrowedJoint>,
    /// Margins of every joint (narrowed ranges).
    pub joints: Vec<JointMargin>,
    /// Largest position excursion over all joints \[rad\] (≤ 0: no limit exceeded).
    pub worst_position_margin: f64,
    /// Largest velocity excursion \[rad/s\].
    pub worst_velocity_margin: f64,
    /// Largest acceleration excursion \[rad/s²\].
    pub worst_acceleration_margin: f64,
    /// Ticks where some joint sat on its position limit.
    pub position_binding_steps: usize,
    /// Ticks where some joint sat on its velocity limit.
    pub velocity_binding_steps: usize,
    /// Ticks where some joint sat on its acceleration limit.
    pub acceleration_binding_steps: usize,
    /// Ticks where a narrowed joint sat on its position limit.
    pub narrowed_at_limit_steps: usize,
    /// Ticks where the pelvis attitude or height level was corrected.
    pub pelvis_corrected_steps: usize,
    /// How often the corrected level changed between consecutive corrected ticks.
    pub level_switches: crate::sim::LevelSwitches,
    /// Smoothness of the commanded q̈ of every joint (jerk, sign reversals of its change).
    pub smoothness: Vec<crate::sim::JointSmoothness>,
    /// The same for the narrowed joints only, in the order of [`ImitateConfig::narrow`].
    pub narrowed_smoothness: Vec<crate::sim::JointSmoothness>,
    /// Ticks where a pelvis level was corrected while a narrowed joint sat on its limit.
    pub pelvis_corrected_while_narrowed_at_limit: usize,
    /// Largest feet error ‖x_d − x‖ while a lower level was corrected.
    pub feet_error_while_lower_corrected: f64,
    /// Largest ‖J q̈ − h‖ of the feet level while a lower level was corrected
    /// \[m/s², rad/s²\] (0 to rounding: the correction leaves the level untouched).
    pub feet_residual_while_lower_corrected: f64,
    /// Largest ‖J q̈ − h‖ of the COM level while a lower level was corrected \[m/s²\].
    pub com_residual_while_lower_corrected: f64,
    /// Largest COM error \[m\] while a lower level was corrected.
    pub com_error_while_lower_corrected: f64,
    /// Largest foot position drift \[m\].
    pub foot_drift: f64,
    /// Largest foot orientation drift \[rad\].
    pub foot_rotation_drift: f64,
    /// Whether the COM stayed over the support polygon at every tick.
    pub com_inside_support: bool,
    /// Smallest COM margin to the polygon edge \[m\].
    pub com_min_margin: f64,
    /// Smallest ZMP margin to the polygon edge \[m\] (negative: the ZMP left the polygon).
    pub zmp_min_margin: f64,
    /// The run's checks: feet held, state finite, ZMP inside the support polygon.
    pub health: HealthReport,
    /// Tracking per level.
    pub levels: Vec<LevelSummary>,
    /// Ticks with an empty box.
    pub empty_box_steps: usize,
    /// Ticks with a fallback.
    pub fallback_steps: usize,
    /// Ticks in which some joint was being brought back into its range.
    pub recovering_steps: usize,
    /// Ticks with a fallback, by kind: "empty_box" (the acceleration box was empty on some
    /// dof), "clamped_to_box" (IKTC found no level to correct),
    /// "cascade_stopped_at_level_N" (GF: level N, 1-based, had no feasible solution).
    pub fallbacks_by_kind: std::collections::BTreeMap<String, usize>,
    /// Mean QPs per tick.
    pub qp_per_step_mean: f64,
    /// Largest QPs in a tick.
    pub qp_per_step_max: usize,
    /// Median tick time \[µs\].
    pub tick_median_us: f64,
    /// 99th percentile tick time \[µs\].
    pub tick_p99_us: f64,
}

/// A whole run.
#[derive(Debug, Clone, Serialize)]
pub struct ImitateRun {
    /// Every tick.
    pub steps: Vec<ImitateStep>,
    /// Summary.
    pub summary: ImitateSummary,
    /// Names of the dofs (nv).
    pub dof_names: Vec<String>,
    /// The limits used, per dof (narrowed).
    pub limits: Vec<JointLimit>,
    /// The references actually tracked (joint references clamped into the ranges).
    #[serde(skip)]
    pub references: RobotReferences,
    /// Support polygon \[m\] (counter-clockwise).
    pub support: Vec<[f64; 3]>,
}

/// Z-Y-X angles as (roll, pitch, yaw) \[rad\].
fn rpy(q: &UnitQuaternion<f64>) -> [f64; 3] {
    let (r, p, y) = q.euler_angles();
    [r, p, y]
}

/// Runs the experiment: [`ImitationController::new`], then one tick per reference sample,
/// each checked by a [`HealthMonitor`] with [`ImitateConfig::health`]:
///
/// * the feet: position and rotation of each foot frame against its initial (held) pose;
/// * the state: q, q̇, the commanded q̈ and the COM finite (and q, q̇ again after integration);
/// * the COM's ground projection inside the support polygon of the initial feet (the static
///   balance criterion). The imitation is kinematic — no contact forces, no dynamics — so the
///   ZMP is only recorded, not checked: its cart-table value for the commanded motion,
///   `p_xy = c_xy − c_z c̈_xy / (g + c̈_z)` with `c̈ = J_c q̈ + J̇_c q̇` (the COM Jacobian and
///   drift of [`crate::model::Kinematics`], `g` = [`crate::balance::STANDARD_GRAVITY`],
///   ground z = 0), leaves the polygon by up to 2.7 m for 25 ticks (0.10–0.34 s) of the
///   default run, where the commanded q̈ of the start-up transient is far beyond what feet
///   on the ground could carry.
///
/// Errors: bad settings or references, and [`crate::Error::RunFailed`] when a check fails
/// (unless [`crate::sim::HealthSettings::keep_going`]: the run then goes on and the summary's
/// [`HealthReport`] lists the failures; a non-finite state ends the run there, the steps
/// recorded so far all finite).
pub fn run_imitate(
    robot: &Robot,
    refs: &RobotReferences,
    cfg: &ImitateConfig,
) -> Result<ImitateRun> {
    let mut ctl = ImitationController::new(robot, refs, cfg)?;
    let n = ctl.references().len();
    let nv = robot.nv();
    let limits = held_limits(robot, &ctl);
    let feet_ids = cfg
        .feet
        .iter()
        .map(|f| robot.frame_id(f))
        .collect::<Result<Vec<_>>>()?;
    let pelvis = robot.frame_id(&cfg.pelvis)?;
    let polygon = support_polygon(ctl.feet0(), &cfg.support)?;
    let mut health = HealthMonitor::new(cfg.health)?;
    let dof_names = robot.dof_names();
    let mut com_jacobian = DMatrix::zeros(3, nv);
    let mut steps = Vec::with_capacity(n);
    for k in 0..n {
        let t = k as f64 * cfg.dt;
        let start = Instant::now();
        ctl.tick(k).map_err(|e| {
            e.at(|| {
                format!(
                    "imitation, tick {k} (t = {} s)",
                    crate::resources::fmt_value(t)
                )
            })
        })?;
        let tick_us = start.elapsed().as_secs_f64() * 1e6;
        let kin = ctl.kinematics();
        let com = kin.com();
        if check_state_finite(&mut health, t, &dof_names, &ctl, &com, &[])? == Verdict::Stop {
            break;
        }
        let (foot_drift, foot_rotation_drift) =
            check_feet_drift(robot, cfg, &ctl, &feet_ids, &mut health, t)?;
        let zmp = cart_table_zmp(robot, &ctl, &com, &mut com_jacobian)?;
        health.check_support(t, &polygon, (com.x, com.y), "COM", "world axes")?;
        health.end_tick();
        let measured = TickMeasure {
            k,
            t,
            tick_us,
            com,
            zmp,
            foot_drift,
            foot_rotation_drift,
        };
        steps.push(imitate_step(
            robot, cfg, &ctl, &limits, &polygon, pelvis, measured,
        )?);
        ctl.integrate()?;
    }
    let summary = summarize(
        robot,
        cfg,
        &steps,
        &limits,
        &ctl.level_dims(),
        health.report(),
    );
    Ok(ImitateRun {
        steps,
        summary,
        dof_names,
        limits,
        references: ctl.references().clone(),
        support: polygon.vertices().iter().map(|p| [p.0, p.1, 0.0]).collect(),
    })
}

/// Each dof's limits as the run holds them ([`held_limit`], the effort from the model).
fn held_limits(robot: &Robot, ctl: &ImitationController) -> Vec<JointLimit> {
    ctl.limits()
        .dofs()
        .iter()
        .zip(robot.dof_limits())
        .map(|(d, l)| held_limit(d, l.effort))
        .collect()
}

/// The cart-table ZMP \[m\] of the commanded motion, ground z = 0: `p_xy = c_xy − c_z c̈_xy /
/// (g + c̈_z)` with `c̈ = J_c q̈ + J̇_c q̇` (`com_jacobian` is the 3 × nv scratch for `J_c`).
fn cart_table_zmp(
    robot: &Robot,
    ctl: &ImitationController,
    com: &Vector3<f64>,
    com_jacobian: &mut DMatrix<f64>,
) -> Result<[f64; 2]> {
    let kin = ctl.kinematics();
    kin.com_jacobian(robot, com_jacobian)?;
    let cdd = &*com_jacobian * ctl.qdd() + kin.com_drift();
    let lever = com.z / (crate::balance::STANDARD_GRAVITY + cdd.z);
    Ok([com.x - lever * cdd.x, com.y - lever * cdd.y])
}

/// Every link's position \[m\] and rotation (quaternion x, y, z, w) in `kin`, for a step's
/// record.
pub(crate) fn link_frames(kin: &Kinematics) -> (Vec<[f64; 3]>, Vec<[f64; 4]>) {
    kin.link_poses()
        .iter()
        .map(|p| {
            let t = p.translation.vector;
            let r: [f64; 4] = p.rotation.coords.into();
            ([t.x, t.y, t.z], r)
        })
        .unzip()
}

/// Checks q, q̇, the commanded q̈, the COM \[m\] and then each of `extra` (name with unit,
/// values) for non-finite values at time `t` \[s\], in that order, stopping at the first
/// verdict to stop.
pub(crate) fn check_state_finite(
    health: &mut HealthMonitor,
    t: f64,
    dof_names: &[String],
    ctl: &ImitationController,
    com: &Vector3<f64>,
    extra: &[(&str, &[f64])],
) -> Result<Verdict> {
    let state = ctl.state();
    let rows = [
        ("joint position q [rad]", ctl.dof_positions()),
        ("velocity q̇ [rad/s]", state.qd.as_slice()),
        ("commanded acceleration q̈ [rad/s²]", ctl.qdd().as_slice()),
        ("COM [m]", com.as_slice()),
    ];
    let mut verdict = Verdict::Continue;
    for &(what, values) in rows.iter().chain(extra) {
        if verdict == Verdict::Continue {
            verdict = health.check_finite(t, what, dof_names, values)?;
        }
    }
    Ok(verdict)
}

/// Checks each foot frame against its initial (held) pose at time `t` \[s\]; returns the
/// largest position drift \[m\] and rotation drift \[rad\] of the feet.
fn check_feet_drift(
    robot: &Robot,
    cfg: &ImitateConfig,
    ctl: &ImitationController,
    feet_ids: &[FrameId],
    health: &mut HealthMonitor,
    t: f64,
) -> Result<(f64, f64)> {
    let kin = ctl.kinematics();
    let mut foot_drift = 0.0f64;
    let mut foot_rotation_drift = 0.0f64;
    for ((id, p0), name) in feet_ids.iter().zip(ctl.feet0()).zip(&cfg.feet) {
        let p = kin.frame_pose(robot, *id)?;
        let (dp, dr) = (
            (p.translation.vector - p0.translation.vector).norm(),
            p.rotation.angle_to(&p0.rotation),
        );
        health.check_foot(t, name, dp, dr)?;
        foot_drift = foot_drift.max(dp);
        foot_rotation_drift = foot_rotation_drift.max(dr);
    }
    Ok((foot_drift, foot_rotation_drift))
}

/// What one tick of [`run_imitate`] measured beside the controller's state: tick `k`, time
/// \[s\], wall-clock time \[µs\], COM \[m\], cart-table ZMP \[m\] and the feet's largest
/// position \[m\] and rotation \[rad\] drift.
struct TickMeasure {
    k: usize,
    t: f64,
    tick_us: f64,
    com: Vector3<f64>,
    zmp: [f64; 2],
    foot_drift: f64,
    foot_rotation_drift: f64,
}

/// Each level's error ‖x_d − x‖, correction and residual of the last tick (first five levels).
fn level_figures(ctl: &ImitationController) -> ([f64; 5], [f64; 5], [f64; 5]) {
    let rep = ctl.report();
    let mut level_error = [0.0; 5];
    let mut correction = [0.0; 5];
    let mut level_residual = [0.0; 5];
    for (i, r) in rep.task_error_norms.iter().enumerate().take(5) {
        level_residual[i] = *r;
    }
    for (i, e) in ctl.equations().iter().enumerate().take(5) {
        level_error[i] = e.error.norm();
        correction[i] = rep.corrections.get(i).map_or(0.0, |c| c.norm());
    }
    (level_error, correction, level_residual)
}

/// The actuated dofs at a limit: position within `on_limit_position` \[rad\] of a bound, or
/// rate or acceleration within `on_limit_fraction` of its bound.
fn dofs_on_limit(
    robot: &Robot,
    cfg: &ImitateConfig,
    limits: &[JointLimit],
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> Vec<usize> {
    let pos_tol = cfg.on_limit_position;
    let frac = cfg.on_limit_fraction;
    let mut on_limit = Vec::new();
    for d in robot.base_nv()..robot.nv() {
        let l = &limits[d];
        let at_pos = q[d] <= l.lower + pos_tol || q[d] >= l.upper - pos_tol;
        let at_vel = qd[d].abs() >= (1.0 - frac) * l.velocity;
        let at_acc = qdd[d].abs() >= (1.0 - frac) * l.acceleration;
        if at_pos || at_vel || at_acc {
            on_limit.push(d);
        }
    }
    on_limit
}

/// The recorded [`ImitateStep`] of one tick: the controller's state and report, the pelvis
/// against its reference, and what the tick measured.
fn imitate_step(
    robot: &Robot,
    cfg: &ImitateConfig,
    ctl: &ImitationController,
    limits: &[JointLimit],
    polygon: &SupportPolygon,
    pelvis: FrameId,
    m: TickMeasure,
) -> Result<ImitateStep> {
    let rep = ctl.report();
    let kin = ctl.kinematics();
    let state = ctl.state();
    let (level_error, correction, level_residual) = level_figures(ctl);
    let com = m.com;
    let pp = kin.frame_pose(robot, pelvis)?;
    let r = ctl.references();
    let kk = m.k.min(r.len().saturating_sub(1));
    let desired_att = r.attitude[kk] * ctl.pelvis0().rotation;
    let q = ctl.dof_positions().to_vec();
    let qd = state.qd.as_slice().to_vec();
    let qdd = ctl.qdd().as_slice().to_vec();
    let on_limit = dofs_on_limit(robot, cfg, limits, &q, &qd, &qdd);
    let (links, link_rotations) = link_frames(kin);
    let bx = ctl.acceleration_box();
    Ok(ImitateStep {
        t: m.t,
        base: {
            let b = state.base_pose(robot);
            let (p, r) = (b.translation.vector, b.rotation.coords);
            [p.x, p.y, p.z, r.x, r.y, r.z, r.w]
        },
        box_lower: bx.lower.as_slice().to_vec(),
        box_upper: bx.upper.as_slice().to_vec(),
        q,
        qd,
        qdd,
        level_error,
        level_residual,
        correction,
        corrected_from: match (rep.method, rep.corrected_from) {
            (Method::Iktc, c) => c,
            _ => level_residual
                .iter()
                .position(|r| *r > cfg.corrected_tolerance),
        },
        foot_drift: m.foot_drift,
        foot_rotation_drift: m.foot_rotation_drift,
        com: [com.x, com.y, com.z],
        com_margin: polygon.margin((com.x, com.y)),
        zmp: m.zmp,
        zmp_margin: polygon.margin((m.zmp[0], m.zmp[1])),
        pelvis_height_desired: ctl.pelvis0().translation.z + r.height.position[kk],
        pelvis_height: pp.translation.z,
        pelvis_rpy_desired: rpy(&desired_att),
        pelvis_rpy: rpy(&pp.rotation),
        links,
        link_rotations,
        on_limit,
        qp_solves: rep.qp_solves,
        empty_dofs: rep.empty_box_dofs,
        recovering: bx.recovering_dofs().collect(),
        fallback: rep.fallback.is_some(),
        fallback_kind: rep.fallback,
        tick_us: m.tick_us,
    })
}

/// Each actuated joint's margins to its limits over the recorded `steps`.
fn joint_margins(
    robot: &Robot,
    cfg: &ImitateConfig,
    steps: &[ImitateStep],
    limits: &[JointLimit],
    names: &[String],
) -> Vec<JointMargin> {
    (robot.base_nv()..robot.nv())
        .map(|d| {
            let col = |f: &dyn Fn(&ImitateStep) -> f64| steps.iter().map(f).collect::<Vec<f64>>();
            let q = col(&|s| s.q[d]);
            let qd = col(&|s| s.qd[d]);
            let qdd = col(&|s| s.qdd[d]);
            let m = dof_margins(d, &q, &qd, &qdd, cfg.dt, &limits[d]);
            JointMargin::new(names.get(d).cloned().unwrap_or_default(), &m)
        })
        .collect()
}

/// The steps with some actuated dof at its position limit (within `on_limit_position` \[rad\]),
/// its rate limit and its acceleration limit (within `on_limit_fraction`).
fn binding_steps(
    robot: &Robot,
    cfg: &ImitateConfig,
    steps: &[ImitateStep],
    limits: &[JointLimit],
) -> [usize; 3] {
    let nb = robot.base_nv();
    let (pos_tol, frac) = (cfg.on_limit_position, cfg.on_limit_fraction);
    let count = |f: &dyn Fn(&ImitateStep, usize) -> bool| {
        steps
            .iter()
            .filter(|s| (nb..robot.nv()).any(|d| f(s, d)))
            .count()
    };
    let position_binding_steps =
        count(&|s, d| s.q[d] <= limits[d].lower + pos_tol || s.q[d] >= limits[d].upper - pos_tol);
    let velocity_binding_steps = count(&|s, d| s.qd[d].abs() >= (1.0 - frac) * limits[d].velocity);
    let acceleration_binding_steps =
        count(&|s, d| s.qdd[d].abs() >= (1.0 - frac) * limits[d].acceleration);
    [
        position_binding_steps,
        velocity_binding_steps,
        acceleration_binding_steps,
    ]
}

/// Each level's (the first five) error figures and corrected steps over the recorded `steps`.
fn level_summaries(steps: &[ImitateStep], level_dims: &[usize]) -> Vec<LevelSummary> {
    (0..level_dims.len().min(5))
        .map(|i| {
            let errs: Vec<f64> = steps.iter().map(|s| s.level_error[i]).collect();
            let corrected: Vec<f64> = steps
                .iter()
                .filter(|s| matches!(s.corrected_from, Some(l) if l <= i))
                .map(|s| s.t)
                .collect();
            LevelSummary {
                name: LEVEL_NAMES[i].into(),
                dim: level_dims[i],
                max_error: errs.iter().copied().fold(0.0, f64::max),
                rms_error: (errs.iter().map(|e| e * e).sum::<f64>() / errs.len().max(1) as f64)
                    .sqrt(),
                corrected_steps: corrected.len(),
                corrected_span: corrected
                    .first()
                    .zip(corrected.last())
                    .map(|(a, b)| [*a, *b]),
            }
        })
        .collect()
}

/// The smoothness of the commanded q̈ of `dofs` over the recorded `steps`.
fn joints_smoothness_of(
    cfg: &ImitateConfig,
    steps: &[ImitateStep],
    names: &[String],
    dofs: Vec<usize>,
) -> Vec<crate::sim::JointSmoothness> {
    crate::sim::smoothness::joints_smoothness(
        dofs,
        0..steps.len(),
        cfg.dt,
        |k, d| steps[k].qdd[d],
        |d| names.get(d).cloned().unwrap_or_default(),
    )
}

/// Over the steps corrected from the pelvis attitude (index 2) or below: the largest feet
/// error, feet residual, COM residual and COM error (task units).
fn lower_corrected_figures(steps: &[ImitateStep]) -> [f64; 4] {
    let lower_corrected: Vec<&ImitateStep> = steps
        .iter()
        .filter(|s| matches!(s.corrected_from, Some(l) if l >= 2))
        .collect();
    [
        lower_corrected
            .iter()
            .map(|s| s.level_error[0])
            .fold(0.0, f64::max),
        lower_corrected
            .iter()
            .map(|s| s.level_residual[0])
            .fold(0.0, f64::max),
        lower_corrected
            .iter()
            .map(|s| s.level_residual[1])
            .fold(0.0, f64::max),
        lower_corrected
            .iter()
            .map(|s| s.level_error[1])
            .fold(0.0, f64::max),
    ]
}

/// How many steps fell back, by kind ([`fallback_name`]).
fn fallbacks_by_kind(steps: &[ImitateStep]) -> std::collections::BTreeMap<String, usize> {
    steps
        .iter()
        .filter_map(|s| s.fallback_kind)
        .fold(Default::default(), |mut m, f| {
            *m.entry(fallback_name(f)).or_insert(0) += 1;
            m
        })
}

/// The steps with a narrowed dof at its position limit (within `on_limit_position` \[rad\]),
/// the steps corrected from a level at or above the pelvis height (index 3), and the steps
/// with both.
fn narrowed_counts(
    cfg: &ImitateConfig,
    steps: &[ImitateStep],
    limits: &[JointLimit],
    narrowed_dofs: &[usize],
) -> [usize; 3] {
    let pos_tol = cfg.on_limit_position;
    let narrowed_at = |s: &ImitateStep| {
        narrowed_dofs
            .iter()
            .any(|&d| s.q[d] <= limits[d].lower + pos_tol || s.q[d] >= limits[d].upper - pos_tol)
    };
    // Corrected from a level at or above the pelvis height (index 3).
    let pelvis_corrected = |s: &ImitateStep| matches!(s.corrected_from, Some(l) if l <= 3);
    [
        steps.iter().filter(|s| narrowed_at(s)).count(),
        steps.iter().filter(|s| pelvis_corrected(s)).count(),
        steps
            .iter()
            .filter(|s| pelvis_corrected(s) && narrowed_at(s))
            .count(),
    ]
}

/// The smallest COM and ZMP margins inside the support polygon over the recorded `steps` \[m\].
fn min_margins(steps: &[ImitateStep]) -> (f64, f64) {
    (
        steps
            .iter()
            .map(|s| s.com_margin)
            .fold(f64::INFINITY, f64::min),
        steps
            .iter()
            .map(|s| s.zmp_margin)
            .fold(f64::INFINITY, f64::min),
    )
}

/// The feet's largest position \[m\] and rotation \[rad\] drift over the recorded `steps`.
fn max_foot_drifts(steps: &[ImitateStep]) -> (f64, f64) {
    (
        steps.iter().map(|s| s.foot_drift).fold(0.0, f64::max),
        steps
            .iter()
            .map(|s| s.foot_rotation_drift)
            .fold(0.0, f64::max),
    )
}

/// The summary of recorded steps (see [`ImitateSummary`]).
pub(crate) fn summarize(
    robot: &Robot,
    cfg: &ImitateConfig,
    steps: &[ImitateStep],
    limits: &[JointLimit],
    level_dims: &[usize],
    health: HealthReport,
) -> ImitateSummary {
    let names = robot.dof_names();
    let nb = robot.base_nv();
    let joints = joint_margins(robot, cfg, steps, limits, &names);
    let worst =
        |f: &dyn Fn(&JointMargin) -> f64| joints.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
    let [position_binding_steps, velocity_binding_steps, acceleration_binding_steps] =
        binding_steps(robot, cfg, steps, limits);
    let narrowed_dofs: Vec<usize> = cfg
        .narrow
        .iter()
        .filter_map(|n| robot.joint_v_index(&n.joint).ok())
        .collect();
    let [narrowed_at_limit_steps, pelvis_corrected_steps, pelvis_corrected_while_narrowed_at_limit] =
        narrowed_counts(cfg, steps, limits, &narrowed_dofs);
    let lower = lower_corrected_figures(steps);
    let ticks: Vec<f64> = steps.iter().map(|s| s.tick_us).collect();
    let levels = level_summaries(steps, level_dims);
    let (com_min_margin, zmp_min_margin) = min_margins(steps);
    let (foot_drift, foot_rotation_drift) = max_foot_drifts(steps);
    let smoothness = joints_smoothness_of(cfg, steps, &names, (nb..robot.nv()).collect());
    let narrowed_smoothness = joints_smoothness_of(cfg, steps, &names, narrowed_dofs.clone());
    ImitateSummary {
        solver: cfg.method.name().into(),
        bounds: cfg.bounds.name().into(),
        approach_rate: cfg.bounds.approach_rate_at(cfg.dt),
        smoothing_hz: cfg.smoothing,
        dt: cfg.dt,
        duration: steps.len() as f64 * cfg.dt,
        steps: steps.len(),
        nv: robot.nv(),
        level_dims: level_dims.to_vec(),
        narrowed: cfg.narrow.clone(),
        worst_position_margin: worst(&|m| m.position),
        worst_velocity_margin: worst(&|m| m.velocity),
        worst_acceleration_margin: worst(&|m| m.acceleration),
        joints,
        position_binding_steps,
        velocity_binding_steps,
        acceleration_binding_steps,
        narrowed_at_limit_steps,
        pelvis_corrected_steps,
        level_switches: crate::sim::LevelSwitches::count(
            &steps.iter().map(|s| s.corrected_from).collect::<Vec<_>>(),
        ),
        smoothness,
        narrowed_smoothness,
        pelvis_corrected_while_narrowed_at_limit,
        feet_error_while_lower_corrected: lower[0],
        feet_residual_while_lower_corrected: lower[1],
        com_residual_while_lower_corrected: lower[2],
        com_error_while_lower_corrected: lower[3],
        foot_drift,
        foot_rotation_drift,
        com_inside_support: com_min_margin > 0.0,
        com_min_margin,
        zmp_min_margin,
        health,
        levels,
        empty_box_steps: steps.iter().filter(|s| s.empty_dofs > 0).count(),
        fallback_steps: steps.iter().filter(|s| s.fallback).count(),
        recovering_steps: steps.iter().filter(|s| !s.recovering.is_empty()).count(),
        fallbacks_by_kind: fallbacks_by_kind(steps),
        qp_per_step_mean: steps.iter().map(|s| s.qp_solves as f64).sum::<f64>()
            / steps.len().max(1) as f64,
        qp_per_step_max: steps.iter().map(|s| s.qp_solves).max().unwrap_or(0),
        tick_median_us: median(&ticks),
        tick_p99_us: percentile(&ticks, 0.99),
    }
}

/// The name of a fallback kind in summaries (levels 1-based).
pub fn fallback_name(f: Fallback) -> String {
    match f {
        Fallback::ClampedToBox => "clamped_to_box".into(),
        Fallback::CascadeStoppedAtLevel(l) => format!("cascade_stopped_at_level_{}", l + 1),
        Fallback::EmptyBox => "empty_box".into(),
    }
}
