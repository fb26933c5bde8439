//! Motion loading and retargeting for Python: `iktc.load_motion` (every format
//! `iktc::motion::load_motion` reads, or a built-in DeepMimic clip), the body keypoints, and
//! `iktc.retarget` (the joint-route retargeting of Section 5.3) returning numpy arrays.

use std::path::{Path, PathBuf};

use iktc::motion::{
    builtin_clip, builtin_map, load_motion, motion_from_content, retarget_joint_angles, Clip,
    Motion, MotionContent, MotionFormat, MotionOptions, RetargetMap, Retargeted, RobotReferences,
    Track, BUILTIN_CLIP_NAMES, BUILTIN_MAP_NAMES,
};
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;

use crate::convert::{array, table};
use crate::robot::PyRobot;
use crate::{to_py, IktcError};

/// A loaded motion: what a file (or a built-in clip) holds, its format, its body points.
///
/// Made by [`py_load_motion`]; `clip` is the skeleton clip in metres, Z or Y up as decided
/// (`None` for marker data).
#[pyclass(name = "Motion", module = "iktc", frozen)]
pub struct PyMotion {
    pub(crate) motion: Motion,
    pub(crate) clip: Option<Clip>,
}

/// Reads a motion: a built-in DeepMimic clip name (`humanoid3d_dance_a`, `humanoid3d_dance_b`,
/// `humanoid3d_punch`, `humanoid3d_walk`) or a file of any format the library reads (BVH, ASF,
/// AMC, DeepMimic JSON, C3D, points CSV, AMASS `.npz`; detected by content, then by
/// extension), with the library's automatic units, up axis and body-point recognition.
/// `body_model`: the SMPL-H or SMPL-X body model file (`.npz`) an AMASS archive is read with
/// (iktc ships none; without it, an AMASS archive is an error naming the model it needs).
#[pyfunction]
#[pyo3(name = "load_motion", signature = (spec, *, body_model=None))]
pub fn py_load_motion(
    py: Python<'_>,
    spec: &str,
    body_model: Option<PathBuf>,
) -> PyResult<PyMotion> {
    let options = MotionOptions {
        body_model,
        ..MotionOptions::default()
    };
    let (motion, builtin) = py
        .detach(|| -> iktc::Result<(Motion, Option<Clip>)> {
            if BUILTIN_CLIP_NAMES.contains(&spec) {
                let clip = builtin_clip(spec)?;
                let m = motion_from_content(
                    spec.to_string(),
                    MotionFormat::DeepMimic,
                    MotionContent::Skeleton(clip.clone()),
                    &options,
                )?;
                Ok((m, Some(clip)))
            } else {
                Ok((load_motion(Path::new(spec), &options)?, None))
            }
        })
        .map_err(to_py)?;
    let clip = match builtin {
        Some(c) => Some(c),
        None => motion.clip().transpose().map_err(to_py)?,
    };
    Ok(PyMotion { motion, clip })
}

#[pymethods]
impl PyMotion {
    /// The file (or built-in clip name).
    #[getter]
    fn source(&self) -> &str {
        &self.motion.source
    }

    /// The format: "BVH", "ASF", "AMC", "DeepMimic JSON", "C3D", "points CSV" or
    /// "AMASS (SMPL-H/SMPL-X)".
    #[getter]
    fn format(&self) -> &'static str {
        self.motion.format.name()
    }

    /// Whether it holds a skeleton (and so can be retargeted joint by joint).
    #[getter]
    fn has_skeleton(&self) -> bool {
        self.clip.is_some()
    }

    /// A few words: source, format, units, up axis, body points.
    fn summary(&self) -> String {
        self.motion.summary()
    }

    /// Frame times [s] of the skeleton clip (numpy array); an error for marker data.
    fn times<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(array(py, self.clip()?.times()))
    }

    /// The body keypoints: (names, times [s] of shape (F,), positions [m] of shape (F, K, 3),
    /// Z up, NaN where a marker was missing and not filled).
    #[allow(clippy::type_complexity)]
    fn keypoints<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Vec<String>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray3<f64>>,
    )> {
        let kp = py
            .detach(|| self.motion.keypoints(iktc::motion::DEFAULT_MAX_GAP))
            .map_err(to_py)?;
        let names = kp.points.iter().map(|p| p.name().to_string()).collect();
        let flat: Vec<f64> = kp.positions.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        let positions = table(py, [kp.frame_count(), kp.points.len(), 3], flat)?;
        Ok((names, array(py, &kp.times), positions))
    }

    fn __repr__(&self) -> String {
        format!(
            "Motion(source={:?}, format={:?}, skeleton={})",
            self.motion.source,
            self.motion.format.name(),
            self.clip.is_some()
        )
    }
}

