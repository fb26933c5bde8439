//! `iktc.Robot`: an immutable robot model from a built-in name, a robot profile (TOML), a
//! URDF or a MuJoCo MJCF file.

use iktc::model::RobotFiles;
use std::path::Path;
use std::sync::Arc;

use iktc::model::{builtin_robot, declared_base, BaseKind, Kinematics, ModelOptions, Robot, State};
use iktc::profile::{RobotProfile, BUILTIN_PROFILES};
use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{array, matrix, pose_matrix, vector};
use crate::to_py;

/// A state as numpy arrays: (q, v).
type StateArrays<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// A robot model (immutable), with its robot profile when it has one.
///
/// `Robot("jvrc1")` or `Robot("g1")` loads a built-in robot through its built-in profile (feet,
/// pelvis, posture, locks, acceleration limits, retargeting maps), like the command line's
/// `--robot g1`; `Robot("planar3r")` is the 3R arm (no profile); `Robot("my_robot.toml")` reads
/// a profile file; with a profile, `accel` [rad/s²] and `velocity` [rad/s] (joint, limit) pairs
/// and `default_velocity` replace its keys `acceleration.limits`, `velocity.limits` and
/// `velocity.default` for the joints they name; `Robot("path/to/robot.urdf", floating=True, lock=[("finger", 0.0)],
/// accel=[("knee", 30.0)], velocity=[("knee", 14.0)], default_velocity=20.0)` reads a bare
/// URDF file (no profile; `velocity` [rad/s] replaces a joint's velocity limit,
/// `default_velocity` [rad/s] is the limit of the joints the file gives none, with the
/// acceleration limits 10 × these unless `accel` names the joint), and `Robot("model.xml")` a
/// MuJoCo MJCF model (floating when it has a free joint, unless `floating` says otherwise;
/// q's joint part is MuJoCo's qpos after the free joint, the quaternion (x, y, z, w)). q is (base position [m], base
/// quaternion (x, y, z, w), joints [rad]) and v (base linear and angular velocity in base axes,
/// joint rates), as in the Rust library.
#[pyclass(name = "Robot", module = "iktc", frozen)]
pub struct PyRobot {
    pub(crate) robot: Arc<Robot>,
    /// The profile the robot was built from (built-in name or profile file), if any.
    pub(crate) profile: Option<Arc<RobotProfile>>,
}

#[pymethods]
impl PyRobot {
    #[new]
    #[pyo3(signature = (spec, *, floating=None, lock=None, accel=None, velocity=None, default_velocity=None))]
    fn new(
        spec: &str,
        floating: Option<bool>,
        lock: Option<Vec<(String, f64)>>,
        accel: Option<Vec<(String, f64)>>,
        velocity: Option<Vec<(String, f64)>>,
        default_velocity: Option<f64>,
    ) -> PyResult<Self> {
        let is_urdf = spec.ends_with(".urdf") || spec.ends_with(".xml");
        let is_profile = spec.ends_with(".toml") || BUILTIN_PROFILES.contains(&spec);
        let keywords = Keywords {
            floating,
            lock,
            accel,
            velocity,
            default_velocity,
        };
        keywords.check(spec, is_urdf, is_profile)?;
        let profile = if spec.ends_with(".toml") {
            Some(RobotProfile::load(Path::new(spec)).map_err(to_py)?)
        } else if BUILTIN_PROFILES.contains(&spec) {
            Some(RobotProfile::builtin(spec).map_err(to_py)?)
        } else {
            None
        };
        if let Some(p) = profile {
            return keywords.profile_robot(spec, p);
        }
        let robot = if is_urdf {
            keywords.file_robot(spec)?
        } else {
            builtin_robot(spec).map_err(to_py)?
        };
        Ok(Self {
            robot: Arc::new(robot),
            profile: None,
        })
    }

    /// Whether the robot comes with a profile (feet, pelvis, posture, retargeting maps).
    #[getter]
    fn has_profile(&self) -> bool {
        self.profile.is_some()
    }

    /// The robot's name.
    #[getter]
    fn name(&self) -> &str {
        self.robot.name()
    }

    /// Size of q.
    #[getter]
    fn nq(&self) -> usize {
        self.robot.nq()
    }

    /// Size of v (and of q̈).
    #[getter]
    fn nv(&self) -> usize {
        self.robot.nv()
    }

    /// Whether the base floats (q starts with 7 base entries, v with 6).
    #[getter]
    fn floating(&self) -> bool {
        self.robot.base() == BaseKind::Floating
    }

