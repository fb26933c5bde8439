//! The closed loop of a keypoint retargeting: [`Controller`]s with the keypoint stack, the
//! references of every tick ([`super::plan`]) and the state, sized once.
//!
//! Levels, in priority order ([`KEYPOINT_LEVELS`]):
//! 1. `stance_feet`: the feet on the ground, 6D each, held where they touched down; and the
//!    height, roll and pitch of every foot near the ground that is not held (landing, or in
//!    the air with its floor engaged): the floor ([`super::floor`]) keeps their soles above
//!    the ground, and no level below can correct it away;
//! 2. `swing_floor`: the feet the clip puts on the ground that have not landed yet, their
//!    horizontal position and yaw towards the plan's hold;
//! 3. `com_xy`: only with [`KeypointSettings::balance`] (or standing imitation), the COM over
//!    the support polygon, horizontal;
//! 4. `swing_feet`: the positions of the feet in the air;
//! 5. `pelvis_torso`: the pelvis pose, 6D, and (without the COM level) the torso's
//!    orientation: the trunk's lean and twist follow the person's, and no level below can
//!    trade them for a hand;
//! 6. `hands`: the wrists' positions; the elbows' and the head's positions and the
//!    orientations of the feet in the air with their rows weighted by
//!    [`KeypointSettings::body_weight`]; and every active joint at its posture reference with
//!    its rows weighted by [`KeypointSettings::posture_weight`] (a regulariser, see below).
//!    The body points are the robot's joint centres ([`super::centres`]), the points the
//!    fidelity figures measure;
//! 7. `elbows_head`: only with a body weight of 0, the elbows, head and swing feet's
//!    orientations (and, with the COM level, the torso's) in a level of their own; with weighted posture rows in the sixth level it
//!    has no coordinate left (rank 0) and moves nothing, and only its errors are reported;
//! 8. `posture`: only with a posture weight of 0, every active joint at its posture reference
//!    in a level of its own (below the weighted rows such a level could only move what they
//!    already move: it would have rank 0).
//!
//! The feet in the air have a level of their own above the pelvis: sharing the hands' level
//! they would be traded against the posture rows and corrected away with the hands whenever
//! the joint limits bind, and land late. The floor rows are in the first level: in the second,
//! below nothing but the held feet, two landing feet whose holds the legs cannot both reach
//! would trade their heights.
//!
//! The torso's orientation is in the pelvis' level, above the hands: in a level below the
//! weighted posture rows it would have rank 0, and the waist would be left to whatever the
//! hands' least-squares compromise asks of it. Above a pelvis and a torso held to the
//! person's, the COM level of [`KeypointSettings::balance`] could only move the COM with the
//! arms (it is off by default, see there); with it the torso's orientation joins the elbows
//! and the head, and the waist moves the COM as before.
//!
//! The levels above the last can take every coordinate (on G1 the feet, pelvis, torso, hands
//! and elbows take all 35): each level is then solved exactly in what its betters leave it,
//! however ill-conditioned that is, and nothing damps a joint's velocity but the tasks' own.
//! Without the regulariser G1's arms do not come to rest on a held frame, and its joints'
//! accelerations ride the box. In the sixth level the posture rows make the level's
//! least-squares problem a compromise between the hands and the posture's `q̈_d + k_v (q̇_d −
//! q̇) + k_p (q_d − q)`, which holds and damps the hands' null space: the motion of an arm
//! that leaves its hand where it is.
//!
//! A foot is in the first level only once it has landed, and in the second only while it
//! lands or its floor is engaged: one stack per pair of foot modes ([`FootMode`]: stance,
//! swing, swing with its floor, landing; 16 stacks) is built once, and each tick is solved by
//! the stack of its modes. The floor engages from the foot's own height and speed; a swing
//! foot rising off the ground does not engage it, and a correction of the level it shares
//! with the hands could then pull it below the ground within the tick (18 mm on a clip of
//! Bandai Namco's dataset). So after each solve the lowest sole corner of a swing foot is
//! predicted at the end of the tick (its second-order expansion, [`super::floor`]); a corner
//! below the ground has the tick solved again with that foot's floor engaged
//! ([`KeypointController::dip_ticks`]). A swing foot that the robot cannot follow (a kick faster than its
//! joint limits allow) then costs the hands' level accuracy, never the stance foot's hold.
//!
//! The hold is closed-loop. A foot the clip puts on the ground is first brought to the plan's
//! hold in the second level (its height under the floor); it lands (moves to the first level)
//! once its lowest sole corner is within `land_height` of the ground, every sole corner
//! slower than `land_speed` ([`KeypointSettings`]) against its reference (a foot the plan
//! pivots lands while it turns with it; a still reference leaves the corners' own speed), and
//! its sole tilted less than [`LAND_TILT`]; while it lands its sole's centre is brought to rest
//! horizontally as the foot turns about it; a foot
//! that does not get there is not held (landing it at speed, or in the air, would make it
//! slide or stamp). At landing the offset `δ = (x, y, ψ)_robot − (x, y, ψ)_plan` of the
//! robot's foot from the plan's hold (horizontal position of the sole's centre \[m\] and yaw
//! \[rad\]) is latched and added to the foot's reference with the weight [`Plan::latch_weight`]
//! (1 in stance, fading to 0 over the next swing): the foot is held where its sole landed, at
//! rest, not pulled to where the plan wanted it, and flattened about its sole's centre. A held
//! foot's reference also carries the compensation of the integration's drift
//! ([`super::drift`]).
//!
//! Each level is linearised as in the controller (`J_i q̈ = ẍ_d + k_v(ẋ_d − ẋ) + k_p(x_d − x)
//! − J̇_i q̇`, eqs. 3, 11) and solved under the quiet box of the robot's own joint limits with
//! IKTC (eqs. 19–25); q̈ is integrated as is, nothing is clipped afterwards.

use std::sync::Arc;

use nalgebra::{DVector, Point3, UnitQuaternion, Vector3};

