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
//!
//! ## Balanced reach
//!
//! The same descent, from the same posture, also with what a retargeting must keep at a
//! standstill: every foot the clip has on the ground stays where the run has it at that tick
//! (its pose, 6D), and the COM stays over the soles of those feet, at least the keypoint
//! settings' `com_margin` inside their support polygon. Both enter the sum as penalties,
//! `K Σ_c ‖r_c‖` with `K` = 30 (`HOLD_WEIGHT`, per unit of the mean error), by the same reweighting:
//! r_c is a held foot's position error and its rotation error `log(R R_heldᵀ)` times
//! 0.1 m (`ROTATION_LENGTH`; 6 rows, `J_c` its frame Jacobian, the angular rows scaled alike), and
//! the COM's horizontal distance from the shrunk polygon (2 rows, `J_c` the COM Jacobian's; 0
//! inside). What is left between this figure and the run's is what the run gives up to the
//! rates of its motion, its priorities and its references (the pelvis pose, the torso's
//! orientation, the lowering of the pelvis for the legs), not to its feet or balance. On the
//! shared clips (2026-12-03) G1's balanced reach is 1.8–6.2 cm (4.4 cm on
//! `humanoid3d_dance_a`, whose run gives 14.0 cm), JVRC-1's 2.9–21.0 cm.

use nalgebra::{DMatrix, DVector, Isometry3, Vector3};

use super::body::RobotBody;
use super::plan::{pull_inside, soles_polygon, Plan};
use crate::error::{check_dim, Result};
use crate::model::{FrameId, Kinematics, Robot, State};
use crate::motion::BodyPoint;
use crate::sim::imitate::{sole_pose, SupportSettings};
use crate::walk::SupportPolygon;

/// Smallest residual a weight is taken at \[m\]: points closer than 1 mm weigh as if 1 mm
/// away, so that a point on its target does not take the whole step.
const WEIGHT_FLOOR: f64 = 1e-3;

/// Initial Levenberg–Marquardt damping μ \[m/rad²\], in the units of the weighted
/// Gauss–Newton matrix Σ w_p J_pᵀ J_p (w_p in 1/m, J_p in m/rad).
const MU_START: f64 = 1e-3;

/// Largest μ tried before a tick's descent stops \[m/rad²\].
const MU_MAX: f64 = 1e3;

/// Weight of the balanced reach's penalties \[–\]: a metre of a held foot's or the COM's
/// residual costs as much as 30 m of mean body point error, which holds them to about a
/// millimetre where the points pull (the descent stops at gains of 0.01 mm).
pub(crate) const HOLD_WEIGHT: f64 = 30.0;

/// Smallest residual a penalty's weight is taken at \[m\] (0.1 mm).
const HOLD_FLOOR: f64 = 1e-4;

/// Length a held foot's rotation error is counted at \[m/rad\]: a radian of it as 10 cm
/// (about a sole's half length) of position error.
pub(crate) const ROTATION_LENGTH: f64 = 0.1;

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
    /// The same, by a posture that also keeps the clip's feet and the COM over them (see the
    /// module documentation, balanced reach) \[m\].
    pub(crate) balanced: Vec<f64>,
}

/// What the balanced reach keeps at one tick: the feet the clip has on the ground at the
/// poses the run has them in, and the COM inside their support polygon shrunk by `margin`.
#[derive(Debug, Clone)]
struct Balance {
    feet: Vec<(FrameId, Isometry3<f64>)>,
    /// `None` without a foot on the ground.
    polygon: Option<SupportPolygon>,
    margin: f64,
}

impl Balance {
    /// The balance of tick `k` of `plan`, with `kin` at the run's posture of that tick.
    fn of_tick(
        robot: &Robot,
        body: &RobotBody,
        plan: &Plan,
        k: usize,
        kin: &Kinematics,
        (support, margin): (&SupportSettings, f64),
    ) -> Result<Self> {
        let mut feet = Vec::with_capacity(2);
        for (i, f) in body.feet.iter().enumerate() {
            if plan.contact[i].get(k).copied().unwrap_or(false) {
                feet.push((*f, kin.frame_pose(robot, *f)?));
            }
        }
        let soles: Vec<_> = feet.iter().map(|(_, p)| sole_pose(p, support)).collect();
        let polygon = soles_polygon(&soles, support.sole_length, support.sole_width);
        Ok(Self {
            feet,
            polygon,
            margin,
        })
    }
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

