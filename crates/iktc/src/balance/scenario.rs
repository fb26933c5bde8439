//! The three balance scenarios as plain, serialisable results (time series and summaries):
//!
//! * [`run_identify`]: a sine sweep on the simulated plant, the identified model over the
//!   measured Bode data (Figure 12), identified against true parameters;
//! * [`run_design`]: the pole-placement gain, the closed-loop poles and the root locus
//!   (Figure 13);
//! * [`run_push`]: the ZMP after a push on the COM with and without the controller
//!   (Figures 16–17), with peak, settling time and damping ratio measured from the response,
//!   and the static COM→ZMP gain with and without it.

use nalgebra::{Complex, RowVector4};
use serde::Serialize;

use super::cases::{BalanceController, BalanceSettings, CaseParams, Plane, SupportPhase};
use super::design::{design_discrete, place_poles, ContinuousDesign, DiscreteSettings, PoleSpec};
use super::identify::{identify, Identification, IdentifySettings};
use super::model::{invalid, Bode, FullModelParams, Modal};
use super::response::{analyse_response, ResponseMetrics, ResponseSettings};
use super::sim::{PlantParams, SimPlant, SimSettings};
use super::sweep::{sine_sweep, SweepSettings};
use crate::error::Result;
use crate::sim::health::{HealthMonitor, HealthReport, HealthSettings, Verdict};
use crate::walk::{Pose2, SupportPolygon};

/// Bode data for plotting: frequency \[Hz\], magnitude \[dB re 1 m/rad\], phase \[deg\].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BodeSeries {
    /// Frequencies \[Hz\].
    pub frequency_hz: Vec<f64>,
    /// Magnitudes `20 log₁₀ |y/u|` \[dB\].
    pub magnitude_db: Vec<f64>,
    /// Phases \[deg\], unwrapped.
    pub phase_deg: Vec<f64>,
}

impl BodeSeries {
    fn from_bode(b: &Bode) -> Self {
        Self {
            frequency_hz: b.omega.iter().map(|w| w / std::f64::consts::TAU).collect(),
            magnitude_db: b.magnitude.iter().map(|m| 20.0 * m.log10()).collect(),
            phase_deg: b.phase.iter().map(|p| p.to_degrees()).collect(),
        }
    }
}

/// The identification experiment.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IdentifyScenario {
    /// The true plant.
    pub plant: PlantParams,
    /// Simulation settings (rate, substeps, noise seed).
    pub sim: SimSettings,
    /// The sweep.
    pub sweep: SweepSettings,
    /// The fit.
    pub identify: IdentifySettings,
    /// Points of the model curves \[–\].
    pub curve_points: usize,
}

impl Default for IdentifyScenario {
    /// The `ỹz̃`-DSP case of [`CaseParams::synthetic`] (the errata's plant), 45 kg, 0.5 mm
    /// sensor noise, true delay `2T`.
    fn default() -> Self {
        let model = CaseParams::synthetic()
            .map(|c| c.yz_dsp)
            .unwrap_or(FALLBACK_MODEL);
        Self {
            plant: PlantParams::from_model(model, 45.0, 5e-4),
            sim: SimSettings::default(),
            sweep: SweepSettings::default(),
            identify: IdentifySettings::default(),
            curve_points: 300,
        }
    }
}

/// The errata's plant written out, used only if the synthetic cases could not be built.
const FALLBACK_MODEL: FullModelParams = FullModelParams {
    ipcj: super::model::IpcjParams {
        length: 0.8,
        stiffness_per_mass: 108.912_749_067_155,
        damping_per_mass: 0.804_247_719_318_987,
        gravity: super::model::STANDARD_GRAVITY,
    },
    lag: 0.02,
    pade: 0.01,
};

/// One parameter, true against identified.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterComparison {
    /// Name and symbol.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// The simulated plant's value.
    pub true_value: f64,
    /// The identified value.
    pub identified: f64,
    /// Its one-sigma standard error.
    pub std_error: f64,
    /// `(identified − true)/true` \[–\].
    pub relative_error: f64,
}

