//! Footsteps and footstep plans: stepping in place, walking forward, turning, and following a
//! root (pelvis) trajectory.
//!
//! Every generated plan starts from the nominal stance around a *body pose* `(x, y, ψ)`: the
//! feet at `R(ψ) (0, ±d/2)` from it, `d` = [`WalkSettings::foot_separation`], both with yaw `ψ`.
//! Footstep `k = 1 … n` of a plan places the swinging foot (sides alternate, starting with
//! [`WalkSettings::first_swing`]) at its nominal place around body pose `k`; the last footstep
//! is a *closing step* that brings the swinging foot beside the other one, so every plan ends in
//! the nominal stance.

use serde::Serialize;

use super::settings::{check_positive, invalid, Side, WalkSettings};
use crate::error::{check_finite, Error, Result};

/// A planar pose on the ground: position and heading.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Pose2 {
    /// Position along the world x axis \[m\].
    pub x: f64,
    /// Position along the world y axis \[m\].
    pub y: f64,
    /// Heading, rotation about the world z axis \[rad\]. Not wrapped: plans keep it continuous.
    pub yaw: f64,
}

impl Pose2 {
    /// A pose from its parts, `x`, `y` \[m\], `yaw` \[rad\].
    pub fn new(x: f64, y: f64, yaw: f64) -> Self {
        Self { x, y, yaw }
    }

    /// The point `(lx, ly)` given in this pose's frame, in world coordinates \[m\]:
    /// `p + R(ψ) (lx, ly)`.
    pub fn transform_point(&self, lx: f64, ly: f64) -> (f64, f64) {
        let (s, c) = self.yaw.sin_cos();
        (self.x + c * lx - s * ly, self.y + s * lx + c * ly)
    }

    /// The nominal pose of foot `side` when the body is at `self`: offset `±separation/2`
    /// along the body's y axis, same heading.
    pub fn foot(&self, side: Side, separation: f64) -> Pose2 {
        let (x, y) = self.transform_point(0.0, side.lateral_sign() * 0.5 * separation);
        Pose2::new(x, y, self.yaw)
    }
}

/// One footstep: the foot that swings and the pose it lands at.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Footstep {
    /// The foot that swings (the other one is the stance foot during the step).
    pub side: Side,
    /// Touch-down pose of the sole centre on the ground \[m, m, rad\].
    pub pose: Pose2,
}

/// A sample of a root (pelvis) trajectory on the ground plane, for
/// [`FootstepPlan::from_root_trajectory`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RootSample {
    /// Time \[s\]; samples must be strictly increasing in time. Only the order is used: the
    /// step timing comes from [`WalkSettings`].
    pub t: f64,
    /// Position along the world x axis \[m\].
    pub x: f64,
    /// Position along the world y axis \[m\].
    pub y: f64,
    /// Heading \[rad\]; jumps of the wrapped angle are unwrapped.
    pub yaw: f64,
}

/// How [`FootstepPlan::from_root_trajectory`] places the steps along the path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RootPlanParams {
    /// Nominal advance of the body per footstep along the path \[m\], `> 0`. Longer strides
    /// mean fewer, larger steps.
    pub stride: f64,
    /// Largest change of heading per footstep \[rad\], in `(0, π/2)`; the same foot then turns
    /// by less than π between two of its steps.
    pub max_yaw_per_step: f64,
    /// Rounding of the step count \[–\], in `[0, 0.5)`: a path worth `m + count_rounding`
    /// strides or less gets `m` steps (slightly longer ones), so that round-off in the path
    /// length does not add a tiny extra step.
    pub count_rounding: f64,
}

impl Default for RootPlanParams {
    fn default() -> Self {
        Self {
            stride: 0.2,
            max_yaw_per_step: 0.3,
            count_rounding: 1e-6,
        }
    }
}

impl RootPlanParams {
    /// Checks `stride > 0`, `0 < max_yaw_per_step < π/2`, `0 ≤ count_rounding < 0.5`.
    pub fn validate(&self) -> Result<()> {
        check_positive("RootPlanParams::stride [m]", self.stride)?;
        let y = self.max_yaw_per_step;
        if !(y.is_finite() && y > 0.0 && y < std::f64::consts::FRAC_PI_2) {
            return Err(invalid(
                "RootPlanParams::max_yaw_per_step [rad]",
                y,
                "in (0, pi/2)",
            ));
        }
        let r = self.count_rounding;
        if !(r.is_finite() && (0.0..0.5).contains(&r)) {
            return Err(invalid("RootPlanParams::count_rounding", r, "in [0, 0.5)"));
        }
        Ok(())
    }
}

