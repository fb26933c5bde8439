//! Biovision hierarchy (BVH) files: reader, writer and conversion to and from [`Clip`](super::Clip).
//!
//! Rotation convention (see [`bvh_rotation`]): a joint's rotation channels, listed `c_1 c_2 c_3`,
//! give `R = Rot(c_1, θ_1) · Rot(c_2, θ_2) · Rot(c_3, θ_3)`, intrinsic rotations in the listed
//! order; `R` maps the joint's frame to its parent's.

mod convert;
mod read;
mod types;
mod write;

pub use convert::{bvh_rotation, repeats_offsets};
pub use read::read_bvh;
pub use types::{
    BvhChannel, BvhClip, BvhExportOptions, BvhJoint, BvhReadOptions, BvhWriteOptions, LengthUnit,
    RotationOrder,
};
pub use write::{write_bvh, write_clip_bvh};
