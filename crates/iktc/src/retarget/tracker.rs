//! The closed loop of a keypoint retargeting: a [`Controller`] with the keypoint stack, the
//! references of every tick ([`super::plan`]) and the state, sized once.
//!
//! Levels, in priority order ([`KEYPOINT_LEVELS`]):
//! 1. `feet`: both feet, 6D each (held where they touched down while on the ground);
//! 2. `com_xy`: the COM over the support polygon, horizontal;
//! 3. `pelvis`: the pelvis pose, 6D;
//! 4. `hands`: the hand frames' positions;
//! 5. `elbows_head_torso`: the elbows' and the head's positions and the torso's orientation;
//! 6. `posture`: every active joint at its posture reference (a regulariser).
//!
//! Each level is linearised as in the controller (`J_i q̈ = ẍ_d + k_v(ẋ_d − ẋ) + k_p(x_d − x)
//! − J̇_i q̇`, eqs. 3, 11) and solved under the viable box of the robot's own joint limits with
//! IKTC (eqs. 19–25); q̈ is integrated as is, nothing is clipped afterwards.

use std::sync::Arc;

use nalgebra::DVector;

use super::body::RobotBody;
use super::plan::Plan;
use super::KeypointSettings;
use crate::controller::{
    ComHandle, Controller, ControllerBuilder, ControllerSettings, FrameHandle, JointsHandle,
};
use crate::error::Result;
use crate::model::{Robot, State};
use crate::motion::BodyPoint;
use crate::solver::{Method, SolveReport};
use crate::task::{Axes, ComReference};

/// Joint names and their (position, rate, acceleration) references per tick.
pub(crate) type PostureTracks = (Vec<String>, Vec<[Vec<f64>; 3]>);

/// Names of the levels of the keypoint stack, in priority order.
pub const KEYPOINT_LEVELS: [&str; 6] = [
    "feet",
    "com_xy",
    "pelvis",
    "hands",
    "elbows_head_torso",
    "posture",
];

/// The keypoint stack on a robot, its references and its state (see the module docs).
#[derive(Debug, Clone)]
pub struct KeypointController {
    ctl: Controller,
    /// The same stack solved by GF, for the ticks where IKTC's answer leaves the box.
    fallback: Controller,
    /// Whether the last tick was solved by `fallback`.
    used_fallback: bool,
    /// Ticks solved by `fallback` so far.
    fallback_ticks: usize,
    plan: Plan,
    state: State,
    dt: f64,
    tasks: Tasks,
    posture_ref: [Vec<f64>; 3],
}

/// The handles of the stack's tasks and the posture references.
#[derive(Debug, Clone)]
struct Tasks {
    feet: [FrameHandle; 2],
    com: ComHandle,
    pelvis: FrameHandle,
    torso: Option<FrameHandle>,
    points: Vec<(FrameHandle, usize)>,
    posture: JointsHandle,
    posture_track: Vec<[Vec<f64>; 3]>,
}

