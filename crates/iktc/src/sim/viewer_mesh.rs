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
pub(crate) const QUAT_SCALE: f32 = 32767.0;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{unpack, LinkMesh, QuantizedMesh, TriMesh};
    use crate::model::planar3r;
    use crate::sim::viewer::{robot_figure, Figure3d};
    use nalgebra::{UnitQuaternion, Vector3};

    fn data(robot: &Robot, rotations: Vec<Vec<[f32; 4]>>) -> ViewerData {
        let mut figure = robot_figure(robot);
        figure.frames = vec![vec![[0.0; 3]; robot.links().len()]; rotations.len()];
        ViewerData {
            title: "t".into(),
            dt: 0.02,
            robot: figure,
            skeleton: Figure3d {
                name: "s".into(),
                segments: Vec::new(),
                frames: Vec::new(),
            },
            com: Vec::new(),
            support: Vec::new(),
            on_limit: Vec::new(),
            on_limit_names: Vec::new(),
            support_frames: Vec::new(),
            footsteps: Vec::new(),
            phases: Vec::new(),
            robot_rotations: rotations,
            meshes: None,
        }
    }

    fn mesh(link: &str) -> LinkMesh {
        let m = TriMesh {
            vertices: vec![[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.2, 0.0]],
            triangles: vec![[0, 1, 2]],
        };
        LinkMesh {
            link: link.into(),
            color: [1, 2, 3],
            mesh: QuantizedMesh::new(&m).unwrap(),
        }
    }

    #[test]
    fn orientations_round_trip_within_half_a_step_and_unknown_links_are_warned() {
        let robot = planar3r();
        let nl = robot.links().len();
        // Turns about a tilted axis, one per link and frame.
        let axis = nalgebra::Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
        let rotations: Vec<Vec<[f32; 4]>> = (0..3)
            .map(|f| {
                (0..nl)
                    .map(|l| {
                        let q = UnitQuaternion::from_axis_angle(&axis, 0.4 * (f * nl + l) as f64);
                        q.coords.map(|x| x as f32).into()
                    })
                    .collect()
            })
            .collect();
        let mut d = data(&robot, rotations.clone());
        let set = MeshSet {
            meshes: vec![mesh("link2"), mesh("no_such_link")],
        };
        let warnings = d.attach_meshes(&robot, &set).unwrap();
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("no_such_link"), "{}", warnings[0]);
        let m = d.meshes.as_ref().unwrap();
        assert_eq!(m.triangles, 1);
        assert_eq!(m.links.len(), nl);
        let packed = unpack(&base64::decode(&m.packed).unwrap()).unwrap();
        assert_eq!(packed.meshes, vec![mesh("link2")]);
        let bytes = base64::decode(&m.rotations).unwrap();
        assert_eq!(bytes.len(), 3 * nl * 4 * 2);
        let read: Vec<f32> = bytes
            .chunks(2)
            .map(|b| f32::from(i16::from_le_bytes([b[0], b[1]])) / QUAT_SCALE)
            .collect();
        let want: Vec<f32> = rotations.iter().flatten().flatten().copied().collect();
        for (a, b) in read.iter().zip(&want) {
            // Half a step of 1/32767, plus the f32 rounding of the division.
            assert!((a - b).abs() <= 0.5 / QUAT_SCALE + 1e-7, "{a} vs {b}");
        }
    }

    #[test]
    fn orientations_of_the_wrong_size_are_an_error() {
        let robot = planar3r();
        let mut d = data(&robot, vec![vec![[0.0, 0.0, 0.0, 1.0]; 2]]);
        let e = d
            .attach_meshes(&robot, &MeshSet::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("link orientations"), "{e}");
        let mut d = data(&robot, Vec::new());
        d.robot.frames.push(Vec::new());
        assert!(d.attach_meshes(&robot, &MeshSet::default()).is_err());
    }
}