/// Result of [`run_identify`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IdentifyResult {
    /// The measured points.
    pub measured: BodeSeries,
    /// The identified model on a fine grid.
    pub fitted: BodeSeries,
    /// The true plant's model (with the Padé term) on the same grid.
    pub truth: BodeSeries,
    /// The true plant.
    pub plant: PlantParams,
    /// The fit.
    pub identification: Identification,
    /// True against identified, in the order l, K/m, b/m, τ_s, T.
    pub comparison: Vec<ParameterComparison>,
}

/// Runs the sine sweep and the identification.
pub fn run_identify(s: &IdentifyScenario) -> Result<IdentifyResult> {
    if s.curve_points < 2 {
        return Err(invalid(
            "IdentifyScenario::curve_points",
            s.curve_points as f64,
            ">= 2",
        ));
    }
    let data = sine_sweep(&s.plant, &s.sim, &s.sweep)?;
    let id = identify(&data, &s.identify)?;
    let (w0, w1) = (
        std::f64::consts::TAU * s.sweep.min_frequency / 2.0,
        std::f64::consts::TAU * s.sweep.max_frequency * 2.0,
    );
    let grid: Vec<f64> = (0..s.curve_points)
        .map(|i| w0 * (w1 / w0).powf(i as f64 / (s.curve_points - 1) as f64))
        .collect();
    let fitted_bode = id.params.bode(&grid);
    let truth_bode = s.plant.model.bode(&grid);
    // Measured phase: principal value, unwrapped to the fitted model's branch.
    let reference = id.params.bode(&data.omega);
    let measured = Bode {
        omega: data.omega.clone(),
        magnitude: data.response.iter().map(|h| h.norm()).collect(),
        phase: data
            .response
            .iter()
            .zip(&reference.phase)
            .map(|(h, r)| {
                let tau = std::f64::consts::TAU;
                h.arg() + tau * ((r - h.arg()) / tau).round()
            })
            .collect(),
    };
    let truth = [
        s.plant.model.ipcj.length,
        s.plant.model.ipcj.stiffness_per_mass,
        s.plant.model.ipcj.damping_per_mass,
        s.plant.model.lag,
        s.plant.model.pade,
    ];
    let comparison = id
        .estimates
        .iter()
        .zip(truth)
        .map(|(e, t)| ParameterComparison {
            name: e.name.to_string(),
            unit: e.unit.to_string(),
            true_value: t,
            identified: e.value,
            std_error: e.std_error,
            relative_error: (e.value - t) / t,
        })
        .collect();
    Ok(IdentifyResult {
        measured: BodeSeries::from_bode(&measured),
        fitted: BodeSeries::from_bode(&fitted_bode),
        truth: BodeSeries::from_bode(&truth_bode),
        plant: s.plant,
        identification: id,
        comparison,
    })
}

/// The design scenario.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DesignScenario {
    /// The model designed for.
    pub params: FullModelParams,
    /// Desired poles.
    pub poles: PoleSpec,
    /// Discretisation and observer.
    pub discrete: DiscreteSettings,
    /// Points of the root locus per decade of gain \[–\].
    pub locus_points_per_decade: usize,
    /// Largest output-feedback gain of the root locus, as a multiple of `1/|G(0)|` \[–\].
    pub locus_max_gain: f64,
}

impl Default for DesignScenario {
    /// The `ỹz̃`-DSP synthetic case (the errata's plant), `ζ_d = 0.72`, `w_d = w_n`, 200 Hz.
    fn default() -> Self {
        Self {
            params: CaseParams::synthetic()
                .map(|c| c.yz_dsp)
                .unwrap_or(FALLBACK_MODEL),
            poles: PoleSpec::default(),
            discrete: DiscreteSettings::default(),
            locus_points_per_decade: 60,
            locus_max_gain: 1e4,
        }
    }
}

/// A root locus: branches of the closed-loop poles as the gain grows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RootLocus {
    /// The gains, increasing from 0.
    pub gains: Vec<f64>,
    /// One branch per pole: `[re, im]` \[rad/s\] at each gain.
    pub branches: Vec<Vec<[f64; 2]>>,
}

