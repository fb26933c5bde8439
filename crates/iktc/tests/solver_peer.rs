//! The solver on the peer problem (`benches/peer/problem.rs`): the warm-started
//! correction QP against the reference path (every QP solved from scratch) on a recorded
//! sequence of its problems, and the limits the problem is known to bind.

#[path = "../benches/peer/problem.rs"]
mod peer;

use iktc::limits::AccelerationBox;
use iktc::solver::{Method, Solver, SolverSettings};
use iktc::task::TaskEquation;
use nalgebra::DVector;
use peer::{PeerProblem, TIMED, WARMUP};

/// Relative agreement of q̈, the corrections and the task errors between the warm-started and
/// the reference solver \[–\], relative to 1 + the largest entry of the reference. Both solve
/// the same strictly convex QP, so they agree up to rounding (≈ 1e-15 measured) unless a row
/// sits within the QP's feasibility tolerance (1e-9) of its bound, which one path may leave
/// inactive and the other not; this bound allows that case with a margin.
const AGREEMENT: f64 = 1e-8;

/// The (levels, box) of every step of the closed loop (2 050 steps from t = 0), solved with
/// the default settings.
fn record() -> Vec<(Vec<TaskEquation>, AccelerationBox)> {
    let mut p = PeerProblem::new(Method::Iktc, SolverSettings::default()).expect("problem");
    let mut out = Vec::with_capacity(WARMUP + TIMED);
    for _ in 0..WARMUP + TIMED {
        p.prepare().expect("prepare");
        out.push((p.ctl.equations().to_vec(), p.ctl.bounds().clone()));
        p.finish().expect("solve and integrate");
    }
    out
}