use super::body::RobotBody;
use super::drift::StanceDrift;
use super::floor::{
    engaged, fastest_corner, floor_acceleration, lowest_after, lowest_corner,
    origin_floor_acceleration, sole_corners,
};
use super::plan::Plan;
use super::KeypointSettings;
use crate::controller::{
    ComHandle, Controller, ControllerBuilder, ControllerSettings, FrameHandle, JointsHandle,
};
use crate::error::Result;
use crate::model::{FrameId, Kinematics, Robot, State};
use crate::motion::BodyPoint;
use crate::sim::imitate::SupportSettings;
use crate::solver::{Method, SolveReport};
use crate::task::{Axes, ComReference, FrameReference, Gains};

/// Joint names and their (position, rate, acceleration) references per tick.
pub(crate) type PostureTracks = (Vec<String>, Vec<[Vec<f64>; 3]>);

/// Names of the levels of the keypoint stack, in priority order.
pub const KEYPOINT_LEVELS: [&str; 8] = [
    "stance_feet",
    "swing_floor",
    "com_xy",
    "swing_feet",
    "pelvis_torso",
    "hands",
    "elbows_head",
    "posture",
];

/// Per level of the keypoint stack ([`KEYPOINT_LEVELS`] order), the ticks on which IKTC
/// sacrificed it: the highest-priority level it corrected to keep every joint limit
/// ([`crate::solver::SolveReport::corrected_from`]). A level sacrificed on most ticks names the
/// task the robot cannot follow within its limits (a foot out of reach, a pelvis pose the legs
/// cannot hold).
#[derive(Debug, Clone, PartialEq)]
pub struct Sacrifices {
    /// Ticks counted.
    pub ticks: usize,
    /// Level name and the ticks on which it was sacrificed, every level of [`KEYPOINT_LEVELS`].
    pub levels: Vec<(String, usize)>,
}

/// As `{"ticks": n, "levels": {"stance_feet": n₀, …}}`, the levels in priority order.
impl serde::Serialize for Sacrifices {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        struct Levels<'a>(&'a [(String, usize)]);
        impl serde::Serialize for Levels<'_> {
            fn serialize<S: serde::Serializer>(
                &self,
                serializer: S,
            ) -> std::result::Result<S::Ok, S::Error> {
                serializer.collect_map(self.0.iter().map(|(l, n)| (l, n)))
            }
        }
        let mut st = serializer.serialize_struct("Sacrifices", 2)?;
        st.serialize_field("ticks", &self.ticks)?;
        st.serialize_field("levels", &Levels(&self.levels))?;
        st.end()
    }
}

impl Default for Sacrifices {
    fn default() -> Self {
        Self::new()
    }
}

impl Sacrifices {
    /// No tick counted yet, every level of [`KEYPOINT_LEVELS`] at 0.
    pub fn new() -> Self {
        Self {
            ticks: 0,
            levels: KEYPOINT_LEVELS.iter().map(|l| (l.to_string(), 0)).collect(),
        }
    }

    /// Counts one tick whose sacrificed level is `KEYPOINT_LEVELS[level]` (`None`: none).
    fn count(&mut self, level: Option<usize>) {
        self.ticks += 1;
        if let Some(entry) = level.and_then(|i| self.levels.get_mut(i)) {
            entry.1 += 1;
        }
    }

    /// The ticks on which `level` was sacrificed (0 for a name not in [`KEYPOINT_LEVELS`]).
    pub fn of(&self, level: &str) -> usize {
        self.levels
            .iter()
            .find(|(l, _)| l == level)
            .map_or(0, |(_, n)| *n)
    }

    /// The levels sacrificed on at least one tick, as `name n` joined by commas, "none" if no
    /// tick was corrected.
    pub fn describe(&self) -> String {
        let parts: Vec<String> = self
            .levels
            .iter()
            .filter(|(_, n)| *n > 0)
            .map(|(l, n)| format!("{l} {n}"))
            .collect();
        if parts.is_empty() {
            "none".into()
        } else {
            parts.join(", ")
        }
    }
}

/// The keypoint stack on a robot, its references and its state (see the module docs).
#[derive(Debug, Clone)]
pub struct KeypointController {
    /// One stack per pair of [`FootMode`]s, indexed by `left + 4 right`.
    stacks: Vec<Stack>,
    /// The stack of the last tick.
    active: usize,
    /// Whether the last tick was solved by the active stack's GF fallback.
    used_fallback: bool,
    /// Ticks solved by GF so far because IKTC's answer left the box.
    fallback_ticks: usize,
    /// Ticks solved by GF so far because it kept the feet's levels better than IKTC.
    stance_gf_ticks: usize,
    /// The levels IKTC sacrificed so far, over the ticks with moving references and over the
    /// held ones (settling).
    sacrificed: Sacrifices,
    settle_sacrificed: Sacrifices,
    plan: Plan,
    state: State,
    dt: f64,
    feet: [FrameId; 2],
    /// The offset latched at each foot's last touch-down: horizontal position \[m\] (z = 0)
    /// and yaw \[rad\].
    latch: [(Vector3<f64>, f64); 2],
    /// Whether each foot has landed (is in the first level).
    stance: [bool; 2],
    /// Whether each foot's floor was in the stack at the last tick (`Floor` or `Landing`): its
    /// drift is measured as a held foot's ([`super::drift`]).
    floored: [bool; 2],
    /// Landing thresholds: height \[m\], speed \[m/s\].
    landing: (f64, f64),
    /// Kinematics of the state, updated while a foot is in the air.
    kin: Kinematics,
    /// The floor of each swing foot at the current tick ([`super::floor`]).
    floor: [Floor; 2],
    /// The sole's corners in the foot frame \[m\].
    corners: [Vector3<f64>; 4],
    /// The sole's centre in the foot frame \[m\]: a landing foot is held where it puts it.
    sole: Vector3<f64>,
    /// The tasks' gains (the floor's approach uses them too).
    gains: Gains,
    /// Ticks with a swing foot's floor engaged so far.
    floor_ticks: usize,
    /// Ticks solved again with a swing foot's floor engaged (it would have dipped).
    dip_ticks: usize,
    robot: Arc<Robot>,
    posture_track: Vec<[Vec<f64>; 3]>,
    posture_ref: [Vec<f64>; 3],
    /// The held feet's compensation of the integration's drift ([`super::drift`]).
    drift: StanceDrift,
    /// Scratch: a foot frame's Jacobian (6 × nv), for the dip check.
    dip_jac: nalgebra::DMatrix<f64>,
}

