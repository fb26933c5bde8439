//! Keypoint retargeting: a captured motion's body points ([`Keypoints`]) scaled to a robot and
//! tracked by a strict-priority stack on a [`Controller`](crate::Controller), under the
//! robot's joint limits, with quality figures.
//!
//! 1. The robot's counterparts of the body points are found from its profile and its tree
//!    ([`RobotBody`]).
//! 2. The clip is aligned (facing +x, first pelvis over the origin, lowest ankle on the
//!    ground) and scaled segment by segment ([`Scaling`], module `scale`).
//! 3. Foot contacts are detected from the clip's foot heights and speeds; every task's
//!    references are computed at the control rate, the stance feet held, the swings leaving
//!    and reaching the holds at rest, and the COM pulled over the support polygon (module
//!    `plan`).
//! 4. The stack of [`KEYPOINT_LEVELS`] is tracked ([`KeypointController`]): after a settling
//!    phase at rest on the first frame's references, one tick per control period; IKTC under
//!    the quiet box of the robot's own limits, nothing clipped after the solve. Only the feet
//!    that have landed are in the first level, held where the robot's foot landed; a foot
//!    lands low, slow and flat, brought down in the second level, where a swing foot near the
//!    ground also meets its floor (module `floor`: its soles kept above the ground). One
//!    stack per pair of foot modes is built once.
//! 5. The same quality figures ([`RetargetQuality`]) measure this run and, for comparison, the
//!    joint-angle route ([`joint_route_quality`]).
//!
//! ```no_run
//! use iktc::motion::{load_motion, MotionOptions};
//! use iktc::profile::RobotProfile;
//! use iktc::retarget::{retarget_keypoints, KeypointSettings};
//!
//! let motion = load_motion("walk.bvh".as_ref(), &MotionOptions::default())?;
//! let kp = motion.keypoints(iktc::motion::DEFAULT_MAX_GAP)?;
//! let run = retarget_keypoints(&RobotProfile::builtin("g1")?, &kp, None, &KeypointSettings::default())?;
//! println!("mean keypoint error {:.1} cm", run.quality.mean_cm);
//! # Ok::<(), iktc::Error>(())
//! ```

mod body;
pub mod centres;
mod com;
mod contacts;
mod drift;
#[cfg(all(feature = "json", feature = "npz"))]
pub mod evaluate;
pub mod fidelity;
pub mod fit;
mod floor;
mod plan;
mod quality;
pub mod reach;
mod scale;
mod tracker;
mod viewer;

pub use body::{BodyFrameNames, RobotBody};
pub use centres::RobotJointCentres;
pub use contacts::PIVOT_TURN;
#[cfg(all(feature = "json", feature = "npz"))]
pub use evaluate::{
    evaluate_trajectory, read_trajectory_csv, read_trajectory_npz, RobotTrajectory,
    TrajectoryEvaluation,
};
pub use fidelity::{Fidelity, FidelityLimits};
pub use quality::{
    JointOnLimit, OrientationError, PointError, QualityRecorder, RetargetQuality, FLOAT_HEIGHT,
    LIMIT_BAND,
};
pub use scale::Scaling;
pub use tracker::{KeypointController, Sacrifices, KEYPOINT_LEVELS};
pub use viewer::keypoint_viewer;

use std::sync::Arc;
use std::time::Instant;

use nalgebra::DVector;

use crate::error::{Error, Result};
use crate::limits::BoundMethod;
use crate::model::{Kinematics, Robot, State};
use crate::motion::{Keypoints, RobotReferences};
use crate::profile::RobotProfile;
use crate::resources::RunLimits;
use crate::sim::imitate::SupportSettings;
use crate::sim::{percentile, ImitateConfig, ImitationController};
use crate::solver::{Damping, Method, SolveReport, SolverSettings};
use crate::task::Gains;

/// Damping λ_max reached at a singularity by default \[unit of a singular value of J\]: the
/// keypoint stack uses every dof of the robot, its levels come close to singular (stretched
/// legs and arms), and undamped inverses there ask for accelerations of 10⁶ rad/s² that IKTC
/// must then correct away. Larger values track less exactly near singularities.
pub(crate) const DEFAULT_DAMPING: f64 = 0.05;

/// Size of the singular region of the default damping \[unit of a singular value of J\].
pub(crate) const DEFAULT_DAMPING_REGION: f64 = 0.1;

/// Which support polygon the COM reference is kept over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SupportArea {
    /// The soles of the feet on the ground (the static support polygon: in single support
    /// the one sole, which asks a walking robot to lean over its stance foot).
    Stance,
    /// The hull of both feet's soles at their references whenever a foot is on the ground
    /// (the stride's polygon: the COM may pass between the feet as the captured person's does).
    BothFeet,
}

/// Where the references of the hands ([`KeypointSettings::hands`]) or of the feet
/// ([`KeypointSettings::feet`]) are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimbScaling {
    /// From the middle of the hips' reference by the leg ratio, `p' = p'_m + s_leg (a(p) −
    /// a(m))` (`m` the middle of the hips, `p` the wrist or the ankle): the hands and feet are
    /// where the captured person's are relative to the pelvis, scaled as a whole, so hands
    /// that meet (a clap, hands on the hips) still meet on the robot and the feet keep the
    /// person's stance width. The quality figures' neutral targets are placed the same way.
    Leg,
    /// Along the limb from the shoulder (hip), each segment at the robot's own length: the
    /// limb keeps the captured limb's direction, and the hand (foot) lands wherever the
    /// robot's proportions put it (a robot with wider hips than the scaled person stands and
    /// walks with its feet as much wider apart).
    Segments,
}

