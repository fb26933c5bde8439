//! The closed loop of a keypoint retargeting: [`Controller`]s with the keypoint stack, the
//! references of every tick ([`super::plan`]) and the state, sized once.
//!
//! Levels, in priority order ([`KEYPOINT_LEVELS`]):
//! 1. `stance_feet`: the feet on the ground, 6D each, held where they touched down;
//! 2. `com_xy`: the COM over the support polygon, horizontal;
//! 3. `pelvis`: the pelvis pose, 6D;
//! 4. `hands_swing_feet`: the hand frames' positions and the feet in the air, 6D;
//! 5. `elbows_head_torso`: the elbows' and the head's positions and the torso's orientation;
//! 6. `posture`: every active joint at its posture reference (a regulariser).
//!
//! A foot is in the first level only while the clip has it on the ground: one stack per
//! contact state (both feet, left, right, none; the last without the first level) is built
//! once, and each tick is solved by the stack of its contacts. A swing foot that the robot
//! cannot follow (a kick faster than its joint limits allow) then costs the hands' level
//! accuracy, never the stance foot's hold.
//!
//! The hold is closed-loop. A foot the clip puts on the ground is first brought to the plan's
//! hold in the swing levels; it lands (moves to the first level) once its ankle is within
//! `land_height` of the hold's height and slower than `land_speed`, or after
//! `max_landing_delay` ([`KeypointSettings`]). At landing the offset `δ = (x, y, ψ)_robot −
//! (x, y, ψ)_plan` of the robot's foot from the plan's hold (horizontal position \[m\] and yaw
//! \[rad\]) is latched and added to the foot's reference with the weight
//! [`Plan::latch_weight`] (1 in stance, fading to 0 over the next swing): the foot is held
//! where it landed, at rest, not pulled to where the plan wanted it.
//!
//! Each level is linearised as in the controller (`J_i q̈ = ẍ_d + k_v(ẋ_d − ẋ) + k_p(x_d − x)
//! − J̇_i q̇`, eqs. 3, 11) and solved under the viable box of the robot's own joint limits with
//! IKTC (eqs. 19–25); q̈ is integrated as is, nothing is clipped afterwards.

use std::sync::Arc;

use nalgebra::{DVector, UnitQuaternion, Vector3};

use super::body::RobotBody;
use super::plan::Plan;
use super::KeypointSettings;
use crate::controller::{
    ComHandle, Controller, ControllerBuilder, ControllerSettings, FrameHandle, JointsHandle,
};
use crate::error::Result;
use crate::model::{FrameId, Kinematics, Robot, State};
use crate::motion::BodyPoint;
use crate::solver::{Method, SolveReport};
use crate::task::{Axes, ComReference, FrameReference};

/// Joint names and their (position, rate, acceleration) references per tick.
pub(crate) type PostureTracks = (Vec<String>, Vec<[Vec<f64>; 3]>);

/// Names of the levels of the keypoint stack, in priority order.
pub const KEYPOINT_LEVELS: [&str; 6] = [
    "stance_feet",
    "com_xy",
    "pelvis",
    "hands_swing_feet",
    "elbows_head_torso",
    "posture",
];

/// The keypoint stack on a robot, its references and its state (see the module docs).
#[derive(Debug, Clone)]
pub struct KeypointController {
    /// One stack per contact state, indexed by `left + 2 right` (feet on the ground).
    stacks: Box<[Stack; 4]>,
    /// The stack of the last tick.
    active: usize,
    /// Whether the last tick was solved by the active stack's GF fallback.
    used_fallback: bool,
    /// Ticks solved by GF so far because IKTC's answer left the box.
    fallback_ticks: usize,
    /// Ticks solved by GF so far because it kept the stance feet better than IKTC.
    stance_gf_ticks: usize,
    plan: Plan,
    state: State,
    dt: f64,
    feet: [FrameId; 2],
    /// The offset latched at each foot's last touch-down: horizontal position \[m\] (z = 0)
    /// and yaw \[rad\].
    latch: [(Vector3<f64>, f64); 2],
    /// Whether each foot has landed (is in the first level).
    stance: [bool; 2],
    /// Ticks each foot has waited to land since the clip put it on the ground.
    waiting: [usize; 2],
    /// Landing thresholds: height \[m\], speed \[m/s\], largest wait \[ticks\].
    landing: (f64, f64, usize),
    /// Kinematics of the state, updated while a foot waits to land.
    kin: Kinematics,
    robot: Arc<Robot>,
    posture_track: Vec<[Vec<f64>; 3]>,
    posture_ref: [Vec<f64>; 3],
}

/// The controllers of one contact state: IKTC, and GF for the ticks where IKTC's answer leaves
/// the box or corrects the stance feet ([`KeypointController::tick`]).
#[derive(Debug, Clone)]
struct Stack {
    ctl: Controller,
    fallback: Controller,
    tasks: Tasks,
}

