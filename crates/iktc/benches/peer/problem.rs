//! "The peer problem" (the five levels of the paper's Table 1 on JVRC-1, measured beside
//! mink, Pink and TSID), as one self-contained closed loop shared by the `peer_problem` bench
//! and the solver tests that replay it.
//!
//! - JVRC-1 built in (32 joints, fingers locked, floating base: n = 38), Δt = 5 ms, viable
//!   bounds, a_max = 10·v_max (the model's default acceleration per velocity), no damping.
//! - Initial pose: base at the origin, hip pitch −0.4, knee 0.8, ankle pitch −0.4 rad on both
//!   legs, shoulder roll ∓0.3 rad (right −, left +), elbow pitch −0.5 rad, everything else 0,
//!   at rest.
//! - Tasks in priority order, k_p = 400 s⁻², k_v = 40 s⁻¹ on every task: (1) both ankle frames
//!   6D held at their initial pose; (2) COM x, y held; (3) pelvis orientation held; (4) pelvis
//!   height held; (5) the 20 upper-body joints following
//!   q_ref,j(t) = q0,j + A·s(t)·sin(2π f t + φ_j), A = 0.8 rad, f = 1 Hz, s(t) the quintic
//!   smoothstep 10τ³ − 15τ⁴ + 6τ⁵, τ = min(t / 1 s, 1), with the reference's velocity and
//!   acceleration fed forward.
//! - φ_j: uniform in [0, 2π) from `rand_chacha::ChaCha8Rng::seed_from_u64(PHASE_SEED)`
//!   (rand 0.9, `random_range(0.0..TAU)`), drawn in the order of [`UPPER_BODY`].
//! - One step = kinematics update, task linearisation, acceleration box, solve, integration
//!   ([`PeerProblem::step`], [`Controller::step`]); it allocates nothing.
#![allow(dead_code)]

use std::f64::consts::{PI, TAU};

use iktc::controller::{ControllerSettings, JointsHandle};
use iktc::limits::{AccelerationBox, BoundMethod, JointLimits};
use iktc::model::{jvrc1, ModelOptions, Robot, State};
use iktc::solver::{Method, SolveReport, SolverSettings};
use iktc::task::{Axes, Gains};
use iktc::Controller;
use nalgebra::DVector;
use rand::{Rng, SeedableRng};

/// Control period Δt \[s\].
pub const DT: f64 = 0.005;
/// Steps run before the timed ones.
pub const WARMUP: usize = 50;
/// Timed steps.
pub const TIMED: usize = 2000;
/// Seed of the ChaCha8 generator that draws the phases φ_j.
pub const PHASE_SEED: u64 = 17;
/// Amplitude A of the upper-body sinusoids \[rad\].
pub const AMPLITUDE: f64 = 0.8;
/// Frequency f of the upper-body sinusoids \[Hz\].
pub const FREQUENCY: f64 = 1.0;
/// Duration of the quintic smoothstep that fades the sinusoids in \[s\].
pub const RAMP: f64 = 1.0;
/// Task gains: k_p \[1/s²\], k_v \[1/s\].
pub const GAINS: Gains = Gains {
    kp: 400.0,
    kv: 40.0,
};

/// The 20 upper-body joints of level 5 (waist 3, neck 3, arms 2 × 7), in row order.
pub const UPPER_BODY: [&str; 20] = [
    "WAIST_Y",
    "WAIST_P",
    "WAIST_R",
    "NECK_Y",
    "NECK_R",
    "NECK_P",
    "R_SHOULDER_P",
    "R_SHOULDER_R",
    "R_SHOULDER_Y",
    "R_ELBOW_P",
    "R_ELBOW_Y",
    "R_WRIST_R",
    "R_WRIST_Y",
    "L_SHOULDER_P",
    "L_SHOULDER_R",
    "L_SHOULDER_Y",
    "L_ELBOW_P",
    "L_ELBOW_Y",
    "L_WRIST_R",
    "L_WRIST_Y",
];

/// The initial joint angles that are not zero \[rad\].
pub const INITIAL_POSE: [(&str, f64); 10] = [
    ("R_HIP_P", -0.4),
    ("R_KNEE", 0.8),
    ("R_ANKLE_P", -0.4),
    ("L_HIP_P", -0.4),
    ("L_KNEE", 0.8),
    ("L_ANKLE_P", -0.4),
    ("R_SHOULDER_R", -0.3),
    ("L_SHOULDER_R", 0.3),
    ("R_ELBOW_P", -0.5),
    ("L_ELBOW_P", -0.5),
];

/// The closed loop of the peer problem: a [`Controller`] with the five levels and its state.
#[derive(Debug, Clone)]
pub struct PeerProblem {
    pub ctl: Controller,
    pub state: State,
    upper: JointsHandle,
    /// q0,j and φ_j of the upper-body joints \[rad\].
    q0: Vec<f64>,
    pub phases: Vec<f64>,
    qr: [Vec<f64>; 3],
    /// The next step's index k (time k Δt).
    pub k: usize,
}