/// Settings of a keypoint retargeting.
#[derive(Debug, Clone, PartialEq)]
pub struct KeypointSettings {
    /// Control period Δt \[s\].
    pub dt: f64,
    /// Range of Δt and largest tick count.
    pub run_limits: RunLimits,
    /// CLIK gains of every task (default k_p = 100 s⁻², k_v = 20 s⁻¹).
    pub gains: Gains,
    /// Solver (IKTC by default).
    pub method: Method,
    /// Joint bounds (default [`BoundMethod::quiet`], as in the rest of the crate): the quiet
    /// bounds reverse the joints' change of q̈ on fewer ticks than the viable ones
    /// ([`BoundMethod::Viable`]). On the development set (`devset/`, ten clips of six rigs)
    /// the default's share of such ticks is 0.203 on G1 and 0.178 on JVRC-1;
    /// `book/src/retarget-defaults.md` has the viable bounds' figures.
    pub bounds: BoundMethod,
    /// Solver settings (default: adaptive damping, 0.05 within
    /// 0.1 of a singularity).
    pub solver: SolverSettings,
    /// Longest time at rest on the first frame's references before the clip starts \[s\]
    /// (default 1.5 s, about 15 time constants of the default gains): the robot moves from its
    /// standing posture to the first frame. Not recorded. Shorter settling leaves a transient
    /// at the start of the clip.
    pub settle_time: f64,
    /// The settling ends before `settle_time` once the robot is at rest on the first frame:
    /// every velocity coordinate below this \[rad/s or m/s\] and every acceleration below this
    /// times the gains' `k_v` \[rad/s² or m/s²\] (with the default gains, |q̇| < 0.01 rad/s and
    /// |q̈| < 0.2 rad/s²: the tasks' errors are a few milliradians from their rest and decay
    /// within a time constant). Default 0.01; 0 settles for the whole `settle_time`. Larger
    /// values end the settling sooner and leave more of its transient in the clip. On 57
    /// clips (the shared ones and 51 Bandai Namco ones) on G1 the default ends the settling
    /// after a median of 0.89 s; a clip whose first frame keeps moving the robot (a swing
    /// foot at the floor's threshold) settles for the whole `settle_time`.
    pub settle_speed: f64,
    /// A foot (ankle or toe) within this height of the clip's lowest ankle (toe) height is low
    /// enough to be on the ground \[m\] (human scale, default 0.05 m). Larger values hold the
    /// feet longer (more stance, less swing fidelity); smaller ones miss contacts.
    pub contact_height: f64,
    /// ... and slow enough below this speed \[m/s\] (default 0.4 m/s).
    pub contact_speed: f64,
    /// Contact and flight phases shorter than this are removed \[s\] (default 0.2 s): a
    /// shorter flight would have its foot travel between two holds in less time than the
    /// feet level can follow. Longer values hold quick steps on the ground.
    pub min_phase: f64,
    /// The polygon the COM reference is kept over (default [`SupportArea::BothFeet`]).
    pub support_area: SupportArea,
    /// The COM reference keeps at least this distance inside the support polygon \[m\]
    /// (default 0.02 m). Larger values keep the COM more central, further from the pelvis'.
    pub com_margin: f64,
    /// Width of the COM reference's moving average \[s\] (applied twice; default 0.2 s).
    /// Wider is smoother but lags the support changes.
    pub com_smoothing: f64,
    /// A leg is not asked to stretch beyond this fraction of its length (hip–knee plus
    /// knee–ankle) \[–\], nor a foot on the ground beyond the reach the person's knee angle
    /// gives the robot's leg: the pelvis is lowered instead (default [`MAX_LEG_EXTENSION`]).
    pub max_leg_extension: f64,
    /// Posture references from the joint route are kept this far inside the joint ranges
    /// \[rad\] (default 0.05 rad).
    pub posture_margin: f64,
    /// A foot the clip puts on the ground lands (is held by the first level) once its lowest
    /// sole corner is within this height of the ground \[m\] (default 0.02 m) ...
    pub land_height: f64,
    /// ... every corner of its sole slower than this \[m/s\] (default 0.06 m/s; the corners,
    /// not the ankle: a foot pivoting about a slow ankle turns its sole, and the held foot's
    /// yaw then overshoots about the ankle), and its sole tilted less than 0.03 rad. A
    /// held foot decelerates under the first level's gains: a foot
    /// landing at speed `v` slides about `v / (e ω)` (`ω` = 20 rad/s, the held feet's
    /// gains), about 1.1 mm at the default; a larger value lands faster feet, which slide more,
    /// a smaller one lands them later and holds the feet for less of the clip's stance, at a
    /// larger keypoint error (`book/src/retarget-defaults.md` has 0.03 m/s measured).
    /// Until it lands the foot is brought down in the second level, above the ground
    /// (once the floor bounds its lowest corner's downward acceleration to less than 2 m/s²).
    pub land_speed: f64,
    /// Standing imitation (default false): the feet and the pelvis are held at the robot's
    /// start pose for the whole clip, the COM over the middle of the soles, and only the clip's
    /// upper body is imitated, relative to its pelvis (the torso's orientation, the elbows and
    /// the hands). For a robot that must keep its stance while it moves like the captured
    /// person from the waist up; the clip's steps, crouches and pelvis sway are left out.
    pub standing: bool,
    /// Keep the COM over the support polygon of the feet on the ground, horizontally, in a
    /// level of its own (`com_xy`) above the swing feet and the pelvis (default false;
    /// standing imitation always does, [`KeypointSettings::standing`]). A static balance the
    /// captured person does not keep: walking, their COM passes between the feet instead of
    /// over the stance foot. With it the torso's orientation leaves the pelvis' level for the
    /// elbows' (above a pelvis and a torso that follow the person's the level could move the
    /// COM only with the arms, which it swings to their limits: G1's wrists 24 cm off the
    /// person's), and the waist moves the COM, leaning the trunk off the person's. Off, the
    /// robot's COM goes where the person's body puts it; a physical robot tracking the result
    /// balances by its own controller. On the development set (`devset/run.sh OUT g1`, ten
    /// clips of six rigs) the default gives G1 a mean keypoint error of 9.14 cm and a trunk
    /// lean 3.6° from the person's; `book/src/retarget-defaults.md` has the figures with it on.
    pub balance: bool,
    /// Cut-off \[Hz\] of the zero-phase low-pass ([`crate::motion::lowpass`]) applied to the
    /// scaled body points before they are interpolated and differentiated into the tasks'
    /// references (default `None`: as captured; a cut-off at or above the clip's Nyquist
    /// frequency leaves them as captured too). Noise at the capture's frame rate otherwise
    /// reaches the references' accelerations; a lower cut-off removes more of it (lower joint
    /// jerk) and more of the clip's quick motion, and can put the soles below the ground
    /// (`book/src/retarget-defaults.md` has the jerk at 6 and 8 Hz and the soles' depth at
    /// 6 Hz). The quality figures still compare the robot with the captured points.
    pub smoothing: Option<f64>,
    /// Weight of the posture rows in the `hands` level \[–\] (default
    /// 0.1; 0 puts them in a level of their own, `posture`, below all tracking):
    /// a joint's acceleration 1 rad/s² off its posture reference costs as much there as a
    /// hand's `weight` m/s² off its reference. The levels above the posture level can take
    /// every coordinate (on G1 all 35), and each is then solved exactly in what the levels
    /// above leave it, however ill-conditioned, with no damping of a joint's velocity but the
    /// tasks' own: without these rows G1's arms never come to rest on a held frame (9–26 rad/s
    /// after 3 s) and its joints' accelerations ride the box. With them the hands' level is a
    /// least-squares compromise with the posture's `q̈_d + k_v (q̇_d − q̇) + k_p (q_d − q)`,
    /// which holds and damps the motion of an arm that leaves its hand in place (and the
    /// level takes every coordinate, so the `elbows_head` level below it moves nothing).
    pub posture_weight: f64,
    /// Weight of the elbows' and head's positions and the swing feet's orientations in the
    /// `hands` level \[–\] (default 0;
    /// 0 puts them in a level of their own, `elbows_head`, where below the
    /// posture rows they have no coordinate left to move). A unit of their error costs
    /// `weight²` as much as a hand's.
    pub body_weight: f64,
    /// Share of the person's trunk lean given to the pelvis' reference \[–\] (default
    /// 0): its frame's vertical axis is `(1 − a) ẑ + a t̂` made orthogonal to
    /// the hip axis, `t̂` the direction from the hips' middle to the shoulders'. 0 keeps the
    /// pelvis upright and leaves the lean to the waist's joints alone.
    pub pelvis_lean: f64,
    /// Track the robot's joint centres ([`centres`]: frames `centre:<point>` added at the
    /// hips, knees, shoulders, elbows and wrists) instead of the links and frames
    /// [`RobotBody::find`] names (the hip-pitch links, the hands' frames; default false).
    /// The neutral figures are measured at the centres either way
    /// (`book/src/retarget-defaults.md` has what tracking the centres measured).
    pub track_joint_centres: bool,
    /// Where no joint-angle reference is given, the posture level follows the person's
    /// posture fitted to the directions of their segments ([`fit`]: per tick, the joint angles
    /// whose arms, shoulder axis and trunk point where the person's do, the base held at the
    /// pelvis' reference) instead of holding the start posture (default false). What the
    /// levels above leave free then takes the person's shape: the waist's lean and twist, the
    /// arms' swivel. The legs keep the start posture's references: the feet and the pelvis
    /// set a stance leg, and posture rows pulling its knee toward the person's straighter one
    /// bring it to its singularity (G1 then does not come to rest on a held frame). Off by
    /// default: on the development set (ten clips of six rigs, the neutral figures of
    /// [`fidelity`]) the fit lowers the mean keypoint error, but G1's feet slip further over
    /// the person's contacts and its soles go deeper (`book/src/retarget-defaults.md` has the
    /// figures).
    pub posture_fit: bool,
    /// Where the feet's references are placed (default [`LimbScaling::Leg`]): the person's
    /// ankles relative to the middle of their hips, scaled by the leg ratio; the toes keep
    /// their offset from the ankle along the robot's foot. On the development set
    /// (`devset/run.sh OUT g1`, ten clips of six rigs, the neutral figures of [`fidelity`],
    /// with [`KeypointSettings::balance`] off) the default gives G1 a mean keypoint error of
    /// 9.13 cm and a slip over the person's contacts of 23 mm (mean over clips; worst clip
    /// 90 mm); `book/src/retarget-defaults.md` has [`LimbScaling::Segments`]' figures.
    pub feet: LimbScaling,
    /// Where the hands' references are placed (default [`LimbScaling::Leg`]). On the shared
    /// clips (`tests/retarget_keypoints.rs`) the default brings G1's wrists within a mean
    /// 2.7–4.8 cm of the captured ones on three DeepMimic clips;
    /// `book/src/retarget-defaults.md` has [`LimbScaling::Segments`]' figures.
    pub hands: LimbScaling,
    /// Measure the static reach of the body points after the run (default off): per tick
    /// sampled every 0.05 s, the least mean body point error of a posture within the
    /// joint ranges alone, in [`RetargetQuality::reach_cm`] ([`mod@reach`]). It separates what the
    /// robot's body cannot do from what the retargeting gives up for its feet, balance and
    /// smoothness. Costs about as much again as the run (G1, `131_01`: 0.11 s for 1 656
    /// ticks).
    pub reach: bool,
    /// Smallest turn of a foot over one of the clip's stances for the foot to pivot there
    /// \[rad\] (default `Some(`[`PIVOT_TURN`]`)`): the foot's yaw then follows
    /// the captured one about its sole's centre instead of being held at the stance's mean.
    /// `None` holds every stance's yaw (both feet planted, as `hold_feet` in Python asks).
    pub pivot_turn: Option<f64>,
    /// A stance over which the captured ankle slides further than this from where the stance
    /// (or its last part) began, horizontally, at human scale \[m\], is split into steps: the
    /// robot lifts the foot for `min_phase` and sets it down again where the captured foot
    /// has slid (default `Some(`[`MAX_SLIDE`]`)`): a held foot cannot follow a slide. `None`
    /// holds every stance whatever the captured foot does (as `hold_feet` in Python asks).
    pub max_slide: Option<f64>,
}