/// Result of [`run_design`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignResult {
    /// The model.
    pub params: FullModelParams,
    /// Open-loop natural frequency and damping ratio of the IPCJ pair.
    pub open_loop_modal: Modal,
    /// Static gain `y/u` \[m/rad\].
    pub dc_gain: f64,
    /// Open-loop poles `[re, im]` \[rad/s\] (eq. 32).
    pub open_loop_poles: [[f64; 2]; 4],
    /// Zeros \[rad/s\].
    pub zeros: [f64; 3],
    /// The continuous design: `K_f`, `N`, closed-loop poles (eq. 33).
    pub continuous: ContinuousDesign,
    /// Discrete gain `K_d` on `[θ, θ̇, z, p]`.
    pub discrete_gain: [f64; 4],
    /// Discrete feed-forward `N_d`.
    pub discrete_feedforward: f64,
    /// Discrete observer gain `M` (current estimator).
    pub observer_gain: [f64; 4],
    /// Continuous-equivalent observer poles `[re, im]` \[rad/s\].
    pub observer_poles: [[f64; 2]; 4],
    /// Classic root locus of `1 + k G(s)` (output feedback `u = −k y`), `k ≥ 0` (Figure 13).
    pub root_locus: RootLocus,
    /// Path of the poles of `A − B (κ K_f)` for `κ` from 0 to 1: open loop to design.
    pub design_path: RootLocus,
}

/// Runs the design.
pub fn run_design(s: &DesignScenario) -> Result<DesignResult> {
    let p = &s.params;
    let continuous = place_poles(p, &s.poles)?;
    let disc = design_discrete(p, &s.poles, &s.discrete)?;
    if s.locus_points_per_decade == 0 || !(s.locus_max_gain.is_finite() && s.locus_max_gain > 0.0) {
        return Err(invalid(
            "DesignScenario::locus_points_per_decade / locus_max_gain",
            s.locus_max_gain,
            "points >= 1 and a gain > 0",
        ));
    }
    let tf = p.transfer_function();
    let k_unit = 1.0 / p.dc_gain().abs();
    let decades = 4.0 + s.locus_max_gain.log10();
    let n = (decades * s.locus_points_per_decade as f64).ceil() as usize;
    let mut gains = vec![0.0];
    gains.extend((0..=n).map(|i| k_unit * 10f64.powf(-4.0 + decades * i as f64 / n as f64)));
    let root_locus = track(&gains, |k| {
        tf.denominator.add_scaled(k, &tf.numerator).roots()
    });
    let ss = p.state_space();
    let kappas: Vec<f64> = (0..=200).map(|i| i as f64 / 200.0).collect();
    let design_path = track(&kappas, |kappa| {
        let k = RowVector4::new(continuous.gain[0], continuous.gain[1], 0.0, 0.0) * kappa;
        (ss.a - ss.b * k)
            .complex_eigenvalues()
            .iter()
            .copied()
            .collect()
    });
    let h = s.discrete.control_period;
    let pair = |c: Complex<f64>| [c.re, c.im];
    let observer_poles = disc
        .observer_poles
        .map(|z| pair(Complex::new(z[0], z[1]).ln() / h));
    Ok(DesignResult {
        params: *p,
        open_loop_modal: p.ipcj.modal()?,
        dc_gain: p.dc_gain(),
        open_loop_poles: p.poles().map(pair),
        zeros: p.zeros(),
        continuous,
        discrete_gain: disc.gain.into(),
        discrete_feedforward: disc.feedforward,
        observer_gain: disc.observer_gain.into(),
        observer_poles,
        root_locus,
        design_path,
    })
}

/// Follows the roots along the parameter values by nearest-neighbour matching.
fn track(params: &[f64], roots: impl Fn(f64) -> Vec<Complex<f64>>) -> RootLocus {
    let mut branches: Vec<Vec<[f64; 2]>> = Vec::new();
    let mut last: Vec<Complex<f64>> = Vec::new();
    for &k in params {
        let mut r = roots(k);
        if last.is_empty() {
            branches = r.iter().map(|z| vec![[z.re, z.im]]).collect();
            last = r;
            continue;
        }
        for (b, prev) in branches.iter_mut().zip(last.iter_mut()) {
            let best = r
                .iter()
                .enumerate()
                .min_by(|x, y| (x.1 - *prev).norm().total_cmp(&(y.1 - *prev).norm()))
                .map(|(i, _)| i);
            if let Some(i) = best {
                let z = r.swap_remove(i);
                b.push([z.re, z.im]);
                *prev = z;
            }
        }
    }
    RootLocus {
        gains: params.to_vec(),
        branches,
    }
}

