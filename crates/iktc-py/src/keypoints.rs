//! `iktc.retarget_keypoints`: the keypoint retargeting of `iktc::retarget` (the default route of
//! `iktc imitate`) run from Python, its state recorded tick by tick (q, v, q̈) as numpy arrays,
//! e.g. as the set points of a simulated robot's servos.

use std::sync::Arc;

use iktc::batch::{body_frames, posture_references, MotionFormat, Posture, TrainingTrajectory};
use iktc::model::Robot;
use iktc::motion::DEFAULT_MAX_GAP;
use iktc::retarget::{retarget_keypoints, KeypointRun, KeypointSettings, LimbScaling, Sacrifices};
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
    robot: Arc<Robot>,
    /// The body frames the saved files carry (`iktc::batch::body_frames`).
    bodies: Vec<String>,
    run: KeypointRun,
}

/// Runs the keypoint retargeting of `motion` on `robot` (which must have a profile) as
/// `iktc imitate` does by default (see `iktc::retarget`): the clip's body points scaled to the
/// robot, stance feet held, the COM reference kept over the support polygon, the strict-priority
/// keypoint stack solved by IKTC under the quiet bounds, integrated with constant acceleration
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
/// (`iktc::retarget::LimbScaling`); `feet` the same for the ankles (`"leg"`, the default,
/// keeps the person's stance width). `balance`: keep the COM over the feet's support polygon
/// in a level above the pelvis and torso (`iktc::retarget::KeypointSettings::balance`; off by
/// default, standing imitation always balances). `reach`: also measure the static reach of the body points
/// (`iktc::retarget::KeypointSettings::reach`; about doubles the time), in `quality`.
/// `posture_fit`: where no joint map gives the posture level its angles, follow the person's
/// posture fitted to their segments' directions (`iktc::retarget::fit`) instead of the start
/// posture. `max_leg_extension` (0, 1]: the largest share of a leg's length the pelvis height
/// may ask of a stance leg (`iktc::retarget::MAX_LEG_EXTENSION` by default); larger values
/// follow straight knees closer and land the feet less exactly.
/// `"leg"` or `"segments"` of the argument `name`.
fn limb_scaling(name: &str, value: &str) -> PyResult<LimbScaling> {
    match value {
        "leg" => Ok(LimbScaling::Leg),
        "segments" => Ok(LimbScaling::Segments),
        other => Err(crate::IktcError::new_err(format!(
            "{name} = `{other}`: expected \"leg\" or \"segments\""
        ))),
    }
}