/// The controllers of one contact state: IKTC, and GF for the ticks where IKTC's answer leaves
/// the box or corrects the stance feet ([`KeypointController::tick`]).
#[derive(Debug, Clone)]
struct Stack {
    ctl: Controller,
    fallback: Controller,
    tasks: Tasks,
    /// Number of feet's levels leading the stack: the stance feet's, then the floor's (feet
    /// landing, swing feet near the ground).
    feet_levels: usize,
}

/// The handles of a stack's tasks.
#[derive(Debug, Clone)]
struct Tasks {
    /// Foot index (left 0, right 1) and handle, stance feet first.
    feet: Vec<(usize, FrameHandle)>,
    /// Foot index and handle of the swing feet whose floor is engaged ([`super::floor`]).
    floor: Vec<(usize, FrameHandle)>,
    /// The COM's task, with [`KeypointSettings::balance`] (or standing imitation).
    com: Option<ComHandle>,
    pelvis: FrameHandle,
    torso: Option<FrameHandle>,
    points: Vec<(FrameHandle, usize)>,
    posture: JointsHandle,
}

/// The roll, pitch and height of a swing foot while its floor is engaged ([`super::floor`]).
const FLOOR_AXES: Axes = Axes([false, false, true, true, true, false]);

/// The rows of a landing foot in the second level: horizontal position and yaw (its height,
/// roll and pitch are [`FLOOR_AXES`] in the first).
const LANDING_AXES: Axes = Axes([true, true, false, false, false, true]);

/// A foot lands only while its sole is tilted less than this from the ground \[rad\] (about
/// 1.7°): the first level holds it flat, about the sole's centre where it landed (flattened
/// about the ankle, its sole's centre would slide by `ankle_height · sin θ`: 3 mm on JVRC-1
/// at this angle).
pub(crate) const LAND_TILT: f64 = 0.03;

/// Gains of the held feet's level (k_p \[1/s²\], k_v \[1/s\]; critically damped, ω = 20 rad/s),
/// stiffer than the other tasks': the held foot's level is solved exactly, yet the foot
/// drifted by up to 6.6 mm over a stance at the default 100 / 20 (G1, dance_a), the
/// integration's error over a tick (constant q̈ over Δt on a whirling floating base) acting
/// as a disturbance that the feedback pulls back in proportion to `1/k_p`. At 900 / 60 a run
/// diverged (G1, punch). The disturbance is now also compensated ([`super::drift`]).
pub(crate) const STANCE_GAINS: Gains = Gains {
    kp: 400.0,
    kv: 40.0,
};

/// What the stack does with a foot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FootMode {
    /// Held where it landed, 6D, in the first level.
    Stance,
    /// In the air, tracked with the hands (position) and the torso (orientation).
    Swing,
    /// In the air near the ground: as `Swing`, and its floor ([`super::floor`]) with its roll
    /// and pitch in the second level.
    Floor,
    /// The clip has it on the ground, it has not landed yet and its floor is engaged: 6D, its
    /// height under the floor, its horizontal motion damped out, in the second level (higher
    /// up it is brought down to the hold as a swing).
    Landing,
}

impl FootMode {
    /// Every mode, in the order of their index.
    const ALL: [FootMode; 4] = [Self::Stance, Self::Swing, Self::Floor, Self::Landing];

    /// The mode's index in [`FootMode::ALL`].
    fn index(self) -> usize {
        self as usize
    }
}

/// The floor's state of one swing foot at the current tick.
#[derive(Debug, Clone, Copy, Default)]
struct Floor {
    /// Height of the foot frame \[m\].
    z: f64,
    /// Its vertical speed \[m/s\].
    z_dot: f64,
    /// The vertical acceleration asked of it, `max(a_ref, a_min)` \[m/s²\].
    acceleration: f64,
    /// While landing, its horizontal position \[m\]: its sole centre's horizontal motion is
    /// damped out where it is rather than carried on to the plan's hold (where the foot lands
    /// is latched anyway), while the foot turns about that centre as its reference does.
    stop: Option<[f64; 2]>,
    /// From the sole's centre to the foot frame's origin, world axes \[m\].
    arm: Vector3<f64>,
}

/// The reference of foot `i` at tick `k` with the latched offset `(d, yaw)` (see the module
/// documentation), `sole` the sole's centre in the foot frame \[m\]. The offset moves the
/// plan's sole centre by `w d` and turns the foot about it by `w ψ`: with the plan's foot at
/// `(p, R)` and `r = R s`, the reference is `R' = R_z(w ψ) R`, `p' = p + r + w d − R' s`, so a
/// held foot whose plan pivots about its sole's centre pivots about the same point. Its
/// velocity and acceleration are those of `p + r` and of `−R' s` (`ω × r`, `α × r + ω × (ω ×
/// r)` of each rotating vector) plus the latch weight's rates times `d` and `ψ`.
fn foot_reference(
    p: &Plan,
    i: usize,
    k: usize,
    hold: bool,
    latch: (Vector3<f64>, f64),
    sole: &Vector3<f64>,
) -> FrameReference {
    let mut r = p.feet[i][k].frame(hold);
    let [w, wd, wdd] = p.latch_weight[i][k];
    let (d, yaw) = latch;
    let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), w * yaw);
    let r_plan = r.pose.rotation * sole;
    r.pose.rotation = turn * r.pose.rotation;
    let r_ref = r.pose.rotation * sole;
    r.pose.translation.vector += r_plan + w * d - r_ref;
    if !hold {
        let (om_p, al_p) = (
            r.velocity.fixed_rows::<3>(3).into_owned(),
            r.acceleration.fixed_rows::<3>(3).into_owned(),
        );
        let om = turn * om_p + wd * yaw * Vector3::z();
        let al = turn * al_p + wdd * yaw * Vector3::z();
        let v = r.velocity.fixed_rows::<3>(0) + om_p.cross(&r_plan) - om.cross(&r_ref) + wd * d;
        let a = r.acceleration.fixed_rows::<3>(0)
            + al_p.cross(&r_plan)
            + om_p.cross(&om_p.cross(&r_plan))
            - al.cross(&r_ref)
            - om.cross(&om.cross(&r_ref))
            + wdd * d;
        r.velocity.fixed_rows_mut::<3>(0).copy_from(&v);
        r.velocity.fixed_rows_mut::<3>(3).copy_from(&om);
        r.acceleration.fixed_rows_mut::<3>(0).copy_from(&a);
        r.acceleration.fixed_rows_mut::<3>(3).copy_from(&al);
    }
    r
}

