//! The robot's meshes in the viewer data: the packed meshes ([`crate::mesh::pack`]) and every
//! frame's link orientations, both base64 in the page.
//!
//! Orientations are stored as 16-bit integers: each quaternion component `c ∈ [−1, 1]` as
//! `round(c · 32767)` (little-endian `i16`), frames × links × (x, y, z, w). The page places
//! each mesh vertex `v` (link frame) at `p + R(q)·v` with `p` the link's position of the frame
//! ([`Figure3d::frames`](super::viewer::Figure3d::frames)) and `q` its orientation.

use serde::Serialize;

use super::viewer::ViewerData;
use crate::error::{Error, Result};
use crate::mesh::{base64, pack, MeshSet};
use crate::model::Robot;

/// Scale of a quaternion component in its 16-bit integer (1 ↦ 32767).
pub const QUAT_SCALE: f32 = 32767.0;

/// The meshes and link orientations of a viewer page.
#[derive(Debug, Clone, Serialize)]
pub struct ViewerMeshes {
    /// Base64 of the packed meshes of the robot's links ([`crate::mesh::pack`]).
    pub packed: String,
    /// The robot's link names, in the order of the frames' points.
    pub links: Vec<String>,
    /// Base64 of the link orientations of every frame (module docs).
    pub rotations: String,
    /// Triangles over all meshes.
    pub triangles: usize,
}

impl ViewerData {
    /// Puts `set`, the meshes of `robot`'s links, in the page; returns a warning for every mesh
    /// of a link the robot does not have (left out).
    ///
    /// # Errors
    /// [`Error::DimensionMismatch`] when the link orientations recorded do not match the
    /// robot's links at every frame.
    pub fn attach_meshes(&mut self, robot: &Robot, set: &MeshSet) -> Result<Vec<String>> {
        let links: Vec<String> = robot.links().iter().map(|l| l.name.clone()).collect();
        let n = self.robot.frames.len();
        if self.robot_rotations.len() != n {
            return Err(Error::DimensionMismatch {
                what: "viewer frames with link orientations".into(),
                expected: n,
                got: self.robot_rotations.len(),
            });
        }
        let mut bytes = Vec::with_capacity(n * links.len() * 8);
        for f in &self.robot_rotations {
            if f.len() != links.len() {
                return Err(Error::DimensionMismatch {
                    what: "link orientations of a viewer frame".into(),
                    expected: links.len(),
                    got: f.len(),
                });
            }
            for c in f.iter().flatten() {
                let v = (c.clamp(-1.0, 1.0) * QUAT_SCALE).round() as i16;
                bytes.extend(v.to_le_bytes());
            }
        }
        let (kept, unknown): (Vec<_>, Vec<_>) = set
            .meshes
            .iter()
            .cloned()
            .partition(|m| links.contains(&m.link));
        let kept = MeshSet { meshes: kept };
        self.meshes = Some(ViewerMeshes {
            packed: base64::encode(&pack(&kept)),
            links,
            rotations: base64::encode(&bytes),
            triangles: kept.triangle_count(),
        });
        Ok(unknown
            .iter()
            .map(|m| {
                format!(
                    "the mesh of link `{}` is left out: {} has no such link",
                    m.link,
                    robot.name()
                )
            })
            .collect())
    }
}
