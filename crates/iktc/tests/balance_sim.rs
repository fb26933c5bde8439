//! The simulated plant against closed forms: the free IPCJ response after a push, and the
//! delay line.

use std::f64::consts::TAU;

use iktc::balance::{FullModelParams, IpcjParams, PlantParams, SimPlant, SimSettings};

fn model() -> FullModelParams {
    FullModelParams {
        ipcj: IpcjParams::from_modal(0.8, TAU * 2.0, 0.05, 9.81).unwrap(),
        lag: 0.02,
        pade: 0.01,
    }
}

/// After an impulse J on the COM, θ(t) = (J/(m l w_d)) e^{−ζ w_n t} sin(w_d t).
#[test]
fn free_response_after_push_matches_closed_form() {
    let (m, j) = (45.0, 3.0);
    let mut p = SimPlant::new(
        PlantParams::from_model(model(), m, 0.0),
        &SimSettings::default(),
    )
    .unwrap();
    p.push(j).unwrap();
    let (wn, z) = (TAU * 2.0, 0.05);
    let wd = wn * (1.0f64 - z * z).sqrt();
    let v0 = j / (m * 0.8);
    for k in 1..=400 {
        p.advance(0.0).unwrap();
        let t = k as f64 * 0.005;
        let want = v0 / wd * (-z * wn * t).exp() * (wd * t).sin();
        assert!((p.state()[0] - want).abs() < 1e-10, "t = {t}");
    }
}

/// The measured ZMP of a plant with delay d equals the undelayed plant's output d earlier,
/// for a delay on the grid (exact) and one between grid points (linear interpolation).
#[test]
fn delay_line_shifts_the_output() {
    let s = SimSettings::default();
    let mut no_delay = PlantParams::from_model(model(), 45.0, 0.0);
    no_delay.delay = 0.0;
    let mut reference = SimPlant::new(no_delay, &s).unwrap();
    let mut hist = Vec::new();
    let u = |k: usize| 0.01 * (0.7 * k as f64 * 0.005).sin() + if k > 20 { 0.005 } else { 0.0 };
    for k in 0..400 {
        hist.push(reference.measure());
        reference.advance(u(k)).unwrap();
    }
    let mut delayed = SimPlant::new(PlantParams::from_model(model(), 45.0, 0.0), &s).unwrap();
    for (k, h) in hist.iter().enumerate() {
        let y = delayed.measure();
        let want = if k >= 4 { hist[k - 4] } else { 0.0 };
        assert!((y - want).abs() < 1e-12, "k = {k}: {y} vs {want} ({h})");
        delayed.advance(u(k)).unwrap();
    }
    // 4.5 samples with one substep per period: the mean of the two neighbours (the
    // integration is exact at any substep count, so `hist` still applies).
    let mut frac = PlantParams::from_model(model(), 45.0, 0.0);
    frac.delay = 0.0225;
    let one = SimSettings {
        substeps: 1,
        ..SimSettings::default()
    };
    let mut p = SimPlant::new(frac, &one).unwrap();
    for k in 0..400 {
        let y = p.measure();
        if k >= 5 {
            let want = 0.5 * (hist[k - 4] + hist[k - 5]);
            assert!((y - want).abs() < 1e-12, "k = {k}");
        }
        p.advance(u(k)).unwrap();
    }
}

#[test]
fn bad_plant_parameters_are_errors() {
    let mut p = PlantParams::from_model(model(), 45.0, 0.0);
    p.delay = -0.01;
    assert!(SimPlant::new(p, &SimSettings::default()).is_err());
    let mut p = PlantParams::from_model(model(), 45.0, 0.0);
    p.mass = 0.0;
    assert!(SimPlant::new(p, &SimSettings::default()).is_err());
    let mut ok = SimPlant::new(
        PlantParams::from_model(model(), 45.0, 0.0),
        &SimSettings::default(),
    )
    .unwrap();
    assert!(ok.advance(f64::NAN).is_err());
    assert!(ok.push(f64::INFINITY).is_err());
}