    /// Mean of the least errors of balanced postures over the sampled ticks \[m\].
    pub(crate) fn balanced_mean(&self) -> f64 {
        mean(&self.balanced)
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
    /// What a balanced descent keeps (none for the reach within the ranges alone).
    balance: Option<Balance>,
    /// The penalties' rows and residuals ([`Balance`]; the module documentation).
    held_rows: Vec<DMatrix<f64>>,
    held_res: Vec<DVector<f64>>,
    com_jac: DMatrix<f64>,
    /// Body points measured and their mean error at the last evaluation \[m\].
    count: usize,
    points: f64,
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
            balance: None,
            held_rows: Vec::new(),
            held_res: Vec::new(),
            com_jac: DMatrix::zeros(3, nv),
            count: 0,
            points: 0.0,
        })
    }

    /// The descent's objective at `state`: the mean error against `targets` \[m\] (kept in
    /// `points`), plus the balance's penalties `HOLD_WEIGHT Σ ‖r_c‖` when there is a balance,
    /// with the residuals in `res` and `held_res` (and, with `jacobians`, their Jacobians in
    /// `rows` and `held_rows`).
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
        self.count = count;
        self.points = sum / count.max(1) as f64;
        Ok(self.points + HOLD_WEIGHT * self.penalties(jacobians)?)
    }

    /// The balance's residuals (and, with `jacobians`, their rows) and the sum of their norms
    /// \[m\]; 0 without a balance.
    fn penalties(&mut self, jacobians: bool) -> Result<f64> {
        let (robot, kin) = (self.robot, &self.kin);
        self.held_res.clear();
        if jacobians {
            self.held_rows.clear();
        }
        let Some(balance) = &self.balance else {
            return Ok(0.0);
        };
        let mut sum = 0.0;
        for (f, held) in &balance.feet {
            let pose = kin.frame_pose(robot, *f)?;
            let dp = pose.translation.vector - held.translation.vector;
            let dr = (pose.rotation * held.rotation.inverse()).scaled_axis() * ROTATION_LENGTH;
            let r = DVector::from_iterator(6, dp.iter().chain(dr.iter()).copied());
            sum += r.norm();
            self.held_res.push(r);
            if jacobians {
                kin.frame_jacobian(robot, *f, &mut self.jac)?;
                let mut j = self.jac.clone();
                j.rows_mut(3, 3).scale_mut(ROTATION_LENGTH);
                self.held_rows.push(j);
            }
        }
        if let Some(polygon) = &balance.polygon {
            let c = kin.com();
            let inside = pull_inside(polygon, (c.x, c.y), balance.margin);
            let r = DVector::from_vec(vec![c.x - inside.0, c.y - inside.1]);
            sum += r.norm();
            self.held_res.push(r);
            if jacobians {
                kin.com_jacobian(robot, &mut self.com_jac)?;
                self.held_rows.push(self.com_jac.rows(0, 2).into_owned());
            }
        }
        Ok(sum)
    }

    /// Descends from `state` (changed in place) on the targets of one tick; returns the
    /// mean error at the start and at the end \[m\] (the points' alone: a balanced descent's
    /// penalties are not in them).
    fn run(
        &mut self,
        state: &mut State,
        targets: &[(BodyPoint, Vector3<f64>)],
    ) -> Result<(f64, f64)> {
        let nv = self.robot.nv();
        let start = self.evaluate(state, targets, true)?;
        let start_points = self.points;
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
            // The penalties, on the scale of the points' sum (the mean times their count).
            for (rows, r) in self.held_rows.iter().zip(&self.held_res) {
                let w = self.count as f64 * HOLD_WEIGHT / r.norm().max(HOLD_FLOOR);
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
        // The points' error at the state kept (the objective's `best` there).
        self.evaluate(state, targets, false)?;
        Ok((start_points, self.points))
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
/// documentation); the balanced reach keeps the COM `com_margin` \[m\] inside the soles of
/// `support`. Errors: a configuration of the wrong length.
pub(crate) fn static_reach(
    robot: &Robot,
    body: &RobotBody,
    plan: &Plan,
    trajectory: &[Vec<f64>],
    stride: usize,
    (support, com_margin): (&SupportSettings, f64),
) -> Result<Reach> {
    let mut state = State::neutral(robot);
    let mut descent = Descent::new(robot, body, &state)?;
    let mut out = Reach {
        ticks: Vec::new(),
        run: Vec::new(),
        reach: Vec::new(),
        balanced: Vec::new(),
    };
    for k in (0..trajectory.len().min(plan.ticks)).step_by(stride.max(1)) {
        check_dim("configuration", robot.nq(), trajectory[k].len())?;
        state.q.copy_from_slice(&trajectory[k]);
        state.qd.fill(0.0);
        descent.balance = None;
        let (run, reach) = descent.run(&mut state, &plan.neutral[k])?;
        state.q.copy_from_slice(&trajectory[k]);
        let kin = Kinematics::new(robot, &state)?;
        let balance = Balance::of_tick(robot, body, plan, k, &kin, (support, com_margin))?;
        descent.balance = Some(balance);
        let (_, balanced) = descent.run(&mut state, &plan.neutral[k])?;
        out.ticks.push(k);
        out.run.push(run);
        out.reach.push(reach);
        out.balanced.push(balanced);
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
    use crate::sim::imitate::sole_pose;

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

    /// G1's sole settings and a balance holding both feet where `state` has them, the COM
    /// `margin` inside their soles.
    fn both_feet(robot: &Robot, body: &RobotBody, state: &State, margin: f64) -> Balance {
        let support = RobotProfile::builtin("g1")
            .unwrap()
            .imitate_config(Default::default())
            .unwrap()
            .support;
        let kin = Kinematics::new(robot, state).unwrap();
        let feet: Vec<_> = body
            .feet
            .iter()
            .map(|f| (*f, kin.frame_pose(robot, *f).unwrap()))
            .collect();
        let (a, b) = (
            sole_pose(&feet[0].1, &support),
            sole_pose(&feet[1].1, &support),
        );
        let mut polygon = SupportPolygon::default();
        polygon.set_hull_of_soles(&a, &b, support.sole_length, support.sole_width);
        Balance {
            feet,
            polygon: Some(polygon),
            margin,
        }
    }

    /// The balanced descent towards a posture with the arms and legs moved keeps both feet
    /// where they stood (within a millimetre and 0.1°, the penalties' weight against the
    /// points' pull) and the COM inside the soles' polygon, and still lowers the points'
    /// error; a balance with no foot on the ground is the reach within the ranges alone, to
    /// the bit.
    #[test]
    fn the_balanced_reach_keeps_the_feet_and_the_com() {
        let (robot, body, start) = g1();
        let margin = 0.02;
        for seed in 0..3 {
            let goal = moved(&robot, &start, 0.4, true, 20 + seed);
            let targets = targets_of(&robot, &body, &goal);
            let mut d = Descent::new(&robot, &body, &start).unwrap();
            d.balance = Some(both_feet(&robot, &body, &start, margin));
            let mut state = start.clone();
            let (first, last) = d.run(&mut state, &targets).unwrap();
            assert!(last < 0.8 * first, "seed {seed}: {first} -> {last}");
            let held = d.balance.clone().unwrap();
            let kin = Kinematics::new(&robot, &state).unwrap();
            for (f, pose) in &held.feet {
                let now = kin.frame_pose(&robot, *f).unwrap();
                let moved_by = (now.translation.vector - pose.translation.vector).norm();
                let turned = (now.rotation * pose.rotation.inverse()).angle();
                assert!(moved_by < 1e-3, "seed {seed}: foot moved {moved_by} m");
                assert!(
                    turned < 0.1f64.to_radians(),
                    "seed {seed}: foot turned {turned} rad"
                );
            }
            let c = kin.com();
            let inside = held.polygon.as_ref().unwrap().margin((c.x, c.y));
            assert!(inside > margin - 1e-3, "seed {seed}: COM {inside} m inside");
            assert!(in_range(&robot, &state));
            // No foot on the ground: nothing kept, the same descent as without a balance.
            let mut free = start.clone();
            d.balance = None;
            let without = d.run(&mut free, &targets).unwrap();
            let mut idle = start.clone();
            d.balance = Some(Balance {
                feet: Vec::new(),
                polygon: None,
                margin,
            });
            assert_eq!(d.run(&mut idle, &targets).unwrap(), without);
            assert_eq!(idle.q, free.q);
        }
    }

    /// A COM that starts outside the polygon is brought inside it, the feet held: the polygon
    /// of soles 12 cm ahead of the feet (half a G1 sole's length past the front ones'
    /// centres), the COM about 2 cm behind it at the start.
    #[test]
    fn the_balanced_reach_brings_the_com_over_the_soles() {
        let (robot, body, start) = g1();
        let support = RobotProfile::builtin("g1")
            .unwrap()
            .imitate_config(Default::default())
            .unwrap()
            .support;
        let mut balance = both_feet(&robot, &body, &start, 0.0);
        let ahead = |pose: &Isometry3<f64>| {
            let mut p = *pose;
            p.translation.vector.x += 0.12;
            sole_pose(&p, &support)
        };
        let (a, b) = (ahead(&balance.feet[0].1), ahead(&balance.feet[1].1));
        let mut polygon = SupportPolygon::default();
        polygon.set_hull_of_soles(&a, &b, support.sole_length, support.sole_width);
        balance.polygon = Some(polygon);
        let c = Kinematics::new(&robot, &start).unwrap().com();
        let before = polygon.margin((c.x, c.y));
        assert!(before < -0.005, "COM {before} m inside at the start");
        let targets = targets_of(&robot, &body, &start);
        let mut d = Descent::new(&robot, &body, &start).unwrap();
        d.balance = Some(balance.clone());
        let mut state = start.clone();
        d.run(&mut state, &targets).unwrap();
        let kin = Kinematics::new(&robot, &state).unwrap();
        let c = kin.com();
        let now = polygon.margin((c.x, c.y));
        assert!(now > -1e-3, "COM {now} m inside (from {before})");
        for (f, pose) in &balance.feet {
            let moved = (kin.frame_pose(&robot, *f).unwrap().translation.vector
                - pose.translation.vector)
                .norm();
            assert!(moved < 1e-3, "foot moved {moved} m");
        }
    }

    /// The penalties' rows are the derivatives of their residuals (finite differences, as
    /// for the points): a held foot's 6 rows and the COM's 2 rows once it is outside. The
    /// rotation rows are the foot's angular velocity, the derivative of `log(R R_heldᵀ)` to
    /// first order in the rotation error θ (the descent starts at θ = 0): with the feet held
    /// about 0.01 rad from the posture, they agree to θ.
    #[test]
    fn the_penalty_rows_are_the_residuals_derivatives() {
        let (robot, body, start) = g1();
        let state = moved(&robot, &start, 0.3, true, 31);
        let near = moved(&robot, &state, 0.002, true, 33);
        // Feet held where `near` has them and a polygon the COM of `state` is outside of:
        // a margin wider than the soles' hull.
        let mut d = Descent::new(&robot, &body, &state).unwrap();
        d.balance = Some(both_feet(&robot, &body, &near, 0.5));
        let targets: Vec<_> = body
            .points
            .iter()
            .map(|(p, _)| (*p, Vector3::zeros()))
            .collect();
        d.evaluate(&state, &targets, true).unwrap();
        let (res, rows) = (d.held_res.clone(), d.held_rows.clone());
        assert_eq!(res.len(), 3, "two feet and the COM");
        // The COM's residual: from the point of the polygon `margin` inside on the way from the
        // COM to the soles' centroid (the polygon's vertex centroid), to the COM. No point of
        // the soles' hull is 0.5 m inside it, so that point is the centroid itself.
        let polygon = d.balance.as_ref().unwrap().polygon.unwrap();
        let c = d.kin.com();
        let v = polygon.vertices();
        let n = v.len() as f64;
        let centroid = v
            .iter()
            .fold((0.0, 0.0), |a, q| (a.0 + q.0 / n, a.1 + q.1 / n));
        let r = &res[2];
        let at = (c.x - r[0], c.y - r[1]);
        // Bisection's resolution and rounding [m].
        const ON_THE_WAY: f64 = 1e-6;
        assert!(r.norm() > 0.01, "COM {} m outside", r.norm());
        assert!(polygon.margin(centroid) < 0.5);
        let off = (at.0 - centroid.0).hypot(at.1 - centroid.1);
        assert!(
            off < ON_THE_WAY,
            "pulled to {at:?}, the centroid {centroid:?}"
        );
        let mut rng = rand::rngs::StdRng::seed_from_u64(32);
        let h = 1e-6;
        let delta = DVector::from_fn(robot.nv(), |_, _| h * rng.random_range(-1.0..1.0));
        let mut moved_state = state.clone();
        d.step(&mut moved_state, &delta).unwrap();
        d.evaluate(&moved_state, &targets, false).unwrap();
        for (i, (r0, j)) in res.iter().zip(&rows).enumerate() {
            let finite = &d.held_res[i] - r0;
            let linear = j * &delta;
            assert!(finite.norm() > 1e-8, "penalty {i} did not move");
            let gap = (&finite - &linear).norm();
            assert!(gap < 1e-2 * finite.norm(), "penalty {i}: {finite} {linear}");
        }
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

    use super::{static_reach, Balance};
    use crate::model::Kinematics;
    use crate::motion::DEFAULT_MAX_GAP;
    use crate::profile::RobotProfile;
    use crate::retarget::{builtin_motion, retarget_keypoints, setup, KeypointSettings, Setup};
    use crate::sim::imitate::sole_pose;

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
        assert_eq!(run.quality.balanced_reach_cm, None);
        assert_eq!(run.quality.reach_run_cm, None);
        let robot = Arc::new(profile.robot().unwrap());
        let Setup {
            robot,
            body,
            controller,
            ..
        } = setup(robot, &profile, &kp, None, &s).unwrap();
        let support = &profile.imitate_config(Default::default()).unwrap().support;
        let balance = (support, s.com_margin);
        let all = static_reach(
            &robot,
            &body,
            controller.plan(),
            &run.trajectory,
            1,
            balance,
        );
        let all = all.unwrap();
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
        assert_eq!(all.balanced.len(), all.reach.len());
        let balanced = all.balanced.iter().sum::<f64>() / n;
        assert!((all.balanced_mean() - balanced).abs() <= f64::EPSILON * balanced);
        assert!(balanced > 0.0);
        assert!(0.0 < reach && reach < all.run_mean());
        let asked = KeypointSettings { reach: true, ..s };
        let q = retarget_keypoints(&profile, &kp, None, &asked)
            .unwrap()
            .quality;
        let stride = (crate::retarget::REACH_PERIOD / s.dt).round() as usize;
        let sampled = static_reach(
            &robot,
            &body,
            controller.plan(),
            &run.trajectory,
            stride,
            balance,
        );
        let sampled = sampled.unwrap();
        assert_eq!(q.reach_cm, Some(100.0 * sampled.reach_mean()));
        assert_eq!(q.balanced_reach_cm, Some(100.0 * sampled.balanced_mean()));
        assert_eq!(q.reach_run_cm, Some(100.0 * sampled.run_mean()));
    }

    /// A tick's balance holds the feet the clip has on the ground, and its polygon (none
    /// without a foot) is that of their soles: each held sole's centre lies inside it by at
    /// least half the sole's width. The walk has ticks on one foot and on none, the punch on
    /// both.
    #[test]
    fn a_ticks_balance_holds_its_contact_feet_over_their_soles() {
        let mut seen = [false; 3];
        for clip in ["humanoid3d_walk", "humanoid3d_punch"] {
            balances_of(clip, &mut seen);
        }
        assert!(seen.iter().all(|s| *s), "{seen:?}");
    }

    fn balances_of(clip: &str, seen: &mut [bool; 3]) {
        let profile = RobotProfile::builtin("g1").unwrap();
        let kp = builtin_motion(clip)
            .unwrap()
            .keypoints(DEFAULT_MAX_GAP)
            .unwrap();
        let s = KeypointSettings::default();
        let robot = Arc::new(profile.robot().unwrap());
        let Setup {
            robot,
            body,
            controller,
            support,
            ..
        } = setup(robot, &profile, &kp, None, &s).unwrap();
        let plan = controller.plan();
        let kin = Kinematics::new(&robot, controller.state()).unwrap();
        // Half a sole's width, less its rounding [m].
        let inside = 0.5 * support.sole_width - 1e-9;
        for k in 0..plan.ticks {
            let on: Vec<usize> = (0..2).filter(|i| plan.contact[*i][k]).collect();
            let b = Balance::of_tick(&robot, &body, plan, k, &kin, (&support, 0.02)).unwrap();
            seen[on.len()] = true;
            assert_eq!(b.feet.len(), on.len(), "tick {k}");
            for ((f, pose), i) in b.feet.iter().zip(&on) {
                assert_eq!(*f, body.feet[*i]);
                let sole = sole_pose(pose, &support);
                let m = b.polygon.as_ref().unwrap().margin((sole.x, sole.y));
                assert!(m >= inside, "tick {k}: sole centre {m} m inside");
            }
            assert_eq!(b.polygon.is_none(), on.is_empty(), "tick {k}");
            assert_eq!(b.margin, 0.02);
        }
    }
}
