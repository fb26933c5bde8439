//! The static reach of the body points: per tick, a posture within the joint ranges whose
//! body points come closer to the scaled human's than the run's own posture, by the measure
//! of the quality figures ([`super::RetargetQuality`]).
//!
//! ## Method
//!
//! The measure of tick k is the mean over the body points p of e_p(q) = ‖r_p(q)‖ with
//! r_p(q) = x_p(q) − x_m(q) − t_p, where x_m is the middle of the robot's hips and
//! t_p = s_leg (a(p) − a(m)) the neutral target of the quality figures; the
//! pelvis point is the alignment point (e = 0). Nothing else is asked of the posture: no
//! foot on the ground, no balance, no velocity or acceleration limit, only each joint's
//! position range. The least mean error over such postures is a floor for any retargeting
//! of the clip onto the robot (a motion is a posture per tick, and a retargeting must also
//! keep its feet and balance and move within the rates); the gap between the run's figure
//! and this one is what the run gives up for them.
//!
//! The sum of norms Σ_p ‖r_p‖ is minimised by iteratively reweighted Levenberg–Marquardt
//! (weights w_p = 1 / max(‖r_p‖, 1 mm)): the step δ ∈ ℝ^nv solves
//!
//! (Σ_p w_p J_pᵀ J_p + μ I) δ = −Σ_p w_p J_pᵀ r_p,  J_p = ∂x_p/∂q − ∂x_m/∂q (3 × nv),
//!
//! the configuration moves by δ (the floating base by its body twist, as
//! [`State::integrate`] does) and each joint is put back into its range; a joint on a bound
//! that −g would push out of it keeps its place (its row and column leave the system: the
//! projected Newton step). A step is taken only if it lowers the mean error (μ ÷ 3), else
//! μ × 4 and the step is tried again. Starting from the run's posture, each tick's result is
//! at most the run's error. The least mean error over all postures is a floor for any
//! retargeting of the clip onto the robot (a motion is a posture per tick, which must also
//! keep its feet and balance and move within the rates); the descent finds a local minimum,
//! so the figure is an upper bound on that floor, tight where the run's posture is near the
//! best one.
//!
//! On the shared clips (`tests/retarget_keypoints.rs`, 2026-12-03) the reach is 1.4–2.3 cm
//! on G1 and 2.3–4.7 cm on JVRC-1, against the runs' 6.3–14.0 and 7.8–33.3 cm: the bodies
//! are not what keeps the error above a few centimetres.

use nalgebra::{DMatrix, DVector, Vector3};

use super::body::RobotBody;
use super::plan::Plan;
use crate::error::{check_dim, Result};
use crate::model::{Kinematics, Robot, State};
use crate::motion::BodyPoint;

/// Smallest residual a weight is taken at \[m\]: points closer than 1 mm weigh as if 1 mm
/// away, so that a point on its target does not take the whole step.
const WEIGHT_FLOOR: f64 = 1e-3;

/// Initial Levenberg–Marquardt damping μ \[m/rad²\], in the units of the weighted
/// Gauss–Newton matrix Σ w_p J_pᵀ J_p (w_p in 1/m, J_p in m/rad).
const MU_START: f64 = 1e-3;

/// Largest μ tried before a tick's descent stops \[m/rad²\].
const MU_MAX: f64 = 1e3;

/// Iterations per tick at most.
const MAX_ITERATIONS: usize = 60;

/// The descent stops when its last [`WINDOW`] steps lowered the mean error by less than this
/// together \[m\] (0.01 mm).
const MIN_GAIN: f64 = 1e-5;

/// Steps over which the gain is measured (a single step of the reweighted descent can gain
/// little and the next much).
const WINDOW: usize = 5;

/// The static reach of a run: per sampled tick, the run's mean error and the least found.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Reach {
    /// The ticks sampled.
    pub(crate) ticks: Vec<usize>,
    /// The run's mean body point error at each sampled tick \[m\].
    pub(crate) run: Vec<f64>,
    /// The least mean error found at each sampled tick, by a posture within the joint ranges
    /// \[m\]; at most `run`.
    pub(crate) reach: Vec<f64>,
}