/// Default [`KeypointSettings::max_slide`] \[m\]: 0.05 m, a few centimetres, well below a
/// step's length. A larger value holds more of the captured feet's slides in place (the held
/// foot lags the captured one); a smaller one splits more stances into steps, and the feet
/// are held for fewer ticks. On CMU 131_01 the default gives G1 a mean keypoint error of
/// 8.82 cm and JVRC-1 11.16 cm (`iktc retarget <clips> --robot R --jobs 2 --no-viewer --out
/// DIR`); `book/src/retarget-defaults.md` has every stance held measured.
pub const MAX_SLIDE: f64 = 0.05;

/// Default [`KeypointSettings::body_weight`] \[–\]: 0, the elbows, head, torso and swing
/// feet's orientations in a level of their own. A larger weight follows the elbows and the
/// head more closely in the hands' level, at the price of arms that do not come to rest on a
/// held frame and, larger still, of the feet's hold (`book/src/retarget-defaults.md` has 0.2
/// and 0.5 measured).
pub(crate) const BODY_WEIGHT: f64 = 0.0;

/// Default [`KeypointSettings::pelvis_lean`] \[–\]: 0, the pelvis upright. A larger share
/// follows the person's trunk lean more closely, with the pelvis as well as the waist, but
/// puts the soles deeper and the knees further from the person's
/// (`book/src/retarget-defaults.md` has a share of 1 measured).
pub(crate) const PELVIS_LEAN: f64 = 0.0;

/// Default [`KeypointSettings::max_leg_extension`] \[–\]: 0.95, a knee bent at least 36°
/// (equal thigh and shank, `2 acos 0.95`) under a foot right below its hip. Straighter legs
/// follow the person's knees closer but land the feet worse. On the development set
/// (`devset/run.sh OUT ROBOT --max-leg-extension E`, ten clips of six rigs, the neutral
/// figures of [`fidelity`]) the default gives G1 a knee flexion 14.2° from the person's (mean
/// over clips of the medians' gap), a mean keypoint error of 9.01 cm and a slip over the
/// person's contacts of 27 mm (mean over clips); `book/src/retarget-defaults.md` has 0.92 to
/// 0.97 measured, and other robots.
pub const MAX_LEG_EXTENSION: f64 = 0.95;

