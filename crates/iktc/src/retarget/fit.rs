//! The person's posture on the robot: per tick, the robot's joint angles whose segments point
//! where the person's do, for any skeleton and without a joint map. They are the posture
//! level's reference where no joint-angle reference is given and
//! [`super::KeypointSettings::posture_fit`] asks for them, so that what the levels above leave
//! free (the waist between the pelvis and the shoulders, the arms' swivel about their hands)
//! takes the person's shape rather than the start posture's. The keypoint route fits with the
//! floating base held at the pelvis' reference of each tick (the pelvis level holds it there)
//! and keeps the start posture's references for the legs, which the feet and the pelvis set.
//!
//! ## Method
//!
//! The posture is fitted to the directions of the person's segments, not to their points'
//! positions: a direction does not depend on the segments' lengths, so a robot with other
//! proportions (G1's hips 24 cm apart against a scaled person's 10 cm) still takes the
//! person's knee and elbow flexion, limb directions, trunk lean and twist. The segments
//! (`SEGMENTS`) are the thighs, shanks, upper arms and forearms, the hip axis, the shoulder
//! axis and the trunk (the middle of the hips to the middle of the shoulders), each where both
//! bodies have its ends. The head is not among them: a robot's head frame (a camera, the
//! head link's origin) is no anatomical point, and fitted it bent the waist. With
//! `u_s(q) = x_b(q) − x_a(q)` a segment's vector on the robot (its ends `a`, `b`: body points
//! or the middle of two) and `d_s` the person's unit direction at the tick, the fit is
//!
//! `min_q Σ_s ‖u_s(q)/‖u_s(q)‖ − d_s‖²` over postures within the joint ranges,
//!
//! by Levenberg–Marquardt: `(Σ_s J_sᵀJ_s + μI) δ = −Σ_s J_sᵀ r_s` with `r_s` the residual and
//! `J_s = (I − ûûᵀ)/‖u‖ (J_b − J_a)` (the frames' translational Jacobians), the configuration
//! moved by `δ` (the floating base by its body twist, [`State::integrate`]) and each joint put
//! back into its range; a joint on a bound that the gradient pushes out of it keeps its place
//! (its row and column leave the system), and so does a held base. A step is kept if it lowers the sum (μ ÷ 3), else
//! μ × 4 and it is tried again; at most 30 steps per sample, until a step
//! gains less than 10⁻⁸. Each sample starts at the previous one's result (the robot's
//! start posture for the first). A step has no component in the null space of the
//! directions' Jacobian (`H`, `g` lie in its row space), so the coordinates the directions do
//! not fix (a hand's roll, the base's position) keep the start posture's values.
//!
//! At every `n`-th tick (`n = round(0.02 s / Δt)`) the directions come from the
//! scaled person's points the plan places relative to the hips (`Plan::neutral`). Each joint's samples are then
//! low-passed at 6 Hz (zero phase, [`crate::motion::lowpass`]) and interpolated by a
//! natural cubic spline; the reference at tick `k` is the spline's value, rate and
//! acceleration at `k Δt`, kept `margin` inside the joint's range (rate and acceleration 0
//! where it is clamped).

use nalgebra::{DMatrix, DVector, Matrix3, UnitQuaternion, Vector3};

use super::body::RobotBody;
use super::tracker::PostureTracks;
use crate::error::{Error, Result};
use crate::model::{FrameId, JointLimit, Kinematics, Robot, State};
use crate::motion::{lowpass_track, BodyPoint, CubicSpline};

/// Period of the fit's samples \[s\]: 50 Hz, above twice [`FIT_CUTOFF`].
pub(crate) const FIT_PERIOD: f64 = 0.02;

/// Cut-off of the low-pass on each joint's fitted angles \[Hz\]: the person's limbs move
/// below it; what is above is the fit's and the capture's noise, which the posture rows would
/// pass on to the joints' jerk.
pub(crate) const FIT_CUTOFF: f64 = 6.0;

/// Most Levenberg–Marquardt steps per sample.
pub(crate) const MAX_ITERATIONS: usize = 30;

/// A sample's descent stops when a step lowers the sum of squared direction errors by less
/// than this \[–\] (squared unit vectors: 1e-8 is a direction 1e-4 rad off on one segment).
pub(crate) const MIN_GAIN: f64 = 1e-8;