impl Reach {
    /// Mean of the run's errors over the sampled ticks \[m\].
    pub(crate) fn run_mean(&self) -> f64 {
        mean(&self.run)
    }

    /// Mean of the least errors over the sampled ticks \[m\].
    pub(crate) fn reach_mean(&self) -> f64 {
        mean(&self.reach)
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Workspace of one tick's descent.
struct Descent<'a> {
    robot: &'a Robot,
    body: &'a RobotBody,
    kin: Kinematics,
    jac: DMatrix<f64>,
    hips_jac: DMatrix<f64>,
    /// Per body point: the robot frame and its Jacobian rows (3 × nv, minus the hips').
    rows: Vec<DMatrix<f64>>,
    res: Vec<Vector3<f64>>,
    /// Position range of each active joint \[rad or m\].
    range: Vec<(f64, f64)>,
}

impl<'a> Descent<'a> {
    fn new(robot: &'a Robot, body: &'a RobotBody, state: &State) -> Result<Self> {
        let nv = robot.nv();
        let range = robot
            .dof_limits()
            .iter()
            .skip(robot.base_nv())
            .map(|l| (l.lower, l.upper))
            .collect();
        Ok(Self {
            robot,
            body,
            kin: Kinematics::new(robot, state)?,
            jac: DMatrix::zeros(6, nv),
            hips_jac: DMatrix::zeros(6, nv),
            rows: body.points.iter().map(|_| DMatrix::zeros(3, nv)).collect(),
            res: vec![Vector3::zeros(); body.points.len()],
            range,
        })
    }

    /// The mean error of `state` against `targets` \[m\], with the residuals in `res` (and,
    /// with `jacobians`, their Jacobians in `rows`).
    fn evaluate(
        &mut self,
        state: &State,
        targets: &[(BodyPoint, Vector3<f64>)],
        jacobians: bool,
    ) -> Result<f64> {
        let (robot, body) = (self.robot, self.body);
        self.kin.update(robot, state)?;
        // The middle of the hips and, when asked, its Jacobian (the pelvis frame's on a robot
        // without both hips, as the quality figures do).
        let x_m = body.hips_middle(robot, &self.kin)?;
        if jacobians {
            match body.hips() {
                Some(hips) => {
                    self.hips_jac.fill(0.0);
                    for f in hips {
                        self.kin.frame_jacobian(robot, f, &mut self.jac)?;
                        self.hips_jac += 0.5 * &self.jac;
                    }
                }
                None => self
                    .kin
                    .frame_jacobian(robot, body.pelvis, &mut self.hips_jac)?,
            }
        }
        let (mut sum, mut count) = (0.0, 0usize);
        for (i, (p, f)) in body.points.iter().enumerate() {
            self.res[i] = Vector3::zeros();
            let Some((_, t)) = targets.iter().find(|(q, _)| q == p) else {
                continue;
            };
            count += 1;
            if *p == BodyPoint::Pelvis {
                continue;
            }
            let x = self.kin.frame_pose(robot, *f)?.translation.vector;
            self.res[i] = x - x_m - t;
            sum += self.res[i].norm();
            if jacobians {
                self.kin.frame_jacobian(robot, *f, &mut self.jac)?;
                let d = self.jac.rows(0, 3) - self.hips_jac.rows(0, 3);
                self.rows[i].copy_from(&d);
            }
        }
        Ok(sum / count.max(1) as f64)
    }