impl PeerProblem {
    /// The problem at t = 0 with the viable bounds, solved by `method` with `settings`.
    pub fn new(method: Method, settings: SolverSettings) -> iktc::Result<Self> {
        Self::with_bounds(method, settings, BoundMethod::viable())
    }

    /// The problem at t = 0 with `bounds`, solved by `method` with `settings`.
    pub fn with_bounds(
        method: Method,
        settings: SolverSettings,
        bounds: BoundMethod,
    ) -> iktc::Result<Self> {
        Self::with_model(method, settings, bounds, &ModelOptions::default())
    }

    /// The problem at t = 0 on JVRC-1 built with `options` (e.g. jerk limits), with `bounds`,
    /// solved by `method` with `settings`.
    pub fn with_model(
        method: Method,
        settings: SolverSettings,
        bounds: BoundMethod,
        options: &ModelOptions,
    ) -> iktc::Result<Self> {
        Self::with_upper_body(method, settings, bounds, options, &UPPER_BODY)
    }

    /// The problem with level 5 holding `upper` (joints of [`UPPER_BODY`], phases drawn in
    /// their order): [`UPPER_BODY`]`[..19]` is the 37-row variant, whose stack leaves one
    /// coordinate free (no longer square).
    pub fn with_upper_body(
        method: Method,
        settings: SolverSettings,
        bounds: BoundMethod,
        options: &ModelOptions,
        upper: &[&str],
    ) -> iktc::Result<Self> {
        let robot = jvrc1(options)?;
        let mut state = State::neutral(&robot);
        for (name, v) in INITIAL_POSE {
            state.set_joint(&robot, name, v)?;
        }
        let mut b = Controller::builder(robot, &state)?;
        b.gains(GAINS).settings(ControllerSettings {
            method,
            bounds,
            solver: settings,
        });
        b.level("feet").frame("r_ankle", Axes::ALL)?;
        b.frame("l_ankle", Axes::ALL)?;
        b.level("com_xy").com([true, true, false])?;
        b.level("pelvis_attitude")
            .frame("PELVIS_S", Axes::ORIENTATION)?;
        b.level("pelvis_height").frame("PELVIS_S", Axes::Z)?;
        let joints = upper;
        let upper = b.level("upper_body").joints(joints)?;
        let ctl = b.build()?;
        let q0 = joints
            .iter()
            .map(|j| state.joint(ctl.robot(), j))
            .collect::<iktc::Result<Vec<_>>>()?;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(PHASE_SEED);
        let phases = (0..joints.len())
            .map(|_| rng.random_range(0.0..TAU))
            .collect();
        Ok(Self {
            ctl,
            state,
            upper,
            q0,
            phases,
            qr: std::array::from_fn(|_| vec![0.0; joints.len()]),
            k: 0,
        })
    }

    /// The robot.
    pub fn robot(&self) -> &Robot {
        self.ctl.robot()
    }

    /// Its joint limits.
    pub fn limits(&self) -> &JointLimits {
        self.ctl.limits()
    }

    /// The acceleration box of the last step \[rad/s²\].
    pub fn bounds(&self) -> &AccelerationBox {
        self.ctl.bounds()
    }

    /// The q̈ of the last solve \[rad/s² or m/s²\].
    pub fn qdd(&self) -> &DVector<f64> {
        self.ctl.qdd()
    }

    /// The upper-body reference at time t \[s\]: positions \[rad\], rates \[rad/s\] and
    /// accelerations \[rad/s²\] into `self.qr`.
    fn reference(&mut self, t: f64) {
        let (s, sd, sdd) = iktc::walk::smoothstep(0.0, RAMP, t);
        let w = 2.0 * PI * FREQUENCY;
        for j in 0..self.q0.len() {
            let (sn, cs) = (w * t + self.phases[j]).sin_cos();
            self.qr[0][j] = self.q0[j] + AMPLITUDE * s * sn;
            self.qr[1][j] = AMPLITUDE * (sd * sn + s * w * cs);
            self.qr[2][j] = AMPLITUDE * (sdd * sn + 2.0 * sd * w * cs - s * w * w * sn);
        }
    }

    /// The reference of step k, then kinematics, task linearisation and the box, without
    /// solving ([`Controller::prepare`]; read them with [`Controller::equations`] and
    /// [`Controller::bounds`]).
    pub fn prepare(&mut self) -> iktc::Result<()> {
        self.reference(self.k as f64 * DT);
        self.ctl
            .set_joints_reference(self.upper, &self.qr[0], &self.qr[1], &self.qr[2])?;
        self.ctl.prepare(&self.state, DT)
    }

    /// Solves the prepared step, integrates its q̈ over Δt and advances k.
    pub fn finish(&mut self) -> iktc::Result<&SolveReport> {
        self.ctl.solve()?;
        self.ctl.integrate(&mut self.state)?;
        self.k += 1;
        Ok(self.ctl.report())
    }

    /// One step: kinematics, linearisation, box, solve, integration. Allocates nothing.
    pub fn step(&mut self) -> iktc::Result<&SolveReport> {
        self.prepare()?;
        self.finish()
    }
}
