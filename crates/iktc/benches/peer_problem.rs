//! The control tick on "the peer problem" (defined in `peer/problem.rs`: JVRC-1,
//! Δt = 5 ms, viable bounds, a_max = 10·v_max, five levels with k_p = 400 s⁻², k_v = 40 s⁻¹,
//! the 20 upper-body joints on sinusoids with phases from `ChaCha8Rng::seed_from_u64(17)`).
//!
//! Also IKTC with one joint left out of level 5 (`iktc_37_rows`: 37 rows for n = 38, the stack
//! no longer square).
//!
//! One criterion iteration is one step (kinematics update, task linearisation, box, solve,
//! integration) of the 2 000 timed steps that follow 50 untimed warm-up steps; the loop restarts
//! from the warmed-up state after the 2 000th. Solved by IKTC and by GF. Afterwards the median
//! per-step time of whole passes, interleaved between the methods, and what the run does (levels
//! corrected, QPs, which joints reach their position and velocity limits) are printed.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::limits::BoundMethod;
use iktc::model::ModelOptions;
use iktc::solver::{Method, SolverSettings};

#[path = "peer/problem.rs"]
mod peer;
use peer::{PeerProblem, TIMED, UPPER_BODY, WARMUP};

/// The problem after the warm-up steps, level 5 holding `upper`.
fn warmed(method: Method, settings: SolverSettings, upper: &[&str]) -> PeerProblem {
    let mut p = PeerProblem::with_upper_body(
        method,
        settings,
        BoundMethod::viable(),
        &ModelOptions::default(),
        upper,
    )
    .expect("peer problem");
    for _ in 0..WARMUP {
        p.step().expect("warm-up step");
    }
    p
}

/// The variants timed: name, method, settings, level 5's joints.
fn variants() -> Vec<(
    &'static str,
    Method,
    SolverSettings,
    &'static [&'static str],
)> {
    vec![
        ("iktc", Method::Iktc, SolverSettings::default(), &UPPER_BODY),
        (
            "iktc_cold",
            Method::Iktc,
            SolverSettings {
                warm_start: false,
                ..SolverSettings::default()
            },
            &UPPER_BODY,
        ),
        (
            "gf",
            Method::Cascade,
            SolverSettings::default(),
            &UPPER_BODY,
        ),
        // One joint left out of level 5: 37 rows for 38 coordinates.
        (
            "iktc_37_rows",
            Method::Iktc,
            SolverSettings::default(),
            &UPPER_BODY[..19],
        ),
    ]
}

fn bench(c: &mut Criterion) {
    let variants = variants();
    let starts: Vec<PeerProblem> = variants
        .iter()
        .map(|(_, m, s, upper)| warmed(*m, *s, upper))
        .collect();
    summary();
    // Interleaved whole passes of the 2 000 timed steps: median per-step time of each.
    let rounds = 5;
    let mut passes: Vec<Vec<f64>> = vec![Vec::with_capacity(rounds); variants.len()];
    for _ in 0..rounds {
        for (start, times) in starts.iter().zip(passes.iter_mut()) {
            let mut p = start.clone();
            let t0 = Instant::now();
            for _ in 0..TIMED {
                let _ = std::hint::black_box(p.step().map(|r| r.qp_solves));
            }
            times.push(t0.elapsed().as_secs_f64() * 1e6 / TIMED as f64);
        }
    }
    let medians: Vec<f64> = passes
        .iter()
        .map(|t| iktc::sim::percentile(t, 0.5))
        .collect();
    for ((name, ..), m) in variants.iter().zip(&medians) {
        eprintln!(
            "peer_problem/{name}: interleaved passes: median {m:.2} µs per step, {:.3} × {}",
            m / medians[0],
            variants[0].0
        );
    }
    let mut group = c.benchmark_group("peer_problem");
    for ((name, ..), start) in variants.iter().zip(&starts) {
        group.bench_function(*name, |b| {
            b.iter_custom(|iters| {
                let mut p = start.clone();
                let mut k = 0;
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    if k == TIMED {
                        p = start.clone();
                        k = 0;
                    }
                    let t0 = Instant::now();
                    let _ = std::hint::black_box(p.step().map(|r| r.qp_solves));
                    total += t0.elapsed();
                    k += 1;
                }
                total
            })
        });
    }
    group.finish();
}

/// What the IKTC run does over the 2 050 steps (from t = 0): corrected levels, QPs, and the
/// joints that reach a position limit (within `POSITION_REACHED` \[rad\]) or their velocity
/// limit (|q̇| ≥ (1 − `VELOCITY_REACHED`) v_max).
fn summary() {
    /// A joint this close to a position limit has reached it \[rad\].
    const POSITION_REACHED: f64 = 1e-3;
    /// A joint this close to its velocity limit, as a fraction of it, has reached it \[–\].
    const VELOCITY_REACHED: f64 = 1e-3;
    let mut p = PeerProblem::new(Method::Iktc, SolverSettings::default()).expect("peer problem");
    let names = p.robot().dof_names();
    let (nb, nqb) = (p.robot().base_nv(), p.robot().base_nq());
    let dofs = p.limits().dofs().to_vec();
    let nv = names.len();
    let mut closest = vec![f64::INFINITY; nv];
    let mut fastest = vec![0.0_f64; nv];
    let (mut corrected, mut qps, mut infeasible, mut screened) = (vec![0; 5], 0, 0, 0);
    let (mut warm, mut iterations) = (0, 0);
    let mut uncorrected = 0;
    for _ in 0..WARMUP + TIMED {
        let r = p.step().expect("step");
        match r.corrected_from {
            Some(i) => corrected[i] += 1,
            None => uncorrected += 1,
        }
        qps += r.qp_solves;
        infeasible += r.qp_infeasible;
        screened += r.screened_infeasible;
        warm += r.qp_warm_started;
        iterations += r.qp_iterations;
        for d in nb..nv {
            let q = p.state.q[d + nqb - nb];
            let qd = p.state.qd[d];
            let l = &dofs[d];
            closest[d] = closest[d].min((q - l.position_min).min(l.position_max - q));
            fastest[d] = fastest[d].max(qd.abs() / l.velocity_max);
        }
    }
    eprintln!(
        "peer_problem: {} steps: corrected from level (1-based) {:?}, {uncorrected} uncorrected; \
         {qps} QPs ({infeasible} infeasible, {warm} warm-started, {iterations} iterations), \
         {screened} levels screened",
        WARMUP + TIMED,
        corrected
    );
    let pos: Vec<&str> = (nb..nv)
        .filter(|&d| closest[d] <= POSITION_REACHED)
        .map(|d| names[d].as_str())
        .collect();
    let vel: Vec<&str> = (nb..nv)
        .filter(|&d| fastest[d] >= 1.0 - VELOCITY_REACHED)
        .map(|d| names[d].as_str())
        .collect();
    eprintln!("peer_problem: position limits reached (≤ {POSITION_REACHED} rad): {pos:?}");
    eprintln!(
        "peer_problem: velocity limits reached (≥ {} v_max): {vel:?}",
        1.0 - VELOCITY_REACHED
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