impl PyMotion {
    /// The skeleton clip in metres, or an error naming the format.
    pub(crate) fn clip(&self) -> PyResult<&Clip> {
        self.clip.as_ref().ok_or_else(|| {
            IktcError::new_err(format!(
                "`{}` holds marker trajectories ({}); joint retargeting needs a skeleton (BVH, ASF/AMC, DeepMimic)",
                self.motion.source,
                self.motion.format.name()
            ))
        })
    }
}

/// The retargeting map: `spec` (a built-in map name or a TOML file) or, without one, the robot
/// profile's map for the motion's format (`deepmimic` for DeepMimic, `bvh` otherwise).
pub(crate) fn resolve_map(
    robot: &PyRobot,
    motion: &PyMotion,
    spec: Option<&str>,
) -> PyResult<RetargetMap> {
    match spec {
        Some(s) if BUILTIN_MAP_NAMES.contains(&s) => builtin_map(s).map_err(to_py),
        Some(s) => {
            let text = std::fs::read_to_string(s).map_err(|e| {
                IktcError::new_err(format!(
                    "map `{s}`: not a built-in map ({}) and cannot read it as a file: {e}",
                    BUILTIN_MAP_NAMES.join(", ")
                ))
            })?;
            let map = RetargetMap::from_toml_str(&text, s).map_err(to_py)?;
            iktc::profile::check_map_joints(&robot.robot, &map).map_err(to_py)?;
            Ok(map)
        }
        None => {
            let profile = robot.profile.as_ref().ok_or_else(|| {
                IktcError::new_err(format!(
                    "robot `{}` has no profile: pass map= (a built-in map: {}, or a TOML file)",
                    robot.robot.name(),
                    BUILTIN_MAP_NAMES.join(", ")
                ))
            })?;
            let format = if motion.motion.format == MotionFormat::DeepMimic {
                "deepmimic"
            } else {
                "bvh"
            };
            profile.retarget_map(format, &robot.robot).map_err(to_py)
        }
    }
}

/// Robot references at the clip's frame times (see `iktc::motion::Retargeted`).
#[pyclass(name = "Retargeted", module = "iktc", frozen)]
pub struct PyRetargeted {
    inner: Retargeted,
}

/// Retargets a motion's skeleton clip to `robot` joint by joint (Section 5.3): per joint map the
/// source joint's rotation, taken into the robot's parent-link frame, is decomposed about the
/// target joints' axes, `q_i = offset_i + sign_i · scale_i · θ_i` [rad]; the pelvis height
/// change and attitude follow the source root. `map`: a built-in map name or a TOML file;
/// without it the robot profile's map for the motion's format.
#[pyfunction]
#[pyo3(name = "retarget_joint_angles", signature = (motion, robot, map=None))]
pub fn py_retarget_joint_angles(
    py: Python<'_>,
    motion: &PyMotion,
    robot: &PyRobot,
    map: Option<&str>,
) -> PyResult<PyRetargeted> {
    let map = resolve_map(robot, motion, map)?;
    let clip = motion.clip()?;
    let inner = py
        .detach(|| retarget_joint_angles(clip, &robot.robot, &map))
        .map_err(to_py)?;
    Ok(PyRetargeted { inner })
}

