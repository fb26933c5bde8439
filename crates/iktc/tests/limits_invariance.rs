//! Property tests of the viable bounds (errata §3.1): from a viable state, any acceleration in
//! the box keeps the joint inside its limits over the step (in-step peak included) and leads
//! to a viable state whose box is again non-empty; over hundreds of steps under a random
//! policy the joint never leaves.
//!
//! Parameters are drawn where the time step is fine compared with the limits (range ≥ 0.05
//! rad ≥ 5 a_max Δt², v_max ≥ 1 rad/s ≥ a_max Δt, a_stop ≤ 0.95 a_max), the regime the
//! guarantee documented in `iktc::limits::viable` is stated for.

use iktc::limits::{
    compute_box, compute_dof, integrate_constant_acceleration, peak_in_step, AccelerationBox,
    BoundMethod, DofBounds, DofLimits, JointLimits, ViableSettings,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, RngSeed};

/// Rounding slack on positions [rad]: the bounds are exact, the arithmetic is not.
const POSITION_SLACK: f64 = 1e-12;
/// Rounding slack on velocities [rad/s].
const VELOCITY_SLACK: f64 = 1e-9;

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0x1c7c_b0d5),
        failure_persistence: None,
        ..Config::default()
    }
}

#[derive(Debug, Clone, Copy)]
struct Case {
    limits: DofLimits,
    fraction: f64,
    dt: f64,
}

impl Case {
    fn a_stop(&self) -> f64 {
        self.fraction * self.limits.acceleration_max
    }

    fn method(&self) -> BoundMethod {
        BoundMethod::Viable(ViableSettings {
            braking_fraction: self.fraction,
        })
    }

    /// The velocity interval of the viable set at position `q`.
    fn viable_velocities(&self, q: f64) -> (f64, f64) {
        let l = &self.limits;
        let up = l
            .velocity_max
            .min((2.0 * self.a_stop() * (l.position_max - q).max(0.0)).sqrt());
        let down = l
            .velocity_max
            .min((2.0 * self.a_stop() * (q - l.position_min).max(0.0)).sqrt());
        (-down, up)
    }

    fn is_viable(&self, q: f64, qd: f64) -> bool {
        let (low, high) = self.viable_velocities(q);
        let l = &self.limits;
        q >= l.position_min - POSITION_SLACK
            && q <= l.position_max + POSITION_SLACK
            && qd >= low - VELOCITY_SLACK
            && qd <= high + VELOCITY_SLACK
    }

    fn bounds(&self, q: f64, qd: f64) -> DofBounds {
        compute_dof(&self.limits, &self.method(), q, qd, self.dt)
            .unwrap()
            .1
    }
}

fn case() -> impl Strategy<Value = Case> {
    (
        -2.0..1.0_f64,
        0.05..4.0_f64,
        1.0..10.0_f64,
        1.0..100.0_f64,
        prop_oneof![Just(0.5), Just(0.95), 0.05..0.95_f64],
        0.001..0.010_f64,
    )
        .prop_map(|(q_min, width, v_max, a_max, fraction, dt)| Case {
            limits: DofLimits {
                position_min: q_min,
                position_max: q_min + width,
                velocity_max: v_max,
                acceleration_max: a_max,
            },
            fraction,
            dt,
        })
}

/// Picks a point of [lower, upper] from `u ∈ [0, 1]`, with the two ends over-represented.
fn pick(bounds: &DofBounds, u: f64) -> f64 {
    if u < 0.3 {
        bounds.lower
    } else if u > 0.7 {
        bounds.upper
    } else {
        bounds.lower + (u - 0.3) / 0.4 * (bounds.upper - bounds.lower)
    }
}