    /// Descends from `state` (changed in place) on the targets of one tick; returns the
    /// mean error at the start and at the end \[m\].
    fn run(
        &mut self,
        state: &mut State,
        targets: &[(BodyPoint, Vector3<f64>)],
    ) -> Result<(f64, f64)> {
        let nv = self.robot.nv();
        let start = self.evaluate(state, targets, true)?;
        let mut best = start;
        let mut mu = MU_START;
        let mut h = DMatrix::zeros(nv, nv);
        let mut g = DVector::zeros(nv);
        let mut trial = state.clone();
        let mut history = [start; WINDOW];
        for it in 0..MAX_ITERATIONS {
            h.fill(0.0);
            g.fill(0.0);
            for (rows, r) in self.rows.iter().zip(&self.res) {
                if *r == Vector3::zeros() {
                    continue;
                }
                let w = 1.0 / r.norm().max(WEIGHT_FLOOR);
                h.gemm_tr(w, rows, rows, 1.0);
                g.gemv_tr(w, rows, r, 1.0);
            }
            // A joint on a bound that the descent direction −g pushes out of it stays there:
            // its row and column leave the system (projected Newton).
            let (nb, nqb) = (self.robot.base_nv(), self.robot.base_nq());
            for (k, (lo, hi)) in self.range.iter().enumerate() {
                let (q, j) = (state.q[nqb + k], nb + k);
                if (q <= *lo && g[j] > 0.0) || (q >= *hi && g[j] < 0.0) {
                    h.row_mut(j).fill(0.0);
                    h.column_mut(j).fill(0.0);
                    h[(j, j)] = 1.0;
                    g[j] = 0.0;
                }
            }
            let mut stepped = false;
            while mu <= MU_MAX {
                let mut a = h.clone();
                for k in 0..nv {
                    a[(k, k)] += mu;
                }
                let Some(chol) = a.cholesky() else {
                    mu *= 4.0;
                    continue;
                };
                let delta = -chol.solve(&g);
                trial.clone_from(state);
                self.step(&mut trial, &delta)?;
                let e = self.evaluate(&trial, targets, false)?;
                if e < best {
                    best = e;
                    history[it % WINDOW] = best;
                    stepped = it < WINDOW || history[(it + 1) % WINDOW] - best >= MIN_GAIN;
                    state.clone_from(&trial);
                    mu = (mu / 3.0).max(1e-9);
                    break;
                }
                mu *= 4.0;
            }
            if !stepped {
                break;
            }
            self.evaluate(state, targets, true)?;
        }
        Ok((start, best))
    }

