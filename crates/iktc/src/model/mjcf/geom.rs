//! `<geom>`s: their shape and pose in the body (for soles and the viewer) and the mass and
//! inertia MuJoCo infers from them (`<compiler inertiafromgeom>`).

use std::collections::HashMap;
use std::f64::consts::PI;

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, Vector3};

use super::defaults::Attrs;
use super::spec::{numbers, orientation, vec3, z_to, Compiler, MIN_NORM};
use crate::error::Result;

/// MuJoCo's default geom density \[kg/m³\] (water).
pub(crate) const DEFAULT_DENSITY: f64 = 1000.0;

/// A mesh asset: its file relative to the model's folder and its scale.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MeshAsset {
    /// `meshdir` joined with the asset's `file`, relative to the model's folder.
    pub file: String,
    /// Per-axis scale \[–\].
    pub scale: [f64; 3],
}

/// The shape of a geom, sizes \[m\].
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Shape {
    /// Half extents along the geom's axes.
    Box(Vector3<f64>),
    /// Radius.
    Sphere(f64),
    /// Radius and half length of the cylindrical part, along the geom's z.
    Capsule(f64, f64),
    /// Radius and half length along the geom's z.
    Cylinder(f64, f64),
    /// Radii along the geom's axes.
    Ellipsoid(Vector3<f64>),
    /// A mesh asset, by name.
    Mesh(String),
    /// A plane, height field or other shape without a volume iktc reads.
    Other,
}

/// One geom in its body.
#[derive(Debug, Clone)]
pub(crate) struct Geom {
    /// Pose in the body frame.
    pub pose: Isometry3<f64>,
    pub shape: Shape,
    /// Colour (`rgba`, else its `material`'s), components in \[0, 1\].
    pub rgba: Option<[f64; 4]>,
    /// Whether it collides (`contype` or `conaffinity` non-zero).
    pub collides: bool,
    /// Mass \[kg\] from `mass`, else `density` × volume; 0 for a mesh or a shape without
    /// volume.
    pub mass: f64,
    /// Whether its mass cannot be computed here (a mesh with a non-zero density or mass).
    pub mass_unknown: bool,
}

/// Reads the geom `a` (in its class), its pose relative to `pre` (the frames around it).
///
/// Errors: a bad number, a wrong count of `size` numbers for the shape, a negative size,
/// mass or density, an unknown `type`, an unknown mesh.
pub(crate) fn geom(
    a: &Attrs,
    pre: &Isometry3<f64>,
    c: &Compiler,
    meshes: &HashMap<String, MeshAsset>,
    materials: &HashMap<String, [f64; 4]>,
) -> Result<Geom> {
    let kind = a.get("type").unwrap_or("sphere");
    let size = read_sizes(a)?;
    let (pose, half_from) = read_placement(a, kind, c)?;
    let pose = pre * pose;
    let shape = read_shape(a, kind, &size, half_from, meshes)?;
    let (mass, mass_unknown) = read_mass(a, &shape)?;
    let collides = read_collides(a)?;
    let rgba = match numbers(a, "rgba", Some(4))? {
        Some(v) => Some([v[0], v[1], v[2], v[3]]),
        None => a.get("material").and_then(|m| materials.get(m).copied()),
    };
    Ok(Geom {
        pose,
        shape,
        rgba,
        collides,
        mass,
        mass_unknown,
    })
}

/// The geom's `size` numbers \[m\]: up to 3, each >= 0 (none when not given).
fn read_sizes(a: &Attrs) -> Result<Vec<f64>> {
    let size = numbers(a, "size", None)?.unwrap_or_default();
    if size.iter().any(|s| *s < 0.0) || size.len() > 3 {
        return Err(a.el.error(format!(
            "size=\"{}\": expected up to 3 sizes >= 0 [m]",
            a.get("size").unwrap_or("")
        )));
    }
    Ok(size)
}