/// Sets the references of tick `k` on `ctl` (see [`KeypointController::tick`]).
#[allow(clippy::too_many_arguments)]
fn set_references(
    ctl: &mut Controller,
    t: &Tasks,
    p: &Plan,
    latch: &[(Vector3<f64>, f64); 2],
    sole: &Vector3<f64>,
    drift: &StanceDrift,
    floor: &[Floor; 2],
    posture_track: &[[Vec<f64>; 3]],
    posture_ref: &mut [Vec<f64>; 3],
    k: usize,
    hold: bool,
) -> Result<()> {
    for (i, h) in &t.feet {
        let mut r = foot_reference(p, *i, k, hold, latch[*i], sole);
        r.acceleration += drift.compensation(*i);
        ctl.set_frame_reference(*h, r)?;
    }
    for (i, h) in &t.floor {
        let mut r = foot_reference(p, *i, k, hold, latch[*i], sole);
        let f = &floor[*i];
        // z̈ = max(a_ref, a_min) as the reference's feed-forward at the current height and
        // speed (the row's feedback terms vanish).
        r.pose.translation.vector.z = f.z;
        r.velocity[2] = f.z_dot;
        // With the vertical part of the drift's compensation, so that the floor's bound holds
        // over the tick, not only at its start ([`super::drift`]).
        r.acceleration[2] = f.acceleration + drift.compensation(*i)[2];
        if let Some([x, y]) = f.stop {
            // Landing: the sole centre's horizontal motion is damped out where it is (ẍ = −k_v
            // ẋ without a turn), and the origin moves as the foot's turn at the reference's
            // rate about that centre carries it: `ω × a`, `α × a + ω × (ω × a)`.
            let w = r.velocity.fixed_rows::<3>(3).into_owned();
            let al = r.acceleration.fixed_rows::<3>(3).into_owned();
            let v = w.cross(&f.arm);
            let acc = al.cross(&f.arm) + w.cross(&w.cross(&f.arm));
            r.pose.translation.vector.x = x;
            r.pose.translation.vector.y = y;
            for a in 0..2 {
                r.velocity[a] = v[a];
                r.acceleration[a] = acc[a];
            }
        }
        ctl.set_frame_reference(*h, r)?;
    }
    if let Some(com) = t.com {
        let c = p.com[k];
        let c = if hold {
            ComReference::hold(c.position)
        } else {
            c
        };
        ctl.set_com_reference(com, c)?;
    }
    ctl.set_frame_reference(t.pelvis, p.pelvis[k].frame(hold))?;
    if let Some(h) = t.torso {
        ctl.set_frame_reference(h, p.torso[k].frame(hold))?;
    }
    for (h, i) in &t.points {
        ctl.set_frame_reference(*h, p.points[*i].1[k].frame(hold))?;
    }
    for (j, track) in posture_track.iter().enumerate() {
        for d in 0..3 {
            let v = track[d].get(k).or(track[d].last()).copied().unwrap_or(0.0);
            posture_ref[d][j] = if hold && d > 0 { 0.0 } else { v };
        }
    }
    ctl.set_joints_reference(t.posture, &posture_ref[0], &posture_ref[1], &posture_ref[2])
}

/// The name of frame `f` of `robot` (empty for an id it does not have).
fn frame_name(robot: &Robot, f: FrameId) -> String {
    robot
        .frames()
        .get(f.0)
        .map(|f| f.name.clone())
        .unwrap_or_default()
}

/// Adds the elbows' and head's positions, the orientation of `torso_frame` (unless `torso` is
/// set already) and the swing feet's orientations to the builder's current level, their rows
/// weighted by `w`.
#[allow(clippy::too_many_arguments)]
fn add_body_tasks(
    b: &mut ControllerBuilder,
    robot: &Robot,
    body: &RobotBody,
    plan: &Plan,
    points: &mut Vec<(FrameHandle, usize)>,
    torso: &mut Option<FrameHandle>,
    torso_frame: Option<FrameId>,
    feet: &mut Vec<(usize, FrameHandle)>,
    swing: [bool; 2],
    w: f64,
) -> Result<()> {
    let name = |f: FrameId| frame_name(robot, f);
    for (i, (p, _)) in plan
        .points
        .iter()
        .enumerate()
        .filter(|(_, (p, _))| !hand(p))
    {
        if let Some(f) = body.frame_of(*p) {
            points.push((b.weighted_frame(&name(f), Axes::POSITION, w)?, i));
        }
    }
    if let (Some(f), None) = (torso_frame, &*torso) {
        *torso = Some(b.weighted_frame(&name(f), Axes::ORIENTATION, w)?);
    }
    for i in (0..2).filter(|i| swing[*i]) {
        feet.push((
            i,
            b.weighted_frame(&name(body.feet[i]), Axes::ORIENTATION, w)?,
        ));
    }
    Ok(())
}

