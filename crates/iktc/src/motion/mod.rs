//! Captured motion: clips, readers and writers, and the rotation decomposition used to retarget
//! captured joint rotations onto robot joints.
//!
//! * [`Clip`] — plain data: a [`Skeleton`] (named joints, parents, rest offsets \[m\], spherical /
//!   hinge / fixed / root), frame times \[s\] and one [`Pose`] per frame (root position \[m\], root
//!   orientation, local joint rotations); sampling at any time (slerp) and forward kinematics.
//! * [`read_deepmimic`], [`builtin_clip`] — DeepMimic motion files on the DeepMimic humanoid
//!   (Y-up; convert with [`Clip::to_z_up`] / [`y_up_to_z_up`]).
//! * [`read_bvh`], [`write_bvh`], [`BvhClip`] — Biovision hierarchy files with any hierarchy
//!   and channel order, in centimetres, metres or any length unit.
//! * [`load_motion`] — any motion file (BVH, ASF/AMC, DeepMimic, C3D, points CSV, AMASS
//!   archives with a body model file), its format
//!   detected, its units and up axis given or decided ([`Units`], [`UpChoice`]), its body
//!   points recognised without a map ([`recognise_skeleton`], [`recognise_markers`], or a
//!   [`BodyMap`] TOML), reduced to [`Keypoints`]: named body points per frame in metres, Z up.
//! * [`read_asf`], [`read_amc`], [`read_c3d`], [`read_points_csv`], [`amass`] (feature
//!   `amass`) — the readers behind it.
//! * [`decompose_rotation`] — a rotation as a product of rotations about 1–3 given joint axes
//!   (generalised Euler / Davenport angles in closed form, least squares otherwise).
//! * [`retarget_joint_angles`], [`RetargetMap`], [`builtin_map`] — a clip to robot joint, pelvis height and
//!   pelvis attitude references (a TOML map names which source joint drives which robot joints),
//!   resampled to the control rate by C² splines ([`Retargeted::resample`], [`CubicSpline`]).
//!
//! ```
//! use iktc::motion::{builtin_clip, decompose_rotation, write_clip_bvh, BvhExportOptions,
//!     BvhWriteOptions};
//! use nalgebra::Vector3;
//!
//! let clip = builtin_clip("humanoid3d_walk")?.to_z_up();
//! assert_eq!(clip.frame_count(), 39);
//! let pose = clip.sample(0.5)?; // slerp between frames 15 and 16
//! let shoulder = clip.skeleton().index_of("right_shoulder")?;
//! // The shoulder's rotation as three angles about the character's z, x, y axes [rad].
//! let mut angles = [0.0; 3];
//! let report = decompose_rotation(
//!     &pose.rotations[shoulder],
//!     &[Vector3::z(), Vector3::x(), Vector3::y()],
//!     None,
//!     &mut angles,
//! )?;
//! assert!(report.residual < 1e-9);
//! let bvh_text = write_clip_bvh(&clip, &BvhExportOptions::default(), &BvhWriteOptions::default())?;
//! assert!(bvh_text.starts_with("HIERARCHY"));
//! # Ok::<(), iktc::Error>(())
//! ```

#[cfg(feature = "amass")]
pub mod amass;
mod amc;
mod angles;
mod asf;
mod body_map;
mod body_point;
mod bvh;
mod c3d;
mod clip;
mod decompose;
#[cfg(all(feature = "urdf", feature = "json"))]
mod deepmimic;
mod keypoints;
mod load;
mod lowpass;
mod markers;
mod names;
pub mod plausible;
mod points_csv;
mod recognise;
mod retarget;
mod retarget_map;
mod shape;
mod skeleton;
mod spline;
mod units;

pub use amc::{read_amc, AMC_DEFAULT_RATE};
pub use angles::{nearest_equivalent, unwrap_track, wrap_to_pi};
pub use asf::{read_asf, Asf, AsfBone, AsfDof};
pub use body_map::{BodyMap, FoundBy, MappedPoint, PointSource};
pub use body_point::{BodyPoint, Side};
pub use bvh::{
    bvh_rotation, read_bvh, repeats_offsets, write_bvh, write_clip_bvh, BvhChannel, BvhClip,
    BvhExportOptions, BvhJoint, BvhReadOptions, BvhWriteOptions, LengthUnit, RotationOrder,
};
pub use c3d::read_c3d;
pub use clip::{y_up_to_z_up, Clip, Pose, UpAxis};
pub use decompose::{
    compose_rotation, decompose_rotation, decompose_rotation_with, rotation_angle,
    DecomposeSettings, Decomposition, DecompositionMethod, MAX_DECOMPOSITION_AXES,
};
#[cfg(all(feature = "urdf", feature = "json"))]
pub use deepmimic::{
    builtin_clip, builtin_clip_text, deepmimic_skeleton, read_deepmimic, read_deepmimic_with,
    DeepMimicSettings, BUILTIN_CLIP_NAMES, DEEPMIMIC_FRAME_LEN, DEEPMIMIC_URDF,
    DEEPMIMIC_URDF_SCALE,
};
pub use keypoints::{clip_keypoints, marker_keypoints, Keypoints};
pub use load::{
    detect_format, find_asf, is_amass_archive, is_amass_file, load_motion, motion_from_content,
    scale_clip, strip_bom, Motion, MotionContent, MotionFormat, MotionOptions,
};
pub use lowpass::{check_smoothing, lowpass, lowpass_track};
pub use markers::{FilledGap, MarkerSet, DEFAULT_MAX_GAP};
pub use points_csv::read_points_csv;
pub use recognise::{
    builtin_body_map, draft_body_map_toml, marker_points, recognise_markers, recognise_skeleton,
    skeleton_points, BUILTIN_BODY_MAP_NAMES,
};
pub use retarget::{retarget_joint_angles, shrunk_range, Retargeted, RobotReferences, Track};
#[cfg(feature = "toml")]
pub use retarget_map::{builtin_map, builtin_map_text, BUILTIN_MAP_NAMES};
pub use retarget_map::{HoldJoint, JointMap, RetargetMap, RootMap, TargetJoint};
pub use skeleton::{JointKind, Skeleton, SkeletonJoint};
pub use spline::CubicSpline;
pub use units::{
    decide_units, decide_up, stands, to_z_up, unit_name, Measured, Units, UnitsDecision, UpChoice,
    UpDecision, CMU_METRES_PER_UNIT, HUMAN_HEIGHT_MAX, HUMAN_HEIGHT_MIN,
};