/// A footstep plan: the initial poses of both feet and the footsteps in order.
///
/// Invariants (checked by [`FootstepPlan::new`]): at least one footstep, all numbers finite,
/// and each foot turns by less than π between two consecutive poses of its own (so that the
/// swing interpolates the heading unambiguously).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FootstepPlan {
    initial_left: Pose2,
    initial_right: Pose2,
    steps: Vec<Footstep>,
}

fn check_pose(what: &str, p: &Pose2) -> Result<()> {
    check_finite(|| format!("{what}.x [m]"), p.x)?;
    check_finite(|| format!("{what}.y [m]"), p.y)?;
    check_finite(|| format!("{what}.yaw [rad]"), p.yaw)?;
    Ok(())
}

/// Wraps an angle into `(−π, π]` \[rad\].
pub(crate) fn wrap_angle(a: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    let w = a - two_pi * (a / two_pi).round();
    if w <= -std::f64::consts::PI {
        w + two_pi
    } else {
        w
    }
}

fn check_count(n: usize) -> Result<()> {
    if n == 0 {
        Err(Error::InvalidSetting {
            name: "number of footsteps".to_string(),
            value: "0".to_string(),
            expected: "at least 1".to_string(),
        })
    } else {
        Ok(())
    }
}

impl FootstepPlan {
    /// A plan from the initial foot poses and the footsteps. Errors if there are no steps, a
    /// number is not finite, or a foot turns by π or more between two of its poses.
    pub fn new(initial_left: Pose2, initial_right: Pose2, steps: Vec<Footstep>) -> Result<Self> {
        check_pose("FootstepPlan initial_left", &initial_left)?;
        check_pose("FootstepPlan initial_right", &initial_right)?;
        if steps.is_empty() {
            return Err(Error::InsufficientData {
                what: "footstep plan".to_string(),
                message: "no footsteps (expected at least 1)".to_string(),
            });
        }
        let (mut left, mut right) = (initial_left, initial_right);
        for (i, s) in steps.iter().enumerate() {
            check_pose(&format!("footstep {i} pose"), &s.pose)?;
            let prev = match s.side {
                Side::Left => &mut left,
                Side::Right => &mut right,
            };
            let turn = s.pose.yaw - prev.yaw;
            if turn.abs() >= std::f64::consts::PI {
                return Err(invalid(
                    &format!("footstep {i} yaw change [rad]"),
                    turn,
                    "|change of the foot's yaw since its previous pose| < pi",
                ));
            }
            *prev = s.pose;
        }
        Ok(Self {
            initial_left,
            initial_right,
            steps,
        })
    }

    /// Builds the plan whose footstep `k = 1 … n` lands at the nominal place around
    /// `body(k)` (clamped to `n − 1`, the closing step), sides alternating from
    /// `settings.first_swing`, starting from the nominal stance around `body(0)`.
    fn from_body_poses(
        n: usize,
        settings: &WalkSettings,
        body: impl Fn(usize) -> Pose2,
    ) -> Result<Self> {
        settings.validate()?;
        check_count(n)?;
        let d = settings.foot_separation;
        let start = body(0);
        let mut side = settings.first_swing;
        let steps = (1..=n)
            .map(|k| {
                let step = Footstep {
                    side,
                    pose: body(k.min(n - 1)).foot(side, d),
                };
                side = side.opposite();
                step
            })
            .collect();
        Self::new(start.foot(Side::Left, d), start.foot(Side::Right, d), steps)
    }

    /// `n ≥ 1` steps in place around the origin: every footstep lands where the foot was.
    pub fn in_place(n: usize, settings: &WalkSettings) -> Result<Self> {
        Self::from_body_poses(n, settings, |_| Pose2::default())
    }

    /// `n ≥ 1` steps straight ahead along `+x` from the origin: footstep `k` lands
    /// `step_length` \[m\] (negative: backwards) ahead of footstep `k − 1`, at
    /// `x = min(k, n − 1) · step_length`; the last one closes beside its predecessor.
    /// The body advances by `(n − 1) · step_length`.
    pub fn forward(n: usize, step_length: f64, settings: &WalkSettings) -> Result<Self> {
        check_finite(|| "step_length [m]".to_string(), step_length)?;
        Self::from_body_poses(n, settings, |k| {
            Pose2::new(k as f64 * step_length, 0.0, 0.0)
        })
    }