/// Initial and largest Levenberg–Marquardt damping μ \[1/rad²\] (the units of `JᵀJ`, J in
/// 1/rad).
const MU_START: f64 = 1e-3;
const MU_MAX: f64 = 1e6;

/// A segment shorter than this on the robot has no direction \[m\] (its ends coincide).
const MIN_SEGMENT: f64 = 1e-4;

/// An end of a segment: a body point, or the middle of two.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum End {
    Point(BodyPoint),
    Middle(BodyPoint, BodyPoint),
}

use BodyPoint as P;

/// The segments whose directions are fitted, from `a` to `b` (see the module documentation).
const SEGMENTS: [(End, End); 11] = [
    (End::Point(P::LeftHip), End::Point(P::LeftKnee)),
    (End::Point(P::LeftKnee), End::Point(P::LeftAnkle)),
    (End::Point(P::RightHip), End::Point(P::RightKnee)),
    (End::Point(P::RightKnee), End::Point(P::RightAnkle)),
    (End::Point(P::LeftShoulder), End::Point(P::LeftElbow)),
    (End::Point(P::LeftElbow), End::Point(P::LeftWrist)),
    (End::Point(P::RightShoulder), End::Point(P::RightElbow)),
    (End::Point(P::RightElbow), End::Point(P::RightWrist)),
    (End::Point(P::RightHip), End::Point(P::LeftHip)),
    (End::Point(P::RightShoulder), End::Point(P::LeftShoulder)),
    (
        End::Middle(P::LeftHip, P::RightHip),
        End::Middle(P::LeftShoulder, P::RightShoulder),
    ),
];

/// The fitted posture of every tick: the posture level's reference of each active joint.
#[derive(Debug, Clone)]
pub(crate) struct PostureFit {
    /// Active joint names and, per joint, position, rate and acceleration per tick
    /// \[rad, rad/s, rad/s²\] (or m for prismatic joints).
    pub tracks: PostureTracks,
    /// Root mean square over the samples and segments of the fitted directions' error
    /// `‖û − d‖` \[–\] (a chord of the unit sphere: `2 sin(θ/2)` for directions θ apart).
    pub rms_error: f64,
}

/// A segment's ends on the robot: one or two frames each, weighted.
type Ends = [Vec<(FrameId, f64)>; 2];

/// Workspace of the fit.
struct Directions<'a> {
    robot: &'a Robot,
    /// Per segment fitted: its index in [`SEGMENTS`] and its ends on the robot.
    segments: Vec<(usize, Ends)>,
    kin: Kinematics,
    jac: DMatrix<f64>,
    rows: Vec<DMatrix<f64>>,
    res: Vec<Vector3<f64>>,
    range: Vec<(f64, f64)>,
}

impl<'a> Directions<'a> {
    fn new(robot: &'a Robot, body: &RobotBody, state: &State) -> Result<Self> {
        let frame = |p: BodyPoint| body.frame_of(p);
        let end = |e: End| -> Option<Vec<(FrameId, f64)>> {
            match e {
                End::Point(p) => Some(vec![(frame(p)?, 1.0)]),
                End::Middle(p, q) => Some(vec![(frame(p)?, 0.5), (frame(q)?, 0.5)]),
            }
        };
        let segments: Vec<(usize, Ends)> = SEGMENTS
            .iter()
            .enumerate()
            .filter_map(|(i, (a, b))| Some((i, [end(*a)?, end(*b)?])))
            .collect();
        let nv = robot.nv();
        Ok(Self {
            robot,
            rows: vec![DMatrix::zeros(3, nv); segments.len()],
            res: vec![Vector3::zeros(); segments.len()],
            segments,
            kin: Kinematics::new(robot, state)?,
            jac: DMatrix::zeros(6, nv),
            range: robot
                .dof_limits()
                .iter()
                .skip(robot.base_nv())
                .map(|l| (l.lower, l.upper))
                .collect(),
        })
    }

