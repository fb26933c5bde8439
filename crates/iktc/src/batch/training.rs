//! A retargeted clip in the shape training code reads: one row per output frame at a chosen
//! rate, the base pose and twist, the joint positions and rates in the robot's joint order,
//! and the world positions of named body frames; written as CSV ([`TrainingTrajectory::csv`])
//! and NPZ ([`TrainingTrajectory::npz`]).
//!
//! Resampling: output frame j is at `t_j = j / rate` for every `t_j` up to the last recorded
//! tick. Between the recorded ticks k and k+1 around `t_j` (`s = (t_j − t_k)/Δt ∈ [0, 1)`)
//! positions and rates are interpolated linearly, `x = (1 − s) x_k + s x_{k+1}`, and the base
//! orientation by spherical interpolation, `slerp(r_k, r_{k+1}, s)`; at the control rate
//! `s = 0` and the recorded ticks are copied. The body positions are then the forward
//! kinematics of the resampled configuration (not interpolated positions).

use nalgebra::{DVector, Quaternion, UnitQuaternion};

use super::npz::{npz_bytes, NpyArray};
use crate::error::{check_finite, Error, Result};
use crate::model::{Kinematics, Robot, State};
use crate::retarget::KeypointRun;
use crate::sim::ImitateRun;

/// The output rate's tolerance on the last frame \[s·Hz\]: a frame at most this fraction of an
/// output period past the last tick (rounding of `j / rate`) is still written.
pub(crate) const LAST_FRAME_SLACK: f64 = 1e-9;

/// A frame time within this many control periods of a recorded tick is taken as that tick
/// \[–\]: `j / rate` and `k Δt` differ by rounding where the output rate divides the control
/// rate, and the tick is then copied exactly.
pub(crate) const TICK_ROUNDING: f64 = 1e-9;

/// One clip resampled for training.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainingTrajectory {
    /// Output rate \[Hz\].
    pub fps: f64,
    /// Active joint names, in the robot's order (the columns of `joint_pos`).
    pub joint_names: Vec<String>,
    /// Body frame names (the rows of `body_pos`).
    pub body_names: Vec<String>,
    /// Time of each frame \[s\].
    pub time: Vec<f64>,
    /// Base position in the world \[m\], per frame.
    pub base_pos: Vec<[f64; 3]>,
    /// Base orientation, unit quaternion (x, y, z, w), per frame.
    pub base_quat_xyzw: Vec<[f64; 4]>,
    /// Base linear velocity in the base's axes \[m/s\], per frame.
    pub base_lin_vel: Vec<[f64; 3]>,
    /// Base angular velocity in the base's axes \[rad/s\], per frame.
    pub base_ang_vel: Vec<[f64; 3]>,
    /// Joint positions \[rad\] (or \[m\] for a prismatic joint), per frame, `joint_names` order.
    pub joint_pos: Vec<Vec<f64>>,
    /// Joint rates \[rad/s\] (or \[m/s\]), per frame.
    pub joint_vel: Vec<Vec<f64>>,
    /// World positions of the body frames \[m\], per frame, `body_names` order.
    pub body_pos: Vec<Vec<[f64; 3]>>,
}

/// The tick `k` a frame at `x` control periods after the first tick falls after, of
/// `ticks`, and its fraction `s` ∈ \[0, 1) towards the next (0 at and after the last tick); a
/// frame within rounding of a tick is that tick (copied, not interpolated).
fn tick_and_fraction(ticks: usize, x: f64) -> (usize, f64) {
    let mut x = x.max(0.0);
    if (x - x.round()).abs() <= TICK_ROUNDING {
        x = x.round();
    }
    let k = (x.floor() as usize).min(ticks - 1);
    let s = if k + 1 < ticks { x - k as f64 } else { 0.0 };
    (k, s)
}