/// The push test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PushScenario {
    /// Support phase of the test (which two cases are used).
    pub phase: SupportPhase,
    /// The robot's four cases (true plant = model, with a true delay `2T`).
    pub cases: CaseParams,
    /// Robot mass \[kg\].
    pub mass: f64,
    /// ZMP sensor noise, standard deviation \[m\].
    pub noise_std: f64,
    /// The controller.
    pub controller: BalanceSettings,
    /// Simulation (substeps, seed); its control period must equal the controller's.
    pub sim: SimSettings,
    /// Time of the push \[s\].
    pub push_time: f64,
    /// Length of the run \[s\].
    pub duration: f64,
    /// The push: horizontal impulse on the COM `[x̃, ỹ]` \[N·s\].
    pub impulse: [f64; 2],
    /// Analysis of the responses without the controller (one mode).
    pub response: ResponseSettings,
    /// Analysis of the responses with the controller (two modes: controller and observer;
    /// the fit starts 0.05 s after the push, where the signal is strong: a later start leaves
    /// less of the quickly damped response above the noise).
    pub closed_loop_response: ResponseSettings,
    /// Step of `u_ref` for the static-gain test \[rad\].
    pub static_step: f64,
    /// Length of the static-gain runs \[s\]; the gain is the mean over their last third.
    pub static_duration: f64,
    /// The feet, for the support polygon the ZMP must stay in.
    pub support: PushSupport,
    /// The run checks: the ZMP of either run (with or without the controller) leaving the
    /// support polygon by more than [`HealthSettings::zmp_tolerance`] stops the scenario with
    /// [`crate::Error::RunFailed`], unless [`HealthSettings::keep_going`].
    pub health: HealthSettings,
}

/// The feet under the pushed robot. The measured ZMP `(x̃, ỹ)` is its deviation from the
/// nominal ZMP in the local frame of Figure 11, which sits at the centre of the support: in
/// single support the stance sole's centre, in double support the midpoint between the soles.
/// The support polygon in that frame is the stance sole (SSP) or the hull of both soles at
/// `ỹ = ±foot_separation/2` (DSP), [`SupportPolygon`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PushSupport {
    /// Sole length along x̃ \[m\].
    pub sole_length: f64,
    /// Sole width along ỹ \[m\].
    pub sole_width: f64,
    /// Distance between the sole centres along ỹ \[m\].
    pub foot_separation: f64,
}

impl Default for PushSupport {
    /// JVRC-1's nominal sole (0.2 × 0.1 m) and stance (0.19 m between the feet).
    fn default() -> Self {
        Self {
            sole_length: 0.2,
            sole_width: 0.1,
            foot_separation: 0.19,
        }
    }
}

impl PushSupport {
    /// The support polygon in the local frame for `phase`. Errors: sizes not finite and > 0.
    pub fn polygon(&self, phase: SupportPhase) -> Result<SupportPolygon> {
        for (name, v) in [
            ("PushSupport::sole_length [m]", self.sole_length),
            ("PushSupport::sole_width [m]", self.sole_width),
            ("PushSupport::foot_separation [m]", self.foot_separation),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "finite and > 0"));
            }
        }
        let (l, w, d) = (self.sole_length, self.sole_width, self.foot_separation);
        let mut p = SupportPolygon::default();
        match phase {
            SupportPhase::Single => p.set_sole(&Pose2::new(0.0, 0.0, 0.0), l, w),
            SupportPhase::Double => p.set_hull_of_soles(
                &Pose2::new(0.0, 0.5 * d, 0.0),
                &Pose2::new(0.0, -0.5 * d, 0.0),
                l,
                w,
            ),
        }
        Ok(p)
    }
}

