//! Smoothness of the commands on the peer problem of issue 17 (`benches/peer/problem.rs`, the
//! 20 upper-body joints driven into their limits), per bound method and level hold: every
//! limit kept in every variant, and the figures of issue 13 printed (`-- --nocapture`):
//! over the 2 000 timed steps, the mean over the 20 joints of the share of ticks where the
//! change of q̈ reverses its sign, and the RMS over joints and ticks of the commanded jerk
//! (q̈ₖ − q̈ₖ₋₁)/Δt. The quiet bounds meet the targets for this problem (reversals on
//! at most 5 % of ticks, RMS jerk below 2 000 rad/s³), which this test asserts.

#[path = "../benches/peer/problem.rs"]
mod peer;

use iktc::limits::BoundMethod;
use iktc::sim::DofSmoothness;
use iktc::solver::{Method, SolverSettings};
use peer::{PeerProblem, DT, TIMED, UPPER_BODY, WARMUP};

/// The box tolerance of the default solver settings: a command outside the box by more than
/// this is a violation \[rad/s²\].
const BOX_TOLERANCE: f64 = 1e-9;

/// Issue 13's target for the share of ticks where the change of q̈ reverses its sign \[–\].
const REVERSAL_TARGET: f64 = 0.05;
/// Issue 13's target for the RMS commanded jerk \[rad/s³\] (TSID 1.9 measured 2 200).
const RMS_JERK_TARGET: f64 = 2000.0;

/// Runs one variant; returns (mean reversal share \[–\], RMS jerk \[rad/s³\], largest jerk
/// \[rad/s³\], corrected-level changes undone at the next tick).
fn run(bounds: BoundMethod, level_hold: usize) -> (f64, f64, f64, usize) {
    let settings = SolverSettings {
        level_hold,
        ..SolverSettings::default()
    };
    let mut p = PeerProblem::with_bounds(Method::Iktc, settings, bounds).expect("problem");
    let dofs: Vec<usize> = UPPER_BODY
        .iter()
        .map(|j| p.robot().joint_v_index(j).expect("joint"))
        .collect();
    let limits = p.limits().dofs().to_vec();
    let (nb, nqb) = (p.robot().base_nv(), p.robot().base_nq());
    let mut qdd: Vec<Vec<f64>> = vec![Vec::with_capacity(TIMED); dofs.len()];
    let mut levels = Vec::with_capacity(TIMED);
    for k in 0..WARMUP + TIMED {
        let r = p.step().expect("step");
        assert!(r.violation <= BOX_TOLERANCE, "step {k}: {}", r.violation);
        assert!(r.fallback.is_none(), "step {k}: {:?}", r.fallback);
        let level = r.corrected_from;
        for (d, l) in limits.iter().enumerate().skip(nb) {
            let (q, qd) = (p.state.q[d - nb + nqb], p.state.qd[d]);
            assert!(q >= l.position_min - BOX_TOLERANCE && q <= l.position_max + BOX_TOLERANCE);
            assert!(qd.abs() <= l.velocity_max * (1.0 + BOX_TOLERANCE));
        }
        if k >= WARMUP {
            for (series, &d) in qdd.iter_mut().zip(&dofs) {
                series.push(p.qdd()[d]);
            }
            levels.push(level);
        }
    }
    let figures: Vec<DofSmoothness> = qdd.iter().map(|s| DofSmoothness::of(s, DT)).collect();
    let n = figures.len() as f64;
    let reversal = figures.iter().map(|f| f.reversal_share).sum::<f64>() / n;
    let rms = (figures.iter().map(|f| f.rms_jerk.powi(2)).sum::<f64>() / n).sqrt();
    let max = figures.iter().map(|f| f.max_jerk).fold(0.0, f64::max);
    let undone = levels
        .windows(3)
        .filter(|w| w[0] != w[1] && w[0] == w[2])
        .count();
    (reversal, rms, max, undone)
}

#[test]
fn every_bound_method_keeps_the_limits_on_the_peer_problem_and_its_smoothness_is_printed() {
    for (name, bounds, hold) in [
        ("viable", BoundMethod::viable(), 1),
        ("quiet", BoundMethod::quiet(), 1),
        ("quiet + hold 3", BoundMethod::quiet(), 3),
        ("viable + hold 3", BoundMethod::viable(), 3),
    ] {
        let (reversal, rms, max, undone) = run(bounds, hold);
        println!(
            "peer problem, {name}: reversals {:.1} % of ticks (mean over the 20 joints), \
             RMS jerk {rms:.0} rad/s³, max {max:.0} rad/s³, level changes undone at the next \
             tick {undone}",
            100.0 * reversal
        );
        assert!(rms.is_finite() && max >= rms);
        if name.starts_with("quiet") {
            assert!(reversal <= REVERSAL_TARGET, "{name}: reversals {reversal}");
            assert!(rms < RMS_JERK_TARGET, "{name}: RMS jerk {rms}");
        }
    }
}