    /// Active joint names, in q order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.robot.active_joints().map(|j| j.name.clone()).collect()
    }

    /// Every frame name (links first).
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.robot.frames().iter().map(|f| f.name.clone()).collect()
    }

    /// Total mass [kg].
    #[getter]
    fn total_mass(&self) -> f64 {
        self.robot.total_mass()
    }

    /// Index of a joint in q.
    fn q_index(&self, joint: &str) -> PyResult<usize> {
        self.robot.joint_q_index(joint).map_err(to_py)
    }

    /// Index of a joint in v.
    fn v_index(&self, joint: &str) -> PyResult<usize> {
        self.robot.joint_v_index(joint).map_err(to_py)
    }

    /// Per velocity dof (base entries unbounded): (lower [rad], upper [rad], velocity [rad/s],
    /// acceleration [rad/s²]) as four numpy arrays of length nv.
    fn limits<'py>(&self, py: Python<'py>) -> [Bound<'py, PyArray1<f64>>; 4] {
        let l = self.robot.dof_limits();
        let pick = |f: fn(&iktc::model::JointLimit) -> f64| l.iter().map(f).collect::<Vec<_>>();
        [
            array(py, &pick(|x| x.lower)),
            array(py, &pick(|x| x.upper)),
            array(py, &pick(|x| x.velocity)),
            array(py, &pick(|x| x.acceleration)),
        ]
    }

    /// The neutral configuration: (q, v) as numpy arrays (base at the origin, joints at 0).
    fn neutral<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let s = State::neutral(&self.robot);
        (array(py, s.q.as_slice()), array(py, s.qd.as_slice()))
    }

    /// The robot standing in its profile's start posture: (q, v) with the joints at the
    /// profile's `posture`, at rest, the base upright above the origin and raised so that the
    /// lower foot's sole is on the ground (z = 0), the state the keypoint route starts from
    /// (`neutral()` has the base at the origin). Needs a profile with feet.
    fn standing<'py>(&self, py: Python<'py>) -> PyResult<StateArrays<'py>> {
        let profile = self.profile.as_ref().ok_or_else(|| {
            crate::IktcError::new_err(format!(
                "robot `{}` has no profile, so no standing posture: load a built-in robot or a profile file (`iktc.profile_init` writes one)",
                self.robot.name()
            ))
        })?;
        let s = profile.standing_state(&self.robot).map_err(to_py)?;
        Ok((array(py, s.q.as_slice()), array(py, s.qd.as_slice())))
    }

    /// Pose of a frame at configuration q, as a 4 × 4 homogeneous matrix (world axes, [m]).
    fn frame_pose<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &str,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let kin = self.kinematics(q)?;
        let f = self.robot.frame_id(frame).map_err(to_py)?;
        let p = kin.frame_pose(&self.robot, f).map_err(to_py)?;
        Ok(pose_matrix(py, &p))
    }

    /// Frame Jacobian at q: 6 × nv, rows (vx, vy, vz, ωx, ωy, ωz) in world axes.
    fn frame_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &str,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let kin = self.kinematics(q)?;
        let f = self.robot.frame_id(frame).map_err(to_py)?;
        let mut j = nalgebra::DMatrix::zeros(6, self.robot.nv());
        kin.frame_jacobian(&self.robot, f, &mut j).map_err(to_py)?;
        Ok(matrix(py, &j))
    }

    /// Centre of mass at q [m], world axes.
    fn com<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let kin = self.kinematics(q)?;
        Ok(array(py, kin.com().as_slice()))
    }

    /// The ZMP [m] (world x, y, shape (n, 2)) of the robot moving through the configurations
    /// `qs` (shape (n, nq), n ≥ 3, one row every `dt` [s]) on the ground plane `z = ground` [m]:
    /// the links' ZMP from their masses, centres of mass and inertias, accelerations by central
    /// differences (`iktc::walk::configuration_zmp`); NaN where the ground would have to pull
    /// (the body falling faster than gravity). Where it leaves the support polygon no plant
    /// can follow the motion without tipping.
    #[pyo3(signature = (qs, dt, ground=0.0, gravity=9.81))]
    fn zmp<'py>(
        &self,
        py: Python<'py>,
        qs: PyReadonlyArray2<'py, f64>,
        dt: f64,
        ground: f64,
        gravity: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let a = qs.as_array();
        if a.ncols() != self.robot.nq() {
            return Err(crate::IktcError::new_err(format!(
                "qs: expected {} columns (nq), got {}",
                self.robot.nq(),
                a.ncols()
            )));
        }
        let rows: Vec<Vec<f64>> = a.rows().into_iter().map(|r| r.to_vec()).collect();
        let robot = &self.robot;
        let z = py
            .detach(|| {
                let refs: Vec<&[f64]> = rows.iter().map(Vec::as_slice).collect();
                iktc::walk::configuration_zmp(robot, &refs, dt, ground, gravity)
            })
            .map_err(to_py)?;
        Ok(matrix(
            py,
            &nalgebra::DMatrix::from_fn(z.len(), 2, |i, j| z[i].map_or(f64::NAN, |p| p[j])),
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot(name={:?}, nq={}, nv={}, mass={:.3} kg)",
            self.robot.name(),
            self.robot.nq(),
            self.robot.nv(),
            self.robot.total_mass()
        )
    }
}

