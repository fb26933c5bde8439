//! Push tests on the simulated robot (true delay on a delay line, lag, 0.5 mm sensor noise),
//! the closed loop with the true delay, and the smooth hand-over between support phases.

use iktc::balance::{
    run_push, BalanceController, BalanceSettings, CaseParams, PlantParams, PushScenario, SimPlant,
    SimSettings, SupportPhase,
};
use nalgebra::{DMatrix, Matrix4};

/// Damping measured from the simulated ZMP after a push. Tolerances and why:
/// * each measurement within ±0.07 of 0.72: the controller mode decays within about one
///   period, so a fit over 0.5 mm noise on a 30–50 mm response scatters by a few hundredths
///   (seen: ±0.03 over seeds), and the fit starts 0.05 s after the push, when the lag and
///   delay modes have decayed only to ~8 %, which biases ζ down by about 0.03;
/// * the mean of 20 measurements (5 seeds × 2 phases × 2 planes) within ±0.04: the scatter
///   averages out; what remains is that bias and the true closed loop's own offset
///   (ζ ≈ 0.718 with the real delay instead of the Padé term, see the next test).
///
/// Also: the oscillation settles at least 3 times faster with the controller, and the
/// open-loop fit recovers the plant's own damping ratio within 0.02.
#[test]
fn controller_damps_pushes_to_the_designed_ratio() {
    let mut zetas = Vec::new();
    for seed in 1..=5u64 {
        for phase in [SupportPhase::Double, SupportPhase::Single] {
            let mut s = PushScenario::new(phase).unwrap();
            s.sim.seed = seed;
            let r = run_push(&s).unwrap();
            for m in &r.metrics {
                let z = m.closed.damping_ratio;
                assert!(
                    (z - 0.72).abs() < 0.07,
                    "{phase:?} {:?} seed {seed}: ζ = {z}",
                    m.plane
                );
                zetas.push(z);
                assert!((m.open.damping_ratio - m.model_damping_ratio).abs() < 0.02);
                let ts_open = m.open.settling_time.unwrap();
                let ts_closed = m.closed.settling_time.unwrap();
                assert!(ts_open > 3.0 * ts_closed, "{ts_open} vs {ts_closed}");
            }
        }
    }
    let mean = zetas.iter().sum::<f64>() / zetas.len() as f64;
    assert!((mean - 0.72).abs() < 0.04, "mean ζ = {mean}, {zetas:?}");
}

/// The static COM→ZMP gain: the model's `K l/(K − m g l)`, measured with and without the
/// controller, agree within 1 % (noise averaged over 10 s).
#[test]
fn static_gain_is_unchanged() {
    for phase in [SupportPhase::Double, SupportPhase::Single] {
        let r = run_push(&PushScenario::new(phase).unwrap()).unwrap();
        for m in &r.metrics {
            let g = m.static_gain_model;
            assert!((m.static_gain_open - g).abs() < 0.01 * g, "{m:?}");
            assert!((m.static_gain_closed - g).abs() < 0.01 * g, "{m:?}");
        }
    }
}