/// The base orientation at fraction `s` between the recorded bases `a` and `b` (position then
/// quaternion x, y, z, w): exactly `a`'s recorded quaternion at s = 0 (not renormalised); a
/// slerp renormalised against round-off otherwise (and the nearer end for opposite
/// orientations, where it is undefined).
fn base_rotation(a: &[f64; 7], b: &[f64; 7], s: f64) -> UnitQuaternion<f64> {
    if s == 0.0 {
        return UnitQuaternion::new_unchecked(Quaternion::new(a[6], a[3], a[4], a[5]));
    }
    let quat =
        |v: &[f64; 7]| UnitQuaternion::from_quaternion(Quaternion::new(v[6], v[3], v[4], v[5]));
    let (ra, rb) = (quat(a), quat(b));
    let r = ra
        .try_slerp(&rb, s, 0.0)
        .unwrap_or(if s < 0.5 { ra } else { rb });
    UnitQuaternion::new_normalize(r.into_inner())
}

fn lerp(a: f64, b: f64, s: f64) -> f64 {
    a + s * (b - a)
}

/// One recorded tick, as resampling reads it.
struct Tick<'a> {
    /// Time \[s\].
    t: f64,
    /// Base position \[m\] and unit quaternion (x, y, z, w).
    base: [f64; 7],
    /// Active joint positions \[rad\] (or \[m\]), the robot's order.
    joints: &'a [f64],
    /// Velocity, length `nv` (base twist in the base's axes, then joint rates).
    qd: &'a [f64],
}

/// The base pose a fixed-base robot records: at the origin, not rotated.
const FIXED_BASE: [f64; 7] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// `value` finite and positive, else an error naming `name` and saying `expected`.
fn check_positive(name: &str, value: f64, expected: &str) -> Result<()> {
    check_finite(|| name.to_string(), value)?;
    if value <= 0.0 {
        return Err(Error::InvalidSetting {
            name: name.into(),
            value: value.to_string(),
            expected: expected.into(),
        });
    }
    Ok(())
}

/// The output rate's setting as errors name it.
const RATE_NAME: &str = "output rate (CLI --rate, Python rate=)";

fn check_rate(rate: f64) -> Result<()> {
    crate::resources::check_output_rate(RATE_NAME, rate).map(|_| ())
}

fn no_tick() -> Error {
    Error::InsufficientData {
        what: "training trajectory".into(),
        message: "the run recorded no tick".into(),
    }
}

impl TrainingTrajectory {
    /// Resamples `run` (of `robot`) at `rate` \[Hz\] and computes the world positions of
    /// `bodies` (frame names of `robot`).
    ///
    /// Errors: [`Error::InvalidSetting`] for a rate outside
    /// [`MIN_OUTPUT_RATE`](crate::resources::MIN_OUTPUT_RATE)`..=`[`MAX_OUTPUT_RATE`](crate::resources::MAX_OUTPUT_RATE),
    /// [`Error::ResourceLimit`] for more than
    /// [`MAX_OUTPUT_FRAMES`](crate::resources::MAX_OUTPUT_FRAMES) frames,
    /// [`Error::InsufficientData`] for a run without ticks, [`Error::UnknownName`] for a body
    /// frame the robot lacks.
    pub fn from_run(robot: &Robot, run: &ImitateRun, bodies: &[String], rate: f64) -> Result<Self> {
        check_rate(rate)?;
        let nb = robot.base_nv();
        let ticks: Vec<Tick> = run
            .steps
            .iter()
            .map(|st| Tick {
                t: st.t,
                base: st.base,
                joints: &st.q[nb..],
                qd: &st.qd,
            })
            .collect();
        Self::resample(
            robot,
            &ticks,
            run.summary.dt,
            &run.dof_names[nb..],
            bodies,
            rate,
        )
    }