/// The stack of the contact state `stance` (left, right on the ground).
fn build_stack(
    robot: &Arc<Robot>,
    state: &State,
    body: &RobotBody,
    plan: &Plan,
    posture: &[String],
    s: &KeypointSettings,
    modes: [FootMode; 2],
) -> Result<Stack> {
    let swing = modes.map(|m| matches!(m, FootMode::Swing | FootMode::Floor));
    let mut b = ControllerBuilder::new(robot.clone(), state)?;
    b.gains(s.gains).settings(ControllerSettings {
        method: s.method,
        bounds: s.bounds,
        solver: s.solver,
    });
    let name = |f: FrameId| frame_name(robot, f);
    let (mut feet, floor) = add_feet_levels(&mut b, robot, body, s, modes)?;
    let com = if s.balance || s.standing {
        Some(b.level(KEYPOINT_LEVELS[2]).com([true, true, false])?)
    } else {
        None
    };
    if swing.contains(&true) {
        b.level(KEYPOINT_LEVELS[3]);
        for i in (0..2).filter(|i| swing[*i]) {
            feet.push((i, b.frame(&name(body.feet[i]), Axes::POSITION)?));
        }
    }
    let pelvis = b
        .level(KEYPOINT_LEVELS[4])
        .frame(&name(body.pelvis), Axes::ALL)?;
    // The torso's orientation beside the pelvis, unless the COM level above would then have
    // only the arms to move the COM with: with it, among the elbows and the head.
    let balanced = com.is_some();
    let torso = match body.torso {
        Some(f) if !balanced => Some(b.frame(&name(f), Axes::ORIENTATION)?),
        _ => None,
    };
    let torso_with_elbows = body.torso.filter(|_| balanced);
    let mut points = Vec::new();
    b.level(KEYPOINT_LEVELS[5]);
    for (i, (p, _)) in plan.points.iter().enumerate().filter(|(_, (p, _))| hand(p)) {
        if let Some(f) = body.frame_of(*p) {
            points.push((b.frame(&name(f), Axes::POSITION)?, i));
        }
    }
    let mut lower = LowerTasks {
        points,
        torso,
        torso_with_elbows,
        feet,
        swing,
    };
    let posture = add_lower_levels(&mut b, robot, body, plan, posture, s, &mut lower)?;
    let LowerTasks {
        points,
        torso,
        feet,
        ..
    } = lower;
    finish_stack(
        b,
        s,
        Tasks {
            feet,
            floor,
            com,
            pelvis,
            torso,
            points,
            posture,
        },
    )
}

/// Foot index (left 0, right 1) and handle of the feet's tasks.
type FootTasks = Vec<(usize, FrameHandle)>;

/// Whether `p` is a hand (tracked in the sixth level; the elbows and head below it).
fn hand(p: &BodyPoint) -> bool {
    matches!(p, BodyPoint::LeftWrist | BodyPoint::RightWrist)
}

/// The first two levels of the stack of `modes`: the held feet, 6D, and the floor rows of
/// every foot near the ground (no level below can take a sole under the floor), then the
/// landing feet's horizontal rows; the feet's and the floor's tasks (foot index, handle).
fn add_feet_levels(
    b: &mut ControllerBuilder,
    robot: &Robot,
    body: &RobotBody,
    s: &KeypointSettings,
    modes: [FootMode; 2],
) -> Result<(FootTasks, FootTasks)> {
    let stance = modes.map(|m| m == FootMode::Stance);
    let name = |f: FrameId| frame_name(robot, f);
    let mut feet = Vec::with_capacity(4);
    let mut floor = Vec::with_capacity(4);
    let near = |m: &FootMode| matches!(m, FootMode::Floor | FootMode::Landing);
    if stance.contains(&true) || modes.iter().any(near) {
        b.level(KEYPOINT_LEVELS[0]);
        b.gains(STANCE_GAINS);
        for i in (0..2).filter(|i| stance[*i]) {
            feet.push((i, b.frame(&name(body.feet[i]), Axes::ALL)?));
        }
        b.gains(s.gains);
        for i in (0..2).filter(|i| near(&modes[*i])) {
            floor.push((i, b.frame(&name(body.feet[i]), FLOOR_AXES)?));
        }
    }
    if modes.contains(&FootMode::Landing) {
        b.level(KEYPOINT_LEVELS[1]);
        for i in (0..2).filter(|i| modes[*i] == FootMode::Landing) {
            floor.push((i, b.frame(&name(body.feet[i]), LANDING_AXES)?));
        }
    }
    Ok((feet, floor))
}

/// The tasks [`add_lower_levels`] adds to: the tracked points, the torso's orientation, the
/// feet, and what decides them (the torso's frame among the elbows, the swing feet).
struct LowerTasks {
    points: Vec<(FrameHandle, usize)>,
    torso: Option<FrameHandle>,
    torso_with_elbows: Option<FrameId>,
    feet: Vec<(usize, FrameHandle)>,
    swing: [bool; 2],
}

/// The elbows, head and swing feet's orientations, weighted into the sixth level or (weight
/// 0) a seventh level of their own, and the posture, weighted into the sixth level or in a
/// level of its own below: the posture's handle.
fn add_lower_levels(
    b: &mut ControllerBuilder,
    robot: &Robot,
    body: &RobotBody,
    plan: &Plan,
    posture: &[String],
    s: &KeypointSettings,
    t: &mut LowerTasks,
) -> Result<JointsHandle> {
    let names: Vec<&str> = posture.iter().map(String::as_str).collect();
    // The elbows, head and swing feet's orientations: weighted into the sixth level, or
    // (weight 0) a seventh level of their own.
    let w = s.body_weight;
    if w > 0.0 {
        add_body_tasks(
            b,
            robot,
            body,
            plan,
            &mut t.points,
            &mut t.torso,
            t.torso_with_elbows,
            &mut t.feet,
            t.swing,
            w,
        )?;
    }
    // Weighted into the sixth level, or (weight 0) a level of its own below the seventh: never
    // both, as a posture level below the weighted rows could only move what they already move.
    let weighted = if s.posture_weight > 0.0 {
        Some(b.weighted_joints(&names, s.posture_weight)?)
    } else {
        None
    };
    if w == 0.0 {
        // The seventh level only with a task in it (a robot without elbows or head frames
        // standing on both feet has none).
        let seventh = t.torso_with_elbows.is_some()
            || t.swing.contains(&true)
            || plan
                .points
                .iter()
                .any(|(p, _)| !hand(p) && body.frame_of(*p).is_some());
        if seventh {
            b.level(KEYPOINT_LEVELS[6]);
        }
        add_body_tasks(
            b,
            robot,
            body,
            plan,
            &mut t.points,
            &mut t.torso,
            t.torso_with_elbows,
            &mut t.feet,
            t.swing,
            1.0,
        )?;
    }
    Ok(match weighted {
        Some(h) => h,
        None => b.level(KEYPOINT_LEVELS[7]).joints(&names)?,
    })
}