impl PushScenario {
    /// The default push test in the given phase: synthetic cases, 45 kg, 0.5 mm noise, an
    /// impulse of (2, 2) N·s at 1 s (about a 20 N shove for 0.1 s), 14 s of data (the open loop
    /// needs about 10 s to settle).
    pub fn new(phase: SupportPhase) -> Result<Self> {
        Ok(Self {
            phase,
            cases: CaseParams::synthetic()?,
            mass: 45.0,
            noise_std: 5e-4,
            controller: BalanceSettings::default(),
            sim: SimSettings::default(),
            push_time: 1.0,
            duration: 14.0,
            impulse: [2.0, 2.0],
            response: ResponseSettings::default(),
            closed_loop_response: ResponseSettings {
                modes: 2,
                second_mode_ratio: 2.0,
                fit_delay: 0.05,
                ..ResponseSettings::default()
            },
            static_step: 0.01,
            static_duration: 30.0,
            support: PushSupport::default(),
            health: HealthSettings::default(),
        })
    }

    fn plants(&self) -> [PlantParams; 2] {
        Plane::BOTH.map(|pl| {
            PlantParams::from_model(*self.cases.get(pl, self.phase), self.mass, self.noise_std)
        })
    }

    /// Checks the parts and that the simulation runs at the controller's rate.
    pub fn validate(&self) -> Result<()> {
        self.controller.validate()?;
        self.sim.validate()?;
        self.response.validate()?;
        self.closed_loop_response.validate()?;
        self.health.validate()?;
        self.support.polygon(self.phase)?;
        if (self.sim.control_period - self.controller.discrete.control_period).abs() > 0.0 {
            return Err(invalid(
                "PushScenario::sim.control_period [s]",
                self.sim.control_period,
                "equal to the controller's control period",
            ));
        }
        for (name, v) in [
            ("PushScenario::duration [s]", self.duration),
            ("PushScenario::static_duration [s]", self.static_duration),
            ("PushScenario::static_step [rad]", self.static_step),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "finite and > 0"));
            }
        }
        if !(self.push_time.is_finite() && self.push_time >= 0.0 && self.push_time < self.duration)
        {
            return Err(invalid(
                "PushScenario::push_time [s]",
                self.push_time,
                "in [0, duration)",
            ));
        }
        for p in self.plants() {
            p.validate()?;
        }
        Ok(())
    }
}

/// Metrics of one plane.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanePushMetrics {
    /// The plane.
    pub plane: Plane,
    /// Without the controller.
    pub open: ResponseMetrics,
    /// With the controller.
    pub closed: ResponseMetrics,
    /// Designed damping ratio `ζ_d` \[–\].
    pub designed_damping_ratio: f64,
    /// Designed natural frequency `w_d` \[rad/s\].
    pub designed_natural_frequency: f64,
    /// Open-loop damping ratio of the model \[–\].
    pub model_damping_ratio: f64,
    /// Static COM→ZMP gain of the model, `K l/(K − m g l)` \[m/rad\].
    pub static_gain_model: f64,
    /// Static gain measured without the controller \[m/rad\].
    pub static_gain_open: f64,
    /// Static gain measured with the controller \[m/rad\].
    pub static_gain_closed: f64,
}

/// Result of [`run_push`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PushResult {
    /// The scenario.
    pub scenario: PushScenario,
    /// Sample times \[s\].
    pub time: Vec<f64>,
    /// Measured ZMP without the controller, `[x̃, ỹ]` \[m\].
    pub zmp_open: [Vec<f64>; 2],
    /// Measured ZMP with the controller \[m\].
    pub zmp_closed: [Vec<f64>; 2],
    /// The controller's COM reference offset `Δc` \[m\].
    pub com_offset: [Vec<f64>; 2],
    /// Per-plane metrics `[x̃z̃, ỹz̃]`.
    pub metrics: [PlanePushMetrics; 2],
    /// The support polygon in the local frame, counter-clockwise \[m\].
    pub support: Vec<(f64, f64)>,
    /// Without the controller: largest distance of the ZMP outside the support polygon
    /// \[m\] (0: it stayed inside).
    pub zmp_excursion_open: f64,
    /// With the controller: the same \[m\].
    pub zmp_excursion_closed: f64,
    /// The checks of both runs (the ZMP inside the support polygon, the ZMP finite).
    pub health: HealthReport,
}