    /// The sum of squared direction errors at `state` against `dirs` (per segment of
    /// [`SEGMENTS`], the person's unit direction, `None` where the person has none), with the
    /// residuals in `res` and, with `jacobians`, their Jacobians in `rows`.
    fn evaluate(
        &mut self,
        state: &State,
        dirs: &[Option<Vector3<f64>>],
        jacobians: bool,
    ) -> Result<f64> {
        let robot = self.robot;
        self.kin.update(robot, state)?;
        let mut sum = 0.0;
        for (n, (i, ends)) in self.segments.iter().enumerate() {
            self.res[n] = Vector3::zeros();
            self.rows[n].fill(0.0);
            let Some(d) = dirs[*i] else { continue };
            let mut u = Vector3::zeros();
            for (sign, end) in [(-1.0, &ends[0]), (1.0, &ends[1])] {
                for (f, w) in end {
                    u += sign * w * self.kin.frame_pose(robot, *f)?.translation.vector;
                }
            }
            let len = u.norm();
            if len < MIN_SEGMENT {
                continue;
            }
            let uh = u / len;
            self.res[n] = uh - d;
            sum += self.res[n].norm_squared();
            if jacobians {
                let project = (Matrix3::identity() - uh * uh.transpose()) / len;
                for (sign, end) in [(-1.0, &ends[0]), (1.0, &ends[1])] {
                    for (f, w) in end {
                        self.kin.frame_jacobian(robot, *f, &mut self.jac)?;
                        let j = project * self.jac.rows(0, 3);
                        self.rows[n] += (sign * w) * j;
                    }
                }
            }
        }
        Ok(sum)
    }

    /// Descends from `state` (changed in place), the floating base held where it is with
    /// `hold_base`; returns the sum of squared errors kept.
    fn run(
        &mut self,
        state: &mut State,
        dirs: &[Option<Vector3<f64>>],
        hold_base: bool,
    ) -> Result<f64> {
        let robot = self.robot;
        let nv = robot.nv();
        let (nb, nqb) = (robot.base_nv(), robot.base_nq());
        let mut best = self.evaluate(state, dirs, true)?;
        let mut mu = MU_START;
        let mut h = DMatrix::zeros(nv, nv);
        let mut g = DVector::zeros(nv);
        let mut trial = state.clone();
        for _ in 0..MAX_ITERATIONS {
            h.fill(0.0);
            g.fill(0.0);
            for (rows, r) in self.rows.iter().zip(&self.res) {
                h.gemm_tr(1.0, rows, rows, 1.0);
                g.gemv_tr(1.0, rows, r, 1.0);
            }
            // A held base's coordinates leave the system, as a joint on a bound does.
            for j in (0..nb).filter(|_| hold_base) {
                h.row_mut(j).fill(0.0);
                h.column_mut(j).fill(0.0);
                h[(j, j)] = 1.0;
                g[j] = 0.0;
            }
            for (k, (lo, hi)) in self.range.iter().enumerate() {
                let (q, j) = (state.q[nqb + k], nb + k);
                if (q <= *lo && g[j] > 0.0) || (q >= *hi && g[j] < 0.0) {
                    h.row_mut(j).fill(0.0);
                    h.column_mut(j).fill(0.0);
                    h[(j, j)] = 1.0;
                    g[j] = 0.0;
                }
            }
            let mut gain = 0.0;
            while mu <= MU_MAX {
                let mut a = h.clone();
                for k in 0..nv {
                    a[(k, k)] += mu;
                }
                let Some(chol) = a.cholesky() else {
                    mu *= 4.0;
                    continue;
                };
                trial.clone_from(state);
                trial.qd.copy_from(&(-chol.solve(&g)));
                trial.integrate(robot, &DVector::zeros(nv), 1.0)?;
                trial.qd.fill(0.0);
                for (k, (lo, hi)) in self.range.iter().enumerate() {
                    trial.q[nqb + k] = trial.q[nqb + k].clamp(*lo, *hi);
                }
                let e = self.evaluate(&trial, dirs, false)?;
                if e < best {
                    gain = best - e;
                    best = e;
                    state.clone_from(&trial);
                    mu = (mu / 3.0).max(1e-9);
                    break;
                }
                mu *= 4.0;
            }
            if gain < MIN_GAIN {
                break;
            }
            self.evaluate(state, dirs, true)?;
        }
        Ok(best)
    }
}