/// Sample period of the static reach ([`KeypointSettings::reach`]) \[s\].
pub(crate) const REACH_PERIOD: f64 = 0.05;

/// Default [`KeypointSettings::posture_weight`] \[–\]: 0.1 rad/s² of a joint against 1 m/s² of
/// a hand. A larger weight holds the joints closer to their posture references and follows
/// the hands less closely (a larger median keypoint error); a smaller one follows the hands more
/// closely but lets the soles dip below the ground. On 51 Bandai Namco clips (`iktc
/// retarget`, the joint route's posture references) the default gives G1 a fastest joint of
/// 0.0002 rad/s at the end of the settling and an RMS jerk of 1 080 rad/s³ (medians over
/// clips), a mean keypoint error of 6.87 cm on the median clip and 9.9 cm on the worst. In
/// MuJoCo's standing imitation (`mujoco_g1.py standing --plan upper-body`) the plan's ZMP
/// leaves the soles by up to 18 mm on 3 of 508 ticks; G1 stays up, the measured ZMP at
/// least 44 mm inside. `book/src/retarget-defaults.md` has the other weights measured.
pub(crate) const POSTURE_WEIGHT: f64 = 0.1;

impl Default for KeypointSettings {
    fn default() -> Self {
        Self {
            dt: 0.005,
            run_limits: RunLimits::default(),
            gains: Gains {
                kp: 100.0,
                kv: 20.0,
            },
            method: Method::Iktc,
            bounds: BoundMethod::quiet(),
            solver: SolverSettings {
                damping: Damping::Adaptive {
                    max: DEFAULT_DAMPING,
                    threshold: DEFAULT_DAMPING_REGION,
                },
                ..SolverSettings::default()
            },
            settle_time: 1.5,
            settle_speed: SETTLE_SPEED,
            contact_height: 0.05,
            contact_speed: 0.4,
            min_phase: 0.2,
            support_area: SupportArea::BothFeet,
            com_margin: 0.02,
            com_smoothing: 0.2,
            max_leg_extension: MAX_LEG_EXTENSION,
            posture_margin: 0.05,
            land_height: 0.02,
            land_speed: 0.06,
            standing: false,
            smoothing: None,
            posture_weight: POSTURE_WEIGHT,
            body_weight: BODY_WEIGHT,
            pelvis_lean: PELVIS_LEAN,
            track_joint_centres: false,
            posture_fit: false,
            hands: LimbScaling::Leg,
            feet: LimbScaling::Leg,
            balance: false,
            reach: false,
            pivot_turn: Some(PIVOT_TURN),
            max_slide: Some(MAX_SLIDE),
        }
    }
}

impl KeypointSettings {
    /// The longest control period \[s\] the keypoint route runs at: below
    /// [`Gains::max_stable_dt`] of the held feet's gains (ω = 20 rad/s: 0.0414 s) and of
    /// [`KeypointSettings::gains`] (0.083 s at the default ω = 10 rad/s). Beyond it a held
    /// foot's error grows tick by tick: on CMU 131_01 JVRC-1 stops at 0.05 s (its QP
    /// overflows at t = 1.6 s) and G1 at 0.1 s (q̈ not finite while settling). Inside it the
    /// runs end but lose quality as the period grows: G1 on 131_01, the highest a foot the
    /// clip has on the ground floats, 0.11 m at the default 0.005 s, 0.55 m at 0.01 s,
    /// 0.27 m at 0.02 s, 1.4 m at 0.04 s; the mean keypoint error 8.8, 10.1, 10.4, 12.3 cm.
    pub fn max_dt(&self) -> f64 {
        self.gains
            .max_stable_dt()
            .min(tracker::STANCE_GAINS.max_stable_dt())
    }

    /// Checks the numbers. The control period must also be one at which every level's gains
    /// track stably ([`KeypointSettings::max_dt`]).
    pub fn validate(&self) -> Result<()> {
        self.run_limits.check_dt("dt", self.dt)?;
        self.gains.validate()?;
        let most = self.max_dt();
        if self.dt >= most {
            return Err(Error::InvalidSetting {
                name: "dt (CLI --dt)".into(),
                value: crate::resources::fmt_value(self.dt),
                expected: format!(
                    "a control period below {:.4} s, at which the held feet's gains (ω = 20 rad/s) \
                     and the tasks' (k_p = {}, k_v = {}) track stably \
                     (KeypointSettings::max_dt, Gains::max_stable_dt)",
                    most,
                    self.gains.kp,
                    self.gains.kv
                ),
            });
        }
        for (name, v, what) in [
            ("settle_time", self.settle_time, "a time >= 0 [s]"),
            (
                "settle_speed",
                self.settle_speed,
                "a speed >= 0 [rad/s or m/s]",
            ),
            ("contact_height", self.contact_height, "a height >= 0 [m]"),
            ("contact_speed", self.contact_speed, "a speed >= 0 [m/s]"),
            ("min_phase", self.min_phase, "a time >= 0 [s]"),
            ("com_margin", self.com_margin, "a distance >= 0 [m]"),
            ("com_smoothing", self.com_smoothing, "a time >= 0 [s]"),
            ("posture_margin", self.posture_margin, "an angle >= 0 [rad]"),
            ("land_height", self.land_height, "a height >= 0 [m]"),
            ("land_speed", self.land_speed, "a speed >= 0 [m/s]"),
            ("posture_weight", self.posture_weight, "a weight >= 0 [–]"),
            ("body_weight", self.body_weight, "a weight >= 0 [–]"),
            ("pelvis_lean", self.pelvis_lean, "a share >= 0 [–]"),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidSetting {
                    name: name.into(),
                    value: v.to_string(),
                    expected: format!("a finite {what}"),
                });
            }
        }
        let e = self.max_leg_extension;
        if !(e > 0.0 && e <= 1.0) {
            return Err(Error::InvalidSetting {
                name: "max_leg_extension".into(),
                value: e.to_string(),
                expected: "a share of the leg's length in (0, 1] [–]".into(),
            });
        }
        if let Some(t) = self.pivot_turn {
            if !(t.is_finite() && t >= 0.0) {
                return Err(Error::InvalidSetting {
                    name: "pivot_turn".into(),
                    value: t.to_string(),
                    expected: "a finite angle >= 0 [rad], or none".into(),
                });
            }
        }
        if let Some(d) = self.max_slide {
            if !(d.is_finite() && d > 0.0) {
                return Err(Error::InvalidSetting {
                    name: "max_slide".into(),
                    value: d.to_string(),
                    expected: "a finite length > 0 [m], or none".into(),
                });
            }
        }
        crate::motion::check_smoothing(self.smoothing)?;
        self.gains.validate()?;
        self.bounds.validate()?;
        self.solver.validate()
    }
}