/// Rows of `tracks[j][frame]` as a (frames, joints) array.
fn by_frame<'py>(
    py: Python<'py>,
    tracks: &[&[f64]],
    frames: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mut flat = Vec::with_capacity(frames * tracks.len());
    for f in 0..frames {
        flat.extend(tracks.iter().map(|t| t.get(f).copied().unwrap_or(f64::NAN)));
    }
    table(py, [frames, tracks.len()], flat)
}

#[pymethods]
impl PyRetargeted {
    /// Frame times [s], shape (F,).
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, &self.inner.times)
    }

    /// Robot joint names, the columns of `joint_angles` (driven joints, then held ones).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joint_names.clone()
    }

    /// Joint angles [rad], shape (F, J), unwrapped.
    #[getter]
    fn joint_angles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let t: Vec<&[f64]> = self.inner.joint_angles.iter().map(Vec::as_slice).collect();
        by_frame(py, &t, self.inner.times.len())
    }

    /// Pelvis height change from the first frame [m], shape (F,).
    #[getter]
    fn pelvis_height<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, &self.inner.pelvis_height)
    }

    /// Pelvis attitude change as Z-Y-X angles (yaw, pitch, roll) [rad], shape (F, 3).
    #[getter]
    fn pelvis_angles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let a = &self.inner.pelvis_angles;
        by_frame(py, &[&a[0], &a[1], &a[2]], self.inner.times.len())
    }

    /// Largest decomposition residual of each joint map over the clip [rad].
    #[getter]
    fn residuals<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, &self.inner.residuals)
    }

    /// Resampled at the control period `dt` [s] (cubic splines, continuous rate and
    /// acceleration).
    fn resample(&self, py: Python<'_>, dt: f64) -> PyResult<PyReferences> {
        let inner = py.detach(|| self.inner.resample(dt)).map_err(to_py)?;
        Ok(PyReferences { inner })
    }
}

/// References at the control rate (see `iktc::motion::RobotReferences`).
#[pyclass(name = "References", module = "iktc", frozen)]
pub struct PyReferences {
    pub(crate) inner: RobotReferences,
}

/// A (ticks, 3) array of one track: position, rate, acceleration.
fn track3<'py>(py: Python<'py>, t: &Track, n: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    by_frame(py, &[&t.position, &t.velocity, &t.acceleration], n)
}

#[pymethods]
impl PyReferences {
    /// Control period [s].
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.dt
    }

    /// Tick times [s], shape (N,).
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, &self.inner.times)
    }

    /// Robot joint names, the columns of `position`, `velocity`, `acceleration`.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joint_names.clone()
    }

    /// Joint positions [rad], shape (N, J).
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.joint_table(py, |t| &t.position)
    }

    /// Joint rates [rad/s], shape (N, J).
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.joint_table(py, |t| &t.velocity)
    }

    /// Joint accelerations [rad/s²], shape (N, J).
    #[getter]
    fn acceleration<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.joint_table(py, |t| &t.acceleration)
    }

    /// Pelvis height change [m], its rate [m/s] and acceleration [m/s²], shape (N, 3).
    #[getter]
    fn pelvis_height<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        track3(py, &self.inner.height, self.inner.len())
    }

    /// Pelvis (yaw, pitch, roll) changes [rad], shape (N, 3).
    #[getter]
    fn pelvis_angles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let a = &self.inner.angles;
        by_frame(
            py,
            &[&a[0].position, &a[1].position, &a[2].position],
            self.inner.len(),
        )
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }
}

impl PyReferences {
    /// One field of every joint track as a (ticks, joints) array.
    fn joint_table<'py>(
        &self,
        py: Python<'py>,
        field: fn(&Track) -> &Vec<f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let t: Vec<&[f64]> = self
            .inner
            .joints
            .iter()
            .map(|t| field(t).as_slice())
            .collect();
        by_frame(py, &t, self.inner.len())
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(py_load_motion, m)?)?;
    m.add_function(wrap_pyfunction!(py_retarget_joint_angles, m)?)?;
    m.add_class::<PyMotion>()?;
    m.add_class::<PyRetargeted>()?;
    m.add_class::<PyReferences>()?;
    Ok(())
}