fn max_abs(v: &DVector<f64>) -> f64 {
    v.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

fn close(a: &DVector<f64>, b: &DVector<f64>) -> bool {
    max_abs(&(a - b)) <= AGREEMENT * (1.0 + max_abs(b))
}

#[test]
fn the_warm_start_gives_the_reference_answers_on_the_peer_problem() {
    let seq = record();
    let dims: Vec<usize> = seq[0].0.iter().map(|l| l.dim()).collect();
    let n = seq[0].1.nv();
    let fast = SolverSettings::default();
    assert!(fast.warm_start);
    let reference = SolverSettings {
        warm_start: false,
        ..Default::default()
    };
    let mut a = Solver::new(n, &dims, fast).expect("solver");
    let mut b = Solver::new(n, &dims, reference).expect("solver");
    let (mut qa, mut qb) = (DVector::zeros(n), DVector::zeros(n));
    let (mut warm, mut qps, mut iters_a, mut iters_b) = (0, 0, 0, 0);
    let mut worst = 0.0_f64;
    for (k, (levels, bx)) in seq.iter().enumerate() {
        let ra = a
            .solve(Method::Iktc, levels, bx, &mut qa)
            .expect("solve")
            .clone();
        let rb = b
            .solve(Method::Iktc, levels, bx, &mut qb)
            .expect("solve")
            .clone();
        assert_eq!(ra.corrected_from, rb.corrected_from, "step {k}");
        assert_eq!(ra.fallback, rb.fallback, "step {k}");
        assert_eq!(ra.ranks, rb.ranks, "step {k}");
        assert_eq!(ra.qp_solves, rb.qp_solves, "step {k}");
        assert_eq!(ra.qp_infeasible, rb.qp_infeasible, "step {k}");
        assert_eq!(ra.screened_infeasible, rb.screened_infeasible, "step {k}");
        assert_eq!(rb.qp_warm_started, 0);
        assert!(close(&qa, &qb), "step {k}: q̈ {qa} vs {qb}");
        for (ca, cb) in ra.corrections.iter().zip(&rb.corrections) {
            assert!(close(ca, cb), "step {k}: correction {ca} vs {cb}");
        }
        for (ea, eb) in ra.task_errors.iter().zip(&rb.task_errors) {
            assert!(close(ea, eb), "step {k}: task error {ea} vs {eb}");
        }
        assert!(ra.violation <= 1e-9 && rb.violation <= 1e-9, "step {k}");
        worst = worst.max(max_abs(&(&qa - &qb)) / (1.0 + max_abs(&qb)));
        warm += ra.qp_warm_started;
        qps += ra.qp_solves;
        iters_a += ra.qp_iterations;
        iters_b += rb.qp_iterations;
    }
    println!(
        "{} steps: {qps} QPs, {warm} warm-started; iterations {iters_a} vs {iters_b}; \
         largest relative q̈ difference {worst:e}",
        seq.len()
    );
    assert!(qps > seq.len() / 2, "the peer problem corrects most steps");
    assert!(
        2 * warm > qps,
        "the warm start must settle most QPs ({warm} of {qps})"
    );
    assert!(iters_a < iters_b);
}

#[test]
fn the_peer_problem_binds_the_limits_the_issue_names() {
    // On the peer problem position limits bind on WAIST_Y, WAIST_P, R/L_SHOULDER_R, R/L_ELBOW_P and
    // velocity limits on R/L_SHOULDER_Y, R/L_ELBOW_Y, R/L_WRIST_Y; the posture level is the
    // one corrected.
    /// A joint this close to a position limit has reached it \[rad\].
    const POSITION_REACHED: f64 = 1e-3;
    /// A joint within this fraction of its velocity limit has reached it \[–\].
    const VELOCITY_REACHED: f64 = 1e-3;
    let mut p = PeerProblem::new(Method::Iktc, SolverSettings::default()).expect("problem");
    let names = p.robot().dof_names();
    let (nb, nqb) = (p.robot().base_nv(), p.robot().base_nq());
    let dofs = p.limits().dofs().to_vec();
    let nv = names.len();
    let mut closest = vec![f64::INFINITY; nv];
    let mut fastest = vec![0.0_f64; nv];
    let mut last_level = 0;
    for _ in 0..WARMUP + TIMED {
        let r = p.step().expect("step");
        assert!(r.violation <= 1e-9 && r.fallback.is_none());
        assert!(matches!(r.corrected_from, None | Some(4)));
        if r.corrected_from == Some(4) {
            last_level += 1;
        }
        for d in nb..nv {
            let (q, qd, l) = (p.state.q[d - nb + nqb], p.state.qd[d], &dofs[d]);
            assert!(q >= l.position_min - 1e-9 && q <= l.position_max + 1e-9);
            assert!(qd.abs() <= l.velocity_max * (1.0 + 1e-9));
            closest[d] = closest[d].min((q - l.position_min).min(l.position_max - q));
            fastest[d] = fastest[d].max(qd.abs() / l.velocity_max);
        }
    }
    let reached = |f: &dyn Fn(usize) -> bool| -> Vec<&str> {
        (nb..nv)
            .filter(|&d| f(d))
            .map(|d| names[d].as_str())
            .collect()
    };
    let mut pos = reached(&|d| closest[d] <= POSITION_REACHED);
    let mut vel = reached(&|d| fastest[d] >= 1.0 - VELOCITY_REACHED);
    pos.sort_unstable();
    vel.sort_unstable();
    let mut want_pos = vec![
        "WAIST_Y",
        "WAIST_P",
        "R_SHOULDER_R",
        "L_SHOULDER_R",
        "R_ELBOW_P",
        "L_ELBOW_P",
    ];
    let mut want_vel = vec![
        "R_SHOULDER_Y",
        "L_SHOULDER_Y",
        "R_ELBOW_Y",
        "L_ELBOW_Y",
        "R_WRIST_Y",
        "L_WRIST_Y",
    ];
    want_pos.sort_unstable();
    want_vel.sort_unstable();
    assert_eq!(pos, want_pos);
    assert_eq!(vel, want_vel);
    assert!(
        10 * last_level > 9 * (WARMUP + TIMED),
        "the posture level is corrected on most steps ({last_level})"
    );
}
