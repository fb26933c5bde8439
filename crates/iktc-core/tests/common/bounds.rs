//! What the property tests of the bound methods share (`limits_quiet`, `limits_approach`,
//! `limits_invariance`): a seeded proptest configuration, the rounding slack of a step, and
//! the multi-joint case, three joints under two levels of linear tasks `x = J q` (1 and 2
//! rows, random J) solved by IKTC, the references asking for joint 0 beyond a limit.

use iktc_core::limits::{
    compute_box, integrate_constant_acceleration, peak_in_step, AccelerationBox, BoundMethod,
    DofLimits, JointLimits,
};
use iktc_core::solver::{Method, Solver, SolverSettings};
use iktc_core::task::TaskEquation;
use nalgebra::{DMatrix, DVector};
use proptest::test_runner::{Config, RngAlgorithm, RngSeed};
use rand::Rng;

/// Rounding slack on positions [rad]: the bounds are exact, the arithmetic is not.
pub const POSITION_SLACK: f64 = 1e-12;
/// Rounding slack on velocities [rad/s].
pub const VELOCITY_SLACK: f64 = 1e-9;

/// `cases` proptest cases from the fixed seed `seed`, ChaCha, nothing persisted.
pub fn proptest_config(cases: u32, seed: u64) -> Config {
    Config {
        cases,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        ..Config::default()
    }
}

/// Joints of the multi-joint case.
pub const NV: usize = 3;
/// Its control period [s].
pub const DT: f64 = 0.005;
/// Its ticks (2.5 s).
pub const TICKS: usize = 500;
/// Its CLIK gains k_p [s⁻²] and k_v [s⁻¹].
const GAINS: (f64, f64) = (100.0, 20.0);
/// Its joints' range [rad], the same for all three.
pub const RANGE: (f64, f64) = (-0.5, 0.5);

/// One multi-joint case: v_max 1–4 rad/s and a_max 20–80 rad/s² (the same on every joint), J
/// diagonally dominant, joint 0's reference 0.2 rad beyond the limit `limit0`, the others'
/// inside, the start inside, at rest.
pub struct ThreeJoints {
    pub limits: JointLimits,
    j: DMatrix<f64>,
    x_d: DVector<f64>,
    pub q0: DVector<f64>,
    /// Whether joint 0 is driven into its upper limit.
    pub upper: bool,
    /// That limit [rad].
    pub limit0: f64,
}

impl ThreeJoints {
    pub fn random(rng: &mut impl Rng) -> Self {
        let dof = DofLimits {
            position_min: RANGE.0,
            position_max: RANGE.1,
            velocity_max: rng.random_range(1.0..4.0),
            acceleration_max: rng.random_range(20.0..80.0),
            jerk_max: f64::INFINITY,
        };
        let limits = JointLimits::new(vec![dof; NV]).unwrap();
        let j = DMatrix::from_fn(3, NV, |r, c| {
            if r == c {
                1.0 + rng.random_range(0.0..0.5)
            } else {
                rng.random_range(-0.4..0.4)
            }
        });
        let upper = rng.random_bool(0.5);
        let limit0 = if upper { RANGE.1 } else { RANGE.0 };
        let target = DVector::from_vec(vec![
            limit0 + if upper { 0.2 } else { -0.2 },
            rng.random_range(-0.3..0.3),
            rng.random_range(-0.3..0.3),
        ]);
        let x_d = &j * &target;
        let q0 = DVector::from_fn(NV, |_, _| rng.random_range(-0.3..0.3));
        Self {
            limits,
            j,
            x_d,
            q0,
            upper,
            limit0,
        }
    }
}

/// The solver, equations and box of the multi-joint case, reused across cases.
pub struct ThreeJointRunner {
    solver: Solver,
    eqs: Vec<TaskEquation>,
    bx: AccelerationBox,
    qdd: DVector<f64>,
}

impl ThreeJointRunner {
    pub fn new() -> Self {
        let dims = [1, 2];
        Self {
            solver: Solver::new(NV, &dims, SolverSettings::default()).unwrap(),
            eqs: dims
                .iter()
                .map(|&m| TaskEquation::zeros("level", m, NV))
                .collect(),
            bx: AccelerationBox::new(NV),
            qdd: DVector::zeros(NV),
        }
    }

    /// Runs `case` under `method` for [`TICKS`] ticks from its start at rest. Every tick: the box
    /// is not empty, `each(k, q, q̇, box)` sees the state and the box before the solve, the
    /// command lies in the box (to 1e-9 rad/s²) and keeps every joint in range over the step
    /// (in-step peak included, to [`POSITION_SLACK`]). Returns each joint's commands and the
    /// final position. `label` names the case in failures.
    pub fn run(
        &mut self,
        case: &ThreeJoints,
        method: &BoundMethod,
        label: &str,
        mut each: impl FnMut(usize, &DVector<f64>, &DVector<f64>, &AccelerationBox),
    ) -> (Vec<Vec<f64>>, DVector<f64>) {
        let (kp, kv) = GAINS;
        let mut q = case.q0.clone();
        let mut v = DVector::<f64>::zeros(NV);
        let mut history: Vec<Vec<f64>> = (0..NV).map(|_| Vec::with_capacity(TICKS)).collect();
        for k in 0..TICKS {
            let x = &case.j * &q;
            let xd = &case.j * &v;
            let mut row = 0;
            for eq in self.eqs.iter_mut() {
                for r in 0..eq.dim() {
                    for c in 0..NV {
                        eq.jacobian[(r, c)] = case.j[(row, c)];
                    }
                    eq.error[r] = case.x_d[row] - x[row];
                    eq.error_rate[r] = -xd[row];
                    eq.rhs[r] = kp * eq.error[r] + kv * eq.error_rate[r];
                    row += 1;
                }
            }
            compute_box(
                &case.limits,
                method,
                q.as_slice(),
                v.as_slice(),
                DT,
                &mut self.bx,
            )
            .unwrap();
            assert!(!self.bx.is_empty(), "{label} tick {k}");
            each(k, &q, &v, &self.bx);
            self.solver
                .solve(Method::Iktc, &self.eqs, &self.bx, &mut self.qdd)
                .unwrap();
            assert!(
                self.bx.max_violation(self.qdd.as_slice()).unwrap() <= 1e-9,
                "{label} tick {k}"
            );
            for d in 0..NV {
                history[d].push(self.qdd[d]);
                let ex = peak_in_step(q[d], v[d], self.qdd[d], DT);
                assert!(
                    ex.max <= RANGE.1 + POSITION_SLACK && ex.min >= RANGE.0 - POSITION_SLACK,
                    "{label} tick {k} joint {d}"
                );
                (q[d], v[d]) = integrate_constant_acceleration(q[d], v[d], self.qdd[d], DT);
            }
        }
        (history, q)
    }
}