/// The geom's pose in the frames around it, and the half length \[m\] along its z that
/// `fromto` gives (for a capsule, cylinder, box or ellipsoid), else from `pos` and its
/// orientation.
fn read_placement(a: &Attrs, kind: &str, c: &Compiler) -> Result<(Isometry3<f64>, Option<f64>)> {
    let fromto = numbers(a, "fromto", Some(6))?;
    Ok(match &fromto {
        Some(v) if matches!(kind, "capsule" | "cylinder" | "box" | "ellipsoid") => {
            let (p0, p1) = (
                Vector3::new(v[0], v[1], v[2]),
                Vector3::new(v[3], v[4], v[5]),
            );
            let d = p1 - p0;
            let axis = Unit::try_new(d, MIN_NORM).ok_or_else(|| {
                a.el.error("fromto: its two points coincide; expected a segment of length > 0 [m]")
            })?;
            (
                Isometry3::from_parts(Translation3::from((p0 + p1) / 2.0), z_to(&axis)),
                Some(d.norm() / 2.0),
            )
        }
        _ => (
            Isometry3::from_parts(
                Translation3::from(vec3(a, "pos")?.unwrap_or_default()),
                orientation(a, c)?,
            ),
            None,
        ),
    })
}

/// The shape of a geom of type `kind` from its sizes `size` \[m\] (the half length along z
/// `half_from` \[m\] when `fromto` gave it).
fn read_shape(
    a: &Attrs,
    kind: &str,
    size: &[f64],
    half_from: Option<f64>,
    meshes: &HashMap<String, MeshAsset>,
) -> Result<Shape> {
    let el = a.el;
    let s = |i: usize| -> Result<f64> {
        size.get(i).copied().ok_or_else(|| {
            el.error(format!(
                "a {kind} needs {} size(s) [m], got {}",
                i + 1,
                size.len()
            ))
        })
    };
    let half = |i: usize| -> Result<f64> {
        match half_from {
            Some(h) => Ok(h),
            None => s(i),
        }
    };
    Ok(match kind {
        "sphere" => Shape::Sphere(s(0)?),
        "capsule" => Shape::Capsule(s(0)?, half(1)?),
        "cylinder" => Shape::Cylinder(s(0)?, half(1)?),
        "box" => Shape::Box(Vector3::new(s(0)?, s(1)?, half(2)?)),
        "ellipsoid" => Shape::Ellipsoid(Vector3::new(s(0)?, s(1)?, half(2)?)),
        "mesh" => {
            let Some(m) = a.get("mesh") else {
                return Err(el.error("a mesh geom needs a `mesh` attribute naming a <mesh> asset"));
            };
            if !meshes.contains_key(m) {
                let mut names: Vec<&String> = meshes.keys().collect();
                names.sort();
                return Err(el.error(format!(
                    "mesh=\"{m}\" names no <mesh> asset; meshes are {}",
                    crate::error::name_list(&names)
                )));
            }
            Shape::Mesh(m.to_string())
        }
        "plane" | "hfield" | "sdf" => Shape::Other,
        other => {
            return Err(el.error(format!(
                "type=\"{other}\": expected plane, hfield, sphere, capsule, ellipsoid, cylinder, box, mesh or sdf"
            )))
        }
    })
}

/// The geom's mass \[kg\] (`mass`, else `density` \[kg/m³\] × volume; 0 without a volume) and
/// whether it is unknown (a mesh with a non-zero density or mass).
fn read_mass(a: &Attrs, shape: &Shape) -> Result<(f64, bool)> {
    let positive = |attr: &str| -> Result<Option<f64>> {
        match numbers(a, attr, Some(1))? {
            Some(v) if v[0] < 0.0 => Err(a.el.error(format!("{attr}=\"{}\": expected >= 0", v[0]))),
            v => Ok(v.map(|v| v[0])),
        }
    };
    let given_mass = positive("mass")?;
    let density = positive("density")?.unwrap_or(DEFAULT_DENSITY);
    let volume = unit_mass(shape).map(|(v, _)| v);
    Ok(match (given_mass, volume) {
        (Some(m), Some(_)) => (m, false),
        (None, Some(v)) => (density * v, false),
        (m, None) => (
            0.0,
            matches!(shape, Shape::Mesh(_)) && m.unwrap_or(density) > 0.0,
        ),
    })
}