/// The handles of a stack's tasks.
#[derive(Debug, Clone)]
struct Tasks {
    /// Foot index (left 0, right 1) and handle, stance feet first.
    feet: Vec<(usize, FrameHandle)>,
    com: ComHandle,
    pelvis: FrameHandle,
    torso: Option<FrameHandle>,
    points: Vec<(FrameHandle, usize)>,
    posture: JointsHandle,
}

/// The reference of foot `i` at tick `k` with the latched offset `(d, yaw)` (see the module
/// documentation).
fn foot_reference(
    p: &Plan,
    i: usize,
    k: usize,
    hold: bool,
    latch: (Vector3<f64>, f64),
) -> FrameReference {
    let mut r = p.feet[i][k].frame(hold);
    let [w, wd, wdd] = p.latch_weight[i][k];
    let (d, yaw) = latch;
    let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), w * yaw);
    r.pose.translation.vector += w * d;
    r.pose.rotation = turn * r.pose.rotation;
    if !hold {
        let (v, om) = (
            r.velocity.fixed_rows::<3>(0) + wd * d,
            turn * r.velocity.fixed_rows::<3>(3) + wd * yaw * Vector3::z(),
        );
        let (a, al) = (
            r.acceleration.fixed_rows::<3>(0) + wdd * d,
            turn * r.acceleration.fixed_rows::<3>(3) + wdd * yaw * Vector3::z(),
        );
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
    posture_track: &[[Vec<f64>; 3]],
    posture_ref: &mut [Vec<f64>; 3],
    k: usize,
    hold: bool,
) -> Result<()> {
    for (i, h) in &t.feet {
        ctl.set_frame_reference(*h, foot_reference(p, *i, k, hold, latch[*i]))?;
    }
    let c = p.com[k];
    let c = if hold {
        ComReference::hold(c.position)
    } else {
        c
    };
    ctl.set_com_reference(t.com, c)?;
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

/// The stack of the contact state `stance` (left, right on the ground).
fn build_stack(
    robot: &Arc<Robot>,
    state: &State,
    body: &RobotBody,
    plan: &Plan,
    posture: &[String],
    s: &KeypointSettings,
    stance: [bool; 2],
) -> Result<Stack> {
    let mut b = ControllerBuilder::new(robot.clone(), state)?;
    b.gains(s.gains).settings(ControllerSettings {
        method: s.method,
        bounds: s.bounds,
        solver: s.solver,
    });
    let name = |f: FrameId| -> String {
        robot
            .frames()
            .get(f.0)
            .map(|f| f.name.clone())
            .unwrap_or_default()
    };
    let mut feet = Vec::with_capacity(2);
    if stance.iter().any(|on| *on) {
        b.level(KEYPOINT_LEVELS[0]);
        for i in (0..2).filter(|i| stance[*i]) {
            feet.push((i, b.frame(&name(body.feet[i]), Axes::ALL)?));
        }
    }
    let com = b.level(KEYPOINT_LEVELS[1]).com([true, true, false])?;
    let pelvis = b
        .level(KEYPOINT_LEVELS[2])
        .frame(&name(body.pelvis), Axes::ALL)?;
    let mut points = Vec::new();
    b.level(KEYPOINT_LEVELS[3]);
    for i in (0..2).filter(|i| !stance[*i]) {
        feet.push((i, b.frame(&name(body.feet[i]), Axes::POSITION)?));
    }
    let mut level = 3;
    for (i, (p, _)) in plan.points.iter().enumerate() {
        if level == 3 && !matches!(p, BodyPoint::LeftWrist | BodyPoint::RightWrist) {
            b.level(KEYPOINT_LEVELS[4]);
            level = 4;
        }
        if let Some(f) = body.frame_of(*p) {
            points.push((b.frame(&name(f), Axes::POSITION)?, i));
        }
    }
    if level == 3 {
        b.level(KEYPOINT_LEVELS[4]);
    }
    let torso = match body.torso {
        Some(f) => Some(b.frame(&name(f), Axes::ORIENTATION)?),
        None => None,
    };
    for i in (0..2).filter(|i| !stance[*i]) {
        feet.push((i, b.frame(&name(body.feet[i]), Axes::ORIENTATION)?));
    }
    let names: Vec<&str> = posture.iter().map(String::as_str).collect();
    let posture = b.level(KEYPOINT_LEVELS[5]).joints(&names)?;
    // The clone keeps the builder's identity: the handles address both controllers.
    let mut gf = b.clone();
    gf.settings(ControllerSettings {
        method: Method::Cascade,
        bounds: s.bounds,
        solver: s.solver,
    });
    Ok(Stack {
        ctl: b.build()?,
        fallback: gf.build()?,
        tasks: Tasks {
            feet,
            com,
            pelvis,
            torso,
            points,
            posture,
        },
    })
}

impl KeypointController {
    pub(crate) fn new(
        robot: Arc<Robot>,
        state: State,
        body: &RobotBody,
        plan: Plan,
        posture: PostureTracks,
        s: &KeypointSettings,
    ) -> Result<Self> {
        let build = |stance| build_stack(&robot, &state, body, &plan, &posture.0, s, stance);
        let kin = Kinematics::new(&robot, &state)?;
        let stacks = Box::new([
            build([false, false])?,
            build([true, false])?,
            build([false, true])?,
            build([true, true])?,
        ]);
        let m = posture.0.len();
        Ok(Self {
            stacks,
            active: 3,
            used_fallback: false,
            fallback_ticks: 0,
            stance_gf_ticks: 0,
            plan,
            state,
            dt: s.dt,
            feet: body.feet,
            latch: [(Vector3::zeros(), 0.0); 2],
            kin,
            robot: robot.clone(),
            stance: [true; 2],
            waiting: [0; 2],
            landing: (
                s.land_height,
                s.land_speed,
                (s.max_landing_delay / s.dt).round() as usize,
            ),
            posture_track: posture.1,
            posture_ref: [vec![0.0; m], vec![0.0; m], vec![0.0; m]],
        })
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
    /// correct the stance feet's level: GF's answer is then taken if it keeps the stance
    /// feet's level more exactly (on CMU 131_01 on G1 IKTC's corrections of a double stance
    /// made the held feet slide by 0.9 m, GF's by 0.1 m). Nothing is clipped. Allocates
    /// nothing.
    pub fn tick(&mut self, k: usize, hold: bool) -> Result<&SolveReport> {
        let k = k.min(self.plan.ticks.saturating_sub(1));
        let on = self.contacts(k);
        self.used_fallback = false;
        let c = &self.plan.contact;
        for i in 0..2 {
            if hold || !on[i] {
                self.stance[i] = on[i];
                self.waiting[i] = 0;
            } else if !self.stance[i] && (k == 0 || !c[i][k - 1]) {
                // The clip's touch-down: the foot goes to the plan's hold, then lands.
                self.latch[i] = (Vector3::zeros(), 0.0);
                self.waiting[i] = 0;
            }
        }
        if (0..2).any(|i| on[i] && !self.stance[i]) {
            // The robot's feet where they are now.
            self.kin.update(&self.robot, &self.state)?;
            let (kin, robot) = (&self.kin, &*self.robot);
            let (height, speed, max_wait) = self.landing;
            let waiting = [on[0] && !self.stance[0], on[1] && !self.stance[1]];
            for i in (0..2).filter(|i| waiting[*i]) {
                let pose = kin.frame_pose(robot, self.feet[i])?;
                let v = kin.frame_velocity(robot, self.feet[i])?;
                let plan = &self.plan.feet[i][k];
                let mut d = pose.translation.vector - plan.position.position;
                let low = d.z <= height;
                let slow = v.fixed_rows::<3>(0).norm() <= speed;
                if (low && slow) || self.waiting[i] >= max_wait {
                    d.z = 0.0;
                    let x = (pose.rotation * plan.rotation.inverse()) * Vector3::x();
                    self.latch[i] = (d, x.y.atan2(x.x));
                    self.stance[i] = true;
                } else {
                    self.waiting[i] += 1;
                }
            }
        }
        self.active = usize::from(self.stance[0]) + 2 * usize::from(self.stance[1]);
        let stack = &mut self.stacks[self.active & 3];
        let tolerance = stack.ctl.settings().solver.box_tolerance;
        let (p, l, pt) = (&self.plan, &self.latch, &self.posture_track);
        set_references(
            &mut stack.ctl,
            &stack.tasks,
            p,
            l,
            pt,
            &mut self.posture_ref,
            k,
            hold,
        )?;
        stack.ctl.prepare(&self.state, self.dt)?;
        let iktc = stack.ctl.settings().method == Method::Iktc;
        let r = stack.ctl.solve()?;
        let held = self.active != 0 && r.corrected_from == Some(0);
        let stance_error = r.task_error_norms.first().copied().unwrap_or(0.0);
        let violation = r.violation;
        if (violation <= tolerance && !held) || !iktc {
            return Ok(stack.ctl.report());
        }
        let f = &mut stack.fallback;
        set_references(f, &stack.tasks, p, l, pt, &mut self.posture_ref, k, hold)?;
        f.prepare(&self.state, self.dt)?;
        let g = f.solve()?;
        let gf_error = g.task_error_norms.first().copied().unwrap_or(0.0);
        if violation <= tolerance {
            if gf_error >= stance_error {
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
            foot_reference(p, i, k, false, self.latch[i])
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

    /// Ticks solved by GF so far because IKTC's answer left the box.
    pub fn fallback_ticks(&self) -> usize {
        self.fallback_ticks
    }

    /// Ticks solved by GF so far because IKTC corrected the stance feet's level and GF kept it
    /// more exactly ([`KeypointController::tick`]).
    pub fn stance_gf_ticks(&self) -> usize {
        self.stance_gf_ticks
    }

    /// Applies the last q̈ over Δt (constant acceleration). Errors: no tick solved since the
    /// last integration.
    pub fn integrate(&mut self) -> Result<()> {
        let s = &mut self.stacks[self.active & 3];
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
        let s = &self.stacks[self.active & 3];
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
        &self.stacks[self.active & 3].ctl
    }
}