/// The keyword arguments of `Robot(spec, …)`.
struct Keywords {
    floating: Option<bool>,
    lock: Option<Vec<(String, f64)>>,
    /// (joint, acceleration limit \[rad/s²\]) pairs.
    accel: Option<Vec<(String, f64)>>,
    /// (joint, velocity limit \[rad/s\]) pairs.
    velocity: Option<Vec<(String, f64)>>,
    /// Velocity limit \[rad/s\] of the joints given none.
    default_velocity: Option<f64>,
}

impl Keywords {
    /// Whether any of accel, velocity and default_velocity is given.
    fn limits_given(&self) -> bool {
        self.accel.is_some() || self.velocity.is_some() || self.default_velocity.is_some()
    }

    /// Errors for keywords that do not apply to `spec` (a URDF or MJCF file when `is_urdf`, a
    /// profile when `is_profile`, else a built-in robot) and for a bad default_velocity.
    fn check(&self, spec: &str, is_urdf: bool, is_profile: bool) -> PyResult<()> {
        let file_keywords = self.floating.is_some() || self.lock.is_some();
        if is_profile && file_keywords {
            return Err(crate::IktcError::new_err(format!(
                "`{spec}` is a profile: floating and lock apply to URDF and MJCF files only (a profile sets them with its keys `base` and `lock`)"
            )));
        }
        if !is_urdf && !is_profile && (file_keywords || self.limits_given()) {
            return Err(crate::IktcError::new_err(format!(
                "`{spec}` is a built-in robot without a profile: floating, lock, accel, velocity and default_velocity apply to URDF and MJCF files only (accel, velocity and default_velocity also to profiles)"
            )));
        }
        if let Some(v) = self.default_velocity {
            if v.is_nan() || v <= 0.0 {
                return Err(crate::IktcError::new_err(format!(
                    "default_velocity = {v}: expected a velocity limit > 0 [rad/s] (or +inf for none)"
                )));
            }
        }
        Ok(())
    }

    /// The robot of the profile `p` read from `spec`, the limit keywords replacing its keys
    /// for the joints they name.
    fn profile_robot(self, spec: &str, mut p: RobotProfile) -> PyResult<PyRobot> {
        if self.limits_given() {
            // The keywords replace the profile's keys for the joints they name.
            p.acceleration.limits.extend(self.accel.unwrap_or_default());
            p.velocity.limits.extend(self.velocity.unwrap_or_default());
            if self.default_velocity.is_some() {
                p.velocity.default = self.default_velocity;
            }
            let keywords = |e: iktc::Error| {
                crate::IktcError::new_err(format!(
                    "accel, velocity or default_velocity given to the profile `{spec}` (they set its keys acceleration.limits, velocity.limits and velocity.default): {e}"
                ))
            };
            p.check_values().map_err(keywords)?;
            let robot = p.robot().map_err(keywords)?;
            return Ok(PyRobot {
                robot: Arc::new(robot),
                profile: Some(Arc::new(p)),
            });
        }
        let robot = p.robot().map_err(to_py)?;
        Ok(PyRobot {
            robot: Arc::new(robot),
            profile: Some(Arc::new(p)),
        })
    }

    /// The robot of the URDF or MJCF file `spec`, with the keywords as its model options.
    fn file_robot(self, spec: &str) -> PyResult<Robot> {
        // Unless told: an MJCF model floats when it has a free joint, a URDF floats.
        let base = match self.floating {
            Some(true) => BaseKind::Floating,
            Some(false) => BaseKind::Fixed,
            None => {
                let path = Path::new(spec);
                let text = std::fs::read_to_string(path)
                    .map_err(|e| crate::IktcError::new_err(format!("cannot read {spec}: {e}")))?;
                declared_base(&text, path.parent())
                    .map_err(to_py)?
                    .unwrap_or(BaseKind::Floating)
            }
        };
        let options = ModelOptions {
            base,
            locked: self.lock.unwrap_or_default(),
            acceleration_limits: self.accel.unwrap_or_default(),
            velocity_limits: self.velocity.unwrap_or_default(),
            fallback_velocity: self.default_velocity.unwrap_or(f64::INFINITY),
            ..ModelOptions::default()
        };
        Robot::from_description_file(Path::new(spec), &options).map_err(to_py)
    }
}

