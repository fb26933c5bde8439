//! Robot profiles: everything iktc needs about a robot beyond its URDF, in one TOML file.
//!
//! ```toml
//! name = "g1"
//! urdf = "../robots/g1/g1_29dof_rev_1_0.urdf"   # relative to this file
//! base = "floating"                              # or "fixed"
//!
//! [[lock]]                                       # joints held at a value, by glob
//! joints = "*_FINGER_*"                          # `*` any run, `?` one character
//! value = 0.0                                    # [rad] or [m]
//!
//! [feet.left]
//! frame = "left_ankle_roll_link"
//! ankle_height = 0.035                           # foot frame above the sole [m]
//! sole = { length = 0.17, width = 0.05, offset_x = 0.035 }   # in the foot frame [m]
//!
//! [feet.right]
//! frame = "right_ankle_roll_link"
//! ankle_height = 0.035
//! sole = { length = 0.17, width = 0.05, offset_x = 0.035 }
//!
//! [[frame]]                                      # frames added to the robot (optional)
//! name = "left_hand_tip"                         # a point the URDF has no link at
//! parent = "left_elbow_link"                     # the link or frame it is fixed to
//! xyz = [0.3, 0.0, 0.0]                          # [m] in the parent; rpy = [...] [rad]
//!
//! [frames]                                       # all optional
//! pelvis = "pelvis"
//! torso = "torso_link"
//! head = "head_link"
//! left_hand = "left_rubber_hand"
//! right_hand = "right_rubber_hand"
//!
//! [posture]                                      # initial joint angles [rad]
//! left_knee_joint = 0.6
//!
//! [narrow]                                       # default narrowed ranges [rad]
//! left_knee_joint = [0.3, 0.9]
//!
//! [velocity]                                    # for files without velocity limits (MJCF)
//! default = 20.0                                 # joints the file gives none [rad/s]
//! limits = { left_knee_joint = 14.0 }            # [rad/s], replacing the file's
//!
//! [acceleration]
//! per_velocity = 10.0                            # default limit / velocity limit [1/s]
//! limits = { left_knee_joint = 200.0 }           # [rad/s²]
//!
//! [jerk]                                         # optional; none by default
//! per_acceleration = 20.0                        # default limit / acceleration limit [1/s]
//! limits = { left_knee_joint = 3000.0 }          # [rad/s³]
//!
//! [walk]                                         # all optional (iktc walk)
//! step_length = 0.1                              # [m]
//! swing_height = 0.04                            # [m]
//! ssp_duration = 0.6                             # single support [s]
//! dsp_duration = 0.1                             # double support between steps [s]
//! push = { time = 2.15, impulse = [2.67, 0.0] }  # [s], [N·s]; default: m × 0.080 m/s
//!
//! [imitate.maps]                                 # retargeting map per motion format
//! deepmimic = "deepmimic_g1"                     # built-in name or file relative to this one
//! ```
//!
//! [`RobotProfile::load`] reads a file, [`RobotProfile::builtin`] a built-in profile (`jvrc1`,
//! `g1`), [`RobotProfile::robot`] builds the [`Robot`](crate::model::Robot) with the locks and
//! acceleration and jerk limits and checks every name the profile uses;
//! [`RobotProfile::imitate_config`] gives the imitation its feet, pelvis, posture, narrowed
//! ranges and soles. Every error names the key that holds the wrong value
//! ([`Error::Profile`](crate::Error::Profile)), e.g. ``profile key `feet.left.frame` = `X`: no
//! such frame; frames are …``. [`init_profile_toml`] guesses a starting profile from a URDF.
//!
//! ```
//! use iktc::profile::RobotProfile;
//!
//! let g1 = RobotProfile::builtin("g1")?;
//! let robot = g1.robot()?;
//! assert_eq!(robot.nv(), 6 + 29);
//! let cfg = g1.imitate_config(iktc::sim::ImitateConfig::default())?;
//! assert_eq!(cfg.feet, ["right_ankle_roll_link", "left_ankle_roll_link"]);
//! # Ok::<(), iktc::Error>(())
//! ```

mod build;
mod glob;
mod init;
mod load;
mod schema;
mod shape;
#[cfg(test)]
mod shape_tests;
mod sole;
mod walk;

pub use build::{check_map_joints, MISSING};
pub use glob::glob_match;
pub use init::{
    init_profile_toml, init_profile_toml_at, init_profile_toml_with, urdf_key, InitOptions,
    GUESSED_VELOCITY,
};
pub use load::{builtin_profile_text, BUILTIN_PROFILES};
pub use schema::{
    AccelerationProfile, AddedFrame, BodyFrames, Feet, Foot, ImitateProfile, JerkProfile, LockRule,
    ProfileOrigin, PushProfile, RobotProfile, Sole, VelocityProfile, WalkProfile,
};
pub use walk::DEFAULT_PUSH_VELOCITY_CHANGE;
