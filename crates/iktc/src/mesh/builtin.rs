//! The built-in robots' meshes, embedded in the library.
//!
//! `data/robots/g1/meshes.bin` holds the Unitree G1's 35 visual meshes (Unitree's STL files,
//! BSD 3-Clause; see `data/NOTICE.md`), decimated on [`VIEWER_CELL`](super::VIEWER_CELL) and
//! packed by [`pack`](super::pack). It is made from the G1 description folder (the URDF with
//! its `meshes/`) by
//!
//! ```text
//! cargo run -p iktc --release --example pack_meshes -- PATH/g1_29dof_rev_1_0.urdf \
//!     crates/iktc/data/robots/g1/meshes.bin
//! ```

use super::{unpack, MeshSet};
use crate::error::Result;

/// The packed G1 meshes.
pub const G1_MESHES: &[u8] = include_bytes!("../../data/robots/g1/meshes.bin");

/// The file name of the built-in G1's URDF, as the built-in profile names it.
const G1_URDF_NAME: &str = "g1_29dof_rev_1_0.urdf";

/// The meshes of the built-in robot whose profile names the URDF `urdf` (a path ending in the
/// embedded file's name); `Ok(None)` for a built-in robot without meshes (JVRC-1).
///
/// # Errors
/// [`crate::error::Error::Parse`] if the embedded data are damaged (a build problem).
pub fn builtin_meshes(urdf: &str) -> Result<Option<MeshSet>> {
    if urdf.rsplit('/').next() == Some(G1_URDF_NAME) {
        return unpack(G1_MESHES).map(Some);
    }
    Ok(None)
}

#[cfg(all(test, feature = "urdf"))]
mod tests {
    use super::*;
    use crate::model::{g1, Kinematics, ModelOptions, State, G1_URDF};

    #[test]
    fn g1_meshes_cover_its_links_and_stand_on_the_soles() {
        let set = builtin_meshes("../robots/g1/g1_29dof_rev_1_0.urdf")
            .unwrap()
            .unwrap();
        assert!(builtin_meshes("../robots/jvrc1/jvrc1.urdf")
            .unwrap()
            .is_none());
        let robot = g1(&ModelOptions::default()).unwrap();
        let names: Vec<&str> = robot.links().iter().map(|l| l.name.as_str()).collect();
        // Every mesh belongs to a G1 link, and every leg and arm link has one.
        for m in &set.meshes {
            assert!(names.contains(&m.link.as_str()), "{}", m.link);
        }
        for side in ["left", "right"] {
            for l in ["hip_pitch", "knee", "ankle_roll", "shoulder_pitch", "elbow"] {
                let n = format!("{side}_{l}_link");
                assert!(set.meshes.iter().any(|m| m.link == n), "{n} has no mesh");
            }
        }
        // At the zero posture, the lowest mesh point is the soles: at the height of the feet's
        // collision spheres' bottoms (from the URDF, not the meshes), within a cell.
        let state = State::neutral(&robot);
        let kin = Kinematics::new(&robot, &state).unwrap();
        let mut lowest = f64::INFINITY;
        for m in &set.meshes {
            let i = names.iter().position(|n| *n == m.link).unwrap();
            let pose = kin.link_poses()[i];
            for v in m.mesh.vertices() {
                let p = pose * nalgebra::Point3::new(v[0] as f64, v[1] as f64, v[2] as f64);
                lowest = lowest.min(p.z);
            }
        }
        let sole = sphere_bottom(&robot, &kin, "left_ankle_roll_link");
        assert!(
            (lowest - sole).abs() < 2.0 * crate::mesh::VIEWER_CELL,
            "lowest mesh point {lowest} m, sole {sole} m"
        );
        // Well under the 1 MB the crate may grow by (160 KB when made).
        assert!(G1_MESHES.len() < 250_000, "{} bytes", G1_MESHES.len());
    }

    /// The lowest point of the collision spheres of `link` in the G1 URDF \[m\], world.
    fn sphere_bottom(robot: &crate::model::Robot, kin: &Kinematics, link: &str) -> f64 {
        let u = urdf_rs::read_from_string(G1_URDF).unwrap();
        let l = u.links.iter().find(|l| l.name == link).unwrap();
        let i = robot.links().iter().position(|x| x.name == link).unwrap();
        let pose = kin.link_poses()[i];
        l.collision
            .iter()
            .filter_map(|c| match c.geometry {
                urdf_rs::Geometry::Sphere { radius } => {
                    let o = nalgebra::Point3::from(c.origin.xyz.0);
                    Some((pose * o).z - radius)
                }
                _ => None,
            })
            .fold(f64::INFINITY, f64::min)
    }
}