    /// Resamples a keypoint retargeting `run` of `robot` recorded every `dt` \[s\], as
    /// [`Self::from_run`] does an imitation run.
    ///
    /// Errors: those of [`Self::from_run`], and [`Error::DimensionMismatch`] for a recorded
    /// configuration or velocity whose length is not the robot's `nq` or `nv`.
    pub fn from_keypoint_run(
        robot: &Robot,
        run: &KeypointRun,
        dt: f64,
        bodies: &[String],
        rate: f64,
    ) -> Result<Self> {
        check_rate(rate)?;
        let (nqb, nq, nv) = (robot.base_nq(), robot.nq(), robot.nv());
        for (what, expected, got) in [
            (
                "recorded ticks' velocities",
                run.trajectory.len(),
                run.velocities.len(),
            ),
            (
                "recorded ticks' times",
                run.trajectory.len(),
                run.times.len(),
            ),
        ] {
            if got != expected {
                return Err(Error::DimensionMismatch {
                    what: what.into(),
                    expected,
                    got,
                });
            }
        }
        let mut ticks = Vec::with_capacity(run.trajectory.len());
        for ((t, q), qd) in run.times.iter().zip(&run.trajectory).zip(&run.velocities) {
            for (what, expected, got) in [
                ("a recorded configuration", nq, q.len()),
                ("a recorded velocity", nv, qd.len()),
            ] {
                if got != expected {
                    return Err(Error::DimensionMismatch {
                        what: what.into(),
                        expected,
                        got,
                    });
                }
            }
            let mut base = FIXED_BASE;
            if nqb == 7 {
                base.copy_from_slice(&q[..7]);
            }
            ticks.push(Tick {
                t: *t,
                base,
                joints: &q[nqb..],
                qd,
            });
        }
        let names = robot.dof_names();
        Self::resample(robot, &ticks, dt, &names[robot.base_nv()..], bodies, rate)
    }