/// A keypoint retargeting run.
#[derive(Debug, Clone)]
pub struct KeypointRun {
    /// How the clip was aligned and scaled.
    pub scaling: Scaling,
    /// Time of every recorded tick from the clip's start \[s\].
    pub times: Vec<f64>,
    /// The robot's configuration q at every recorded tick (base position \[m\] and quaternion,
    /// then joints \[rad\]).
    pub trajectory: Vec<Vec<f64>>,
    /// The robot's velocity at every recorded tick (base twist in the base's axes \[m/s,
    /// rad/s\], then joint rates \[rad/s\]).
    pub velocities: Vec<Vec<f64>>,
    /// The acceleration q̈ applied over every recorded tick, from its configuration and
    /// velocity to the next's (base \[m/s², rad/s²\] in the base's axes, then joints
    /// \[rad/s²\]).
    pub accelerations: Vec<Vec<f64>>,
    /// The clip's contacts per tick, left and right foot.
    pub contacts: [Vec<bool>; 2],
    /// The robot's stance per tick, left and right foot: the foot landed and held by the first
    /// level (it lands after the clip's touch-down, once low and slow).
    pub stance: [Vec<bool>; 2],
    /// Quality figures.
    pub quality: RetargetQuality,
    /// Ticks solved by GF because IKTC's answer left the box ([`KeypointController::tick`]),
    /// over the settling and the clip.
    pub fallback_ticks: usize,
    /// Ticks solved by GF because IKTC corrected the feet's levels while a foot was held (the
    /// stance feet's level, or the floor's below it) and GF kept them more exactly
    /// ([`KeypointController::tick`]), over the settling and the clip.
    pub stance_gf_ticks: usize,
    /// Median time of one control tick (references, kinematics, box, solve, integration) \[µs\].
    pub tick_median_us: f64,
    /// Why tasks were sacrificed: per level of the keypoint stack, the recorded ticks on which
    /// IKTC's answer was corrected from it ([`KeypointController::sacrificed`]).
    pub sacrificed: Sacrifices,
    /// The same over the settling on the first frame, before the clip starts.
    pub settle_sacrificed: Sacrifices,
    /// Ticks of the settling on the first frame, before the clip starts (at most
    /// `settle_time / dt`; fewer where the robot came to rest, see
    /// [`KeypointSettings::settle_speed`]).
    pub settle_ticks: usize,
}

/// Fewest frames of a clip the keypoint route retargets \[frames\]: two, one interval to
/// follow (as `iktc retarget` asks of every clip).
pub(crate) const MIN_FRAMES: usize = 2;

/// Default [`KeypointSettings::settle_speed`] \[rad/s or m/s\].
pub(crate) const SETTLE_SPEED: f64 = 0.01;

/// Runs the settling of `controller` on the first frame's references: `settle_time / dt`
/// ticks, or fewer once every velocity coordinate is below `settle_speed` and every
/// acceleration below `settle_speed · k_v` ([`KeypointSettings::settle_speed`]). Returns the
/// ticks run.
fn settle(controller: &mut KeypointController, s: &KeypointSettings) -> Result<usize> {
    let most = (s.settle_time / s.dt).round() as usize;
    for k in 0..most {
        let at = || {
            format!(
                "tick {k} (t = {} s)",
                crate::resources::fmt_value(k as f64 * s.dt)
            )
        };
        controller.tick(0, true).map_err(|e| e.at(at))?;
        controller.integrate().map_err(|e| e.at(at))?;
        if at_rest(&controller.state().qd, controller.qdd(), s) {
            return Ok(k + 1);
        }
    }
    Ok(most)
}

/// Whether a state moving with `qd` under `qdd` is at rest by `s.settle_speed`: every
/// velocity coordinate below it \[rad/s or m/s\] and every acceleration below it times the
/// gains' `k_v` \[rad/s² or m/s²\] (a slow state whose errors still pull it, at the turn of an
/// oscillation, is not at rest).
fn at_rest(qd: &DVector<f64>, qdd: &DVector<f64>, s: &KeypointSettings) -> bool {
    qd.amax() < s.settle_speed && qdd.amax() < s.settle_speed * s.gains.kv
}

/// Everything a keypoint run needs, built once.
struct Setup {
    robot: Arc<Robot>,
    body: RobotBody,
    centres: RobotJointCentres,
    support: SupportSettings,
    controller: KeypointController,
    scaling: Scaling,
    /// The posture fit's RMS direction error \[rad\] ([`fit`]), where the posture was fitted.
    fit_error: Option<f64>,
}

/// Refuses a start state outside the robot's joint ranges (the profile's `posture` against
/// the URDF's limits) with [`Error::StateOutsideLimits`] naming the joint, its value and its
/// range, unless `bounds` asks for [`OutsideLimits::Recover`](crate::limits::OutsideLimits)
/// (CLI `--recover`): the viable box then brings the joint back into its range.
fn check_start(robot: &Robot, state: &State, bounds: &BoundMethod) -> Result<()> {
    if bounds.outside_limits() == crate::limits::OutsideLimits::Recover {
        return Ok(());
    }
    let limits = crate::limits::JointLimits::from_robot(robot)?;
    let mut pos = vec![0.0; robot.nv()];
    state.dof_positions(robot, &mut pos)?;
    limits.check_state(&pos, state.qd.as_slice())
}

fn frame_names(profile: &RobotProfile, cfg: &ImitateConfig) -> Result<BodyFrameNames> {
    let f = &profile.frames;
    let missing = |key: &str| Error::Profile {
        key: key.into(),
        value: crate::profile::MISSING.into(),
        message: "keypoint retargeting tracks the hands: set the hand frames".into(),
    };
    Ok(BodyFrameNames {
        pelvis: cfg.pelvis.clone(),
        torso: f.torso.clone(),
        head: f.head.clone(),
        // The imitation lists the feet right, left.
        feet: [cfg.feet[1].clone(), cfg.feet[0].clone()],
        hands: [
            f.left_hand
                .clone()
                .ok_or_else(|| missing("frames.left_hand"))?,
            f.right_hand
                .clone()
                .ok_or_else(|| missing("frames.right_hand"))?,
        ],
    })
}

