//! `iktc.retarget_keypoints`: the keypoint retargeting of `iktc::retarget` (the default route of
//! `iktc imitate`) run from Python, its state recorded tick by tick (q, v, q̈) as numpy arrays,
//! e.g. as the set points of a simulated robot's servos.

use iktc::batch::{posture_references, Posture};
use iktc::motion::DEFAULT_MAX_GAP;
use iktc::retarget::{
    retarget_keypoints, HandScaling, KeypointSettings, RetargetQuality, Sacrifices,
};
use iktc::sim::ImitateConfig;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{array, table};
use crate::motion::PyMotion;
use crate::robot::PyRobot;
use crate::to_py;

/// A keypoint retargeting run, one row per control tick from the clip's start (the settling
/// phase before it is not recorded; row 0 is the state it ends in).
#[pyclass(name = "KeypointTrajectory", module = "iktc", frozen)]
pub struct PyKeypointTrajectory {
    dt: f64,
    times: Vec<f64>,
    nq: usize,
    nv: usize,
    q: Vec<f64>,
    v: Vec<f64>,
    qdd: Vec<f64>,
    fallback_ticks: usize,
    sacrificed: Sacrifices,
    settle_sacrificed: Sacrifices,
    quality: RetargetQuality,
}

/// Runs the keypoint retargeting of `motion` on `robot` (which must have a profile) as
/// `iktc imitate` does by default (see `iktc::retarget`): the clip's body points scaled to the
/// robot, stance feet held, the COM reference kept over the support polygon, the strict-priority
/// keypoint stack solved by IKTC under the viable bounds, integrated with constant acceleration
/// over `dt` [s]; the posture level follows the joint route's references where the profile has
/// a map for the motion's format. `hold_feet`: every frame counts as stance, so both feet are
/// held where they stand for the whole clip (a standing imitation), at their yaw, instead of
/// stepping where the clip's feet leave the ground or slide, or pivoting where they turn.
/// `max_slide` [m, human scale]: a stance over which the captured ankle slides further is
/// split into steps (`iktc::retarget::KeypointSettings::max_slide`; `None` holds every
/// stance). `standing`: the feet and the pelvis held at the robot's
/// start pose and only the clip's upper body imitated, relative to its pelvis (see
/// `iktc::retarget::KeypointSettings::standing`). `smoothing`: cut-off [Hz] of the zero-phase
/// low-pass applied to the body points before they are differentiated (`None`: as captured).
/// `approach_rate` [1/s]: the soft approach to the range ends
/// (`iktc::limits::ViableSettings::approach_rate`; 0, the default, leaves it out). `hands`:
/// `"leg"` (the default) places the hands' references from the middle of the hips by the leg
/// ratio, `"segments"` along the arm at the robot's segment lengths
/// (`iktc::retarget::HandScaling`). `reach`: also measure the static reach of the body points
/// (`iktc::retarget::KeypointSettings::reach`; about doubles the time), in `quality`.
#[pyfunction]
#[pyo3(name = "retarget_keypoints", signature = (motion, robot, *, dt=0.005, hold_feet=false, standing=false, smoothing=None, approach_rate=0.0, hands="leg", reach=false, max_slide=Some(iktc::retarget::MAX_SLIDE)))]
#[allow(clippy::too_many_arguments)]
pub fn py_retarget_keypoints(
    py: Python<'_>,
    motion: &PyMotion,
    robot: &PyRobot,
    dt: f64,
    hold_feet: bool,
    standing: bool,
    smoothing: Option<f64>,
    approach_rate: f64,
    hands: &str,
    reach: bool,
    max_slide: Option<f64>,
) -> PyResult<PyKeypointTrajectory> {
    let profile = robot.required_profile("keypoint retargeting", "feet, pelvis and hands")?;
    let hands = match hands {
        "leg" => HandScaling::Leg,
        "segments" => HandScaling::Segments,
        other => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "unknown hands `{other}`; expected \"leg\" or \"segments\""
            )))
        }
    };
    let mut settings = KeypointSettings {
        dt,
        standing,
        smoothing,
        hands,
        reach,
        max_slide,
        ..KeypointSettings::default()
    };
    settings.bounds = settings
        .bounds
        .with_approach_rate(approach_rate)
        .map_err(to_py)?;
    if hold_feet {
        // Any height above the clip's lowest ankle and any speed count as on the ground.
        settings.contact_height = f64::MAX;
        settings.contact_speed = f64::MAX;
        // Planted: no pivots (the whole clip is one stance, over which the feet turn).
        settings.pivot_turn = None;
        // Nor slides split into steps.
        settings.max_slide = None;
    }
    py.detach(|| -> iktc::Result<PyKeypointTrajectory> {
        let kp = motion.motion.keypoints(DEFAULT_MAX_GAP)?;
        let cfg = ImitateConfig {
            dt,
            narrow: Vec::new(),
            ..profile.imitate_config(ImitateConfig::default())?
        };
        let posture = match &motion.clip {
            Some(clip) => posture_references(
                &robot.robot,
                profile,
                clip,
                motion.motion.format,
                None,
                &cfg,
                settings.smoothing,
            )?,
            None => Posture::Start("the motion has no skeleton".into()),
        };
        let run = retarget_keypoints(profile, &kp, posture.references(), &settings)?;
        let flat = |rows: &[Vec<f64>]| rows.iter().flatten().copied().collect::<Vec<f64>>();
        Ok(PyKeypointTrajectory {
            dt,
            times: run.times.clone(),
            nq: robot.robot.nq(),
            nv: robot.robot.nv(),
            q: flat(&run.trajectory),
            v: flat(&run.velocities),
            qdd: flat(&run.accelerations),
            fallback_ticks: run.fallback_ticks,
            sacrificed: run.sacrificed,
            settle_sacrificed: run.settle_sacrificed,
            quality: run.quality,
        })
    })
    .map_err(to_py)
}