/// Whether the geom collides: `contype` or `conaffinity` (integers, 1 when not given) non-zero.
fn read_collides(a: &Attrs) -> Result<bool> {
    let int = |attr: &str| -> Result<i64> {
        match a.get(attr) {
            None => Ok(1),
            Some(v) => v
                .trim()
                .parse()
                .map_err(|_| super::spec::bad(a.el, attr, v, "an integer")),
        }
    };
    Ok(int("contype")? != 0 || int("conaffinity")? != 0)
}

/// Volume \[m³\] and principal inertia per unit mass \[m²\] (about the geom's centre, in its
/// axes) of a shape of uniform density; `None` for a mesh or a shape without volume.
/// The capsule is a cylinder and two hemispheres, each part's inertia moved to the centre.
pub(crate) fn unit_mass(shape: &Shape) -> Option<(f64, Vector3<f64>)> {
    Some(match *shape {
        Shape::Sphere(r) => (4.0 / 3.0 * PI * r.powi(3), Vector3::repeat(0.4 * r * r)),
        Shape::Box(h) => {
            let (x, y, z) = (h.x * h.x, h.y * h.y, h.z * h.z);
            (
                8.0 * h.x * h.y * h.z,
                Vector3::new(y + z, x + z, x + y) / 3.0,
            )
        }
        Shape::Ellipsoid(r) => {
            let (x, y, z) = (r.x * r.x, r.y * r.y, r.z * r.z);
            (
                4.0 / 3.0 * PI * r.x * r.y * r.z,
                Vector3::new(y + z, x + z, x + y) / 5.0,
            )
        }
        Shape::Cylinder(r, half) => {
            let h = 2.0 * half;
            let across = (3.0 * r * r + h * h) / 12.0;
            (PI * r * r * h, Vector3::new(across, across, r * r / 2.0))
        }
        Shape::Capsule(r, half) => {
            let h = 2.0 * half;
            let (vc, vs) = (PI * r * r * h, 4.0 / 3.0 * PI * r.powi(3));
            let (fc, fs) = (vc / (vc + vs), vs / (vc + vs));
            // Two hemispheres (together a sphere), each at 3r/8 + h/2 from the centre.
            let across = fc * (3.0 * r * r + h * h) / 12.0
                + fs * (0.4 * r * r + h * (3.0 * r + 2.0 * h) / 8.0);
            let along = fc * r * r / 2.0 + fs * 0.4 * r * r;
            (vc + vs, Vector3::new(across, across, along))
        }
        Shape::Mesh(_) | Shape::Other => return None,
    })
}

/// The mass \[kg\], centre of mass \[m\] and inertia about it \[kg·m²\] (body axes) of `geoms`
/// of uniform density each: the sum of their masses, the mass-weighted centre, and their
/// inertias moved to it (parallel axes).
pub(crate) fn combined(geoms: &[Geom]) -> (f64, Vector3<f64>, Matrix3<f64>) {
    let mass: f64 = geoms.iter().map(|g| g.mass).sum();
    if mass <= 0.0 {
        return (0.0, Vector3::zeros(), Matrix3::zeros());
    }
    let com = geoms
        .iter()
        .map(|g| g.pose.translation.vector * g.mass)
        .sum::<Vector3<f64>>()
        / mass;
    let mut inertia = Matrix3::zeros();
    for g in geoms.iter().filter(|g| g.mass > 0.0) {
        let Some((_, per_mass)) = unit_mass(&g.shape) else {
            continue;
        };
        let r = g.pose.rotation.to_rotation_matrix();
        let d = g.pose.translation.vector - com;
        inertia +=
            r.matrix() * Matrix3::from_diagonal(&(per_mass * g.mass)) * r.matrix().transpose()
                + g.mass * (Matrix3::identity() * d.norm_squared() - d * d.transpose());
    }
    (mass, com, inertia)
}