/// One series of samples per plane (x–z, y–z).
type PlaneSeries = [Vec<f64>; 2];

/// The measured ZMP of both planes \[m\] over `n` ticks without the controller
/// (u = u_ref = 0), pushed at tick `k_push`.
fn open_loop_zmp(
    s: &PushScenario,
    plants: &[PlantParams; 2],
    n: usize,
    k_push: usize,
) -> Result<[Vec<f64>; 2]> {
    let mut zmp_open = [Vec::with_capacity(n), Vec::with_capacity(n)];
    for (i, p) in plants.iter().enumerate() {
        let mut sim = SimPlant::new(*p, &seeded(&s.sim, i as u64))?;
        for k in 0..n {
            if k == k_push {
                sim.push(s.impulse[i])?;
            }
            zmp_open[i].push(sim.measure());
            sim.advance(0.0)?;
        }
    }
    Ok(zmp_open)
}

/// The measured ZMP \[m\] and the controller's COM offset \[m\] of both planes over `n` ticks
/// with the controller (the same noise sequence as without), pushed at tick `k_push`.
fn closed_loop_zmp(
    s: &PushScenario,
    plants: &[PlantParams; 2],
    n: usize,
    k_push: usize,
) -> Result<(PlaneSeries, PlaneSeries)> {
    let mut zmp_closed = [Vec::with_capacity(n), Vec::with_capacity(n)];
    let mut com_offset = [Vec::with_capacity(n), Vec::with_capacity(n)];
    let mut sims = [
        SimPlant::new(plants[0], &seeded(&s.sim, 0))?,
        SimPlant::new(plants[1], &seeded(&s.sim, 1))?,
    ];
    let mut ctrl = BalanceController::new(&s.cases, &s.controller, s.phase)?;
    for k in 0..n {
        if k == k_push {
            for (sim, j) in sims.iter_mut().zip(s.impulse) {
                sim.push(j)?;
            }
        }
        let y = [sims[0].measure(), sims[1].measure()];
        let out = ctrl.step(s.phase, [0.0, 0.0], y)?;
        for i in 0..2 {
            zmp_closed[i].push(y[i]);
            com_offset[i].push(out.com_offset[i]);
            sims[i].advance(out.u[i])?;
        }
    }
    Ok((zmp_closed, com_offset))
}

/// Checks both runs' measured ZMP (period `dt` \[s\]): finite, and inside the support polygon;
/// returns each run's (without, with the controller) largest excursion outside it \[m\].
fn check_zmp_runs(
    dt: f64,
    polygon: &SupportPolygon,
    health: &mut HealthMonitor,
    zmp_open: &[Vec<f64>; 2],
    zmp_closed: &[Vec<f64>; 2],
) -> Result<[f64; 2]> {
    let mut excursion = [0.0f64; 2];
    for (run, (zmp, frame)) in [
        (
            zmp_open,
            "local frame of Fig. 11, run without the controller",
        ),
        (
            zmp_closed,
            "local frame of Fig. 11, run with the controller",
        ),
    ]
    .into_iter()
    .enumerate()
    {
        for (k, (x, y)) in zmp[0].iter().zip(&zmp[1]).enumerate() {
            let t = k as f64 * dt;
            if health.check_finite(t, "measured ZMP [m]", &[], &[*x, *y])? == Verdict::Stop {
                break;
            }
            health.check_support(t, polygon, (*x, *y), "ZMP", frame)?;
            health.end_tick();
            excursion[run] = excursion[run].max(-polygon.margin((*x, *y)));
        }
    }
    Ok(excursion)
}

