//! Smoothness of the commands on the peer problem (`benches/peer/problem.rs`, the
//! 20 upper-body joints driven into their limits), per bound method and level hold: every
//! limit kept in every variant, and the smoothness figures printed (`-- --nocapture`):
//! over the 2 000 timed steps, the mean over the 20 joints of the share of ticks where the
//! change of q̈ reverses its sign, and the RMS over joints and ticks of the commanded jerk
//! (q̈ₖ − q̈ₖ₋₁)/Δt. The quiet bounds meet the targets for this problem (reversals on
//! at most 5 % of ticks, RMS jerk below 2 000 rad/s³), which this test asserts. With jerk
//! limits ([`iktc::limits::limit_jerk`]) every tick whose box did not relax the jerk source keeps
//! `|q̈ − q̈₋| ≤ j_max Δt`, and the largest jerk of the run is that of the relaxed ticks.

#[path = "../benches/peer/problem.rs"]
mod peer;

use iktc::limits::BoundMethod;
use iktc::model::ModelOptions;
use iktc::sim::DofSmoothness;
use iktc::solver::{Method, SolverSettings};
use peer::{PeerProblem, DT, TIMED, UPPER_BODY, WARMUP};

/// The box tolerance of the default solver settings: a command outside the box by more than
/// this is a violation \[rad/s²\].
const BOX_TOLERANCE: f64 = 1e-9;

/// The target for the share of ticks where the change of q̈ reverses its sign \[–\].
const REVERSAL_TARGET: f64 = 0.05;
/// The target for the RMS commanded jerk \[rad/s³\] (TSID 1.9 measured 2 200).
const RMS_JERK_TARGET: f64 = 2000.0;

/// The jerk limit of the jerk-limited variants as a multiple of each joint's acceleration limit
/// \[1/s\]: zero to the full acceleration in 50 ms (10 ticks of 5 ms).
const JERK_PER_ACCELERATION: f64 = 20.0;

/// Relative rounding allowed on the jerk interval `q̈₋ ± j_max Δt` \[–\].
const JERK_ROUNDING: f64 = 1e-9;

/// The figures of one variant.
struct Figures {
    /// Mean over the joints of the share of ticks where q̈'s change reverses its sign \[–\].
    reversal: f64,
    /// RMS commanded jerk over joints and ticks \[rad/s³\].
    rms: f64,
    /// Largest commanded jerk \[rad/s³\].
    max: f64,
    /// Corrected-level changes undone at the next tick.
    undone: usize,
    /// Upper-body joint-ticks whose box relaxed the jerk source.
    jerk_relaxed: usize,
}

/// Runs one variant on JVRC-1 built with `options`.
fn run(bounds: BoundMethod, level_hold: usize, continuity: f64, options: &ModelOptions) -> Figures {
    let settings = SolverSettings {
        level_hold,
        continuity,
        ..SolverSettings::default()
    };
    let mut p = PeerProblem::with_model(Method::Iktc, settings, bounds, options).expect("problem");
    let dofs: Vec<usize> = UPPER_BODY
        .iter()
        .map(|j| p.robot().joint_v_index(j).expect("joint"))
        .collect();
    let limits = p.limits().dofs().to_vec();
    let (nb, nqb) = (p.robot().base_nv(), p.robot().base_nq());
    let mut qdd: Vec<Vec<f64>> = vec![Vec::with_capacity(TIMED); dofs.len()];
    let mut levels = Vec::with_capacity(TIMED);
    let mut jerk_relaxed = 0;
    let mut previous = vec![0.0; p.qdd().len()];
    for k in 0..WARMUP + TIMED {
        let r = p.step().expect("step");
        assert!(r.violation <= BOX_TOLERANCE, "step {k}: {}", r.violation);
        assert!(r.fallback.is_none(), "step {k}: {:?}", r.fallback);
        let level = r.corrected_from;
        for (d, l) in limits.iter().enumerate().skip(nb) {
            let (q, qd) = (p.state.q[d - nb + nqb], p.state.qd[d]);
            assert!(q >= l.position_min - BOX_TOLERANCE && q <= l.position_max + BOX_TOLERANCE);
            assert!(qd.abs() <= l.velocity_max * (1.0 + BOX_TOLERANCE));
            // The jerk source holds unless the box says it was relaxed.
            let step = (p.qdd()[d] - previous[d]).abs();
            if p.bounds().dropped[d].jerk {
                jerk_relaxed += usize::from(dofs.contains(&d));
            } else {
                let allowed = l.jerk_max * DT;
                assert!(
                    step <= allowed * (1.0 + JERK_ROUNDING) + BOX_TOLERANCE,
                    "step {k}, dof {d}: |Δq̈| {step} > j_max Δt {allowed}"
                );
            }
        }
        previous.copy_from_slice(p.qdd().as_slice());
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
    Figures {
        reversal,
        rms,
        max,
        undone,
        jerk_relaxed,
    }
}

#[test]
fn every_bound_method_keeps_the_limits_on_the_peer_problem_and_its_smoothness_is_printed() {
    let plain = ModelOptions::default();
    let jerk = ModelOptions {
        jerk_per_acceleration: JERK_PER_ACCELERATION,
        ..ModelOptions::default()
    };
    for (name, bounds, hold, mu, options) in [
        ("viable", BoundMethod::viable(), 1, 0.0, &plain),
        ("quiet", BoundMethod::quiet(), 1, 0.0, &plain),
        ("quiet + hold 3", BoundMethod::quiet(), 3, 0.0, &plain),
        ("viable + hold 3", BoundMethod::viable(), 3, 0.0, &plain),
        (
            "viable + continuity 10",
            BoundMethod::viable(),
            1,
            10.0,
            &plain,
        ),
        (
            "quiet + continuity 10",
            BoundMethod::quiet(),
            1,
            10.0,
            &plain,
        ),
        ("viable + jerk", BoundMethod::viable(), 1, 0.0, &jerk),
        ("quiet + jerk", BoundMethod::quiet(), 1, 0.0, &jerk),
    ] {
        let f = run(bounds, hold, mu, options);
        println!(
            "peer problem, {name}: reversals {:.1} % of ticks (mean over the 20 joints), \
             RMS jerk {:.0} rad/s³, max {:.0} rad/s³, level changes undone at the next \
             tick {}, jerk limit relaxed on {} joint-ticks",
            100.0 * f.reversal,
            f.rms,
            f.max,
            f.undone,
            f.jerk_relaxed
        );
        assert!(f.rms.is_finite() && f.max >= f.rms);
        if name.starts_with("quiet") {
            assert!(
                f.reversal <= REVERSAL_TARGET,
                "{name}: reversals {}",
                f.reversal
            );
            assert!(f.rms < RMS_JERK_TARGET, "{name}: RMS jerk {}", f.rms);
        }
    }
}