/// The person's unit direction of each segment of [`SEGMENTS`] at one tick, from the points
/// `points` (any common origin and scale \[m\]); `None` where an end is missing or its ends
/// coincide.
fn directions(points: &[(BodyPoint, Vector3<f64>)]) -> Vec<Option<Vector3<f64>>> {
    let at = |p: BodyPoint| points.iter().find(|(q, _)| *q == p).map(|(_, x)| *x);
    let end = |e: End| match e {
        End::Point(p) => at(p),
        End::Middle(p, q) => Some(0.5 * (at(p)? + at(q)?)),
    };
    SEGMENTS
        .iter()
        .map(|(a, b)| {
            let u = end(*b)? - end(*a)?;
            let len = u.norm();
            (len > MIN_SEGMENT).then(|| u / len)
        })
        .collect()
}

/// Fits the robot's posture to the directions of the person's segments in `neutral` (per
/// tick, each body point's position relative to the middle of the hips \[m\]) at the control
/// period `dt` \[s\], from `start`; references are kept `margin` \[rad\] inside the ranges
/// (see the module documentation). With `base` (per tick, the floating base's orientation)
/// the base is held at it and only the joints are fitted: the trunk's lean then falls to the
/// waist's joints, as it does on a robot whose pelvis is held at that orientation. Errors: from the kinematics; fewer than one segment the
/// robot and the person both have.
pub(crate) fn fit(
    robot: &Robot,
    body: &RobotBody,
    start: &State,
    neutral: &[Vec<(BodyPoint, Vector3<f64>)>],
    base: Option<&[UnitQuaternion<f64>]>,
    dt: f64,
    margin: f64,
) -> Result<PostureFit> {
    let ticks = neutral.len();
    let stride = ((FIT_PERIOD / dt).round() as usize).max(1);
    let samples: Vec<usize> = (0..ticks).step_by(stride).collect();
    let mut state = start.clone();
    state.qd.fill(0.0);
    let mut fit = Directions::new(robot, body, &state)?;
    if fit.segments.is_empty() {
        return Err(Error::InsufficientData {
            what: "posture fit".into(),
            message: "the robot's body points give no segment (hip, knee, ankle, shoulder, \
                      elbow, wrist) to fit"
                .into(),
        });
    }
    let joints: Vec<_> = robot.active_joints().collect();
    let index: Vec<usize> = joints
        .iter()
        .map(|j| robot.joint_q_index(&j.name))
        .collect::<Result<_>>()?;
    let mut values: Vec<Vec<f64>> = vec![Vec::with_capacity(samples.len()); joints.len()];
    let (mut sum, mut count) = (0.0, 0usize);
    for &k in &samples {
        let dirs = directions(&neutral[k]);
        if let Some(r) = base.and_then(|b| b.get(k)) {
            let mut pose = state.base_pose(robot);
            pose.rotation = *r;
            state.set_base_pose(robot, &pose)?;
        }
        sum += fit.run(&mut state, &dirs, base.is_some())?;
        count += fit
            .segments
            .iter()
            .filter(|(i, _)| dirs[*i].is_some())
            .count();
        for (v, i) in values.iter_mut().zip(&index) {
            v.push(state.q[*i]);
        }
    }
    let times: Vec<f64> = samples.iter().map(|k| *k as f64 * dt).collect();
    let mut names = Vec::with_capacity(joints.len());
    let mut tracks = Vec::with_capacity(joints.len());
    for (j, v) in joints.iter().zip(&values) {
        let track = fitted_track(v, &times, &j.limit, margin, ticks, dt)?;
        names.push(j.name.clone());
        tracks.push(track);
    }
    Ok(PostureFit {
        tracks: (names, tracks),
        rms_error: (sum / count.max(1) as f64).sqrt(),
    })
}