/// Each plane's push metrics: the responses without and with the controller (push at
/// `t_push` \[s\]), the designed and the model's damping, and the static gains.
fn plane_metrics(
    s: &PushScenario,
    plants: &[PlantParams; 2],
    time: &[f64],
    zmp_open: &[Vec<f64>; 2],
    zmp_closed: &[Vec<f64>; 2],
    t_push: f64,
) -> Result<[PlanePushMetrics; 2]> {
    let mut metrics = Vec::with_capacity(2);
    for (i, plane) in Plane::BOTH.iter().enumerate() {
        let model = s.cases.get(*plane, s.phase);
        let open = analyse_response(time, &zmp_open[i], t_push, s.noise_std, &s.response)?;
        let closed = analyse_response(
            time,
            &zmp_closed[i],
            t_push,
            s.noise_std,
            &s.closed_loop_response,
        )?;
        let design = place_poles(model, &s.controller.poles)?;
        let (g_open, g_closed) = static_gains(s, *plane, &plants[i])?;
        metrics.push(PlanePushMetrics {
            plane: *plane,
            open,
            closed,
            designed_damping_ratio: design.damping_ratio,
            designed_natural_frequency: design.natural_frequency,
            model_damping_ratio: model.ipcj.modal()?.damping_ratio,
            static_gain_model: model.dc_gain(),
            static_gain_open: g_open,
            static_gain_closed: g_closed,
        });
    }
    let metrics: [PlanePushMetrics; 2] =
        metrics
            .try_into()
            .map_err(|_| crate::Error::InsufficientData {
                what: "push metrics".into(),
                message: "two planes expected".into(),
            })?;
    Ok(metrics)
}

/// Runs the push test with and without the controller, and the static-gain runs.
pub fn run_push(s: &PushScenario) -> Result<PushResult> {
    s.validate()?;
    let dt = s.sim.control_period;
    let n = (s.duration / dt).round() as usize;
    let k_push = (s.push_time / dt).round() as usize;
    let plants = s.plants();
    let time: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    // Without the controller: u = u_ref = 0.
    let zmp_open = open_loop_zmp(s, &plants, n, k_push)?;
    // With the controller (same noise sequence).
    let (zmp_closed, com_offset) = closed_loop_zmp(s, &plants, n, k_push)?;
    let polygon = s.support.polygon(s.phase)?;
    let mut health = HealthMonitor::new(s.health)?;
    let excursion = check_zmp_runs(dt, &polygon, &mut health, &zmp_open, &zmp_closed)?;
    let t_push = k_push as f64 * dt;
    let metrics = plane_metrics(s, &plants, &time, &zmp_open, &zmp_closed, t_push)?;
    Ok(PushResult {
        scenario: *s,
        time,
        zmp_open,
        zmp_closed,
        com_offset,
        metrics,
        support: polygon.vertices().to_vec(),
        zmp_excursion_open: excursion[0],
        zmp_excursion_closed: excursion[1],
        health: health.report(),
    })
}

/// Static COM→ZMP gain of one plane with and without the controller: step `u_ref` at 0 and
/// average `y/u_ref` over the last third of the run.
fn static_gains(s: &PushScenario, plane: Plane, plant: &PlantParams) -> Result<(f64, f64)> {
    let dt = s.sim.control_period;
    let n = (s.static_duration / dt).round() as usize;
    let tail = n - n / 3;
    let i = match plane {
        Plane::Xz => 0,
        Plane::Yz => 1,
    };
    let mut open = SimPlant::new(*plant, &seeded(&s.sim, 10 + i as u64))?;
    let mut closed = SimPlant::new(*plant, &seeded(&s.sim, 20 + i as u64))?;
    let mut ctrl = BalanceController::new(&s.cases, &s.controller, s.phase)?;
    let (mut sum_o, mut sum_c) = (0.0, 0.0);
    let step = s.static_step;
    for k in 0..n {
        let yo = open.measure();
        open.advance(step)?;
        let yc = closed.measure();
        let mut u_ref = [0.0; 2];
        let mut y = [0.0; 2];
        u_ref[i] = step;
        y[i] = yc;
        let out = ctrl.step(s.phase, u_ref, y)?;
        closed.advance(out.u[i])?;
        if k >= tail {
            sum_o += yo;
            sum_c += yc;
        }
    }
    let m = (n - tail).max(1) as f64;
    Ok((sum_o / m / step, sum_c / m / step))
}

fn seeded(sim: &SimSettings, offset: u64) -> SimSettings {
    SimSettings {
        seed: sim.seed.wrapping_mul(1000).wrapping_add(offset),
        ..*sim
    }
}
