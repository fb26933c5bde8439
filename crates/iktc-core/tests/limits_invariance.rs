//! Property tests of the viable bounds (the theorem of `iktc_core::limits::viable`): from a viable
//! state, every acceleration in the box keeps the joint inside its limits over the step (in-step
//! peak included), keeps the velocity and acceleration limits, and leads to a viable state whose
//! box is again non-empty, for any control period and any ratio of the limits.
//!
//! Parameters span `a_max/v_max` over eight decades (1e-2 … 1e6 s⁻¹), `Δt` from 1e-4 s to
//! 0.5 s, ranges from zero width to 4 rad (so ranges far below `a_max Δt²` and `v_max` far
//! below `a_max Δt` occur), and `a_stop/a_max` in (0, 1]. The accelerations applied are random
//! inside the box, with the two edges over-represented (the adversarial choice: always push
//! into a limit). Every step taken is counted: 40 000 single steps and 400 runs of 500 steps
//! (2.4·10⁵ steps), plus 36 000 dof-steps through `compute_box`.

mod common;

use std::sync::atomic::{AtomicUsize, Ordering};

use common::bounds::proptest_config;
use iktc_core::limits::{
    compute_box, compute_dof, integrate_constant_acceleration, peak_in_step, viable,
    AccelerationBox, BoundMethod, DofBounds, DofLimits, JointLimits, ViableSettings,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

/// Relative rounding slack [–]: the bounds are exact, the arithmetic is not. Positions are
/// compared within `ROUNDING · (1 + |q| + v_max Δt + a_max Δt²)` \[rad\], velocities within
/// `ROUNDING · (v_max + a_max Δt)` \[rad/s\].
const ROUNDING: f64 = 1e-9;
/// Resolution of a position in floating point, relative to `1 + |q|` [–] (a few ulps). Where
/// the braking acceleration sits right on the acceleration limit (`a_stop = a_max`, or on the
/// braking curve next to a limit), rounding of that size may exceed it slightly (as
/// `limits::viable` documents); see `check_step` for the amounts.
const POSITION_RESOLUTION: f64 = 1e-14;

fn config(cases: u32) -> Config {
    proptest_config(cases, 0x1c7c_b0d5)
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
            ..ViableSettings::default()
        })
    }

    /// The regime of the theorem: the continuous braking curve where `a_stop Δt ≤ v_max` and
    /// `a_stop Δt² ≤ q_max − q_min`, the discrete stopping distance otherwise.
    fn distance(&self, v: f64) -> f64 {
        let (a, l) = (self.a_stop(), &self.limits);
        if a * self.dt <= l.velocity_max && a * self.dt * self.dt <= l.position_max - l.position_min
        {
            if v > 0.0 {
                v * v / (2.0 * a)
            } else {
                0.0
            }
        } else {
            viable::stopping_distance(v, a, self.dt)
        }
    }

    fn position_slack(&self, q: f64) -> f64 {
        let l = &self.limits;
        ROUNDING * (1.0 + q.abs() + l.velocity_max * self.dt + l.acceleration_max * self.dt.powi(2))
    }

    fn velocity_slack(&self) -> f64 {
        ROUNDING * (self.limits.velocity_max + self.limits.acceleration_max * self.dt)
    }

    /// The largest speed toward each end at which the state is viable, by bisection on the
    /// stopping distance (independent of the closed form of the bound): `(down, up)`.
    fn viable_speeds(&self, q: f64) -> (f64, f64) {
        let l = &self.limits;
        let largest = |room: f64| {
            let (mut lo, mut hi) = (0.0, l.velocity_max);
            if self.distance(hi) <= room {
                return hi;
            }
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if self.distance(mid) <= room {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        (
            largest((q - l.position_min).max(0.0)),
            largest((l.position_max - q).max(0.0)),
        )
    }

    fn is_viable(&self, q: f64, qd: f64) -> bool {
        let l = &self.limits;
        let slack = self.position_slack(q);
        let room_up = l.position_max - q;
        let room_down = q - l.position_min;
        room_up >= -slack
            && room_down >= -slack
            && qd.abs() <= l.velocity_max + self.velocity_slack()
            && self.distance(qd) <= room_up + slack
            && self.distance(-qd) <= room_down + slack
    }

    fn bounds(&self, q: f64, qd: f64) -> DofBounds {
        compute_dof(&self.limits, &self.method(), q, qd, self.dt)
            .expect("valid case")
            .1
    }
}

/// `10^u` for `u` drawn uniformly: log-uniform over decades.
fn decades(low: f64, high: f64) -> impl Strategy<Value = f64> {
    (low..high).prop_map(|u: f64| 10f64.powf(u))
}

fn case() -> impl Strategy<Value = Case> {
    (
        -2.0..1.0_f64,
        prop_oneof![Just(0.0), decades(-6.0, 0.6)],
        decades(-1.0, 1.0),
        decades(-2.0, 6.0),
        prop_oneof![Just(0.5), Just(1.0), 0.01..1.0_f64],
        decades(-4.0, -0.3),
    )
        .prop_map(|(q_min, width, v_max, ratio, fraction, dt)| Case {
            limits: DofLimits {
                position_min: q_min,
                position_max: q_min + width,
                velocity_max: v_max,
                acceleration_max: ratio * v_max,
                jerk_max: f64::INFINITY,
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
fn check_step(
    c: &Case,
    q: f64,
    qd: f64,
    u: f64,
    steps: &AtomicUsize,
) -> Result<(f64, f64), TestCaseError> {
    steps.fetch_add(1, Ordering::Relaxed);
    let l = &c.limits;
    let b = c.bounds(q, qd);
    prop_assert!(!b.is_empty(), "empty box at q={q} qd={qd}: {b:?}");
    prop_assert!(
        !b.dropped.viability,
        "dropped viability at q={q} qd={qd}: {b:?}"
    );
    // The acceleration limit may only be dropped by rounding, where a_stop = a_max puts the
    // braking acceleration right on it.
    // Positions are resolved to δ = POSITION_RESOLUTION (1 + |q|): the bounds divide them by
    // Δt²/2, and near a limit the in-step peak bound −q̇²/(2d) carries a relative error δ/d.
    let delta = POSITION_RESOLUTION * (1.0 + q.abs());
    let d_near = (l.position_max - q)
        .min(q - l.position_min)
        .max(f64::MIN_POSITIVE);
    let a_slack = 2.0 * delta / c.dt.powi(2) + l.acceleration_max * delta / d_near;
    prop_assert!(
        b.lower >= -l.acceleration_max - a_slack && b.upper <= l.acceleration_max + a_slack,
        "acceleration limit broken at q={q} qd={qd}: {b:?}"
    );
    let qdd = pick(&b, u);
    let peak = peak_in_step(q, qd, qdd, c.dt);
    let slack = c.position_slack(q);
    prop_assert!(
        peak.max <= l.position_max + slack && peak.min >= l.position_min - slack,
        "in-step excursion {peak:?} at q={q} qd={qd} qdd={qdd} in {b:?}"
    );
    let (q1, qd1) = integrate_constant_acceleration(q, qd, qdd, c.dt);
    prop_assert!(qd1.abs() <= l.velocity_max + c.velocity_slack());
    prop_assert!(c.is_viable(q1, qd1), "next state ({q1}, {qd1}) not viable");
    Ok((q1, qd1))
}

/// A state of the viable set from `s, w ∈ [0, 1]`, a third of them on its edge.
fn viable_state(c: &Case, s: f64, w: f64) -> (f64, f64) {
    let l = c.limits;
    let q = l.position_min + s * (l.position_max - l.position_min);
    let (down, up) = c.viable_speeds(q);
    let qd = if w < 0.15 {
        -down
    } else if w > 0.85 {
        up
    } else {
        -down + (w - 0.15) / 0.7 * (up + down)
    };
    (q, qd)
}

/// Runs `cases` cases of `check` under the seeded runner and returns the steps they checked.
fn run_cases<S: Strategy>(
    cases: u32,
    strategy: S,
    check: impl Fn(S::Value, &AtomicUsize) -> Result<(), TestCaseError>,
) -> usize {
    let steps = AtomicUsize::new(0);
    let mut runner = TestRunner::new(config(cases));
    if let Err(e) = runner.run(&strategy, |v| check(v, &steps)) {
        panic!("{e}");
    }
    steps.load(Ordering::Relaxed)
}

#[test]
fn one_step_from_a_viable_state_stays_viable() {
    let strategy = (case(), 0.0..1.0_f64, 0.0..1.0_f64, 0.0..1.0_f64);
    let steps = run_cases(40_000, strategy, |(c, s, w, u), steps| {
        let (q, qd) = viable_state(&c, s, w);
        let (q1, qd1) = check_step(&c, q, qd, u, steps)?;
        // The next box is non-empty too.
        let next = c.bounds(q1, qd1);
        prop_assert!(!next.is_empty() && !next.dropped.viability, "{next:?}");
        Ok(())
    });
    assert_eq!(steps, 40_000);
}

#[test]
fn random_and_pushing_policies_never_leave_over_hundreds_of_steps() {
    let strategy = (
        case(),
        0.0..1.0_f64,
        0.0..1.0_f64,
        proptest::collection::vec(0.0..1.0_f64, 200),
    );
    let steps = run_cases(400, strategy, |(c, s, w, policy), steps| {
        let (mut q, mut qd) = viable_state(&c, s, w);
        for &u in &policy {
            (q, qd) = check_step(&c, q, qd, u, steps)?;
        }
        // Then push into the upper limit, then into the lower one (bang-bang on the edges).
        for u in [1.0; 150].into_iter().chain([0.0; 150]) {
            (q, qd) = check_step(&c, q, qd, u, steps)?;
        }
        Ok(())
    });
    assert!(steps >= 200_000, "{steps}");
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
            let v_max = rng.random_range(1.0..8.0);
            DofLimits {
                position_min: q_min,
                position_max: q_min + rng.random_range(0.0..3.0),
                velocity_max: v_max,
                acceleration_max: v_max * 10f64.powf(rng.random_range(0.0..5.0)),
                jerk_max: f64::INFINITY,
            }
        })
        .collect();
    let limits = JointLimits::new(dofs.clone()).unwrap();
    let method = BoundMethod::viable();
    for dt in [1e-3, 0.005, 0.1] {
        let mut q: Vec<f64> = dofs
            .iter()
            .map(|d| 0.5 * (d.position_min + d.position_max))
            .collect();
        let mut qd = vec![0.0; nv];
        let mut bounds = AccelerationBox::new(nv);
        let mut qdd = vec![0.0; nv];
        for step in 0..1000 {
            compute_box(&limits, &method, &q, &qd, dt, &mut bounds).unwrap();
            assert!(!bounds.is_empty() && !bounds.any_dropped(), "step {step}");
            // Push toward the upper limit for 200 steps, then the lower one, and so on.
            let side = if (step / 200) % 2 == 0 {
                &bounds.upper
            } else {
                &bounds.lower
            };
            qdd.copy_from_slice(side.as_slice());
            assert!(bounds.contains(&qdd, 0.0).unwrap());
            for i in 0..nv {
                let peak = peak_in_step(q[i], qd[i], qdd[i], dt);
                assert!(
                    dofs[i].excursion(peak) <= 1e-12,
                    "dof {i} step {step} dt {dt}"
                );
                (q[i], qd[i]) = integrate_constant_acceleration(q[i], qd[i], qdd[i], dt);
                assert!(qd[i].abs() <= dofs[i].velocity_max * (1.0 + 1e-12));
                assert!(qdd[i].abs() <= dofs[i].acceleration_max);
            }
        }
    }
}
