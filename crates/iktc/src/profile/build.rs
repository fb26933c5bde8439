//! From a profile to a robot model and the imitation's settings, checking every key against the
//! robot; every error names the key that holds the wrong value.

use super::glob::glob_match;
use super::schema::{Feet, Foot, RobotProfile};
use crate::error::{Error, Result};
use crate::model::RobotFiles;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::model::{JointKind, Kinematics, ModelOptions, Robot, State};
use crate::motion::RetargetMap;
use crate::sim::imitate::SupportSettings;
use crate::sim::ImitateConfig;

/// The value written in an error when a key is absent.
pub const MISSING: &str = "(missing)";

pub(super) fn profile_error(key: &str, value: impl ToString, message: impl Into<String>) -> Error {
    Error::Profile {
        key: key.into(),
        value: value.to_string(),
        message: message.into(),
    }
}

fn list(names: impl IntoIterator<Item = impl AsRef<str>>) -> String {
    names
        .into_iter()
        .map(|n| n.as_ref().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

pub(super) fn check_number(key: &str, v: f64, ok: bool, expected: &str) -> Result<()> {
    if v.is_finite() && ok {
        Ok(())
    } else {
        Err(profile_error(key, v, format!("expected {expected}")))
    }
}

fn check_foot(side: &str, f: &Foot) -> Result<()> {
    let k = |s: &str| format!("feet.{side}.{s}");
    check_number(
        &k("ankle_height"),
        f.ankle_height,
        f.ankle_height >= 0.0,
        "a height >= 0 [m]",
    )?;
    check_number(
        &k("sole.length"),
        f.sole.length,
        f.sole.length > 0.0,
        "a length > 0 [m]",
    )?;
    check_number(
        &k("sole.width"),
        f.sole.width,
        f.sole.width > 0.0,
        "a width > 0 [m]",
    )?;
    check_number(
        &k("sole.offset_x"),
        f.sole.offset_x,
        true,
        "a finite offset [m]",
    )
}

impl RobotProfile {
    /// Checks the numbers that do not need the robot: soles, ankle heights, posture angles,
    /// narrowed ranges (`lower ≤ upper`), acceleration limits and ratio (`> 0`), walking
    /// settings.
    pub fn check_values(&self) -> Result<()> {
        for (i, l) in self.lock.iter().enumerate() {
            check_number(&format!("lock[{i}].value"), l.value, true, "a finite value")?;
        }
        for (i, f) in self.added_frames.iter().enumerate() {
            for (key, v) in [("xyz", f.xyz), ("rpy", f.rpy)] {
                for x in v {
                    check_number(
                        &format!("frame[{i}].{key}"),
                        x,
                        true,
                        "three finite numbers ([m] for xyz, [rad] for rpy)",
                    )?;
                }
            }
        }
        if let Some(feet) = &self.feet {
            check_foot("left", &feet.left)?;
            check_foot("right", &feet.right)?;
        }
        for (j, v) in &self.posture {
            check_number(&format!("posture.{j}"), *v, true, "a finite angle [rad]")?;
        }
        for n in &self.narrow {
            if n.validate("narrow").is_err() {
                return Err(profile_error(
                    &format!("narrow.{}", n.joint),
                    format!("[{}, {}]", n.lower, n.upper),
                    "expected finite [lower, upper] with lower <= upper [rad]",
                ));
            }
        }
        if let Some(v) = self.velocity.default {
            check_number("velocity.default", v, v > 0.0, "a limit > 0 [rad/s or m/s]")?;
        }
        for (j, v) in &self.velocity.limits {
            check_number(
                &format!("velocity.limits.{j}"),
                *v,
                *v > 0.0,
                "a limit > 0 [rad/s or m/s]",
            )?;
        }
        let a = &self.acceleration;
        check_number(
            "acceleration.per_velocity",
            a.per_velocity,
            a.per_velocity > 0.0,
            "a ratio > 0 [1/s]",
        )?;
        for (j, v) in &a.limits {
            check_number(
                &format!("acceleration.limits.{j}"),
                *v,
                *v > 0.0,
                "a limit > 0 [rad/s² or m/s²]",
            )?;
        }
        if let Some(r) = self.jerk.per_acceleration {
            check_number("jerk.per_acceleration", r, r > 0.0, "a ratio > 0 [1/s]")?;
        }
        for (j, v) in &self.jerk.limits {
            check_number(
                &format!("jerk.limits.{j}"),
                *v,
                *v > 0.0,
                "a limit > 0 [rad/s³ or m/s³]",
            )?;
        }
        self.check_walk()
    }

    /// The joints each `lock` rule holds, expanded over the movable joints of `joints` (first
    /// matching rule wins). A rule that matches nothing is an error naming it.
    pub fn expand_locks(&self, movable: &[String]) -> Result<Vec<(String, f64)>> {
        let mut out: Vec<(String, f64)> = Vec::new();
        for (i, rule) in self.lock.iter().enumerate() {
            let mut matched = false;
            for name in movable.iter().filter(|n| glob_match(&rule.joints, n)) {
                matched = true;
                if !out.iter().any(|(n, _)| n == name) {
                    out.push((name.clone(), rule.value));
                }
            }
            if !matched {
                return Err(profile_error(
                    &format!("lock[{i}].joints"),
                    &rule.joints,
                    format!(
                        "the pattern matches no movable joint; joints are {}",
                        list(movable)
                    ),
                ));
            }
        }
        Ok(out)
    }

    /// Checks that every joint with an acceleration, velocity or jerk limit is one of the
    /// robot's `movable` joints.
    fn check_limited_joints(&self, movable: &[String]) -> Result<()> {
        let limited = self
            .acceleration
            .limits
            .keys()
            .map(|j| ("acceleration", j))
            .chain(self.velocity.limits.keys().map(|j| ("velocity", j)))
            .chain(self.jerk.limits.keys().map(|j| ("jerk", j)));
        for (key, j) in limited {
            if !movable.contains(j) {
                return Err(profile_error(
                    &format!("{key}.limits.{j}"),
                    j,
                    format!("no such movable joint; joints are {}", list(movable)),
                ));
            }
        }
        Ok(())
    }

    /// Builds the robot: the URDF (key `urdf`) with the profile's base, locked joints and
    /// acceleration limits, then checks every frame and joint the profile names
    /// ([`RobotProfile::check_robot`]).
    pub fn robot(&self) -> Result<Robot> {
        let text = self.urdf_text()?;
        let dir = self.urdf_dir();
        let bare = Robot::from_description_str(
            &text,
            dir.as_deref(),
            &ModelOptions {
                base: self.base,
                ..ModelOptions::default()
            },
        )
        .map_err(|e| profile_error("urdf", &self.urdf, e.to_string()))?;
        let movable: Vec<String> = bare
            .joints()
            .iter()
            .filter(|j| !matches!(j.kind, JointKind::Fixed))
            .map(|j| j.name.clone())
            .collect();
        self.check_limited_joints(&movable)?;
        let options = ModelOptions {
            base: self.base,
            locked: self.expand_locks(&movable)?,
            acceleration_limits: self
                .acceleration
                .limits
                .iter()
                .map(|(k, v)| (k.clone(), *v))
                .collect(),
            velocity_limits: self
                .velocity
                .limits
                .iter()
                .map(|(k, v)| (k.clone(), *v))
                .collect(),
            fallback_velocity: self.velocity.default.unwrap_or(f64::INFINITY),
            acceleration_per_velocity: self.acceleration.per_velocity,
            jerk_limits: self
                .jerk
                .limits
                .iter()
                .map(|(k, v)| (k.clone(), *v))
                .collect(),
            jerk_per_acceleration: self.jerk.per_acceleration.unwrap_or(f64::INFINITY),
            ..ModelOptions::default()
        };
        let mut robot = Robot::from_description_str(&text, dir.as_deref(), &options)
            .map_err(|e| profile_error("urdf", &self.urdf, e.to_string()))?;
        for (i, f) in self.added_frames.iter().enumerate() {
            let offset = Isometry3::from_parts(
                Translation3::from(Vector3::from(f.xyz)),
                UnitQuaternion::from_euler_angles(f.rpy[0], f.rpy[1], f.rpy[2]),
            );
            robot = robot.with_frame(&f.name, &f.parent, offset).map_err(|e| {
                let key = match e {
                    Error::UnknownName { .. } => "parent",
                    Error::InvalidSetting { .. } => "name",
                    _ => "xyz",
                };
                let value = if key == "parent" { &f.parent } else { &f.name };
                profile_error(&format!("frame[{i}].{key}"), value, e.to_string())
            })?;
        }
        self.check_robot(&robot)?;
        Ok(robot)
    }

    /// The robot standing in the profile's start posture: the joints at `posture` (0 where it
    /// names none), at rest, the base upright at the origin's vertical and raised so that the
    /// lower foot frame is `ankle_height` above the ground (z = 0), its sole on it. The state
    /// the keypoint route starts from; `State::neutral` instead has the base at the origin.
    ///
    /// Errors: no feet in the profile, a posture joint or a foot frame `robot` lacks (`robot`
    /// is this profile's robot, [`RobotProfile::robot`]), a fixed-base robot (it does not
    /// stand: key `base`).
    pub fn standing_state(&self, robot: &Robot) -> Result<State> {
        let cfg = self.imitate_config(ImitateConfig::default())?;
        if robot.base() != crate::model::BaseKind::Floating {
            return Err(profile_error(
                "base",
                "fixed",
                "a standing state needs a floating base: the robot is raised onto its feet",
            ));
        }
        let mut state = State::neutral(robot);
        for (name, value) in &cfg.initial_posture {
            state.set_joint(robot, name, *value)?;
        }
        let kin = Kinematics::new(robot, &state)?;
        let mut lowest = f64::INFINITY;
        for foot in &cfg.feet {
            let id = robot.frame_id(foot)?;
            lowest = lowest.min(kin.frame_pose(robot, id)?.translation.z);
        }
        let mut base = state.base_pose(robot);
        base.translation.vector.z += cfg.support.ankle_height - lowest;
        state.set_base_pose(robot, &base)?;
        Ok(state)
    }

    /// Checks every frame and joint the profile names against `robot`: feet and body frames
    /// exist, posture and narrowed joints are active joints, narrowed ranges lie inside the
    /// joints' own.
    pub fn check_robot(&self, robot: &Robot) -> Result<()> {
        let frame = |key: &str, name: &str| -> Result<()> {
            robot.frame_id(name).map(|_| ()).map_err(|_| {
                profile_error(
                    key,
                    name,
                    format!(
                        "no such frame; frames are {}",
                        list(robot.frames().iter().map(|f| &f.name))
                    ),
                )
            })
        };
        if let Some(Feet { left, right }) = &self.feet {
            frame("feet.left.frame", &left.frame)?;
            frame("feet.right.frame", &right.frame)?;
        }
        let f = &self.frames;
        for (key, v) in [
            ("frames.pelvis", &f.pelvis),
            ("frames.torso", &f.torso),
            ("frames.head", &f.head),
            ("frames.left_hand", &f.left_hand),
            ("frames.right_hand", &f.right_hand),
        ] {
            if let Some(name) = v {
                frame(key, name)?;
            }
        }
        let active = || list(robot.active_joints().map(|j| &j.name));
        for j in self.posture.keys() {
            robot.active_joint_index(j).map_err(|_| {
                profile_error(
                    &format!("posture.{j}"),
                    j,
                    format!("no such active joint; active joints are {}", active()),
                )
            })?;
        }
        let limits = robot.dof_limits();
        for n in &self.narrow {
            let (j, lo, hi) = (&n.joint, &n.lower, &n.upper);
            let key = format!("narrow.{j}");
            let v = robot.joint_v_index(j).map_err(|_| {
                profile_error(
                    &key,
                    j,
                    format!("no such active joint; active joints are {}", active()),
                )
            })?;
            if let Some(l) = limits.get(v) {
                if *lo < l.lower || *hi > l.upper {
                    return Err(profile_error(
                        &key,
                        format!("[{lo}, {hi}]"),
                        format!(
                            "expected a range inside the joint's own [{}, {}] rad",
                            l.lower, l.upper
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The imitation's settings for this robot: `base` with its robot-specific fields replaced
    /// by the profile's: feet (right, then left), pelvis, initial posture, narrowed ranges and
    /// the sole and ankle height of the support polygon.
    ///
    /// Errors: no feet or no pelvis frame (naming the key to set), feet with different soles
    /// or ankle heights (the support code uses one sole for both feet).
    pub fn imitate_config(&self, base: ImitateConfig) -> Result<ImitateConfig> {
        let feet = self.feet.as_ref().ok_or_else(|| {
            profile_error(
                "feet",
                MISSING,
                "the imitation holds two feet: set `feet.left` and `feet.right` (frame, sole, ankle_height)",
            )
        })?;
        let pelvis = self.frames.pelvis.clone().ok_or_else(|| {
            profile_error(
                "frames.pelvis",
                MISSING,
                "the imitation drives the pelvis attitude and height: set the pelvis frame",
            )
        })?;
        let (l, r) = (&feet.left, &feet.right);
        if l.sole != r.sole || l.ankle_height != r.ankle_height {
            return Err(profile_error(
                "feet.right.sole",
                format!(
                    "{:?}, ankle height {} m",
                    r.sole, r.ankle_height
                ),
                format!(
                    "the support polygon uses one sole and ankle height for both feet: expected the same as `feet.left` ({:?}, ankle height {} m)",
                    l.sole, l.ankle_height
                ),
            ));
        }
        Ok(ImitateConfig {
            feet: vec![r.frame.clone(), l.frame.clone()],
            pelvis,
            initial_posture: self.posture.iter().map(|(k, v)| (k.clone(), *v)).collect(),
            narrow: self.narrow.clone(),
            support: SupportSettings {
                sole_length: l.sole.length,
                sole_width: l.sole.width,
                sole_offset_x: l.sole.offset_x,
                ankle_height: l.ankle_height,
            },
            ..base
        })
    }

    /// The retargeting map for motions of `format` (`deepmimic`, `bvh`): the entry
    /// `imitate.maps.<format>`, a built-in map name or a TOML file relative to the profile;
    /// checked against `robot` ([`check_map_joints`]).
    pub fn retarget_map(&self, format: &str, robot: &Robot) -> Result<RetargetMap> {
        let key = format!("imitate.maps.{format}");
        let spec = self.imitate.maps.get(format).ok_or_else(|| {
            profile_error(
                &key,
                MISSING,
                format!(
                    "profile `{}` has no retargeting map for {format} motions; maps are given for: {}",
                    self.name,
                    if self.imitate.maps.is_empty() {
                        "none".to_string()
                    } else {
                        list(self.imitate.maps.keys())
                    }
                ),
            )
        })?;
        let map = if crate::motion::BUILTIN_MAP_NAMES.contains(&spec.as_str()) {
            crate::motion::builtin_map(spec)?
        } else {
            let text = self.read_relative(&key, spec)?;
            RetargetMap::from_toml_str(&text, spec)?
        };
        check_map_joints(robot, &map).map_err(|e| profile_error(&key, spec, e.to_string()))?;
        Ok(map)
    }
}

/// Checks that every robot joint a map names is an active joint of `robot`; the error names
/// the map, the entry (source joint or `hold`) and the valid joints.
pub fn check_map_joints(robot: &Robot, map: &RetargetMap) -> Result<()> {
    let targets = map
        .joints
        .iter()
        .flat_map(|j| {
            j.targets
                .iter()
                .map(move |t| (format!("entry `{}`", j.source), &t.joint))
        })
        .chain(map.holds.iter().map(|h| ("a `hold`".to_string(), &h.joint)));
    for (entry, joint) in targets {
        if robot.active_joint_index(joint).is_err() {
            return Err(Error::InvalidSetting {
                name: format!("retargeting map `{}`, {entry}: robot joint", map.name),
                value: joint.clone(),
                expected: format!(
                    "an active joint of `{}`; active joints are {}",
                    robot.name(),
                    list(robot.active_joints().map(|j| &j.name))
                ),
            });
        }
    }
    Ok(())
}
