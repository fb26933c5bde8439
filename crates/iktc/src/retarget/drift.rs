//! The held feet's compensation of the integration's drift.
//!
//! A held foot's level is solved exactly at the start of each tick: its frame's acceleration
//! is `a_k = J_k q̈_k + J̇_k q̇_k`, what the feedback asks. But q̈ is held constant over Δt,
//! and the foot's velocity is a nonlinear function of the state: over the tick it changes by
//!
//! `v_{k+1} − v_k = a_k Δt + δ_k`,  `δ_k = ½ (2 J̇ q̈ + J̈ q̇) Δt² + O(Δt³)`,
//!
//! a disturbance that grows with the cube of the joints' speeds (a whirling floating base
//! above a held foot). The feedback pulls it back only in proportion to `1/k_p`; the
//! compensation below lowers the held feet's slip (`book/src/retarget-defaults.md` has the
//! largest slip on the shared clips with and without it).
//!
//! The disturbance varies slowly from tick to tick, so the last one measured is the best
//! estimate of the next: each held foot's acceleration reference gets `c_{k+1} = −δ_k / Δt`
//! \[m/s², rad/s²\] added, measured at the start of tick k + 1 from the kinematics of its
//! state, before its references are set. The foot's mean acceleration over a tick is then
//! what the feedback asked, up to the change of `δ` from one tick to the next. The compensation enters
//! the task's reference like any feed-forward, so the solver's box still bounds every joint.
//! A foot that has just landed starts without one (its first tick).
//!
//! A swing foot under its floor ([`super::floor`]) is measured the same way, and the floor's
//! height row gets the vertical part of its compensation: the floor bounds the sole's
//! acceleration at the start of the tick, and a foot turning on the ground drifts below it
//! within the tick (G1 on CMU 131_01, a foot turning at up to 3 rad/s, goes 0.04 mm below
//! the ground with it). Its other rows get none (`book/src/retarget-defaults.md` has the
//! height row without it, and all six rows with it, measured).

use nalgebra::{DMatrix, DVector, Vector6};

use crate::error::Result;
use crate::model::{FrameId, Kinematics, Robot};

/// The drift estimate of the two feet.
#[derive(Debug, Clone)]
pub(crate) struct StanceDrift {
    /// Per foot, at the last tick it was held: its frame's velocity `v_k` and acceleration
    /// `a_k` (world axes, origin then angular) \[m/s, rad/s\], \[m/s², rad/s²\].
    last: [Option<(Vector6<f64>, Vector6<f64>)>; 2],
    /// Per foot, the compensation `c` added to its acceleration reference \[m/s², rad/s²\].
    comp: [Vector6<f64>; 2],
    /// Scratch: a frame Jacobian (6 × nv).
    jac: DMatrix<f64>,
}

impl StanceDrift {
    /// An estimate for a robot with `nv` velocity coordinates, with nothing measured yet.
    pub fn new(nv: usize) -> Self {
        Self {
            last: [None; 2],
            comp: [Vector6::zeros(); 2],
            jac: DMatrix::zeros(6, nv),
        }
    }

    /// The compensation of foot `i` \[m/s², rad/s²\] (zero unless held for two ticks).
    pub fn compensation(&self, i: usize) -> &Vector6<f64> {
        &self.comp[i]
    }

    /// Records tick k as it is applied: `kin` at the tick's state, `qdd` the q̈ applied over
    /// it \[rad/s²\], `held` which feet the tick held; a foot not held forgets its estimate.
    /// Allocates nothing.
    pub fn observe(
        &mut self,
        robot: &Robot,
        kin: &Kinematics,
        feet: &[FrameId; 2],
        held: [bool; 2],
        qdd: &DVector<f64>,
    ) -> Result<()> {
        for i in 0..2 {
            if !held[i] {
                self.last[i] = None;
                self.comp[i] = Vector6::zeros();
                continue;
            }
            let v = kin.frame_velocity(robot, feet[i])?;
            kin.frame_jacobian(robot, feet[i], &mut self.jac)?;
            let mut a = kin.frame_drift(robot, feet[i])?;
            a.gemv(1.0, &self.jac, qdd, 1.0);
            self.last[i] = Some((v, a));
        }
        Ok(())
    }