/// Sets the references of tick `k` on `ctl` (see [`KeypointController::tick`]).
fn set_references(
    ctl: &mut Controller,
    t: &Tasks,
    p: &Plan,
    posture_ref: &mut [Vec<f64>; 3],
    k: usize,
    hold: bool,
) -> Result<()> {
    for (h, f) in t.feet.iter().zip(&p.feet) {
        ctl.set_frame_reference(*h, f[k].frame(hold))?;
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
    for (j, track) in t.posture_track.iter().enumerate() {
        for d in 0..3 {
            let v = track[d].get(k).or(track[d].last()).copied().unwrap_or(0.0);
            posture_ref[d][j] = if hold && d > 0 { 0.0 } else { v };
        }
    }
    ctl.set_joints_reference(t.posture, &posture_ref[0], &posture_ref[1], &posture_ref[2])
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
        let mut b = ControllerBuilder::new(robot.clone(), &state)?;
        b.gains(s.gains).settings(ControllerSettings {
            method: s.method,
            bounds: s.bounds,
            solver: s.solver,
        });
        let name = |f: crate::model::FrameId| -> String {
            robot
                .frames()
                .get(f.0)
                .map(|f| f.name.clone())
                .unwrap_or_default()
        };
        b.level(KEYPOINT_LEVELS[0]);
        let feet = [
            b.frame(&name(body.feet[0]), Axes::ALL)?,
            b.frame(&name(body.feet[1]), Axes::ALL)?,
        ];
        let com = b.level(KEYPOINT_LEVELS[1]).com([true, true, false])?;
        let pelvis = b
            .level(KEYPOINT_LEVELS[2])
            .frame(&name(body.pelvis), Axes::ALL)?;
        let mut points = Vec::new();
        b.level(KEYPOINT_LEVELS[3]);
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
        let names: Vec<&str> = posture.0.iter().map(String::as_str).collect();
        let posture_handle = b.level(KEYPOINT_LEVELS[5]).joints(&names)?;
        let m = names.len();
        // The clone keeps the builder's identity: the handles address both controllers.
        let mut gf = b.clone();
        gf.settings(ControllerSettings {
            method: Method::Cascade,
            bounds: s.bounds,
            solver: s.solver,
        });
        Ok(Self {
            ctl: b.build()?,
            fallback: gf.build()?,
            used_fallback: false,
            fallback_ticks: 0,
            plan,
            state,
            dt: s.dt,
            tasks: Tasks {
                feet,
                com,
                pelvis,
                torso,
                points,
                posture: posture_handle,
                posture_track: posture.1,
            },
            posture_ref: [vec![0.0; m], vec![0.0; m], vec![0.0; m]],
        })
    }

    /// Number of ticks of the clip.
    pub fn ticks(&self) -> usize {
        self.plan.ticks
    }

    /// Sets the references of tick `k` (clamped to the last; with `hold`, at rest: zero rates
    /// and accelerations) and solves; q̈ is then in [`KeypointController::qdd`], applied by
    /// [`KeypointController::integrate`]. When IKTC's answer leaves the box by more than the
    /// solver's `box_tolerance` without a fallback of its own (seen with rank-deficient levels
    /// below the corrected one), the tick is solved again by GF on the same stack
    /// ([`KeypointController::used_fallback`]); nothing is clipped. Allocates nothing.
    pub fn tick(&mut self, k: usize, hold: bool) -> Result<&SolveReport> {
        let k = k.min(self.plan.ticks.saturating_sub(1));
        self.used_fallback = false;
        let tolerance = self.ctl.settings().solver.box_tolerance;
        let t = &self.tasks;
        set_references(&mut self.ctl, t, &self.plan, &mut self.posture_ref, k, hold)?;
        self.ctl.prepare(&self.state, self.dt)?;
        let r = self.ctl.solve()?;
        if r.violation <= tolerance || self.ctl.settings().method != Method::Iktc {
            return Ok(self.ctl.report());
        }
        set_references(
            &mut self.fallback,
            t,
            &self.plan,
            &mut self.posture_ref,
            k,
            hold,
        )?;
        self.fallback.prepare(&self.state, self.dt)?;
        self.fallback.solve()?;
        self.used_fallback = true;
        self.fallback_ticks += 1;
        Ok(self.fallback.report())
    }

    /// The position references of tick `k` \[m\]: the pelvis, the feet (ankles) and the
    /// tracked points (hands, elbows).
    pub fn position_references(&self, k: usize) -> Vec<(BodyPoint, nalgebra::Vector3<f64>)> {
        let k = k.min(self.plan.ticks.saturating_sub(1));
        let p = &self.plan;
        let mut out = vec![
            (BodyPoint::Pelvis, p.pelvis[k].position.position),
            (BodyPoint::LeftAnkle, p.feet[0][k].position.position),
            (BodyPoint::RightAnkle, p.feet[1][k].position.position),
        ];
        out.extend(p.points.iter().map(|(b, r)| (*b, r[k].position)));
        out
    }

    /// Whether the last tick was solved by GF (see [`KeypointController::tick`]).
    pub fn used_fallback(&self) -> bool {
        self.used_fallback
    }

    /// Ticks solved by GF so far.
    pub fn fallback_ticks(&self) -> usize {
        self.fallback_ticks
    }

    /// Applies the last q̈ over Δt (constant acceleration). Errors: no tick solved since the
    /// last integration.
    pub fn integrate(&mut self) -> Result<()> {
        if self.used_fallback {
            self.fallback.integrate(&mut self.state)
        } else {
            self.ctl.integrate(&mut self.state)
        }
    }

    /// The state (at the start of the next tick once integrated).
    pub fn state(&self) -> &State {
        &self.state
    }

    /// q̈ of the last tick \[rad/s²\] (base: \[m/s²\], \[rad/s²\]).
    pub fn qdd(&self) -> &DVector<f64> {
        if self.used_fallback {
            self.fallback.qdd()
        } else {
            self.ctl.qdd()
        }
    }

    pub(crate) fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The controller.
    pub fn controller(&self) -> &Controller {
        &self.ctl
    }
}