/// The controller of builder `b` with `tasks`, and its GF fallback on the same stack.
fn finish_stack(b: ControllerBuilder, s: &KeypointSettings, tasks: Tasks) -> Result<Stack> {
    // The clone keeps the builder's identity: the handles address both controllers.
    let mut gf = b.clone();
    gf.settings(ControllerSettings {
        method: Method::Cascade,
        bounds: s.bounds,
        solver: s.solver,
    });
    let ctl = b.build()?;
    let feet_levels = ctl
        .stack()
        .levels
        .iter()
        .take_while(|l| l.name == KEYPOINT_LEVELS[0] || l.name == KEYPOINT_LEVELS[1])
        .count();
    Ok(Stack {
        ctl,
        fallback: gf.build()?,
        feet_levels,
        tasks,
    })
}

impl KeypointController {
    pub(crate) fn new(
        robot: Arc<Robot>,
        state: State,
        body: &RobotBody,
        plan: Plan,
        posture: PostureTracks,
        support: &SupportSettings,
        s: &KeypointSettings,
    ) -> Result<Self> {
        let kin = Kinematics::new(&robot, &state)?;
        let corners = sole_corners(support);
        let sole = corners.iter().sum::<Vector3<f64>>() / 4.0;
        let mut stacks = Vec::with_capacity(16);
        for right in FootMode::ALL {
            for left in FootMode::ALL {
                let modes = [left, right];
                stacks.push(build_stack(
                    &robot, &state, body, &plan, &posture.0, s, modes,
                )?);
            }
        }
        let m = posture.0.len();
        Ok(Self {
            stacks,
            active: 0,
            used_fallback: false,
            fallback_ticks: 0,
            stance_gf_ticks: 0,
            sacrificed: Sacrifices::new(),
            settle_sacrificed: Sacrifices::new(),
            plan,
            state,
            dt: s.dt,
            feet: body.feet,
            latch: [(Vector3::zeros(), 0.0); 2],
            kin,
            floor: [Floor::default(); 2],
            corners,
            sole,
            gains: s.gains,
            floor_ticks: 0,
            dip_ticks: 0,
            robot: robot.clone(),
            stance: [true; 2],
            floored: [false; 2],
            landing: (s.land_height, s.land_speed),
            posture_track: posture.1,
            posture_ref: [vec![0.0; m], vec![0.0; m], vec![0.0; m]],
            drift: StanceDrift::new(robot.nv()),
            dip_jac: nalgebra::DMatrix::zeros(6, robot.nv()),
        })
    }

    /// Sets the references of tick `k` on the active stack's IKTC controller, or with
    /// `fallback` on its GF one ([`set_references`]).
    fn refer(&mut self, fallback: bool, k: usize, hold: bool) -> Result<()> {
        let Stack {
            ctl,
            fallback: gf,
            tasks,
            ..
        } = &mut self.stacks[self.active & 15];
        set_references(
            if fallback { gf } else { ctl },
            tasks,
            &self.plan,
            &self.latch,
            &self.sole,
            &self.drift,
            &self.floor,
            &self.posture_track,
            &mut self.posture_ref,
            k,
            hold,
        )
    }

    /// The floor of a swing foot at `pose` moving with `v` under its reference `r`
    /// ([`foot_reference`]), with the bound `a_min` \[m/s²\], in `mode` (`Floor` or
    /// `Landing`).
    fn floor_of(
        &self,
        r: &FrameReference,
        pose: &nalgebra::Isometry3<f64>,
        v: &nalgebra::Vector6<f64>,
        a_min: f64,
        mode: FootMode,
    ) -> Floor {
        let (z, z_dot) = (pose.translation.vector.z, v[2]);
        // What the level asks of the foot by the frame task's law (world axes): its height's
        // own reference, and the angular acceleration with which its roll and pitch rows turn
        // the corners about the origin.
        let asked = r.desired_acceleration(pose, v, &self.gains);
        let (a_ref, alpha) = (asked[2], asked.fixed_rows::<3>(3).into_owned());
        let a_min = a_min.max(origin_floor_acceleration(
            pose,
            v,
            &alpha,
            &self.corners,
            &self.gains,
        ));
        let p = pose.translation.vector;
        Floor {
            z,
            z_dot,
            acceleration: a_ref.max(a_min),
            stop: (mode == FootMode::Landing).then_some([p.x, p.y]),
            arm: -(pose.rotation * self.sole),
        }
    }

    /// Number of ticks of the clip.
    pub fn ticks(&self) -> usize {
        self.plan.ticks
    }

    /// Sets the references of tick `k` (clamped to the last; with `hold`, at rest: zero rates
    /// and accelerations) on the stack of the feet that have landed (a foot the clip puts on
    /// the ground lands once low and slow, see the module documentation; not while holding,
    /// when the clip's contacts are taken), and solves; q̈ is then in
    /// [`KeypointController::qdd`], applied by [`KeypointController::integrate`]. The tick is
    /// solved again by GF on the same stack ([`KeypointController::used_fallback`]) when IKTC's
    /// answer leaves the box by more than the solver's `box_tolerance` without a fallback of
    /// its own (seen with rank-deficient levels below the corrected one), and when IKTC had to
    /// correct the feet's levels while a foot is held (the stance feet's level, or the floor's
    /// below it): GF's answer is then taken if it keeps those levels more exactly (the sum of
    /// their error norms). On a clip of Bandai Namco's dataset
    /// (`dataset-1_walk-left_feminine_001`) JVRC-1's landing foot, its hold beyond the legs'
    /// reach, goes 0.15 mm into the ground with GF's answer taken;
    /// `book/src/retarget-defaults.md` has IKTC's answer kept, and GF's taken also without a
    /// held foot, measured. Nothing is clipped. Allocates nothing.
    pub fn tick(&mut self, k: usize, hold: bool) -> Result<&SolveReport> {
        let k = k.min(self.plan.ticks.saturating_sub(1));
        let on = self.contacts(k);
        self.used_fallback = false;
        self.touch_downs(k, hold, on);
        let mut modes = self.foot_modes(k, hold, on)?;
        if modes.contains(&FootMode::Floor) {
            self.floor_ticks += 1;
        }
        self.active = modes[0].index() + 4 * modes[1].index();
        self.refer(false, k, hold)?;
        let stack = &mut self.stacks[self.active & 15];
        let tolerance = stack.ctl.settings().solver.box_tolerance;
        // The kinematics of the state, computed above for the feet: swapped in, not
        // computed again (the fallback below computes its own).
        stack
            .ctl
            .prepare_with_kinematics(&self.state, self.dt, &mut self.kin)?;
        let iktc = stack.ctl.settings().method == Method::Iktc;
        stack.ctl.solve()?;
        if self.catch_dips(k, hold, on, &mut modes)? {
            self.dip_ticks += 1;
            self.active = modes[0].index() + 4 * modes[1].index();
            self.refer(false, k, hold)?;
            let ctl = &mut self.stacks[self.active & 15].ctl;
            ctl.prepare(&self.state, self.dt)?;
            ctl.solve()?;
        }
        self.floored = modes.map(|m| matches!(m, FootMode::Floor | FootMode::Landing));
        self.checked_answer(k, hold, tolerance, iktc)
    }

