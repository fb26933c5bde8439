//! `iktc.Imitation`: the humanoid imitation of Section 5.3 (Table 1 stack: feet, COM xy, pelvis
//! attitude, pelvis height, upper-body joints) stepped tick by tick from Python, for a robot
//! with a profile and a motion; the COM reference can be offset each tick (the damping
//! controller's output) and the support-polygon margin of a measured ZMP is computed from the
//! profile's soles.

use std::collections::BTreeMap;

use iktc::limits::{BoundMethod, NarrowedJoint};
use iktc::motion::Clip;
use iktc::sim::imitate::support_polygon;
use iktc::sim::{imitation_references, ImitateConfig, ImitationController};
use iktc::solver::SolverSettings;
use iktc::task::ComReference;
use nalgebra::{Isometry3, Matrix4, Rotation3, Translation3, UnitQuaternion, Vector3};
use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::controller::{parse_bounds, parse_method, PySolveReport};
use crate::convert::{array, pose_matrix};
use crate::motion::{resolve_map, PyMotion};
use crate::robot::PyRobot;
use crate::{to_py, IktcError};

/// The imitation closed loop of one robot and one motion (its own kinematic state, integrated
/// with constant acceleration each tick).
///
/// ```python
/// sim = iktc.Imitation(iktc.Robot("g1"), iktc.load_motion("humanoid3d_dance_b"), duration=2.0)
/// for _ in range(sim.ticks):
///     report = sim.tick()          # one control tick: solve, then integrate over dt
///     q = sim.q                    # numpy, length nq
/// ```
#[pyclass(name = "Imitation", module = "iktc")]
pub struct PyImitation {
    ctl: ImitationController,
    robot: std::sync::Arc<iktc::model::Robot>,
    cfg: ImitateConfig,
    k: usize,
    /// COM offset: position (x, y) [m], velocity [m/s], acceleration [m/s²].
    com_offset: Option<[f64; 6]>,
}

/// `clip` played `time_scale` times slower (its frame times multiplied) and cut after the first
/// frame at or past `duration` [s]; `None` when neither changes it.
fn clip_part(clip: &Clip, time_scale: f64, duration: Option<f64>) -> iktc::Result<Option<Clip>> {
    if !(time_scale.is_finite() && time_scale > 0.0) {
        return Err(iktc::Error::InvalidSetting {
            name: "time_scale".into(),
            value: time_scale.to_string(),
            expected: "a finite factor > 0".into(),
        });
    }
    if let Some(d) = duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(iktc::Error::InvalidSetting {
                name: "duration".into(),
                value: d.to_string(),
                expected: "a finite time > 0 [s]".into(),
            });
        }
    }
    if time_scale == 1.0 && duration.is_none() {
        return Ok(None);
    }
    let times: Vec<f64> = clip.times().iter().map(|t| t * time_scale).collect();
    let keep = match duration {
        Some(d) => times
            .iter()
            .position(|t| *t >= d)
            .map_or(times.len(), |i| i + 1),
        None => times.len(),
    };
    Clip::new(
        clip.name(),
        clip.skeleton().clone(),
        times[..keep].to_vec(),
        clip.frames()[..keep].to_vec(),
        clip.up_axis(),
    )
    .map(Some)
}

/// Narrowed joint ranges from (joint, lower [rad], upper [rad]) triples; the controller checks
/// the names and that each range lies inside the joint's own.
pub(crate) fn narrowed(n: Vec<(String, f64, f64)>) -> Vec<NarrowedJoint> {
    n.into_iter()
        .map(|(joint, lower, upper)| NarrowedJoint {
            joint,
            lower,
            upper,
        })
        .collect()
}

/// A pose from a 4 × 4 homogeneous matrix (its rotation block re-orthonormalised).
pub(crate) fn pose_of(m: &PyReadonlyArray2<'_, f64>) -> PyResult<Isometry3<f64>> {
    let a = m.as_array();
    if a.shape() != [4, 4] {
        return Err(IktcError::new_err(format!(
            "foot pose: expected a 4 × 4 homogeneous matrix, got shape {:?}",
            a.shape()
        )));
    }
    let h = Matrix4::from_fn(|i, j| a[[i, j]]);
    if h.iter().any(|x| !x.is_finite()) {
        return Err(IktcError::new_err("foot pose: not finite"));
    }
    let r = Rotation3::from_matrix(&h.fixed_view::<3, 3>(0, 0).into_owned());
    Ok(Isometry3::from_parts(
        Translation3::new(h[(0, 3)], h[(1, 3)], h[(2, 3)]),
        UnitQuaternion::from_rotation_matrix(&r),
    ))
}