#[pymethods]
impl PyKeypointTrajectory {
    /// Control period [s].
    #[getter]
    fn dt(&self) -> f64 {
        self.dt
    }

    /// Tick times from the clip's start [s], shape (N,).
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, &self.times)
    }

    /// Configurations q at the start of each tick, shape (N, nq): base position [m],
    /// quaternion (x, y, z, w), joints [rad].
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        table(py, [self.times.len(), self.nq], self.q.clone())
    }

    /// Velocities v at the start of each tick, shape (N, nv): base twist [m/s], [rad/s] (base
    /// axes), joint rates [rad/s].
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        table(py, [self.times.len(), self.nv], self.v.clone())
    }

    /// The accelerations q̈ solved at each tick, shape (N, nv) [m/s²], [rad/s²].
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        table(py, [self.times.len(), self.nv], self.qdd.clone())
    }

    /// Ticks solved by GF because IKTC's answer left the box.
    #[getter]
    fn fallback_ticks(&self) -> usize {
        self.fallback_ticks
    }

    /// Which tasks the joint limits cost: per level of the keypoint stack (in priority order),
    /// the ticks of the clip on which IKTC sacrificed it (the highest-priority level it
    /// corrected to keep every limit; `iktc::retarget::Sacrifices`).
    #[getter]
    fn sacrificed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        levels_dict(py, &self.sacrificed)
    }

    /// The same over the settling on the clip's first frame, before the clip starts.
    #[getter]
    fn settle_sacrificed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        levels_dict(py, &self.settle_sacrificed)
    }

    /// The run's quality figures (`iktc::retarget::RetargetQuality`), as `iktc imitate` writes
    /// them in `keypoints_summary.json`: `mean_cm`, `points` (per body point `{"point",
    /// "mean_cm", "max_cm"}`), `orientations` (`{"frame", "mean_deg", "max_deg"}`), `slip_mm`,
    /// `below_ground_mm`, `float_mm` (highest a foot the clip has on the ground floats) and `float_share` (share of those foot-ticks above 1 cm), `stance_ticks`, `jerk_rms` and `jerk_max` [rad/s³], `jerk_limit_share` (the share of the squared jerk on the ticks the solver corrected into the joint limits' box and the ticks after them), the worst
    /// `position_margin` [rad], `velocity_margin` [rad/s] and `acceleration_margin` [rad/s²]
    /// (positive: a limit exceeded), `on_limit` (`(joint, share)` pairs: the joints on a
    /// position limit on some ticks and the share of the ticks, the most often first), and `reach_cm`, `balanced_reach_cm` (the reach keeping
    /// the clip's feet and the COM over them) and `reach_run_cm` (None unless asked for
    /// with `reach=True`).
    #[getter]
    fn quality<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let q = &self.quality;
        let d = PyDict::new(py);
        d.set_item("route", &q.route)?;
        d.set_item("ticks", q.ticks)?;
        let points = q
            .points
            .iter()
            .map(|p| {
                figure_dict(
                    py,
                    ("point", &p.point),
                    [("mean_cm", p.mean_cm), ("max_cm", p.max_cm)],
                )
            })
            .collect::<PyResult<Vec<_>>>()?;
        d.set_item("points", points)?;
        d.set_item("mean_cm", q.mean_cm)?;
        let orientations = q
            .orientations
            .iter()
            .map(|o| {
                figure_dict(
                    py,
                    ("frame", &o.frame),
                    [("mean_deg", o.mean_deg), ("max_deg", o.max_deg)],
                )
            })
            .collect::<PyResult<Vec<_>>>()?;
        d.set_item("orientations", orientations)?;
        d.set_item("slip_mm", q.slip_mm)?;
        d.set_item("below_ground_mm", q.below_ground_mm)?;
        d.set_item("float_mm", q.float_mm)?;
        d.set_item("float_share", q.float_share)?;
        d.set_item("stance_ticks", q.stance_ticks)?;
        d.set_item("jerk_rms", q.jerk_rms)?;
        d.set_item("jerk_max", q.jerk_max)?;
        d.set_item("jerk_limit_share", q.jerk_limit_share)?;
        d.set_item("position_margin", q.position_margin)?;
        d.set_item("velocity_margin", q.velocity_margin)?;
        d.set_item("acceleration_margin", q.acceleration_margin)?;
        let on_limit = q
            .on_limit
            .iter()
            .map(|j| (j.joint.as_str(), j.share))
            .collect::<Vec<_>>();
        d.set_item("on_limit", on_limit)?;
        d.set_item("reach_cm", q.reach_cm)?;
        d.set_item("reach_run_cm", q.reach_run_cm)?;
        d.set_item("balanced_reach_cm", q.balanced_reach_cm)?;
        Ok(d)
    }

    fn __len__(&self) -> usize {
        self.times.len()
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(py_retarget_keypoints, m)?)?;
    m.add_class::<PyKeypointTrajectory>()?;
    Ok(())
}

/// A dict of one name and its mean and largest figure, e.g. `{"point": …, "mean_cm": …,
/// "max_cm": …}`.
fn figure_dict<'py>(
    py: Python<'py>,
    (key, name): (&str, &str),
    values: [(&str, f64); 2],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(key, name)?;
    for (k, v) in values {
        d.set_item(k, v)?;
    }
    Ok(d)
}

/// `{level: ticks}` in priority order.
fn levels_dict<'py>(py: Python<'py>, s: &Sacrifices) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (level, n) in &s.levels {
        d.set_item(level, *n)?;
    }
    Ok(d)
}