    /// The clip's contacts `on` at tick `k` taken for the feet: held (with `hold`) or lifted as
    /// the clip has them; a foot the clip puts down goes to the plan's hold, then lands.
    fn touch_downs(&mut self, k: usize, hold: bool, on: [bool; 2]) {
        let c = &self.plan.contact;
        for i in 0..2 {
            if hold || !on[i] {
                self.stance[i] = on[i];
            } else if !self.stance[i] && (k == 0 || !c[i][k - 1]) {
                // The clip's touch-down: the foot goes to the plan's hold, then lands.
                self.latch[i] = (Vector3::zeros(), 0.0);
            }
        }
    }

    /// The mode of each foot at tick `k` from where the robot's feet are now: a foot the clip
    /// puts on the ground lands once low, slow and flat; the others are in swing, or their
    /// floor is engaged (then set in `self.floor`).
    fn foot_modes(&mut self, k: usize, hold: bool, on: [bool; 2]) -> Result<[FootMode; 2]> {
        let mut modes = [FootMode::Stance; 2];
        // The robot's feet where they are now, and the held feet's drift over the last tick.
        self.kin.update(&self.robot, &self.state)?;
        self.drift
            .measure(&self.robot, &self.kin, &self.feet, self.dt)?;
        let (kin, robot) = (&self.kin, &*self.robot);
        let (height, speed) = self.landing;
        for i in 0..2 {
            if self.stance[i] {
                continue;
            }
            let pose = kin.frame_pose(robot, self.feet[i])?;
            let v = kin.frame_velocity(robot, self.feet[i])?;
            let (e, e_dot) = lowest_corner(&pose, &v, &self.corners);
            let r = foot_reference(&self.plan, i, k, hold, self.latch[i], &self.sole);
            if on[i] {
                let plan = &self.plan.feet[i][k];
                let low = e <= height;
                // Slow against its reference: a foot the plan pivots lands while it turns
                // with it (a still reference leaves the foot's own speed).
                let slow = fastest_corner(&pose, &(v - r.velocity), &self.corners) <= speed;
                let flat = (pose.rotation * Vector3::z()).z >= LAND_TILT.cos();
                if low && slow && flat {
                    // The offset of the sole centre from the plan's, and the yaw from the
                    // plan's: the first level then flattens the foot about where its sole
                    // touched, not about the ankle, which would slide the sole by
                    // `ankle_height · sin θ` (3 mm on JVRC-1 at LAND_TILT), and turns it
                    // about there ([`foot_reference`]).
                    let x = (pose.rotation * plan.rotation.inverse()) * Vector3::x();
                    let yaw = x.y.atan2(x.x);
                    let mut d = pose * Point3::from(self.sole)
                        - (plan.position.position + plan.rotation * self.sole);
                    d.z = 0.0;
                    self.latch[i] = (d.coords, yaw);
                    self.stance[i] = true;
                    continue;
                }
            }
            let a_min = floor_acceleration(e, e_dot, &self.gains);
            modes[i] = match (on[i], engaged(a_min)) {
                (true, true) => FootMode::Landing,
                (false, true) => FootMode::Floor,
                // Far above the ground a foot is brought down to its hold as in a swing.
                (_, false) => FootMode::Swing,
            };
            if modes[i] != FootMode::Swing {
                self.floor[i] = self.floor_of(&r, &pose, &v, a_min, modes[i]);
            }
        }
        Ok(modes)
    }

    /// A swing foot whose floor is not engaged and which this tick's q̈ would take below
    /// the ground (a correction of the level it shares with the hands can pull it down
    /// at hundreds of m/s²): its floor engaged in `modes`; true when the tick is to be
    /// solved again.
    fn catch_dips(
        &mut self,
        k: usize,
        hold: bool,
        on: [bool; 2],
        modes: &mut [FootMode; 2],
    ) -> Result<bool> {
        let mut again = false;
        for i in 0..2 {
            if modes[i] != FootMode::Swing {
                continue;
            }
            let ctl = &self.stacks[self.active & 15].ctl;
            let (kin, robot) = (ctl.kinematics(), &*self.robot);
            let pose = kin.frame_pose(robot, self.feet[i])?;
            let v = kin.frame_velocity(robot, self.feet[i])?;
            kin.frame_jacobian(robot, self.feet[i], &mut self.dip_jac)?;
            let mut a = kin.frame_drift(robot, self.feet[i])?;
            a.gemv(1.0, &self.dip_jac, ctl.qdd(), 1.0);
            if lowest_after(&pose, &v, &a, &self.corners, self.dt) < 0.0 {
                let (e, e_dot) = lowest_corner(&pose, &v, &self.corners);
                let a_min = floor_acceleration(e, e_dot, &self.gains);
                modes[i] = if on[i] {
                    FootMode::Landing
                } else {
                    FootMode::Floor
                };
                let r = foot_reference(&self.plan, i, k, hold, self.latch[i], &self.sole);
                self.floor[i] = self.floor_of(&r, &pose, &v, a_min, modes[i]);
                again = true;
            }
        }
        Ok(again)
    }

