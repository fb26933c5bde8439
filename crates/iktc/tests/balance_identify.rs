//! Identification (Section 4.2): exact recovery from model data, recovery within a stated
//! tolerance from a noisy sine sweep on the simulated plant (true delay, not Padé), and
//! refusal of bad data.

use std::f64::consts::TAU;

use iktc::balance::{
    identify, initial_guess, sine_sweep, FrequencyData, FullModelParams, IdentifySettings,
    IpcjParams, PlantParams, SimSettings, SweepSettings,
};
use iktc::Error;
use nalgebra::Complex;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn plant(f: f64, zeta: f64, lag: f64, pade: f64) -> FullModelParams {
    FullModelParams {
        ipcj: IpcjParams::from_modal(0.8, TAU * f, zeta, 9.81).unwrap(),
        lag,
        pade,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn params(p: &FullModelParams) -> [f64; 5] {
    [
        p.ipcj.length,
        p.ipcj.stiffness_per_mass,
        p.ipcj.damping_per_mass,
        p.lag,
        p.pade,
    ]
}

fn model_data(p: &FullModelParams, n: usize) -> FrequencyData {
    let omega: Vec<f64> = (0..n)
        .map(|i| TAU * 0.2 * (100.0f64).powf(i as f64 / (n - 1) as f64))
        .collect();
    let response = omega.iter().map(|w| p.frequency_response(*w)).collect();
    FrequencyData { omega, response }
}

/// Noise-free model data: the fit recovers the parameters to high precision, for several
/// plants (different resonances, damping, lag and delay).
#[test]
fn exact_data_are_fitted_exactly() {
    for p in [
        plant(2.0, 0.05, 0.02, 0.01),
        plant(1.2, 0.04, 0.03, 0.006),
        plant(3.0, 0.12, 0.01, 0.015),
    ] {
        let id = identify(&model_data(&p, 25), &IdentifySettings::default()).unwrap();
        for (a, b) in params(&id.params).iter().zip(params(&p)) {
            assert!(rel(*a, b) < 1e-6, "{:?}\n vs {p:?}", id.params);
        }
        assert!(id.rms_relative_error < 1e-8);
    }
}

/// Model data with 1 % multiplicative complex noise (seeded): within a few percent.
#[test]
fn noisy_model_data_are_fitted_within_tolerance() {
    let p = plant(2.0, 0.05, 0.02, 0.01);
    let mut d = model_data(&p, 30);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for h in d.response.iter_mut() {
        let e = Complex::new(rng.random_range(-0.01..0.01), rng.random_range(-0.01..0.01));
        *h *= Complex::new(1.0, 0.0) + e;
    }
    let id = identify(&d, &IdentifySettings::default()).unwrap();
    let tol = [0.01, 0.01, 0.05, 0.1, 0.1];
    for ((a, b), t) in params(&id.params).iter().zip(params(&p)).zip(tol) {
        assert!(rel(*a, b) < t, "{:?}\n vs {p:?}", id.params);
    }
    // The residual is the noise level: 1 % uniform in re and im -> RMS |e| ≈ 0.82 %.
    assert!(id.rms_relative_error > 0.004 && id.rms_relative_error < 0.012);
}

/// The sine-sweep experiment on the simulated plant (true delay 2T on a delay line, sensor
/// noise 0.5 mm): the identified parameters are within the stated tolerances. `l`, `K/m`,
/// `b/m` within 3 %; `τ_s` and `T` within 15 %: the Padé term is only an approximation of the
/// true delay, and the fit trades the lag against it at high frequency.
#[test]
fn sine_sweep_on_simulated_plant_recovers_parameters() {
    let p = plant(2.0, 0.05, 0.02, 0.01);
    let plant = PlantParams::from_model(p, 45.0, 5e-4);
    let data = sine_sweep(&plant, &SimSettings::default(), &SweepSettings::default()).unwrap();
    let id = identify(&data, &IdentifySettings::default()).unwrap();
    let tol = [0.03, 0.03, 0.03, 0.15, 0.15];
    for ((a, b), t) in params(&id.params).iter().zip(params(&p)).zip(tol) {
        assert!(rel(*a, b) < t, "{:?}\n vs {p:?}", id.params);
    }
}

#[test]
fn automatic_initial_guess_is_in_the_right_region() {
    let p = plant(2.0, 0.05, 0.02, 0.01);
    let g = initial_guess(&model_data(&p, 30), &IdentifySettings::default()).unwrap();
    let m = g.ipcj.modal().unwrap();
    assert!(rel(m.natural_frequency, TAU * 2.0) < 0.1);
    assert!(rel(g.ipcj.length, 0.8) < 0.3, "{g:?}");
    assert!(g.lag > 0.0 && g.pade > 0.0);
}

#[test]
fn too_few_or_non_finite_data_are_refused() {
    let p = plant(2.0, 0.05, 0.02, 0.01);
    let few = model_data(&p, 4);
    let r = identify(&few, &IdentifySettings::default());
    assert!(matches!(r, Err(Error::InsufficientData { .. })), "{r:?}");
    // Repeated frequencies do not count twice.
    let mut dup = model_data(&p, 3);
    dup.omega.extend(dup.omega.clone());
    dup.response.extend(dup.response.clone());
    assert!(matches!(
        identify(&dup, &IdentifySettings::default()),
        Err(Error::InsufficientData { .. })
    ));
    let mut nan = model_data(&p, 20);
    nan.response[5].im = f64::NAN;
    let r = identify(&nan, &IdentifySettings::default());
    assert!(matches!(r, Err(Error::NonFinite { .. })), "{r:?}");
    let mut neg = model_data(&p, 20);
    neg.omega[0] = -1.0;
    assert!(identify(&neg, &IdentifySettings::default()).is_err());
    let r = FrequencyData::from_bode(&[1.0, 2.0], &[1.0], &[0.0, 0.0]);
    assert!(matches!(r, Err(Error::DimensionMismatch { .. })));
    let r = FrequencyData::from_bode(&[1.0, 2.0], &[1.0, f64::INFINITY], &[0.0, 0.0]);
    assert!(matches!(r, Err(Error::NonFinite { .. })));
}