    /// `n ≥ 1` steps turning in place about the origin by `yaw_per_step` \[rad\] per footstep
    /// (positive: to the left), `|yaw_per_step| < π/2`: footstep `k` lands around the body
    /// heading `min(k, n − 1) · yaw_per_step`. The body turns by `(n − 1) · yaw_per_step`.
    pub fn turn(n: usize, yaw_per_step: f64, settings: &WalkSettings) -> Result<Self> {
        if !(yaw_per_step.is_finite() && yaw_per_step.abs() < std::f64::consts::FRAC_PI_2) {
            return Err(invalid(
                "yaw_per_step [rad]",
                yaw_per_step,
                "finite, |.| < pi/2",
            ));
        }
        Self::from_body_poses(n, settings, |k| {
            Pose2::new(0.0, 0.0, k as f64 * yaw_per_step)
        })
    }

    /// Steps along a root (pelvis) trajectory.
    ///
    /// The path's *progress* accumulates, sample to sample, `‖Δp‖/stride + |Δψ|/max_yaw_per_step`
    /// (`Δψ` unwrapped into `(−π, π]`), so that a stride is one unit of progress whether it
    /// walks or turns. The total `σ` is cut into `m = max(1, ⌈σ − count_rounding⌉)` equal
    /// parts; body pose `k = 0 … m` is the path (linearly interpolated in position and
    /// unwrapped heading) at progress `k σ / m`. Footsteps `1 … m` land around body poses
    /// `1 … m`, and a closing step brings the other foot beside the last: `m + 1` footsteps.
    /// The feet start in the nominal stance around the first sample.
    ///
    /// Errors: fewer than 2 samples, a non-finite number, times not strictly increasing,
    /// invalid parameters or settings.
    pub fn from_root_trajectory(
        samples: &[RootSample],
        params: &RootPlanParams,
        settings: &WalkSettings,
    ) -> Result<Self> {
        params.validate()?;
        settings.validate()?;
        if samples.len() < 2 {
            return Err(Error::InsufficientData {
                what: "root trajectory".to_string(),
                message: format!("{} samples (expected at least 2)", samples.len()),
            });
        }
        for (i, s) in samples.iter().enumerate() {
            check_finite(|| format!("root sample {i} t [s]"), s.t)?;
            check_pose(&format!("root sample {i}"), &Pose2::new(s.x, s.y, s.yaw))?;
        }
        // Unwrapped poses and cumulative progress.
        let mut poses = Vec::with_capacity(samples.len());
        let mut progress = Vec::with_capacity(samples.len());
        let mut prev = samples[0];
        let mut yaw = prev.yaw;
        poses.push(Pose2::new(prev.x, prev.y, yaw));
        progress.push(0.0);
        let mut sigma = 0.0;
        for (i, s) in samples.iter().enumerate().skip(1) {
            if s.t <= prev.t {
                return Err(invalid(
                    &format!("root sample {i} t [s]"),
                    s.t,
                    &format!("> previous sample's t = {}", prev.t),
                ));
            }
            let dyaw = wrap_angle(s.yaw - prev.yaw);
            yaw += dyaw;
            sigma += (s.x - prev.x).hypot(s.y - prev.y) / params.stride
                + dyaw.abs() / params.max_yaw_per_step;
            poses.push(Pose2::new(s.x, s.y, yaw));
            progress.push(sigma);
            prev = *s;
        }
        let m = ((sigma - params.count_rounding).ceil().max(1.0)) as usize;
        let body = |k: usize| -> Pose2 {
            let target = sigma * k as f64 / m as f64;
            // First sample whose progress reaches the target (the last one at worst).
            let j = progress
                .iter()
                .position(|&s| s >= target)
                .unwrap_or(progress.len() - 1)
                .max(1);
            let (s0, s1) = (progress[j - 1], progress[j]);
            let a = if s1 > s0 {
                ((target - s0) / (s1 - s0)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let (p0, p1) = (poses[j - 1], poses[j]);
            Pose2::new(
                p0.x + a * (p1.x - p0.x),
                p0.y + a * (p1.y - p0.y),
                p0.yaw + a * (p1.yaw - p0.yaw),
            )
        };
        Self::from_body_poses(m + 1, settings, body)
    }

    /// Initial pose of the left foot.
    pub fn initial_left(&self) -> Pose2 {
        self.initial_left
    }

    /// Initial pose of the right foot.
    pub fn initial_right(&self) -> Pose2 {
        self.initial_right
    }

    /// Initial pose of foot `side`.
    pub fn initial(&self, side: Side) -> Pose2 {
        match side {
            Side::Left => self.initial_left,
            Side::Right => self.initial_right,
        }
    }

    /// The footsteps, in order.
    pub fn steps(&self) -> &[Footstep] {
        &self.steps
    }

    /// Number of footsteps.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// Always `false`: a plan has at least one footstep.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }
}