/// The closed loop with the *true* delay (4 samples at 200 Hz) instead of the Padé term,
/// built as one linear map (plant, delay line, observer, feedback): its dominant pole pair
/// keeps ζ within 0.01 of the design and is stable. Independent of the simulator's code.
#[test]
fn closed_loop_with_true_delay_keeps_the_design() {
    let cases = CaseParams::synthetic().unwrap();
    let settings = BalanceSettings::default();
    for p in [cases.yz_dsp, cases.xz_dsp, cases.yz_ssp, cases.xz_ssp] {
        let ctrl = BalanceController::new(
            &CaseParams {
                xz_ssp: p,
                xz_dsp: p,
                yz_ssp: p,
                yz_dsp: p,
            },
            &settings,
            SupportPhase::Double,
        )
        .unwrap();
        let d = ctrl
            .controller(iktc::balance::Plane::Xz, SupportPhase::Double)
            .design();
        let dt = 0.005;
        let ip = p.ipcj.state_space();
        let ts = p.lag;
        let mut a = DMatrix::<f64>::zeros(4, 4);
        a[(0, 1)] = 1.0;
        a[(1, 0)] = ip.a[(1, 0)];
        a[(1, 1)] = ip.a[(1, 1)];
        a[(2, 0)] = ip.c[0] / ts;
        a[(2, 1)] = ip.c[1] / ts;
        a[(2, 2)] = -1.0 / ts;
        a[(0, 3)] = ip.b[0];
        a[(1, 3)] = ip.b[1];
        a[(2, 3)] = ip.d / ts;
        let e = (a * dt).exp();
        let nd = (2.0 * p.pade / dt).round() as usize;
        let n = 3 + nd + 4;
        let m = d.observer_gain;
        let i4 = Matrix4::<f64>::identity();
        let xbar_xh = i4 - m * d.c;
        let u_xh = -(d.gain * xbar_xh);
        let u_y = -(d.gain * m)[0];
        let mut big = DMatrix::<f64>::zeros(n, n);
        let y_col = 3 + nd - 1;
        for i in 0..3 {
            for j in 0..3 {
                big[(i, j)] = e[(i, j)];
            }
            big[(i, y_col)] += e[(i, 3)] * u_y;
            for j in 0..4 {
                big[(i, 3 + nd + j)] += e[(i, 3)] * u_xh[j];
            }
        }
        big[(3, 2)] = 1.0;
        for i in 1..nd {
            big[(3 + i, 3 + i - 1)] = 1.0;
        }
        let xh_xh = d.ad * xbar_xh + d.bd * u_xh;
        let xh_y = d.ad * m + d.bd * u_y;
        for i in 0..4 {
            big[(3 + nd + i, y_col)] = xh_y[i];
            for j in 0..4 {
                big[(3 + nd + i, 3 + nd + j)] = xh_xh[(i, j)];
            }
        }
        let s: Vec<_> = big
            .complex_eigenvalues()
            .iter()
            .map(|z| z.ln() / dt)
            .collect();
        assert!(s.iter().all(|z| z.re < 0.0), "unstable: {s:?}");
        let dom = s
            .iter()
            .filter(|z| z.im.abs() > 1e-6)
            .min_by(|a, b| a.norm().total_cmp(&b.norm()))
            .unwrap();
        let zeta = -dom.re / dom.norm();
        assert!((zeta - 0.72).abs() < 0.01, "ζ = {zeta}");
    }
}

/// A support-phase change in mid-oscillation: the command never jumps by more than it moves
/// in an ordinary tick (the cross-fade), switching back mid-blend is smooth too, and the
/// controller keeps the plant stable across the changes.
#[test]
fn phase_hand_over_is_smooth() {
    let cases = CaseParams::synthetic().unwrap();
    let mut ctrl =
        BalanceController::new(&cases, &BalanceSettings::default(), SupportPhase::Double).unwrap();
    let sim = SimSettings::default();
    let mut plants = [
        SimPlant::new(PlantParams::from_model(cases.xz_dsp, 45.0, 0.0), &sim).unwrap(),
        SimPlant::new(PlantParams::from_model(cases.yz_dsp, 45.0, 0.0), &sim).unwrap(),
    ];
    plants[0].push(2.0).unwrap();
    plants[1].push(-2.0).unwrap();
    let mut last = [0.0; 2];
    let mut max_step_steady: f64 = 0.0;
    let mut max_step_switch: f64 = 0.0;
    let mut blends = Vec::new();
    for k in 0..600 {
        // DSP until 0.5 s, SSP from 0.5 s, back to DSP at 0.53 s (mid-blend), SSP at 1.5 s.
        let phase = match k {
            0..=99 => SupportPhase::Double,
            100..=105 => SupportPhase::Single,
            106..=299 => SupportPhase::Double,
            _ => SupportPhase::Single,
        };
        let y = [plants[0].measure(), plants[1].measure()];
        let out = ctrl.step(phase, [0.0, 0.0], y).unwrap();
        blends.push(out.blend);
        for i in 0..2 {
            let step = (out.com_offset[i] - last[i]).abs();
            if (95..100).contains(&k) || (290..300).contains(&k) {
                max_step_steady = max_step_steady.max(step);
            }
            if (100..130).contains(&k) || (300..330).contains(&k) {
                max_step_switch = max_step_switch.max(step);
            }
            last[i] = out.com_offset[i];
            plants[i].advance(out.u[i]).unwrap();
        }
    }
    assert!(
        blends[100] < 0.1 && blends[130] == 1.0,
        "{:?}",
        &blends[95..135]
    );
    assert!(
        max_step_switch < 2.0 * max_step_steady,
        "{max_step_switch} vs {max_step_steady}"
    );
    // Settled at the end: the pushes are damped out in SSP as well.
    for p in &plants {
        assert!(p.delayed_zmp().abs() < 1e-3, "{}", p.delayed_zmp());
    }
    // Non-finite input is refused without changing the state.
    let before = ctrl.clone();
    assert!(ctrl
        .step(SupportPhase::Single, [f64::NAN, 0.0], [0.0, 0.0])
        .is_err());
    assert_eq!(before, ctrl);
}
