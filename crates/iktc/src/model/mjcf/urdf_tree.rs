//! The MJCF model as a URDF tree (`urdf_rs::Robot`), for what reads a robot's geometry:
//! `iktc profile init` (feet, soles), the viewer's meshes, the batch record's mesh files.

use nalgebra::{Isometry3, Matrix3};

use super::body::Tree;
use super::geom::{Geom, MeshAsset, Shape};
use crate::model::{JointKind, JointSpec, Link};
use std::collections::HashMap;

/// A URDF `<origin>` of `p` (rotation as roll, pitch, yaw \[rad\], `Rz·Ry·Rx`).
fn pose(p: &Isometry3<f64>) -> urdf_rs::Pose {
    let (r, pi, y) = p.rotation.euler_angles();
    urdf_rs::Pose {
        xyz: urdf_rs::Vec3(p.translation.vector.into()),
        rpy: urdf_rs::Vec3([r, pi, y]),
    }
}

/// The URDF geometry of a geom; `None` for an ellipsoid, a plane or other shapes URDF lacks.
fn geometry(g: &Geom, meshes: &HashMap<String, MeshAsset>) -> Option<urdf_rs::Geometry> {
    Some(match &g.shape {
        Shape::Box(h) => urdf_rs::Geometry::Box {
            size: urdf_rs::Vec3((h * 2.0).into()),
        },
        Shape::Sphere(r) => urdf_rs::Geometry::Sphere { radius: *r },
        Shape::Capsule(r, half) => urdf_rs::Geometry::Capsule {
            radius: *r,
            length: 2.0 * half,
        },
        Shape::Cylinder(r, half) => urdf_rs::Geometry::Cylinder {
            radius: *r,
            length: 2.0 * half,
        },
        Shape::Mesh(name) => {
            let m = meshes.get(name)?;
            urdf_rs::Geometry::Mesh {
                filename: m.file.clone(),
                scale: Some(urdf_rs::Vec3(m.scale)),
            }
        }
        Shape::Ellipsoid(_) | Shape::Other => return None,
    })
}

fn inertia(m: &Matrix3<f64>) -> urdf_rs::Inertia {
    urdf_rs::Inertia {
        ixx: m[(0, 0)],
        ixy: m[(0, 1)],
        ixz: m[(0, 2)],
        iyy: m[(1, 1)],
        iyz: m[(1, 2)],
        izz: m[(2, 2)],
    }
}

/// The URDF tree of `t`: its links (inertials, and geoms as visuals — the geoms that do not
/// collide, or all of a link's geoms when each of them collides — and as collisions, those
/// that collide) and its joints (a hinge without range is `continuous`), named `name`.
pub(crate) fn urdf_tree(
    name: &str,
    t: &Tree,
    meshes: &HashMap<String, MeshAsset>,
) -> urdf_rs::Robot {
    let links = t.links.iter().map(|l| link(l, t, meshes)).collect();
    let joints = t.joints.iter().map(joint).collect();
    urdf_rs::Robot {
        name: name.to_string(),
        version: None,
        links,
        joints,
        materials: Vec::new(),
    }
}

/// The URDF link of `l`: its inertial, and its geoms in `t` as visuals and collisions (see
/// [`urdf_tree`]).
fn link(l: &Link, t: &Tree, meshes: &HashMap<String, MeshAsset>) -> urdf_rs::Link {
    let geoms: Vec<&Geom> = t
        .geoms
        .iter()
        .filter(|(n, _)| *n == l.name)
        .map(|(_, g)| g)
        .collect();
    let visual_only = geoms.iter().any(|g| !g.collides);
    let visual = geoms
        .iter()
        .filter(|g| !visual_only || !g.collides)
        .filter_map(|g| visual(g, meshes))
        .collect();
    let collision = geoms
        .iter()
        .filter(|g| g.collides)
        .filter_map(|g| {
            Some(urdf_rs::Collision {
                name: None,
                origin: pose(&g.pose),
                geometry: geometry(g, meshes)?,
            })
        })
        .collect();
    urdf_rs::Link {
        name: l.name.clone(),
        inertial: urdf_rs::Inertial {
            origin: urdf_rs::Pose {
                xyz: urdf_rs::Vec3(l.com.into()),
                rpy: urdf_rs::Vec3([0.0; 3]),
            },
            mass: urdf_rs::Mass { value: l.mass },
            inertia: inertia(&l.inertia),
        },
        visual,
        collision,
    }
}

/// The URDF visual of a geom, coloured by its `rgba`; `None` for a shape URDF lacks.
fn visual(g: &Geom, meshes: &HashMap<String, MeshAsset>) -> Option<urdf_rs::Visual> {
    Some(urdf_rs::Visual {
        name: None,
        origin: pose(&g.pose),
        geometry: geometry(g, meshes)?,
        material: g.rgba.map(|c| urdf_rs::Material {
            name: String::new(),
            color: Some(urdf_rs::Color {
                rgba: urdf_rs::Vec4(c),
            }),
            texture: None,
        }),
    })
}

/// The URDF joint of `j` (a hinge without range is `continuous`).
fn joint(j: &JointSpec) -> urdf_rs::Joint {
    let (joint_type, axis) = match j.kind {
        JointKind::Revolute { axis } if j.limit.lower.is_finite() => {
            (urdf_rs::JointType::Revolute, axis.into_inner())
        }
        JointKind::Revolute { axis } => (urdf_rs::JointType::Continuous, axis.into_inner()),
        JointKind::Prismatic { axis } => (urdf_rs::JointType::Prismatic, axis.into_inner()),
        JointKind::Fixed => (urdf_rs::JointType::Fixed, nalgebra::Vector3::x()),
    };
    urdf_rs::Joint {
        name: j.name.clone(),
        joint_type,
        origin: pose(&j.origin),
        parent: urdf_rs::LinkName {
            link: j.parent.clone(),
        },
        child: urdf_rs::LinkName {
            link: j.child.clone(),
        },
        axis: urdf_rs::Axis {
            xyz: urdf_rs::Vec3(axis.into()),
        },
        limit: urdf_rs::JointLimit {
            lower: j.limit.lower,
            upper: j.limit.upper,
            effort: j.limit.effort,
            velocity: j.limit.velocity,
            ..urdf_rs::JointLimit::default()
        },
        calibration: None,
        dynamics: None,
        mimic: j.mimic.as_ref().map(|(m, k, o)| urdf_rs::Mimic {
            joint: m.clone(),
            multiplier: Some(*k),
            offset: Some(*o),
        }),
        safety_controller: None,
    }
}