/// Checks one step from a viable state; returns the next state.
fn check_step(c: &Case, q: f64, qd: f64, u: f64) -> Result<(f64, f64), TestCaseError> {
    let b = c.bounds(q, qd);
    prop_assert!(!b.is_empty(), "empty box at q={q} qd={qd}: {b:?}");
    prop_assert!(!b.dropped.any(), "dropped a source at q={q} qd={qd}: {b:?}");
    prop_assert!(b.lower >= -c.limits.acceleration_max && b.upper <= c.limits.acceleration_max);
    let qdd = pick(&b, u);
    let peak = peak_in_step(q, qd, qdd, c.dt);
    prop_assert!(
        peak.max <= c.limits.position_max + POSITION_SLACK
            && peak.min >= c.limits.position_min - POSITION_SLACK,
        "in-step excursion {peak:?} at q={q} qd={qd} qdd={qdd} in {b:?}"
    );
    let (q1, qd1) = integrate_constant_acceleration(q, qd, qdd, c.dt);
    prop_assert!(qd1.abs() <= c.limits.velocity_max + VELOCITY_SLACK);
    prop_assert!(c.is_viable(q1, qd1), "next state ({q1}, {qd1}) not viable");
    Ok((q1, qd1))
}

proptest! {
    #![proptest_config(config(4000))]

    #[test]
    fn one_step_from_a_viable_state_stays_viable(
        c in case(),
        s in 0.0..1.0_f64,
        w in 0.0..1.0_f64,
        u in 0.0..1.0_f64,
    ) {
        let l = c.limits;
        let q = l.position_min + s * (l.position_max - l.position_min);
        let (low, high) = c.viable_velocities(q);
        // A third of the cases right on the edge of the viable set.
        let qd = if w < 0.15 { low } else if w > 0.85 { high } else { low + w * (high - low) };
        let (q1, qd1) = check_step(&c, q, qd, u)?;
        // The next box is non-empty too.
        let next = c.bounds(q1, qd1);
        prop_assert!(!next.is_empty() && !next.dropped.any(), "{next:?}");
    }
}

proptest! {
    #![proptest_config(config(300))]

    #[test]
    fn random_policy_never_leaves_over_hundreds_of_steps(
        c in case(),
        s in 0.0..1.0_f64,
        w in 0.0..1.0_f64,
        policy in proptest::collection::vec(0.0..1.0_f64, 400),
    ) {
        let l = c.limits;
        let mut q = l.position_min + s * (l.position_max - l.position_min);
        let (low, high) = c.viable_velocities(q);
        let mut qd = low + w * (high - low);
        for &u in &policy {
            (q, qd) = check_step(&c, q, qd, u)?;
        }
    }
}

/// The same property through [`compute_box`] for several dofs at once, with a seeded
/// generator and a bang-bang policy that always pushes toward the nearer limit.
#[test]
fn multi_dof_box_under_a_pushing_policy() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let nv = 12;
    let dofs: Vec<DofLimits> = (0..nv)
        .map(|_| {
            let q_min = rng.random_range(-2.0..0.0);
            DofLimits {
                position_min: q_min,
                position_max: q_min + rng.random_range(0.1..3.0),
                velocity_max: rng.random_range(1.0..8.0),
                acceleration_max: rng.random_range(5.0..80.0),
            }
        })
        .collect();
    let limits = JointLimits::new(dofs.clone()).unwrap();
    let method = BoundMethod::viable();
    let dt = 0.005;
    let mut q: Vec<f64> = dofs
        .iter()
        .map(|d| 0.5 * (d.position_min + d.position_max))
        .collect();
    let mut qd = vec![0.0; nv];
    let mut bounds = AccelerationBox::new(nv);
    let mut qdd = vec![0.0; nv];
    for step in 0..2000 {
        compute_box(&limits, &method, &q, &qd, dt, &mut bounds).unwrap();
        assert!(!bounds.is_empty() && !bounds.any_dropped(), "step {step}");
        // Push toward the upper limit for 400 steps, then the lower one, and so on.
        let side = if (step / 400) % 2 == 0 {
            &bounds.upper
        } else {
            &bounds.lower
        };
        qdd.copy_from_slice(side.as_slice());
        assert!(bounds.contains(&qdd, 0.0).unwrap());
        for i in 0..nv {
            let peak = peak_in_step(q[i], qd[i], qdd[i], dt);
            assert!(
                dofs[i].excursion(peak) <= POSITION_SLACK,
                "dof {i} step {step}"
            );
            (q[i], qd[i]) = integrate_constant_acceleration(q[i], qd[i], qdd[i], dt);
            assert!(qd[i].abs() <= dofs[i].velocity_max + VELOCITY_SLACK);
        }
    }
}