/// Every active joint of `robot` has a finite acceleration limit (the box of the keypoint
/// route bounds every joint; a joint with neither a velocity nor an acceleration limit, as in
/// an MJCF file, lets the solver's answer grow without bound near a singularity). Errors: the
/// first joint without one, and the profile keys that give one.
fn check_acceleration_limits(robot: &Robot) -> Result<()> {
    match robot
        .active_joints()
        .find(|j| !j.limit.acceleration.is_finite())
    {
        None => Ok(()),
        Some(j) => Err(Error::InvalidSetting {
            name: format!("acceleration limit of joint `{}`", j.name),
            value: "none (the robot's file gives it no velocity limit either)".into(),
            expected: "a finite limit for every joint the keypoint route moves: set `velocity.default` [rad/s] (or `velocity.limits`) or `acceleration.limits` [rad/s²] in the robot's profile (`iktc profile init` writes a guessed `velocity.default` for such files)".into(),
        }),
    }
}

/// The robot, body, scaled clip, plan and keypoint controller of a run of `kp` (see the
/// module documentation), its posture fitted unless given.
fn setup(
    robot: Arc<Robot>,
    profile: &RobotProfile,
    kp: &Keypoints,
    posture: Option<&RobotReferences>,
    s: &KeypointSettings,
) -> Result<Setup> {
    s.validate()?;
    if kp.frame_count() < MIN_FRAMES {
        return Err(Error::InsufficientData {
            what: format!("keypoint retargeting of `{}`", kp.source),
            message: format!(
                "it has {} frame(s); at least {MIN_FRAMES} are needed (an interval to follow)",
                kp.frame_count()
            ),
        });
    }
    check_acceleration_limits(&robot)?;
    let cfg = profile.imitate_config(ImitateConfig::default())?;
    let (body, centres, _) = measured_body(&robot, profile)?;
    let mut kin = Kinematics::new(&robot, &State::neutral(&robot))?;
    let (robot, body) = if s.track_joint_centres {
        centres.frames(&robot, body)?
    } else {
        (robot, body)
    };
    let state = profile.standing_state(&robot)?;
    check_start(&robot, &state, &s.bounds)?;
    kin.update(&robot, &state)?;
    let clip = scale::scale_clip(
        &robot,
        &kin,
        &body,
        kp,
        cfg.support.ankle_height,
        s.hands,
        s.feet,
    )?;
    let mut tracks = posture_tracks(&robot, &state, posture, s.posture_margin)?;
    let plan_with = |tracks: &tracker::PostureTracks| {
        let on = plan::PlanRobot {
            robot: &robot,
            start: &state,
            kin: &kin,
            body: &body,
            support: &cfg.support,
            posture: tracks,
        };
        plan::plan(&on, kp, &clip, s)
    };
    let mut plan = plan_with(&tracks)?;
    let mut fit_error = None;
    if posture.is_none() && s.posture_fit && !s.standing {
        // The person's posture, fitted at the joint centres; the plan again with it (the COM
        // offset depends on the posture asked).
        let start = (&robot, &body, &centres, &kin, &state);
        fit_error = Some(fit_posture(start, &plan, s, &mut tracks)?);
        plan = plan_with(&tracks)?;
    }
    let controller =
        KeypointController::new(robot.clone(), state, &body, plan, tracks, &cfg.support, s)?;
    Ok(Setup {
        robot,
        body,
        centres,
        support: cfg.support,
        controller,
        scaling: clip.scaling,
        fit_error,
    })
}

/// The person's posture fitted at the joint centres of the robot (its body, centres, start
/// kinematics and state) to `plan`'s neutral targets, taken into `tracks` for every joint
/// outside the legs; the fit's RMS direction error \[rad\].
fn fit_posture(
    (robot, body, centres, kin, state): (
        &Arc<Robot>,
        &RobotBody,
        &RobotJointCentres,
        &Kinematics,
        &State,
    ),
    plan: &plan::Plan,
    s: &KeypointSettings,
    tracks: &mut tracker::PostureTracks,
) -> Result<f64> {
    let (fit_robot, fit_body) = centres.frames(robot, body.clone())?;
    // The base held at the pelvis' references, which the pelvis level holds.
    let to_base =
        kin.frame_pose(robot, body.pelvis)?.rotation.inverse() * state.base_pose(robot).rotation;
    let base: Vec<_> = plan.pelvis.iter().map(|p| p.rotation * to_base).collect();
    let fitted = fit::fit(
        &fit_robot,
        &fit_body,
        state,
        &plan.neutral,
        Some(&base),
        s.dt,
        s.posture_margin,
    )?;
    // The legs keep the start posture's references: the feet and the pelvis above the
    // posture set a stance leg, and its rows pulling a knee toward the person's
    // straighter one bring it to its singularity (G1 then does not come to rest on a held
    // frame of `humanoid3d_punch`: 0.47 rad/s).
    let fit_error = 2.0 * (0.5 * fitted.rms_error).min(1.0).asin();
    let legs = [
        body::chain(robot, body.feet[0])?,
        body::chain(robot, body.feet[1])?,
    ];
    let below = body::branch(&legs);
    let leg_links: Vec<usize> = legs.iter().flat_map(|c| c[below..].to_vec()).collect();
    for ((name, fitted), track) in fitted
        .tracks
        .0
        .iter()
        .zip(&fitted.tracks.1)
        .zip(&mut tracks.1)
    {
        let in_leg = robot
            .joints()
            .iter()
            .any(|j| j.name == *name && leg_links.contains(&j.child));
        if !in_leg {
            track.clone_from(fitted);
        }
    }
    Ok(fit_error)
}

/// Posture references of every active joint: the joint route's where given (kept
/// `margin` inside the range), else the start posture.
fn posture_tracks(
    robot: &Robot,
    state: &State,
    refs: Option<&RobotReferences>,
    margin: f64,
) -> Result<tracker::PostureTracks> {
    let mut names = Vec::new();
    let mut tracks = Vec::new();
    for j in robot.active_joints() {
        let given = refs.and_then(|r| {
            r.joint_names
                .iter()
                .position(|n| *n == j.name)
                .and_then(|i| r.joints.get(i))
        });
        let (lo, hi) = (j.limit.lower + margin, j.limit.upper - margin);
        let track = match given {
            Some(t) if lo <= hi => {
                let mut p = t.position.clone();
                let mut v = t.velocity.clone();
                let mut a = t.acceleration.clone();
                for k in 0..p.len() {
                    if p[k] < lo || p[k] > hi {
                        p[k] = p[k].clamp(lo, hi);
                        v[k] = 0.0;
                        a[k] = 0.0;
                    }
                }
                [p, v, a]
            }
            // No reference: the start posture regularises.
            _ => [
                vec![state.joint(robot, &j.name)?; 1],
                vec![0.0; 1],
                vec![0.0; 1],
            ],
        };
        names.push(j.name.clone());
        tracks.push(track);
    }
    Ok((names, tracks))
}