#[pyfunction]
#[pyo3(name = "retarget_keypoints", signature = (motion, robot, *, dt=0.005, hold_feet=false, standing=false, smoothing=None, approach_rate=0.0, hands="leg", feet="leg", balance=false, reach=false, max_slide=Some(iktc::retarget::MAX_SLIDE), posture_fit=false, max_leg_extension=iktc::retarget::MAX_LEG_EXTENSION))]
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
    feet: &str,
    balance: bool,
    reach: bool,
    max_slide: Option<f64>,
    posture_fit: bool,
    max_leg_extension: f64,
) -> PyResult<PyKeypointTrajectory> {
    let profile = robot.required_profile("keypoint retargeting", "feet, pelvis and hands")?;
    let hands = limb_scaling("hands", hands)?;
    let feet = limb_scaling("feet", feet)?;
    let mut settings = KeypointSettings {
        dt,
        standing,
        smoothing,
        hands,
        feet,
        balance,
        reach,
        max_slide,
        posture_fit,
        max_leg_extension,
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
        Ok(PyKeypointTrajectory {
            dt,
            robot: robot.robot.clone(),
            bodies: body_frames(profile, &cfg),
            run,
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
        array(py, &self.run.times)
    }

    /// Configurations q at the start of each tick, shape (N, nq): base position [m],
    /// quaternion (x, y, z, w), joints [rad].
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        table(
            py,
            [self.run.times.len(), self.robot.nq()],
            self.run.trajectory.concat(),
        )
    }

    /// Velocities v at the start of each tick, shape (N, nv): base twist [m/s], [rad/s] (base
    /// axes), joint rates [rad/s].
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        table(
            py,
            [self.run.times.len(), self.robot.nv()],
            self.run.velocities.concat(),
        )
    }

    /// The accelerations q̈ solved at each tick, shape (N, nv) [m/s²], [rad/s²].
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        table(
            py,
            [self.run.times.len(), self.robot.nv()],
            self.run.accelerations.concat(),
        )
    }

    /// Ticks solved by GF because IKTC's answer left the box.
    #[getter]
    fn fallback_ticks(&self) -> usize {
        self.run.fallback_ticks
    }

    /// Which tasks the joint limits cost: per level of the keypoint stack (in priority order),
    /// the ticks of the clip on which IKTC sacrificed it (the highest-priority level it
    /// corrected to keep every limit; `iktc::retarget::Sacrifices`).
    #[getter]
    fn sacrificed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        levels_dict(py, &self.run.sacrificed)
    }

    /// The same over the settling on the clip's first frame, before the clip starts.
    #[getter]
    fn settle_sacrificed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        levels_dict(py, &self.run.settle_sacrificed)
    }

    /// The run's quality figures (`iktc::retarget::RetargetQuality`), as `iktc imitate` writes
    /// them in `keypoints_summary.json`: `mean_cm`, `points` (per body point `{"point",
    /// "mean_cm", "max_cm"}`), `orientations` (`{"frame", "mean_deg", "max_deg"}`), `slip_mm`,
    /// `below_ground_mm`, `float_mm` (highest a foot the clip has on the ground floats) and `float_share` (share of those foot-ticks above 1 cm), `stance_ticks`, `jerk_rms` and `jerk_max` [rad/s³], `jerk_limit_share` (the share of the squared jerk on the ticks the solver corrected into the joint limits' box and the ticks after them), the worst
    /// `position_margin` [rad], `velocity_margin` [rad/s] and `acceleration_margin` [rad/s²]
    /// (positive: a limit exceeded), `on_limit` (`(joint, share)` pairs: the joints on a
    /// position limit on some ticks and the share of the ticks, the most often first), and `posture_fit_deg` (the RMS angle between the person's segments and the fitted posture's, `None` without the fit), `reach_cm`, `balanced_reach_cm` (the reach keeping
    /// the clip's feet and the COM over them) and `reach_run_cm` (None unless asked for
    /// with `reach=True`), and `fidelity`: the neutral figures (`iktc::retarget::Fidelity`:
    /// the robot's joint centres against the captured person, contacts from the person,
    /// posture, smoothness, `healthy` and the `failures` in words).
    #[getter]
    fn quality<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let q = &self.run.quality;
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
        d.set_item("posture_fit_deg", q.posture_fit_deg)?;
        let fidelity = serde_json::to_string(&q.fidelity)
            .map_err(|e| crate::IktcError::new_err(format!("fidelity figures: {e}")))?;
        d.set_item(
            "fidelity",
            py.import("json")?.call_method1("loads", (fidelity,))?,
        )?;
        Ok(d)
    }

    /// Names of the body frames whose world positions the saved files carry (`body_names` of
    /// the NPZ): the profile's pelvis, torso, head and hands that are set, then the feet.
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.bodies.clone()
    }

    /// Writes the run as `iktc retarget` writes a clip's `motion.npz`: `fps`, `joint_names`,
    /// `body_names`, `time` [s], `joint_pos` [rad], `joint_vel` [rad/s], `base_pos` [m],
    /// `base_quat_xyzw`, `base_lin_vel` [m/s] and `base_ang_vel` [rad/s] in the base's axes, and
    /// `body_pos_w` (frames × bodies × 3) [m]. `rate` [Hz]: the output rate (default: the
    /// control rate, every tick copied exactly); other rates interpolate the ticks linearly
    /// (the base orientation by slerp) and compute the body positions from the interpolated
    /// configuration (`iktc::batch::TrainingTrajectory`). Raises IktcError for a rate that is
    /// not finite and > 0, or a file that cannot be written.
    #[pyo3(signature = (path, rate=None))]
    fn save_npz(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        rate: Option<f64>,
    ) -> PyResult<()> {
        self.save(py, &path, rate, TrainingTrajectory::npz)
    }

    /// Writes the run as `iktc retarget` writes a clip's `motion.csv`: columns `t`, `base_x
    /// base_y base_z` [m], `base_qx base_qy base_qz base_qw`, then one column per joint [rad];
    /// `rate` as in `save_npz`.
    #[pyo3(signature = (path, rate=None))]
    fn save_csv(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        rate: Option<f64>,
    ) -> PyResult<()> {
        self.save(py, &path, rate, |t| Ok(t.csv().into_bytes()))
    }

    /// Writes the run as `iktc retarget --format gmr` writes `motion_gmr.pkl`: GMR's motion
    /// pickle (`pickle.load` gives a dict; see `iktc::batch::formats`): `fps` (int when whole)
    /// [Hz], `root_pos` (frames × 3) [m], `root_rot` (frames × 4, quaternion x, y, z, w),
    /// `dof_pos` (frames × joints) [rad], `local_body_pos` (frames × bodies × 3, float32, the
    /// bodies' origins in the root frame) [m] and `link_body_list` (the robot's links with a
    /// moving joint, root first: MuJoCo's bodies). Loads with NumPy 1.x and 2.x. `rate` as in
    /// `save_npz`.
    #[pyo3(signature = (path, rate=None))]
    fn save_gmr(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        rate: Option<f64>,
    ) -> PyResult<()> {
        self.save_format(py, &path, rate, MotionFormat::Gmr)
    }

    /// Writes the run as `iktc retarget --format lafan-csv` writes `motion_lafan.csv`: the
    /// LAFAN1 retargeting dataset's CSV, one row per frame, no header: base x, y, z [m],
    /// quaternion x, y, z, w, then the joints [rad] in the robot's order (what BeyondMimic's
    /// and mjlab's `csv_to_npz.py` read; give them the rate). `rate` as in `save_npz`.
    #[pyo3(signature = (path, rate=None))]
    fn save_lafan_csv(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        rate: Option<f64>,
    ) -> PyResult<()> {
        self.save_format(py, &path, rate, MotionFormat::LafanCsv)
    }

    /// Writes the run as `iktc retarget --format mjlab` writes `motion_mjlab.npz`: the motion
    /// NPZ mjlab / BeyondMimic's tracking task loads: `fps` (1,) [Hz], `joint_pos`,
    /// `joint_vel` (frames × joints) [rad], [rad/s], and over the robot's bodies (`body_names`,
    /// root first) in the world frame `body_pos_w` [m], `body_quat_w` (quaternion w, x, y, z),
    /// `body_lin_vel_w` [m/s] and `body_ang_vel_w` [rad/s] (frame Jacobians times the rates);
    /// also `joint_names`. `rate` as in `save_npz`.
    #[pyo3(signature = (path, rate=None))]
    fn save_mjlab(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        rate: Option<f64>,
    ) -> PyResult<()> {
        self.save_format(py, &path, rate, MotionFormat::Mjlab)
    }

    fn __len__(&self) -> usize {
        self.run.times.len()
    }
}