    fn resample(
        robot: &Robot,
        steps: &[Tick],
        dt: f64,
        joint_names: &[String],
        bodies: &[String],
        rate: f64,
    ) -> Result<Self> {
        let (Some(first), Some(last)) = (steps.first(), steps.last()) else {
            return Err(no_tick());
        };
        check_positive("control period [s]", dt, "a period > 0")?;
        let frames =
            crate::resources::output_frames(RATE_NAME, last.t - first.t, rate, LAST_FRAME_SLACK)?;
        let frame_ids = bodies
            .iter()
            .map(|b| robot.frame_id(b))
            .collect::<Result<Vec<_>>>()?;
        let (nb, nqb) = (robot.base_nv(), robot.base_nq());
        let nv = robot.nv();
        let mut out = Self {
            fps: rate,
            joint_names: joint_names.to_vec(),
            body_names: bodies.to_vec(),
            time: Vec::with_capacity(frames),
            base_pos: Vec::with_capacity(frames),
            base_quat_xyzw: Vec::with_capacity(frames),
            base_lin_vel: Vec::with_capacity(frames),
            base_ang_vel: Vec::with_capacity(frames),
            joint_pos: Vec::with_capacity(frames),
            joint_vel: Vec::with_capacity(frames),
            body_pos: Vec::with_capacity(frames),
        };
        let mut state = State::neutral(robot);
        let mut kin = Kinematics::new(robot, &state)?;
        for j in 0..frames {
            let t = first.t + j as f64 / rate;
            let (k, s) = tick_and_fraction(steps.len(), (t - first.t) / dt);
            let (a, b) = (&steps[k], &steps[(k + 1).min(steps.len() - 1)]);
            let pos = [0, 1, 2].map(|i| lerp(a.base[i], b.base[i], s));
            let r = base_rotation(&a.base, &b.base, s);
            let q: Vec<f64> = (0..nv - nb)
                .map(|d| lerp(a.joints[d], b.joints[d], s))
                .collect();
            let qd: Vec<f64> = (0..nv).map(|d| lerp(a.qd[d], b.qd[d], s)).collect();
            // Forward kinematics of the resampled configuration.
            if nqb == 7 {
                state.q.as_mut_slice()[..3].copy_from_slice(&pos);
                state.q.as_mut_slice()[3..7].copy_from_slice(r.coords.as_slice());
            }
            state.q.as_mut_slice()[nqb..].copy_from_slice(&q);
            state.qd = DVector::zeros(nv);
            kin.update(robot, &state)?;
            let body = frame_ids
                .iter()
                .map(|f| {
                    let p = kin.frame_pose(robot, *f)?.translation.vector;
                    Ok([p.x, p.y, p.z])
                })
                .collect::<Result<Vec<_>>>()?;
            let twist = |i: usize| if nb == 6 { qd[i] } else { 0.0 };
            out.time.push(t);
            out.base_pos.push(pos);
            out.base_quat_xyzw.push([r.i, r.j, r.k, r.w]);
            out.base_lin_vel.push([twist(0), twist(1), twist(2)]);
            out.base_ang_vel.push([twist(3), twist(4), twist(5)]);
            out.joint_pos.push(q);
            out.joint_vel.push(qd[nb..].to_vec());
            out.body_pos.push(body);
        }
        Ok(out)
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// Whether there is no frame.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// The CSV columns: `t`, `base_x base_y base_z` \[m\], `base_qx base_qy base_qz base_qw`
    /// (unit quaternion, x y z w order), then one column per joint position in the robot's
    /// joint order, named by the joint \[rad\].
    pub fn csv_header(&self) -> Vec<String> {
        let mut h: Vec<String> = [
            "t", "base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw",
        ]
        .map(String::from)
        .to_vec();
        h.extend(self.joint_names.iter().cloned());
        h
    }

    /// The CSV text: [`Self::csv_header`], then one row per frame; numbers in Rust's shortest
    /// round-trip form (reading them back gives the same `f64`).
    pub fn csv(&self) -> String {
        use std::fmt::Write;
        let mut s = self.csv_header().join(",");
        s.push('\n');
        for j in 0..self.len() {
            let row = std::iter::once(self.time[j])
                .chain(self.base_pos[j])
                .chain(self.base_quat_xyzw[j])
                .chain(self.joint_pos[j].iter().copied());
            for (c, x) in row.enumerate() {
                if c > 0 {
                    s.push(',');
                }
                // Writing into a String cannot fail.
                let _ = write!(s, "{x}");
            }
            s.push('\n');
        }
        s
    }

    /// The NPZ archive. Arrays (n frames, m joints, b bodies): `fps` (scalar \[Hz\]),
    /// `joint_names` (m), `body_names` (b), `time` (n) \[s\], `joint_pos` and `joint_vel`
    /// (n, m) \[rad\], \[rad/s\], `base_pos` (n, 3) \[m\], `base_quat_xyzw` (n, 4),
    /// `base_lin_vel` and `base_ang_vel` (n, 3) in the base's axes \[m/s\], \[rad/s\], and
    /// `body_pos_w` (n, b, 3) world positions \[m\].
    ///
    /// Errors: those of [`npz_bytes`].
    pub fn npz(&self) -> Result<Vec<u8>> {
        let n = self.len();
        let m = self.joint_names.len();
        let b = self.body_names.len();
        let flat3 = |v: &[[f64; 3]]| v.iter().flatten().copied().collect::<Vec<f64>>();
        npz_bytes(&[
            NpyArray::f64("fps", vec![], vec![self.fps]),
            NpyArray::strings("joint_names", self.joint_names.clone()),
            NpyArray::strings("body_names", self.body_names.clone()),
            NpyArray::f64("time", vec![n], self.time.clone()),
            NpyArray::f64("joint_pos", vec![n, m], self.joint_pos.concat()),
            NpyArray::f64("joint_vel", vec![n, m], self.joint_vel.concat()),
            NpyArray::f64("base_pos", vec![n, 3], flat3(&self.base_pos)),
            NpyArray::f64(
                "base_quat_xyzw",
                vec![n, 4],
                self.base_quat_xyzw.iter().flatten().copied().collect(),
            ),
            NpyArray::f64("base_lin_vel", vec![n, 3], flat3(&self.base_lin_vel)),
            NpyArray::f64("base_ang_vel", vec![n, 3], flat3(&self.base_ang_vel)),
            NpyArray::f64("body_pos_w", vec![n, b, 3], flat3(&self.body_pos.concat())),
        ])
    }
}