/// A built-in DeepMimic clip ([`crate::motion::BUILTIN_CLIP_NAMES`]) as a loaded motion, its
/// body map recognised and its units and up axis decided as for a file (its keypoints by
/// [`Motion::keypoints`](crate::motion::Motion::keypoints)). Errors: an unknown name.
#[cfg(feature = "json")]
pub fn builtin_motion(name: &str) -> Result<crate::motion::Motion> {
    use crate::motion::{builtin_clip, motion_from_content, MotionContent, MotionFormat};
    motion_from_content(
        name.to_string(),
        MotionFormat::DeepMimic,
        MotionContent::Skeleton(builtin_clip(name)?),
        &crate::motion::MotionOptions::default(),
    )
}

/// The keypoint controller of a clip on a profile's robot, set up and ready for its first
/// (settling) tick: for benches and tests of the tick; [`retarget_keypoints`] runs it.
pub fn keypoint_controller(
    profile: &RobotProfile,
    kp: &Keypoints,
    posture: Option<&RobotReferences>,
    s: &KeypointSettings,
) -> Result<KeypointController> {
    Ok(setup(Arc::new(profile.robot()?), profile, kp, posture, s)?.controller)
}

/// Retargets `kp` onto the robot of `profile` (see the module documentation); `posture`, the
/// joint route's references at `s.dt` (e.g. [`crate::sim::imitation_references`]), is the
/// posture level's reference where given, else the start posture is.
///
/// Errors: bad settings, a profile without feet, pelvis or hands, keypoints without the
/// pelvis, hips, knees, ankles or shoulders, a clip longer than `s.run_limits` allows. An
/// infeasible tick is not an error (the solver's fallback is taken and reported).
pub fn retarget_keypoints(
    profile: &RobotProfile,
    kp: &Keypoints,
    posture: Option<&RobotReferences>,
    s: &KeypointSettings,
) -> Result<KeypointRun> {
    retarget_keypoints_on(Arc::new(profile.robot()?), profile, kp, posture, s)
}

/// [`retarget_keypoints`] on `robot`, the robot of `profile` already built
/// ([`RobotProfile::robot`]): a batch builds it once for every clip instead of reading the
/// URDF again per clip. A robot that is not the profile's gives the errors of a profile whose
/// frames or joints it lacks, or a retargeting of that other robot.
pub fn retarget_keypoints_on(
    robot: Arc<Robot>,
    profile: &RobotProfile,
    kp: &Keypoints,
    posture: Option<&RobotReferences>,
    s: &KeypointSettings,
) -> Result<KeypointRun> {
    let Setup {
        robot,
        body,
        centres,
        support,
        mut controller,
        scaling,
        fit_error,
    } = setup(robot, profile, kp, posture, s)?;
    let settle_ticks = settle(&mut controller, s).map_err(|e| {
        e.at(|| {
            format!(
                "keypoint retargeting of `{}`, settling on the first frame",
                kp.source
            )
        })
    })?;
    let RunTicks {
        rec,
        trajectory,
        velocities,
        accelerations,
        times,
        tick_us,
        stance,
    } = run_ticks(&mut controller, &robot, &body, &support, kp, s)?;
    let contacts = controller.plan().contact.clone();
    let mut quality = rec.finish(&robot);
    quality.fidelity = Some(measure_fidelity(
        &robot,
        (&body, &centres),
        &support,
        kp,
        (&times, &trajectory, &joint_qdd(&robot, &accelerations)),
        s.dt,
    )?);
    quality.posture_fit_deg = fit_error.map(f64::to_degrees);
    if s.reach {
        let stride = ((REACH_PERIOD / s.dt).round() as usize).max(1);
        let balance = (&support, s.com_margin);
        let r = reach::static_reach(
            &robot,
            &body,
            controller.plan(),
            &trajectory,
            stride,
            balance,
        )?;
        quality.reach_cm = Some(100.0 * r.reach_mean());
        quality.balanced_reach_cm = Some(100.0 * r.balanced_mean());
        quality.reach_run_cm = Some(100.0 * r.run_mean());
    }
    Ok(KeypointRun {
        scaling,
        times,
        trajectory,
        velocities,
        accelerations,
        contacts,
        stance,
        quality,
        fallback_ticks: controller.fallback_ticks(),
        stance_gf_ticks: controller.stance_gf_ticks(),
        tick_median_us: percentile(&tick_us, 0.5),
        sacrificed: controller.sacrificed().clone(),
        settle_sacrificed: controller.settle_sacrificed().clone(),
        settle_ticks,
    })
}

/// What a run records at its ticks.
struct RunTicks {
    rec: QualityRecorder,
    /// Configuration per tick.
    trajectory: Vec<Vec<f64>>,
    /// Velocity per tick.
    velocities: Vec<Vec<f64>>,
    /// q̈ per tick.
    accelerations: Vec<Vec<f64>>,
    /// Clip time per tick \[s\].
    times: Vec<f64>,
    /// The tick's solve and integration per tick \[µs\].
    tick_us: Vec<f64>,
    /// Feet held per tick (left, right).
    stance: [Vec<bool>; 2],
}

/// Ticks the settled `controller` through the clip, recording the quality figures and the
/// trajectory; errors name the tick.
fn run_ticks(
    controller: &mut KeypointController,
    robot: &Robot,
    body: &RobotBody,
    support: &SupportSettings,
    kp: &Keypoints,
    s: &KeypointSettings,
) -> Result<RunTicks> {
    let ticks = controller.ticks();
    let mut rec = QualityRecorder::new("keypoints", body, s.dt);
    let mut trajectory = Vec::with_capacity(ticks);
    let mut velocities = Vec::with_capacity(ticks);
    let mut accelerations = Vec::with_capacity(ticks);
    let mut times = Vec::with_capacity(ticks);
    let mut tick_us = Vec::with_capacity(ticks);
    let mut stance = [Vec::with_capacity(ticks), Vec::with_capacity(ticks)];
    let t0 = kp.times.first().copied().unwrap_or(0.0);
    for k in 0..ticks {
        let at = || {
            format!(
                "keypoint retargeting of `{}`, tick {k} (t = {} s)",
                kp.source,
                crate::resources::fmt_value(t0 + k as f64 * s.dt)
            )
        };
        let state = controller.state().clone();
        let start = Instant::now();
        let report = controller.tick(k, false).map_err(|e| e.at(at))?;
        let corrected = shaped_by_box(report) || controller.used_fallback();
        tick_us.push(start.elapsed().as_secs_f64() * 1e6);
        let plan = controller.plan();
        let on = controller.stance();
        stance[0].push(on[0]);
        stance[1].push(on[1]);
        // The tick's controller prepared its kinematics at `state`.
        rec.record(
            robot,
            controller.controller().kinematics(),
            body,
            plan,
            support,
            (k, on, corrected),
            &state,
            controller.qdd().as_slice(),
        )
        .map_err(|e| e.at(at))?;
        accelerations.push(controller.qdd().as_slice().to_vec());
        let start = Instant::now();
        controller.integrate().map_err(|e| e.at(at))?;
        if let Some(last) = tick_us.last_mut() {
            *last += start.elapsed().as_secs_f64() * 1e6;
        }
        trajectory.push(state.q.as_slice().to_vec());
        velocities.push(state.qd.as_slice().to_vec());
        times.push(t0 + k as f64 * s.dt);
    }
    Ok(RunTicks {
        rec,
        trajectory,
        velocities,
        accelerations,
        times,
        tick_us,
        stance,
    })
}