/// The posture references \[rad\], \[rad/s\], \[rad/s²\] at the `ticks` ticks of period `dt`
/// \[s\] of a joint fitted to `v` at the sample `times` \[s\]: low-passed, interpolated, and
/// held still at `margin` \[rad\] inside the joint's `limit` where it would leave it.
fn fitted_track(
    v: &[f64],
    times: &[f64],
    limit: &JointLimit,
    margin: f64,
    ticks: usize,
    dt: f64,
) -> Result<[Vec<f64>; 3]> {
    let smooth = lowpass_track(v, times, FIT_CUTOFF)?;
    let spline = CubicSpline::new(times, &smooth)?;
    let (lo, hi) = (limit.lower + margin, limit.upper - margin);
    let (mut p, mut v, mut a) = (
        Vec::with_capacity(ticks),
        Vec::with_capacity(ticks),
        Vec::with_capacity(ticks),
    );
    for k in 0..ticks {
        let [x, xd, xdd] = spline.eval(k as f64 * dt);
        let (x, xd, xdd) = if lo > hi {
            (0.5 * (lo + hi), 0.0, 0.0)
        } else if x < lo || x > hi {
            (x.clamp(lo, hi), 0.0, 0.0)
        } else {
            (x, xd, xdd)
        };
        p.push(x);
        v.push(xd);
        a.push(xdd);
    }
    Ok([p, v, a])
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::motion::DEFAULT_MAX_GAP;
    use crate::profile::RobotProfile;
    use crate::retarget::plan::leg_reach;
    use crate::retarget::{builtin_motion, centres, setup, KeypointSettings, Setup};

    /// Largest error of a direction or angle recovered from an exact posture \[rad\].
    const RECOVERED: f64 = 1e-3;

    /// G1 with its joint-centre frames and the start state of a keypoint run.
    fn g1() -> (Arc<Robot>, RobotBody, State) {
        let profile = RobotProfile::builtin("g1").unwrap();
        let kp = builtin_motion("humanoid3d_walk")
            .unwrap()
            .keypoints(DEFAULT_MAX_GAP)
            .unwrap();
        let robot = Arc::new(profile.robot().unwrap());
        let Setup {
            robot,
            body,
            controller,
            ..
        } = setup(robot, &profile, &kp, None, &KeypointSettings::default()).unwrap();
        let c = centres::RobotJointCentres::find(&robot, &body).unwrap();
        let (robot, body) = c.frames(&robot, body).unwrap();
        let state = controller.state().clone();
        (robot, body, state)
    }

    /// The body points of `state`, relative to the middle of the hips.
    fn points_of(robot: &Robot, body: &RobotBody, state: &State) -> Vec<(BodyPoint, Vector3<f64>)> {
        let kin = Kinematics::new(robot, state).unwrap();
        let x = |f| kin.frame_pose(robot, f).unwrap().translation.vector;
        let [l, r] = body.hips().unwrap();
        let m = 0.5 * (x(l) + x(r));
        body.points.iter().map(|(p, f)| (*p, x(*f) - m)).collect()
    }

    #[test]
    fn directions_are_the_unit_vectors_between_the_ends() {
        let pts = vec![
            (P::LeftHip, Vector3::new(0.0, 0.1, 0.0)),
            (P::RightHip, Vector3::new(0.0, -0.1, 0.0)),
            (P::LeftKnee, Vector3::new(0.3, 0.1, -0.4)),
            (P::LeftShoulder, Vector3::new(0.0, 0.2, 0.5)),
            (P::RightShoulder, Vector3::new(0.0, -0.2, 0.5)),
        ];
        let d = directions(&pts);
        // Thigh: (0.3, 0, −0.4) / 0.5.
        let thigh = d[0].unwrap();
        assert!((thigh - Vector3::new(0.6, 0.0, -0.8)).norm() < 1e-15);
        // Hip axis: from the right hip to the left, +y.
        assert!((d[8].unwrap() - Vector3::y()).norm() < 1e-15);
        // Trunk: the middle of the hips (origin) to the middle of the shoulders, +z.
        assert!((d[10].unwrap() - Vector3::z()).norm() < 1e-15);
        // No ankle: no shank.
        assert!(d[1].is_none());
    }

    #[test]
    fn leg_reach_is_the_law_of_cosines() {
        let (t, s) = (0.3, 0.4);
        assert!((leg_reach(t, s, std::f64::consts::PI) - 0.7).abs() < 1e-15);
        assert!((leg_reach(t, s, std::f64::consts::FRAC_PI_2) - 0.5).abs() < 1e-15);
        assert!(leg_reach(t, t, 0.0).abs() < 1e-15);
    }

    /// The direction residuals' Jacobian equals their finite differences along each
    /// coordinate (the base's by its body twist, as the descent moves it).
    #[test]
    fn the_jacobian_matches_finite_differences() {
        let (robot, body, state) = g1();
        let dirs: Vec<Option<Vector3<f64>>> = vec![Some(Vector3::z()); SEGMENTS.len()];
        let mut f = Directions::new(&robot, &body, &state).unwrap();
        f.evaluate(&state, &dirs, true).unwrap();
        let (rows, res) = (f.rows.clone(), f.res.clone());
        let h = 1e-6;
        for c in 0..robot.nv() {
            let mut moved = state.clone();
            moved.qd.fill(0.0);
            moved.qd[c] = h;
            moved
                .integrate(&robot, &DVector::zeros(robot.nv()), 1.0)
                .unwrap();
            f.evaluate(&moved, &dirs, false).unwrap();
            for (n, r0) in res.iter().enumerate() {
                let fd = (f.res[n] - r0) / h;
                let an = rows[n].column(c);
                assert!(
                    (fd - an).norm() < 1e-4 * (1.0 + an.norm()),
                    "segment {n}, coordinate {c}: {fd} vs {an}"
                );
            }
        }
    }

    /// A posture within the ranges is found again from the start posture: the fitted
    /// directions are the posture's, and so the knees' and elbows' bends.
    #[test]
    fn a_reachable_posture_is_recovered() {
        let (robot, body, start) = g1();
        let mut target = start.clone();
        for (name, value) in [
            ("left_knee_joint", 0.2),
            ("right_knee_joint", 1.1),
            ("left_elbow_joint", 0.9),
            ("waist_pitch_joint", 0.3),
            ("left_hip_pitch_joint", -0.6),
        ] {
            target.set_joint(&robot, name, value).unwrap();
        }
        let pts = points_of(&robot, &body, &target);
        let want = directions(&pts);
        let neutral = vec![pts; 30];
        let out = fit(&robot, &body, &start, &neutral, None, 0.005, 0.0).unwrap();
        assert!(out.rms_error < RECOVERED, "rms {}", out.rms_error);
        // The last tick's posture has the target's directions.
        let mut fitted = start.clone();
        for (name, track) in out.tracks.0.iter().zip(&out.tracks.1) {
            fitted.set_joint(&robot, name, track[0][29]).unwrap();
        }
        let kin = Kinematics::new(&robot, &fitted).unwrap();
        let x = |p: BodyPoint| {
            kin.frame_pose(&robot, body.frame_of(p).unwrap())
                .unwrap()
                .translation
                .vector
        };
        let bend = |a: BodyPoint, b: BodyPoint, c: BodyPoint| (x(a) - x(b)).angle(&(x(c) - x(b)));
        let bend_of = |i: usize, j: usize| want[i].unwrap().angle(&want[j].unwrap());
        let knee = std::f64::consts::PI - bend(P::RightHip, P::RightKnee, P::RightAnkle);
        assert!((knee - bend_of(2, 3)).abs() < 10.0 * RECOVERED, "{knee}");
        let elbow = std::f64::consts::PI - bend(P::LeftShoulder, P::LeftElbow, P::LeftWrist);
        assert!((elbow - bend_of(4, 5)).abs() < 10.0 * RECOVERED, "{elbow}");
    }

    /// Every reference stays `margin` inside its joint's range, at rest where clamped.
    #[test]
    fn references_keep_inside_the_ranges() {
        let (robot, body, start) = g1();
        let mut target = start.clone();
        target.set_joint(&robot, "left_knee_joint", 2.8).unwrap();
        let pts = points_of(&robot, &body, &target);
        let margin = 0.3;
        let out = fit(&robot, &body, &start, &vec![pts; 20], None, 0.005, margin).unwrap();
        for (name, track) in out.tracks.0.iter().zip(&out.tracks.1) {
            let j = robot.active_joints().find(|j| j.name == *name).unwrap();
            let (lo, hi) = (j.limit.lower + margin, j.limit.upper - margin);
            for ((&p, &v), &a) in track[0].iter().zip(&track[1]).zip(&track[2]) {
                if lo > hi {
                    // A range narrower than both margins: its middle.
                    assert_eq!(p, 0.5 * (lo + hi), "{name}");
                    continue;
                }
                assert!(p >= lo && p <= hi, "{name}: {p} outside [{lo}, {hi}]");
                if p == hi || p == lo {
                    assert_eq!((v, a), (0.0, 0.0));
                }
            }
        }
    }
}
