//! The ZMP damping controller of Section 4 for Python: ZMP from two foot force/torque sensors
//! (eqs. 29–30), identification of the IPCJ model from frequency-response data (Section 4.2,
//! eq. 31), pole placement (eqs. 32–33) and the per-tick controller of one plane.

use iktc::balance::{
    design_discrete, dominant_mode, identify, measure_zmp, DampingController, DiscreteSettings,
    FootSensor, FrequencyData, FullModelParams, IdentifySettings, IpcjParams, PoleSpec,
    PronySettings, ZmpSettings, ZmpStatus, STANDARD_GRAVITY,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::vector3;
use crate::to_py;

fn sensor(x: &Bound<'_, PyAny>, which: &str) -> PyResult<FootSensor> {
    let (p, f, t): (Bound<'_, PyAny>, Bound<'_, PyAny>, Bound<'_, PyAny>) =
        x.extract().map_err(|_| {
            crate::IktcError::new_err(format!(
                "{which} foot sensor: expected (position, force, torque), three 3-vectors"
            ))
        })?;
    Ok(FootSensor {
        position: vector3(&p, &format!("{which} sensor position [m]"))?,
        force: vector3(&f, &format!("{which} sensor force [N]"))?,
        torque: vector3(&t, &format!("{which} sensor torque [N·m]"))?,
    })
}

/// ZMP from the two foot sensors (eqs. 29–30 with the errata's correction).
///
/// `left` and `right` are (position [m], force [N], torque [N·m]) of each sensor in the local
/// frame (z̃ = 0 at the sole): the force the ground exerts on the foot and the torque about the
/// sensor point. Returns (zmp, status): zmp = (x̃, ỹ) [m] or None without contact; status is
/// "both", "left", "right" or "none".
#[pyfunction]
#[pyo3(name = "measure_zmp", signature = (left, right, min_normal_force=5.0))]
fn py_measure_zmp(
    left: &Bound<'_, PyAny>,
    right: &Bound<'_, PyAny>,
    min_normal_force: f64,
) -> PyResult<(Option<(f64, f64)>, &'static str)> {
    let m = measure_zmp(
        &sensor(left, "left")?,
        &sensor(right, "right")?,
        &ZmpSettings { min_normal_force },
    )
    .map_err(to_py)?;
    let status = match m.status {
        ZmpStatus::BothFeet => "both",
        ZmpStatus::OneFoot(iktc::balance::Foot::Left) => "left",
        ZmpStatus::OneFoot(iktc::balance::Foot::Right) => "right",
        ZmpStatus::NoContact => "none",
    };
    Ok((m.position.map(|p| (p[0], p[1])), status))
}

/// The identified (or given) full model of one plane: IPCJ (l [m], K/m [m²/(s² rad)],
/// b/m [m²/(s rad)]), sensor lag τ_s [s] and Padé parameter T [s] (a delay of 2T).
#[pyclass(name = "PlaneModel", module = "iktc", frozen, get_all)]
#[derive(Clone, Copy)]
pub struct PyPlaneModel {
    /// Pendulum length l [m].
    pub length: f64,
    /// Stiffness per unit mass K/m [m²/(s²·rad)].
    pub stiffness_per_mass: f64,
    /// Damping per unit mass b/m [m²/(s·rad)].
    pub damping_per_mass: f64,
    /// Sensor lag τ_s [s].
    pub lag: f64,
    /// Padé parameter T [s].
    pub pade: f64,
}

impl PyPlaneModel {
    pub(crate) fn params(&self) -> FullModelParams {
        FullModelParams {
            ipcj: IpcjParams {
                length: self.length,
                stiffness_per_mass: self.stiffness_per_mass,
                damping_per_mass: self.damping_per_mass,
                gravity: STANDARD_GRAVITY,
            },
            lag: self.lag,
            pade: self.pade,
        }
    }
}

#[pymethods]
impl PyPlaneModel {
    #[new]
    fn new(
        length: f64,
        stiffness_per_mass: f64,
        damping_per_mass: f64,
        lag: f64,
        pade: f64,
    ) -> PyResult<Self> {
        let m = Self {
            length,
            stiffness_per_mass,
            damping_per_mass,
            lag,
            pade,
        };
        m.params().validate().map_err(to_py)?;
        Ok(m)
    }

    /// The model's frequency response y_ZMP/u at ω [rad/s]: (magnitude [m/rad], phase [rad]).
    fn frequency_response(&self, omega: f64) -> (f64, f64) {
        let h = self.params().frequency_response(omega);
        (h.norm(), h.arg())
    }

    /// Open-loop natural frequency w_n [rad/s] and damping ratio ζ of the IPCJ pole pair.
    fn modal(&self) -> PyResult<(f64, f64)> {
        let m = self.params().ipcj.modal().map_err(to_py)?;
        Ok((m.natural_frequency, m.damping_ratio))
    }

    fn __repr__(&self) -> String {
        format!(
            "PlaneModel(length={:.4}, stiffness_per_mass={:.4}, damping_per_mass={:.5}, lag={:.4}, pade={:.4})",
            self.length, self.stiffness_per_mass, self.damping_per_mass, self.lag, self.pade
        )
    }
}

/// Fits eq. (31) to frequency-response data: ω [rad/s], magnitude of y_ZMP/u [m/rad] and phase
/// [rad]. Returns (model, fit) with fit a dict: rms_relative_error, rms_magnitude_error_db,
/// rms_phase_error_deg, iterations.
#[pyfunction]
#[pyo3(name = "identify")]
fn py_identify<'py>(
    py: Python<'py>,
    omega: Vec<f64>,
    magnitude: Vec<f64>,
    phase: Vec<f64>,
) -> PyResult<(PyPlaneModel, Bound<'py, PyDict>)> {
    let data = FrequencyData::from_bode(&omega, &magnitude, &phase).map_err(to_py)?;
    let id = py
        .detach(|| identify(&data, &IdentifySettings::default()))
        .map_err(to_py)?;
    let p = id.params;
    let model = PyPlaneModel {
        length: p.ipcj.length,
        stiffness_per_mass: p.ipcj.stiffness_per_mass,
        damping_per_mass: p.ipcj.damping_per_mass,
        lag: p.lag,
        pade: p.pade,
    };
    let fit = PyDict::new(py);
    fit.set_item("rms_relative_error", id.rms_relative_error)?;
    fit.set_item("rms_magnitude_error_db", id.rms_magnitude_error_db)?;
    fit.set_item("rms_phase_error_deg", id.rms_phase_error_deg)?;
    fit.set_item("iterations", id.iterations)?;
    Ok((model, fit))
}

/// The dominant oscillatory mode of a response y [m] sampled at the uniformly spaced times t
/// [s] (e.g. the ZMP after a push), by Prony's method (`iktc::balance::dominant_mode`: y
/// low-passed by a moving average of `smoothing` samples applied twice, every
/// `decimation`-th sample kept, a linear prediction of order `order`; of the pairs that turn
/// by half a cycle over the record, the one with the most energy). Returns (damping ratio ζ
/// [–], natural frequency ω_n [rad/s]), both NaN if no pair oscillates.
#[pyfunction]
#[pyo3(name = "dominant_mode", signature = (t, y, *, smoothing=8, decimation=4, order=8))]
fn py_dominant_mode(
    py: Python<'_>,
    t: Vec<f64>,
    y: Vec<f64>,
    smoothing: usize,
    decimation: usize,
    order: usize,
) -> PyResult<(f64, f64)> {
    let settings = PronySettings {
        smoothing,
        decimation,
        order,
    };
    let mode = py
        .detach(|| dominant_mode(&t, &y, &settings))
        .map_err(to_py)?;
    Ok(mode.map_or((f64::NAN, f64::NAN), |m| {
        (m.damping_ratio, m.natural_frequency)
    }))
}

/// The damping controller of one plane (Section 4.3): observer on the full model and state
/// feedback placing the IPCJ poles at damping ratio `damping_ratio` and natural frequency
/// `natural_frequency` [rad/s] (None keeps the open-loop w_n, so only damping is added),
/// discretised at `control_period` [s]; the observer's poles are `observer_pole_scale` [–] times
/// the controller's (faster observers follow a push sooner and act further above the band the
/// model was identified in).
#[pyclass(name = "DampingController", module = "iktc")]
pub struct PyDampingController {
    inner: DampingController,
}

#[pymethods]
impl PyDampingController {
    #[new]
    #[pyo3(signature = (model, damping_ratio=0.72, natural_frequency=None, control_period=0.005, observer_pole_scale=2.0))]
    fn new(
        model: &PyPlaneModel,
        damping_ratio: f64,
        natural_frequency: Option<f64>,
        control_period: f64,
        observer_pole_scale: f64,
    ) -> PyResult<Self> {
        let design = design_discrete(
            &model.params(),
            &PoleSpec {
                damping_ratio,
                natural_frequency,
            },
            &DiscreteSettings {
                control_period,
                observer_pole_scale,
            },
        )
        .map_err(to_py)?;
        Ok(Self {
            inner: DampingController::new(design),
        })
    }

    /// One tick: the reference u_ref [rad] and the measured ZMP deviation y [m]. Returns
    /// (u [rad], com_offset [m]) with com_offset = l (u − u_ref), to add to the COM reference.
    fn step(&mut self, u_ref: f64, y: f64) -> PyResult<(f64, f64)> {
        let c = self.inner.step(u_ref, y).map_err(to_py)?;
        Ok((c.u, c.com_offset))
    }

    /// Forgets the observer state (back at rest).
    fn reset(&mut self) {
        self.inner.reset();
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(py_measure_zmp, m)?)?;
    m.add_function(wrap_pyfunction!(py_identify, m)?)?;
    m.add_function(wrap_pyfunction!(py_dominant_mode, m)?)?;
    m.add_class::<PyPlaneModel>()?;
    m.add_class::<PyDampingController>()?;
    Ok(())
}
