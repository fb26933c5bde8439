//! Captured motion: clips, readers and writers, and the rotation decomposition used to retarget
//! captured joint rotations onto robot joints.
//!
//! * [`decompose_rotation`] — a rotation as a product of rotations about 1–3 given joint axes
//!   (generalised Euler / Davenport angles in closed form, least squares otherwise).

mod angles;
mod decompose;

pub use angles::{nearest_equivalent, unwrap_track, wrap_to_pi};
pub use decompose::{
    compose_rotation, decompose_rotation, decompose_rotation_with, rotation_angle, DecomposeSettings,
    Decomposition, DecompositionMethod, MAX_DECOMPOSITION_AXES,
};