impl PyRobot {
    /// A state at configuration `q` (v = 0).
    pub(crate) fn state(
        &self,
        q: &Bound<'_, PyAny>,
        v: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<State> {
        let mut s = State::neutral(&self.robot);
        let qv = vector(q, self.robot.nq(), "q")?;
        s.q.as_mut_slice().copy_from_slice(&qv);
        if let Some(v) = v {
            if !v.is_none() {
                let vv = vector(v, self.robot.nv(), "v")?;
                s.qd.as_mut_slice().copy_from_slice(&vv);
            }
        }
        s.validate(&self.robot).map_err(to_py)?;
        Ok(s)
    }

    fn kinematics(&self, q: &Bound<'_, PyAny>) -> PyResult<Kinematics> {
        let s = self.state(q, None)?;
        Kinematics::new(&self.robot, &s).map_err(to_py)
    }

    /// The robot's profile, or an error saying that `what` (e.g. "the imitation") needs its
    /// `parts` (e.g. "feet, pelvis and posture").
    pub(crate) fn required_profile(&self, what: &str, parts: &str) -> PyResult<&RobotProfile> {
        self.profile.as_deref().ok_or_else(|| {
            crate::IktcError::new_err(format!(
                "robot `{}` has no profile: {what} needs its {parts} (load it by a built-in name or a profile file; `iktc.profile_init(URDF, out=PROFILE)` writes one with its keys guessed from the URDF)",
                self.robot.name()
            ))
        })
    }
}

/// A starting robot profile for the URDF or MJCF file `urdf` (TOML text, every guess marked
/// `# guessed`), as `iktc profile init` writes it: feet and soles (from collision shapes or
/// meshes), pelvis, torso, head and hands (a frame at the end of a bare forearm), finger locks.
/// With `out` the profile is also written there, its `urdf` key relative to `out`'s folder.
///
/// `feet` and `hands` (`(left, right)` link names), `head`, `torso`, `pelvis` (link names) and
/// `sole` (`(length, width)` or `(length, width, offset_x)` [m]) are given instead of guessed,
/// as `iktc profile init`'s flags. A URDF the model loader rejects raises its error.
#[pyfunction]
#[pyo3(signature = (urdf, *, out=None, feet=None, hands=None, head=None, torso=None, pelvis=None, sole=None))]
#[allow(clippy::too_many_arguments)]
pub fn profile_init(
    urdf: &str,
    out: Option<&str>,
    feet: Option<(String, String)>,
    hands: Option<(String, String)>,
    head: Option<String>,
    torso: Option<String>,
    pelvis: Option<String>,
    sole: Option<Vec<f64>>,
) -> PyResult<String> {
    let sole = match sole.as_deref() {
        None => None,
        Some(&[length, width]) => Some(iktc::profile::Sole {
            length,
            width,
            offset_x: 0.0,
        }),
        Some(&[length, width, offset_x]) => Some(iktc::profile::Sole {
            length,
            width,
            offset_x,
        }),
        Some(v) => {
            return Err(crate::IktcError::new_err(format!(
                "sole = {v:?}: expected (length, width) or (length, width, offset_x) [m]"
            )))
        }
    };
    let options = iktc::profile::InitOptions {
        feet: feet.map(|(l, r)| [l, r]),
        hands: hands.map(|(l, r)| [l, r]),
        head,
        torso,
        pelvis,
        sole,
    };
    let path = Path::new(urdf);
    let text = std::fs::read_to_string(path)
        .map_err(|e| crate::IktcError::new_err(format!("cannot read {urdf}: {e}")))?;
    let key = iktc::profile::urdf_key(path, out.map(Path::new)).map_err(to_py)?;
    let toml = iktc::profile::init_profile_toml_with(&text, &key, path.parent(), &options)
        .map_err(to_py)?;
    if let Some(o) = out {
        std::fs::write(o, &toml)
            .map_err(|e| crate::IktcError::new_err(format!("cannot write {o}: {e}")))?;
    }
    Ok(toml)
}