impl PyKeypointTrajectory {
    /// Writes the run resampled at `rate` ([`Self::training`]) to `path` as `encode` makes it,
    /// outside the GIL; an I/O error is raised as IktcError naming the file.
    fn save(
        &self,
        py: Python<'_>,
        path: &std::path::Path,
        rate: Option<f64>,
        encode: impl Fn(&TrainingTrajectory) -> iktc::Result<Vec<u8>> + Send + Sync,
    ) -> PyResult<()> {
        let bytes = py.detach(|| encode(&self.training(rate)?)).map_err(to_py)?;
        std::fs::write(path, bytes)
            .map_err(|e| crate::IktcError::new_err(format!("cannot write {}: {e}", path.display())))
    }

    /// Writes the run resampled at `rate` as `format`'s file.
    fn save_format(
        &self,
        py: Python<'_>,
        path: &std::path::Path,
        rate: Option<f64>,
        format: MotionFormat,
    ) -> PyResult<()> {
        let robot = Arc::clone(&self.robot);
        self.save(py, path, rate, move |t| format.encode(&robot, t))
    }

    /// The run resampled at `rate` [Hz] (default the control rate).
    fn training(&self, rate: Option<f64>) -> iktc::Result<TrainingTrajectory> {
        let rate = rate.unwrap_or(1.0 / self.dt);
        TrainingTrajectory::from_keypoint_run(&self.robot, &self.run, self.dt, &self.bodies, rate)
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