/// The neutral fidelity figures ([`fidelity`]) of a run on `robot`: per tick its clip time,
/// configuration and the joints' q̈ (active joints only).
fn measure_fidelity(
    robot: &Robot,
    (body, centres): (&RobotBody, &RobotJointCentres),
    support: &SupportSettings,
    kp: &Keypoints,
    (times, trajectory, qdd): (&[f64], &[Vec<f64>], &[Vec<f64>]),
    dt: f64,
) -> Result<Fidelity> {
    let samples = fidelity::robot_samples(robot, centres, body.feet, support, trajectory)?;
    Ok(fidelity::fidelity(
        &fidelity::FidelityInput {
            person: kp,
            times,
            robot: &samples,
            robot_leg: fidelity::robot_leg(robot, centres)?,
            qdd,
            dt,
        },
        &FidelityLimits::default(),
    ))
}

/// The joints' part of every applied q̈ (base and joints) of a run on `robot`.
fn joint_qdd(robot: &Robot, accelerations: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let b = robot.base_nv();
    accelerations
        .iter()
        .map(|a| a.get(b..).unwrap_or_default().to_vec())
        .collect()
}

/// What the fidelity figures measure on the robot of `profile` (`robot` built from it): its
/// body frames, joint centres and soles, as a retargeting run finds them.
fn measured_body(
    robot: &Robot,
    profile: &RobotProfile,
) -> Result<(RobotBody, RobotJointCentres, SupportSettings)> {
    let cfg = profile.imitate_config(ImitateConfig::default())?;
    let names = frame_names(profile, &cfg)?;
    let kin = Kinematics::new(robot, &State::neutral(robot))?;
    let body = RobotBody::find(robot, &kin, &names)?;
    let centres = RobotJointCentres::find(robot, &body)?;
    Ok((body, centres, cfg.support))
}

/// Whether the solve of `r` corrected the prioritized solution into the box: IKTC corrected a
/// level, or a fallback answered ([`RetargetQuality::jerk_limit_share`]).
fn shaped_by_box(r: &SolveReport) -> bool {
    r.corrected_from.is_some() || r.fallback.is_some()
}

/// The quality figures of the joint-angle route on the same clip: the imitation of Table 1
/// ([`ImitationController`]) with the profile's feet, pelvis and posture, the robot's own
/// joint ranges (no narrowed ones), IKTC with `s.method` and `s.bounds`, on the references
/// `refs` (the clip retargeted by decomposition and resampled at `s.dt`), measured against the
/// keypoints `kp` exactly as [`retarget_keypoints`] is.
pub fn joint_route_quality(
    profile: &RobotProfile,
    kp: &Keypoints,
    refs: &RobotReferences,
    s: &KeypointSettings,
) -> Result<RetargetQuality> {
    let setup = setup(Arc::new(profile.robot()?), profile, kp, None, s)?;
    let cfg = ImitateConfig {
        method: s.method,
        bounds: s.bounds,
        dt: s.dt,
        run_limits: s.run_limits,
        gains: s.gains,
        solver: s.solver,
        narrow: Vec::new(),
        ..profile.imitate_config(ImitateConfig::default())?
    };
    let robot = &setup.robot;
    let mut ctl = ImitationController::new(robot, refs, &cfg)?;
    let plan = setup.controller.plan();
    let mut rec = QualityRecorder::new("joints", &setup.body, s.dt);
    let mut kin = Kinematics::new(robot, ctl.state())?;
    let t0 = kp.times.first().copied().unwrap_or(0.0);
    let (mut times, mut trajectory, mut accelerations) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..plan.ticks.min(refs.len()) {
        let state = ctl.state().clone();
        let corrected = shaped_by_box(ctl.tick(k)?);
        times.push(t0 + k as f64 * s.dt);
        trajectory.push(state.q.as_slice().to_vec());
        accelerations.push(ctl.qdd().as_slice().to_vec());
        kin.update(robot, &state)?;
        rec.record(
            robot,
            &kin,
            &setup.body,
            plan,
            &setup.support,
            (k, [plan.contact[0][k], plan.contact[1][k]], corrected),
            &state,
            ctl.qdd().as_slice(),
        )?;
        ctl.integrate()?;
    }
    let mut quality = rec.finish(robot);
    quality.fidelity = Some(measure_fidelity(
        robot,
        (&setup.body, &setup.centres),
        &setup.support,
        kp,
        (&times, &trajectory, &joint_qdd(robot, &accelerations)),
        s.dt,
    )?);
    Ok(quality)
}

#[cfg(test)]
mod rest_tests {
    use super::*;

    /// A vector of the rates or accelerations `x`.
    fn vector(x: &[f64]) -> DVector<f64> {
        DVector::from_row_slice(x)
    }

    /// At rest needs both: slow, and not pulled (the acceleration bound is `settle_speed ·
    /// k_v`, 0.2 rad/s² with the defaults); a settle speed of 0 is never met.
    #[test]
    fn at_rest_needs_slow_rates_and_small_accelerations() {
        let s = KeypointSettings::default();
        let (v, a) = (s.settle_speed, s.settle_speed * s.gains.kv);
        assert_eq!(a, 0.01 * 20.0);
        assert!(at_rest(
            &vector(&[0.0, 0.5 * v]),
            &vector(&[0.0, -0.5 * a]),
            &s
        ));
        assert!(
            !at_rest(&vector(&[0.0, -1.5 * v]), &vector(&[0.0, 0.0]), &s),
            "too fast"
        );
        assert!(
            !at_rest(&vector(&[0.0, 0.0]), &vector(&[0.0, 1.5 * a]), &s),
            "pulled"
        );
        assert!(
            !at_rest(&vector(&[v, 0.0]), &vector(&[0.0, 0.0]), &s),
            "the rate bound is strict"
        );
        assert!(
            !at_rest(&vector(&[0.0]), &vector(&[a]), &s),
            "the acceleration bound is strict"
        );
        let never = KeypointSettings {
            settle_speed: 0.0,
            ..s
        };
        assert!(!at_rest(&vector(&[0.0]), &vector(&[0.0]), &never));
    }
}