/// `bounds` with the soft approach at `rate` \[1/s\], by default the imitation's with the viable
/// or quiet bounds (none with the paper's).
fn imitation_bounds(bounds: BoundMethod, rate: Option<f64>) -> PyResult<BoundMethod> {
    let rate = match (rate, bounds) {
        (Some(r), _) => r,
        (None, BoundMethod::Paper) => 0.0,
        (None, _) => ImitateConfig::default().bounds.approach_rate(),
    };
    bounds.with_approach_rate(rate).map_err(to_py)
}

#[pymethods]
impl PyImitation {
    /// `robot` must have a profile (feet, pelvis, posture, narrowed ranges, soles); `motion` a
    /// skeleton. `map`: a built-in map or TOML file (default: the profile's); `dt` the control
    /// period [s]; `method` iktc, gf, clamp or prioritized; `bounds` quiet (the default), viable or paper
    /// (quiet: viable bounds that come to rest on a limit without chatter); `level_hold` [ticks],
    /// `rebase_release` [–] and `continuity` [–] the solver's hold on IKTC's corrected level
    /// (default `iktc::sim::IMITATE_LEVEL_HOLD`, 4), the release rate of its corrected levels'
    /// demands and the weight of the continuity term of its correction
    /// (`iktc::solver::SolverSettings`; 1, 1.0 and 0.0 are Algorithm 2 as printed); `narrow` a list of (joint, lower, upper) [rad] replacing the profile's
    /// narrowed ranges (the tasks below the level a narrowed joint blocks are corrected);
    /// `duration` [s] keeps the clip's frames up to the first at or past it (default: all);
    /// `time_scale` [–] plays the clip that many times slower (its frame times multiplied:
    /// rates divided by it, accelerations by its square), before the cut. `smoothing` [Hz]: the
    /// cut-off of the zero-phase low-pass applied to the retargeted angles before they are
    /// differentiated (`iktc::sim::ImitateConfig::smoothing`; default 6 Hz, None: as captured).
    /// `approach_rate` [1/s]: the soft approach to the range ends with viable or quiet bounds
    /// (`iktc::limits::ViableSettings::approach_rate`; default None: the imitation's, the tasks'
    /// rate √k_p = 10 /s; 0 turns it off). `root_scales`: keys of the map's `[root]` table
    /// (`height_scale`, `yaw_scale`, `pitch_scale`, `roll_scale` [–]) replacing the map's, e.g.
    /// `{"height_scale": 0.0, "pitch_scale": 0.0, "roll_scale": 0.0}` holds the pelvis at its
    /// start.
    #[new]
    #[pyo3(signature = (robot, motion, *, map=None, root_scales=None, dt=0.005, method="iktc", bounds="quiet", duration=None, time_scale=1.0, level_hold=None, rebase_release=1.0, continuity=0.0, narrow=None, smoothing=Some(iktc::sim::IMITATE_SMOOTHING), approach_rate=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        robot: &PyRobot,
        motion: &PyMotion,
        map: Option<&str>,
        root_scales: Option<BTreeMap<String, f64>>,
        dt: f64,
        method: &str,
        bounds: &str,
        duration: Option<f64>,
        time_scale: f64,
        level_hold: Option<usize>,
        rebase_release: f64,
        continuity: f64,
        narrow: Option<Vec<(String, f64, f64)>>,
        smoothing: Option<f64>,
        approach_rate: Option<f64>,
    ) -> PyResult<Self> {
        let profile = robot.required_profile("the imitation", "feet, pelvis and posture")?;
        let defaults = ImitateConfig::default();
        let bounds = imitation_bounds(parse_bounds(bounds)?, approach_rate)?;
        let base = ImitateConfig {
            method: parse_method(method)?,
            bounds,
            dt,
            ..defaults
        };
        let base = ImitateConfig {
            solver: SolverSettings {
                level_hold: level_hold.unwrap_or(base.solver.level_hold),
                rebase_release,
                continuity,
                ..base.solver
            },
            ..base
        };
        let mut cfg = profile.imitate_config(base).map_err(to_py)?;
        if let Some(n) = narrow {
            cfg.narrow = narrowed(n);
        }
        cfg.smoothing = smoothing;
        let mut map = resolve_map(robot, motion, map)?;
        for (key, value) in root_scales.unwrap_or_default() {
            let scale = match key.as_str() {
                "height_scale" => &mut map.root.height_scale,
                "yaw_scale" => &mut map.root.yaw_scale,
                "pitch_scale" => &mut map.root.pitch_scale,
                "roll_scale" => &mut map.root.roll_scale,
                other => {
                    return Err(IktcError::new_err(format!(
                        "root_scales: unknown key `{other}`; expected height_scale, yaw_scale, pitch_scale or roll_scale"
                    )))
                }
            };
            if !value.is_finite() {
                return Err(IktcError::new_err(format!(
                    "root_scales[{key:?}] = {value}: expected a finite scale [–]"
                )));
            }
            *scale = value;
        }
        let clip = motion.clip()?;
        let part = clip_part(clip, time_scale, duration).map_err(to_py)?;
        let clip = part.as_ref().unwrap_or(clip);
        let r = &robot.robot;
        let ctl = py
            .detach(|| -> iktc::Result<ImitationController> {
                let refs = imitation_references(r, clip, &map, &cfg)?;
                ImitationController::new(r, &refs, &cfg)
            })
            .map_err(to_py)?;
        Ok(Self {
            ctl,
            robot: robot.robot.clone(),
            cfg,
            k: 0,
            com_offset: None,
        })
    }

    /// Number of reference ticks.
    #[getter]
    fn ticks(&self) -> usize {
        self.ctl.references().len()
    }

    /// Index of the next tick (ticks past the end hold the last reference).
    #[getter]
    fn k(&self) -> usize {
        self.k
    }

    /// Control period [s].
    #[getter]
    fn dt(&self) -> f64 {
        self.cfg.dt
    }

    /// One control tick: references of tick k, kinematics, task equations, acceleration box,
    /// solve, then constant-acceleration integration over dt; k advances. The GIL is released.
    fn tick(&mut self, py: Python<'_>) -> PyResult<PySolveReport> {
        let t = self.k as f64 * self.cfg.dt;
        let com = self.com_offset.map(|[dx, dy, vx, vy, ax, ay]| {
            let c = self.ctl.com_reference_at(t);
            ComReference {
                position: c.position + Vector3::new(dx, dy, 0.0),
                velocity: c.velocity + Vector3::new(vx, vy, 0.0),
                acceleration: c.acceleration + Vector3::new(ax, ay, 0.0),
            }
        });
        self.ctl.set_com_override(com);
        let (ctl, k) = (&mut self.ctl, self.k);
        let report = py
            .detach(|| -> iktc::Result<PySolveReport> {
                let report = PySolveReport::from(ctl.tick(k)?);
                ctl.integrate()?;
                Ok(report)
            })
            .map_err(to_py)?;
        self.k += 1;
        Ok(report)
    }

    /// Offsets the COM reference of the next ticks by (dx, dy) [m] in the horizontal plane (the
    /// damping controller's `com_offset`), its rate by `velocity` [m/s] and its acceleration by
    /// `acceleration` [m/s²] (default 0). The COM task's CLIK
    /// `c̈ = c̈_ref + k_v (ċ_ref − ċ) + k_p (c_ref − c)` follows an offset given by its position
    /// alone as a critically damped second-order lag (`k_p = 100 s⁻²`: about 0.2 s); with the
    /// offset's rate and acceleration it follows within a tick. `None` returns to the standing
    /// reference.
    #[pyo3(signature = (offset=None, velocity=None, acceleration=None))]
    fn set_com_offset(
        &mut self,
        offset: Option<(f64, f64)>,
        velocity: Option<(f64, f64)>,
        acceleration: Option<(f64, f64)>,
    ) -> PyResult<()> {
        let Some((dx, dy)) = offset else {
            self.com_offset = None;
            return Ok(());
        };
        let (vx, vy) = velocity.unwrap_or((0.0, 0.0));
        let (ax, ay) = acceleration.unwrap_or((0.0, 0.0));
        for (what, unit, (x, y)) in [
            ("COM offset", "m", (dx, dy)),
            ("COM offset velocity", "m/s", (vx, vy)),
            ("COM offset acceleration", "m/s²", (ax, ay)),
        ] {
            if !(x.is_finite() && y.is_finite()) {
                return Err(IktcError::new_err(format!(
                    "{what} ({x}, {y}) [{unit}] is not finite"
                )));
            }
        }
        self.com_offset = Some([dx, dy, vx, vy, ax, ay]);
        Ok(())
    }

    /// The configuration q (numpy, length nq) at the start of the next tick.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.ctl.state().q.as_slice())
    }

    /// The velocity v (numpy, length nv) at the start of the next tick.
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.ctl.state().qd.as_slice())
    }

    /// q̈ of the last tick (numpy, length nv).
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.ctl.qdd().as_slice())
    }

    /// The standing COM reference at tick k [m] (before any offset): the initial COM blended
    /// to the centre of the support polygon.
    fn com_reference<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let c = self.ctl.com_reference_at(self.k as f64 * self.cfg.dt);
        array(py, c.position.as_slice())
    }

    /// The COM of the state q [m] (world axes).
    fn com<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let kin = iktc::model::Kinematics::new(&self.robot, self.ctl.state()).map_err(to_py)?;
        Ok(array(py, kin.com().as_slice()))
    }

    /// The feet frames (right, then left) and their initial, held poses as 4 × 4 matrices.
    fn feet<'py>(&self, py: Python<'py>) -> Vec<(String, Bound<'py, PyArray2<f64>>)> {
        self.cfg
            .feet
            .iter()
            .zip(self.ctl.feet0())
            .map(|(n, p)| (n.clone(), pose_matrix(py, p)))
            .collect()
    }

    /// The pelvis frame's name and its initial pose (4 × 4).
    fn pelvis<'py>(&self, py: Python<'py>) -> (String, Bound<'py, PyArray2<f64>>) {
        (self.cfg.pelvis.clone(), pose_matrix(py, self.ctl.pelvis0()))
    }

    /// The soles of the support polygon: sole_length, sole_width, sole_offset_x, ankle_height
    /// [m].
    fn sole<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.cfg.support;
        let d = PyDict::new(py);
        d.set_item("sole_length", s.sole_length)?;
        d.set_item("sole_width", s.sole_width)?;
        d.set_item("sole_offset_x", s.sole_offset_x)?;
        d.set_item("ankle_height", s.ankle_height)?;
        Ok(d)
    }

    /// Signed distance [m] from the point (x, y) (a ZMP) to the edge of the support polygon of
    /// the feet at the given ankle poses (4 × 4 each; default: the initial ones): the convex
    /// hull of their soles; positive inside.
    #[pyo3(signature = (point, feet=None))]
    fn support_margin(
        &self,
        point: (f64, f64),
        feet: Option<Vec<PyReadonlyArray2<'_, f64>>>,
    ) -> PyResult<f64> {
        let poses = match feet {
            Some(f) => f.iter().map(pose_of).collect::<PyResult<Vec<_>>>()?,
            None => self.ctl.feet0().to_vec(),
        };
        let p = support_polygon(&poses, &self.cfg.support).map_err(to_py)?;
        Ok(p.margin(point))
    }

    /// Names of the upper-body joints the motion drives (level 5).
    #[getter]
    fn upper_body_joints(&self) -> Vec<String> {
        self.ctl.references().joint_names.clone()
    }

    /// The upper-body joint references of tick `k` [rad] (default: the last tick solved).
    #[pyo3(signature = (k=None))]
    fn upper_body_reference<'py>(
        &self,
        py: Python<'py>,
        k: Option<usize>,
    ) -> Bound<'py, PyArray1<f64>> {
        let r = self.ctl.references();
        let k = k
            .unwrap_or(self.k.saturating_sub(1))
            .min(r.len().saturating_sub(1));
        let v: Vec<f64> = r
            .joints
            .iter()
            .map(|t| t.position.get(k).copied().unwrap_or(f64::NAN))
            .collect();
        array(py, &v)
    }

    /// Resets to the start (state, tick index, no COM offset).
    fn reset(&mut self) -> PyResult<()> {
        let refs = self.ctl.references().clone();
        self.ctl = ImitationController::new(&self.robot, &refs, &self.cfg).map_err(to_py)?;
        self.k = 0;
        self.com_offset = None;
        Ok(())
    }
}