    /// Moves `state` by the velocity-coordinate step `delta` and puts every joint back into
    /// its range.
    fn step(&self, state: &mut State, delta: &DVector<f64>) -> Result<()> {
        state.qd.copy_from(delta);
        state.integrate(self.robot, &DVector::zeros(delta.len()), 1.0)?;
        state.qd.fill(0.0);
        let nqb = self.robot.base_nq();
        for (k, (lo, hi)) in self.range.iter().enumerate() {
            let q = &mut state.q[nqb + k];
            *q = q.clamp(*lo, *hi);
        }
        Ok(())
    }
}

/// The static reach of a run of `plan` on `robot`: `trajectory` holds the configuration q at
/// the start of each tick, and every `stride`-th tick is sampled (see the module
/// documentation). Errors: a configuration of the wrong length.
pub(crate) fn static_reach(
    robot: &Robot,
    body: &RobotBody,
    plan: &Plan,
    trajectory: &[Vec<f64>],
    stride: usize,
) -> Result<Reach> {
    let mut state = State::neutral(robot);
    let mut descent = Descent::new(robot, body, &state)?;
    let mut out = Reach {
        ticks: Vec::new(),
        run: Vec::new(),
        reach: Vec::new(),
    };
    for k in (0..trajectory.len().min(plan.ticks)).step_by(stride.max(1)) {
        check_dim("configuration", robot.nq(), trajectory[k].len())?;
        state.q.copy_from_slice(&trajectory[k]);
        state.qd.fill(0.0);
        let (run, reach) = descent.run(&mut state, &plan.neutral[k])?;
        out.ticks.push(k);
        out.run.push(run);
        out.reach.push(reach);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use rand::{Rng, SeedableRng};

    use super::*;
    use crate::motion::DEFAULT_MAX_GAP;
    use crate::profile::RobotProfile;
    use crate::retarget::{builtin_motion, setup, KeypointSettings, Setup};

    /// G1 and its body frames, from the keypoint setup of a built-in clip.
    fn g1() -> (Arc<Robot>, RobotBody, State) {
        let profile = RobotProfile::builtin("g1").unwrap();
        let kp = builtin_motion("humanoid3d_walk")
            .unwrap()
            .keypoints(DEFAULT_MAX_GAP)
            .unwrap();
        let robot = Arc::new(profile.robot().unwrap());
        let s = KeypointSettings::default();
        let Setup {
            robot,
            body,
            controller,
            ..
        } = setup(robot, &profile, &kp, None, &s).unwrap();
        let state = controller.state().clone();
        (robot, body, state)
    }

    /// The targets a posture meets exactly: each point relative to the middle of the hips.
    fn targets_of(
        robot: &Robot,
        body: &RobotBody,
        state: &State,
    ) -> Vec<(BodyPoint, Vector3<f64>)> {
        let kin = Kinematics::new(robot, state).unwrap();
        let x = |f| kin.frame_pose(robot, f).unwrap().translation.vector;
        let [l, r] = body.hips().unwrap();
        let m = 0.5 * (x(l) + x(r));
        body.points
            .iter()
            .map(|(p, f)| match p {
                BodyPoint::Pelvis => (*p, Vector3::zeros()),
                _ => (*p, x(*f) - m),
            })
            .collect()
    }

    /// A posture `state`'s joints moved by up to `amplitude` \[rad\] each, kept in range if
    /// `inside`.
    fn moved(robot: &Robot, state: &State, amplitude: f64, inside: bool, seed: u64) -> State {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let mut s = state.clone();
        let nqb = robot.base_nq();
        for (k, l) in robot.dof_limits().iter().skip(robot.base_nv()).enumerate() {
            let q = s.q[nqb + k] + amplitude * rng.random_range(-1.0..1.0);
            s.q[nqb + k] = if inside { q.clamp(l.lower, l.upper) } else { q };
        }
        s
    }

    fn in_range(robot: &Robot, state: &State) -> bool {
        let nqb = robot.base_nq();
        robot
            .dof_limits()
            .iter()
            .skip(robot.base_nv())
            .enumerate()
            .all(|(k, l)| (l.lower..=l.upper).contains(&state.q[nqb + k]))
    }

    /// Targets met by a posture within the ranges are found again from another posture, to
    /// well under a millimetre, and the start's error is the measure's.
    #[test]
    fn the_reach_of_a_reachable_posture_is_zero() {
        let (robot, body, start) = g1();
        for seed in 0..3 {
            let goal = moved(&robot, &start, 0.4, true, seed);
            let targets = targets_of(&robot, &body, &goal);
            let mut state = moved(&robot, &goal, 0.2, true, 100 + seed);
            let mut d = Descent::new(&robot, &body, &state).unwrap();
            let before = d.evaluate(&state, &targets, false).unwrap();
            let (first, last) = d.run(&mut state, &targets).unwrap();
            assert_eq!(first, before);
            assert!(first > 0.01, "seed {seed}: start {first} m from the goal");
            assert!(last < 1e-4, "seed {seed}: {first} m -> {last} m");
            assert!(in_range(&robot, &state));
        }
    }

    /// The Jacobian rows are the derivatives of the residuals: a small step δ of every
    /// coordinate (the base's included) changes each residual by its rows times δ, to first
    /// order (finite differences; the second-order remainder is about |δ|² ≈ 1e-12 m).
    #[test]
    fn the_jacobian_rows_are_the_residuals_derivatives() {
        let (robot, body, start) = g1();
        let state = moved(&robot, &start, 0.3, true, 11);
        let targets: Vec<_> = body
            .points
            .iter()
            .map(|(p, _)| (*p, Vector3::zeros()))
            .collect();
        let mut d = Descent::new(&robot, &body, &state).unwrap();
        let mut rng = rand::rngs::StdRng::seed_from_u64(12);
        let h = 1e-6;
        let delta = DVector::from_fn(robot.nv(), |_, _| h * rng.random_range(-1.0..1.0));
        d.evaluate(&state, &targets, true).unwrap();
        let (res, rows) = (d.res.clone(), d.rows.clone());
        let mut moved_state = state.clone();
        d.step(&mut moved_state, &delta).unwrap();
        d.evaluate(&moved_state, &targets, false).unwrap();
        let mut checked = 0;
        for (i, (p, _)) in body.points.iter().enumerate() {
            if *p == BodyPoint::Pelvis {
                continue;
            }
            let finite = d.res[i] - res[i];
            let linear = &rows[i] * &delta;
            assert!(finite.norm() > 1e-8, "{p:?} did not move");
            let gap = (finite - &linear).norm();
            assert!(gap < 1e-4 * finite.norm(), "{p:?}: {finite} {linear}");
            checked += 1;
        }
        assert!(checked >= 10);
    }

    /// Targets of a posture beyond the joint ranges: the least error stays above zero, no
    /// joint leaves its range, and the descent never ends above where it started.
    #[test]
    fn the_reach_keeps_the_joint_ranges() {
        let (robot, body, start) = g1();
        let goal = moved(&robot, &start, 2.5, false, 7);
        assert!(!in_range(&robot, &goal));
        let targets = targets_of(&robot, &body, &goal);
        let mut state = start.clone();
        let mut d = Descent::new(&robot, &body, &state).unwrap();
        let (first, last) = d.run(&mut state, &targets).unwrap();
        assert!(last <= first);
        assert!(last > 1e-3, "{first} -> {last}");
        assert!(in_range(&robot, &state));
        // A second descent from the result finds nothing better.
        let (again, more) = d.run(&mut state, &targets).unwrap();
        assert_eq!(again, last);
        assert!(more >= last - MIN_GAIN * 10.0, "{last} -> {more}");
    }
}

#[cfg(test)]
mod run_tests {
    use std::sync::Arc;

    use super::static_reach;
    use crate::motion::DEFAULT_MAX_GAP;
    use crate::profile::RobotProfile;
    use crate::retarget::{builtin_motion, retarget_keypoints, setup, KeypointSettings, Setup};

    /// Sampling every tick, the run's figure is the quality figures' mean error (computed by
    /// other code), and the reach is at most that; a run asked for the reach reports it on
    /// its ticks sampled every [`crate::retarget::REACH_PERIOD`], one that is not does not.
    #[test]
    fn the_reach_measures_as_the_quality_figures_do() {
        let profile = RobotProfile::builtin("g1").unwrap();
        let kp = builtin_motion("humanoid3d_walk")
            .unwrap()
            .keypoints(DEFAULT_MAX_GAP)
            .unwrap();
        let s = KeypointSettings::default();
        let run = retarget_keypoints(&profile, &kp, None, &s).unwrap();
        assert_eq!(run.quality.reach_cm, None);
        assert_eq!(run.quality.reach_run_cm, None);
        let robot = Arc::new(profile.robot().unwrap());
        let Setup {
            robot,
            body,
            controller,
            ..
        } = setup(robot, &profile, &kp, None, &s).unwrap();
        let all = static_reach(&robot, &body, controller.plan(), &run.trajectory, 1).unwrap();
        assert_eq!(all.ticks.len(), run.trajectory.len());
        let mean = 100.0 * all.run_mean();
        let q = &run.quality;
        assert!(
            (mean - q.mean_cm).abs() < 1e-9 * q.mean_cm,
            "{mean} against {}",
            q.mean_cm
        );
        assert!(all.reach.iter().zip(&all.run).all(|(a, b)| a <= b));
        let n = all.reach.len() as f64;
        let reach = all.reach.iter().sum::<f64>() / n;
        assert!((all.reach_mean() - reach).abs() <= f64::EPSILON * reach);
        assert!(0.0 < reach && reach < all.run_mean());
        let asked = KeypointSettings { reach: true, ..s };
        let q = retarget_keypoints(&profile, &kp, None, &asked)
            .unwrap()
            .quality;
        let stride = (crate::retarget::REACH_PERIOD / s.dt).round() as usize;
        let sampled = static_reach(&robot, &body, controller.plan(), &run.trajectory, stride);
        let sampled = sampled.unwrap();
        assert_eq!(q.reach_cm, Some(100.0 * sampled.reach_mean()));
        assert_eq!(q.reach_run_cm, Some(100.0 * sampled.run_mean()));
    }
}