    /// The answer of the active stack, counted by the level it sacrificed, or GF's on the
    /// same stack where IKTC's leaves the box by more than `tolerance` or corrected the feet's
    /// levels while a foot is held and GF keeps them more exactly.
    fn checked_answer(
        &mut self,
        k: usize,
        hold: bool,
        tolerance: f64,
        iktc: bool,
    ) -> Result<&SolveReport> {
        let stack = &self.stacks[self.active & 15];
        let r = stack.ctl.report();
        let feet_levels = stack.feet_levels;
        let stance = self.stance.contains(&true);
        let held = stance && matches!(r.corrected_from, Some(c) if c < feet_levels);
        let feet_error: f64 = r.task_error_norms.iter().take(feet_levels).sum();
        let violation = r.violation;
        let corrected = r.corrected_from;
        let level = corrected
            .and_then(|i| stack.ctl.stack().levels.get(i))
            .and_then(|l| KEYPOINT_LEVELS.iter().position(|n| *n == l.name));
        if hold {
            self.settle_sacrificed.count(level);
        } else {
            self.sacrificed.count(level);
        }
        if (violation <= tolerance && !held) || !iktc {
            return Ok(self.stacks[self.active & 15].ctl.report());
        }
        self.refer(true, k, hold)?;
        let stack = &mut self.stacks[self.active & 15];
        let f = &mut stack.fallback;
        f.prepare(&self.state, self.dt)?;
        let g = f.solve()?;
        let gf_error: f64 = g.task_error_norms.iter().take(feet_levels).sum();
        if violation <= tolerance {
            if gf_error >= feet_error {
                return Ok(stack.ctl.report());
            }
            self.stance_gf_ticks += 1;
        } else {
            self.fallback_ticks += 1;
        }
        self.used_fallback = true;
        Ok(f.report())
    }

    /// The position references of tick `k` \[m\]: the pelvis, the feet (ankles, with the
    /// offsets latched at their last touch-down) and the tracked points (hands, elbows).
    pub fn position_references(&self, k: usize) -> Vec<(BodyPoint, nalgebra::Vector3<f64>)> {
        let k = k.min(self.plan.ticks.saturating_sub(1));
        let p = &self.plan;
        let foot = |i: usize| {
            foot_reference(p, i, k, false, self.latch[i], &self.sole)
                .pose
                .translation
                .vector
        };
        let mut out = vec![
            (BodyPoint::Pelvis, p.pelvis[k].position.position),
            (BodyPoint::LeftAnkle, foot(0)),
            (BodyPoint::RightAnkle, foot(1)),
        ];
        out.extend(p.points.iter().map(|(b, r)| (*b, r[k].position)));
        out
    }

    /// Whether the clip has the (left, right) foot on the ground at tick `k` (clamped to the
    /// last).
    pub fn contacts(&self, k: usize) -> [bool; 2] {
        let k = k.min(self.plan.ticks.saturating_sub(1));
        let c = &self.plan.contact;
        [
            c[0].get(k).copied().unwrap_or(false),
            c[1].get(k).copied().unwrap_or(false),
        ]
    }

    /// Whether the (left, right) foot is held on the ground by the first level after the last
    /// tick (it landed; see the module documentation).
    pub fn stance(&self) -> [bool; 2] {
        self.stance
    }

    /// Whether the last tick was solved by GF (see [`KeypointController::tick`]).
    pub fn used_fallback(&self) -> bool {
        self.used_fallback
    }

    /// The levels IKTC sacrificed on the ticks so far with moving references (`hold` false in
    /// [`KeypointController::tick`]): per level, the ticks on which it was the highest-priority
    /// level whose correction brought q̈ into the box ([`SolveReport::corrected_from`]).
    pub fn sacrificed(&self) -> &Sacrifices {
        &self.sacrificed
    }

    /// The same over the held ticks (the settling on the first frame).
    pub fn settle_sacrificed(&self) -> &Sacrifices {
        &self.settle_sacrificed
    }

    /// Ticks solved by GF so far because IKTC's answer left the box.
    pub fn fallback_ticks(&self) -> usize {
        self.fallback_ticks
    }

    /// Ticks solved by GF so far because IKTC corrected the feet's levels while a foot was held
    /// and GF kept them more exactly ([`KeypointController::tick`]).
    pub fn stance_gf_ticks(&self) -> usize {
        self.stance_gf_ticks
    }

    /// Ticks so far solved a second time with a swing foot's floor engaged because the first
    /// q̈ would have taken a sole corner of that foot, its floor not engaged, below the ground
    /// within the tick (see the module documentation).
    pub fn dip_ticks(&self) -> usize {
        self.dip_ticks
    }

    /// Ticks so far with a swing foot's floor engaged in the `swing_floor` level (landing feet
    /// not counted).
    pub fn floor_ticks(&self) -> usize {
        self.floor_ticks
    }

    /// Applies the last q̈ over Δt (constant acceleration). Errors: no tick solved since the
    /// last integration.
    pub fn integrate(&mut self) -> Result<()> {
        let s = &mut self.stacks[self.active & 15];
        let ctl = if self.used_fallback {
            &s.fallback
        } else {
            &s.ctl
        };
        self.drift.observe(
            &self.robot,
            ctl.kinematics(),
            &self.feet,
            [0, 1].map(|i| self.stance[i] || self.floored[i]),
            ctl.qdd(),
        )?;
        if self.used_fallback {
            s.fallback.integrate(&mut self.state)
        } else {
            s.ctl.integrate(&mut self.state)
        }
    }

    /// The state (at the start of the next tick once integrated).
    pub fn state(&self) -> &State {
        &self.state
    }

    /// q̈ of the last tick \[rad/s²\] (base: \[m/s²\], \[rad/s²\]).
    pub fn qdd(&self) -> &DVector<f64> {
        let s = &self.stacks[self.active & 15];
        if self.used_fallback {
            s.fallback.qdd()
        } else {
            s.ctl.qdd()
        }
    }

    pub(crate) fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The controller of the last tick's contact state (IKTC).
    pub fn controller(&self) -> &Controller {
        &self.stacks[self.active & 15].ctl
    }
}

#[cfg(test)]
#[path = "tracker_tests.rs"]
mod tests;