    /// Measures the disturbance of the tick last observed from `kin` at the state it led to
    /// (tick k + 1, before its references are set): `δ_k = v_{k+1} − v_k − a_k Δt`, and the
    /// compensation of tick k + 1 is `−δ_k / Δt`. Allocates nothing.
    pub fn measure(
        &mut self,
        robot: &Robot,
        kin: &Kinematics,
        feet: &[FrameId; 2],
        dt: f64,
    ) -> Result<()> {
        for ((last, comp), foot) in self.last.iter().zip(&mut self.comp).zip(feet) {
            if let Some((v0, a0)) = last {
                let v = kin.frame_velocity(robot, *foot)?;
                *comp = -(v - v0 - a0 * dt) / dt;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{builtin_robot, State};
    use rand::{Rng, SeedableRng};

    /// A JVRC-1 state with random joint rates and base twist (seeded), and a random q̈.
    fn setup() -> (Robot, State, DVector<f64>, [FrameId; 2]) {
        let robot = builtin_robot("jvrc1").unwrap();
        let mut state = State::neutral(&robot);
        let mut rng = rand::rngs::StdRng::seed_from_u64(17);
        for v in state.qd.iter_mut() {
            *v = rng.random_range(-2.0..2.0);
        }
        let qdd = DVector::from_fn(robot.nv(), |_, _| rng.random_range(-20.0..20.0));
        let feet = [
            robot.frame_id("l_ankle").unwrap(),
            robot.frame_id("r_ankle").unwrap(),
        ];
        (robot, state, qdd, feet)
    }

    /// The frame acceleration `J q̈ + J̇ q̇` of foot `i` at `state`.
    fn acceleration(robot: &Robot, state: &State, qdd: &DVector<f64>, f: FrameId) -> Vector6<f64> {
        let kin = Kinematics::new(robot, state).unwrap();
        let mut j = DMatrix::zeros(6, robot.nv());
        kin.frame_jacobian(robot, f, &mut j).unwrap();
        kin.frame_drift(robot, f).unwrap() + &j * qdd
    }

    /// Over one tick under constant q̈ the velocity gains `a Δt + ½ ȧ Δt² + O(Δt³)`, so the
    /// compensation is `−½ ȧ Δt` to first order: `ȧ` (the jerk of the frame) by a central
    /// difference of the acceleration along the same motion, with a step 100 × smaller.
    #[test]
    fn the_compensation_is_minus_half_the_frames_jerk_times_the_step() {
        let (robot, state, qdd, feet) = setup();
        let dt = 0.005;
        let mut drift = StanceDrift::new(robot.nv());
        let mut s = state.clone();
        let kin = Kinematics::new(&robot, &s).unwrap();
        drift.measure(&robot, &kin, &feet, dt).unwrap();
        drift
            .observe(&robot, &kin, &feet, [true, true], &qdd)
            .unwrap();
        assert_eq!(
            drift.compensation(0),
            &Vector6::zeros(),
            "nothing measured yet"
        );
        s.integrate(&robot, &qdd, dt).unwrap();
        let kin = Kinematics::new(&robot, &s).unwrap();
        drift.measure(&robot, &kin, &feet, dt).unwrap();
        let h = dt / 100.0;
        for (i, f) in feet.iter().enumerate() {
            // One-sided, second order: ȧ ≈ (−3 a(0) + 4 a(h) − a(2h)) / 2h (Δt > 0 only).
            let (mut one, mut two) = (state.clone(), state.clone());
            one.integrate(&robot, &qdd, h).unwrap();
            two.integrate(&robot, &qdd, 2.0 * h).unwrap();
            let jerk = (-3.0 * acceleration(&robot, &state, &qdd, *f)
                + 4.0 * acceleration(&robot, &one, &qdd, *f)
                - acceleration(&robot, &two, &qdd, *f))
                / (2.0 * h);
            let expected = -0.5 * jerk * dt;
            let got = drift.compensation(i);
            // The O(Δt²) remainder: a few % of the first-order term at these rates.
            let err = (got - expected).norm();
            assert!(
                err <= 0.1 * expected.norm(),
                "foot {i}: {got:?} against {expected:?}"
            );
        }
    }

    /// A foot that is not held has no compensation, and starts afresh when held again.
    #[test]
    fn a_foot_in_the_air_forgets_its_estimate() {
        let (robot, mut s, qdd, feet) = setup();
        let dt = 0.005;
        let mut drift = StanceDrift::new(robot.nv());
        // Tick 0 held, tick 1 measured at its start.
        let kin = Kinematics::new(&robot, &s).unwrap();
        drift
            .observe(&robot, &kin, &feet, [true, true], &qdd)
            .unwrap();
        s.integrate(&robot, &qdd, dt).unwrap();
        let kin = Kinematics::new(&robot, &s).unwrap();
        drift.measure(&robot, &kin, &feet, dt).unwrap();
        assert!(drift.compensation(0).norm() > 0.0);
        assert!(drift.compensation(1).norm() > 0.0);
        // Tick 1 holds only the first foot: the second forgets.
        drift
            .observe(&robot, &kin, &feet, [true, false], &qdd)
            .unwrap();
        assert!(drift.compensation(0).norm() > 0.0);
        assert_eq!(drift.compensation(1), &Vector6::zeros());
        s.integrate(&robot, &qdd, dt).unwrap();
        let kin = Kinematics::new(&robot, &s).unwrap();
        drift.measure(&robot, &kin, &feet, dt).unwrap();
        assert!(drift.compensation(0).norm() > 0.0);
        assert_eq!(
            drift.compensation(1),
            &Vector6::zeros(),
            "first tick held again"
        );
    }
}
