//! The ZMP damping controller of Section 4 ("balance", not "damping": the damped least squares
//! of the IK has a damping too).
//!
//! A stiff, position-controlled humanoid rings on the compliance of its feet. Each plane of
//! each support phase is modelled as an inverted pendulum with a compliant joint (IPCJ,
//! [`IpcjParams`], eqs. 26–28 corrected by the errata), extended by a sensor lag and a Padé
//! delay term to the identification model of eq. (31) ([`FullModelParams`]). The parts:
//!
//! * [`model`]: state space, transfer function, poles, zeros, DC gain, frequency response;
//! * [`zmp`]: the ZMP from the foot force/torque sensors (eqs. 29–30);
//! * [`identify`](mod@identify): fit of eq. (31) to frequency-response data (Section 4.2);
//! * [`design`]: pole placement (eqs. 32–33), its discretisation and the observer;
//! * [`controller`] and [`cases`]: the per-tick controller of one plane, and of both planes
//!   in both support phases with a smooth hand-over; output `Δc = l (u − u_ref)`;
//! * [`sim`], [`sweep`], [`response`], [`scenario`]: a simulated robot with a true delay,
//!   noise and pushes, the sine-sweep experiment, response metrics and the three scenarios
//!   (identify, design, push);
//! * [`prony`]: the dominant mode of a measured response (a physics simulation's or a
//!   robot's push), its damping ratio and natural frequency.
//!
//! Sign conventions: `θ` and `u` are positive toward `+x̃` (`+ỹ`); `y` is the ZMP deviation
//! from nominal \[m\]; the feedback is `u = N u_ref − K_f x`.

pub mod cases;
pub mod controller;
pub mod design;
pub mod identify;
pub mod lm;
pub mod model;
pub mod poly;
pub mod prony;
pub mod response;
pub mod scenario;
pub mod sim;
pub mod sweep;
pub mod zmp;

pub use cases::{
    BalanceController, BalanceOutput, BalanceSettings, CaseParams, Plane, SupportPhase,
};
pub use controller::{BalanceCommand, DampingController};
pub use design::{
    design_discrete, place_poles, ContinuousDesign, DiscreteDesign, DiscreteSettings, PoleSpec,
};
pub use identify::{identify, initial_guess, FrequencyData, Identification, IdentifySettings};
pub use lm::{levenberg_marquardt, LmResult, LmSettings, LmStatus};
pub use model::{Bode, FullModelParams, IpcjParams, Modal, TransferFunction, STANDARD_GRAVITY};
pub use poly::Polynomial;
pub use prony::{dominant_mode, PronySettings};
pub use response::{analyse_response, ResponseMetrics, ResponseSettings};
pub use scenario::{
    run_design, run_identify, run_push, BodeSeries, DesignResult, DesignScenario, IdentifyResult,
    IdentifyScenario, ParameterComparison, PlanePushMetrics, PushResult, PushScenario, PushSupport,
    RootLocus,
};
pub use sim::{NoiseSource, PlantParams, SimPlant, SimSettings};
pub use sweep::{sine_sweep, SweepSettings};
pub use zmp::{measure_zmp, Foot, FootSensor, ZmpMeasurement, ZmpSettings, ZmpStatus};
