//! The `<visual>` meshes of a URDF, ready for the viewer.
//!
//! For every `<link>`'s `<visual>` with a `<mesh filename=… scale=…>`: the file is found
//! (`package://PKG/REST` is looked up as `REST` and `PKG/REST` in the URDF's folder and its
//! ancestors, `file://` is stripped, a relative path is taken from the URDF's folder), read as
//! STL, each vertex mapped into the link frame by `p_link = R·(s ⊙ p) + t` (`s` the scale,
//! `R, t` the visual's `<origin>`, rpy as `Rz·Ry·Rx`), decimated ([`super::decimate()`]) and
//! quantized ([`super::QuantizedMesh`]). A mesh that cannot be used (missing file, Collada or
//! another format, a malformed STL) is left out with a warning naming the file and the link.

use std::path::{Path, PathBuf};

use nalgebra::{UnitQuaternion, Vector3};

use super::{decimate, read_stl, LinkMesh, MeshSet, QuantizedMesh};
use crate::error::{Error, Result};

/// Colour of a visual without a material colour (sRGB).
pub const DEFAULT_COLOR: [u8; 3] = [170, 174, 180];

/// How many folders above the URDF's a `package://` path is looked up in.
const PACKAGE_SEARCH_DEPTH: usize = 3;

/// The meshes found and the warnings about those left out.
#[derive(Debug, Clone, Default)]
pub struct UrdfMeshes {
    /// The meshes read.
    pub set: MeshSet,
    /// One line per mesh left out, naming the file and the link.
    pub warnings: Vec<String>,
}

/// Where a `<mesh filename>` points, seen from the URDF's folder `dir`.
pub fn resolve(filename: &str, dir: &Path) -> PathBuf {
    if let Some(rest) = filename.strip_prefix("package://") {
        let (pkg, rel) = rest.split_once('/').unwrap_or(("", rest));
        let mut candidates = Vec::new();
        let mut d = Some(dir);
        for _ in 0..=PACKAGE_SEARCH_DEPTH {
            let Some(here) = d else { break };
            candidates.push(here.join(rel));
            if !pkg.is_empty() {
                candidates.push(here.join(pkg).join(rel));
            }
            d = here.parent();
        }
        return candidates
            .iter()
            .find(|p| p.is_file())
            .cloned()
            .unwrap_or_else(|| dir.join(rel));
    }
    let f = filename.strip_prefix("file://").unwrap_or(filename);
    dir.join(f)
}

fn color(v: &urdf_rs::Visual, named: &[urdf_rs::Material]) -> [u8; 3] {
    let by_name = |m: &urdf_rs::Material| {
        named
            .iter()
            .find(|n| n.name == m.name && !m.name.is_empty())
            .and_then(|n| n.color.clone())
    };
    v.material
        .as_ref()
        .and_then(|m| m.color.clone().or_else(|| by_name(m)))
        .map(|c| std::array::from_fn(|k| (c.rgba[k].clamp(0.0, 1.0) * 255.0).round() as u8))
        .unwrap_or(DEFAULT_COLOR)
}

/// One visual mesh read from `path`, in the link frame, decimated on `cell` \[m\]; `Ok(None)`
/// when decimation leaves nothing (a part smaller than a cell).
fn link_mesh(
    path: &Path,
    scale: [f64; 3],
    origin: &urdf_rs::Pose,
    cell: f64,
) -> Result<Option<QuantizedMesh>> {
    let bytes = std::fs::read(path).map_err(|e| Error::Parse {
        source_name: path.display().to_string(),
        line: 0,
        message: format!("cannot read the mesh file: {e}"),
    })?;
    let mut mesh = read_stl(&bytes, &path.display().to_string())?.weld();
    let r = UnitQuaternion::from_euler_angles(origin.rpy[0], origin.rpy[1], origin.rpy[2]);
    let t = Vector3::from(origin.xyz.0);
    for v in &mut mesh.vertices {
        let p = Vector3::from_fn(|k, _| f64::from(v[k]) * scale[k]);
        let q = r * p + t;
        *v = [q.x as f32, q.y as f32, q.z as f32];
    }
    let d = decimate(&mesh, cell)?;
    if d.triangles.is_empty() {
        return Ok(None);
    }
    QuantizedMesh::new(&d).map(Some)
}

/// The visual meshes of the URDF `text` whose folder is `dir`, decimated on `cell` \[m\].
///
/// # Errors
/// [`Error::Urdf`] when the URDF cannot be parsed; every problem with one mesh is a warning.
pub fn meshes_from_urdf(text: &str, dir: &Path, cell: f64) -> Result<UrdfMeshes> {
    let u = urdf_rs::read_from_string(text.trim_end_matches('\0')).map_err(|e| Error::Urdf {
        message: format!("cannot parse the URDF: {e}"),
    })?;
    let mut out = UrdfMeshes::default();
    for link in &u.links {
        for v in &link.visual {
            let urdf_rs::Geometry::Mesh { filename, scale } = &v.geometry else {
                continue;
            };
            let path = resolve(filename, dir);
            let ext = path
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase)
                .unwrap_or_default();
            if ext != "stl" {
                let kind = if ext == "dae" {
                    "Collada (.dae)"
                } else {
                    "this format"
                };
                out.warnings.push(format!(
                    "link `{}`: mesh {filename}: {kind} is not supported (STL only); the link \
                     is drawn without it",
                    link.name
                ));
                continue;
            }
            let s = scale.as_ref().map(|s| s.0).unwrap_or([1.0; 3]);
            match link_mesh(&path, s, &v.origin, cell) {
                Ok(Some(mesh)) => out.set.meshes.push(LinkMesh {
                    link: link.name.clone(),
                    color: color(v, &u.materials),
                    mesh,
                }),
                Ok(None) => {}
                Err(e) => out.warnings.push(format!(
                    "link `{}`: mesh {filename} ({}) left out: {e}",
                    link.name,
                    path.display()
                )),
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of one triangle.
    fn one_triangle(corners: [[f32; 3]; 3]) -> Vec<u8> {
        let mut b = vec![0u8; 80];
        b.extend(1u32.to_le_bytes());
        for x in [0f32; 3].iter().chain(corners.iter().flatten()) {
            b.extend(x.to_le_bytes());
        }
        b.extend([0u8, 0]);
        b
    }

    fn urdf(visuals: &str) -> String {
        format!(
            r#"<robot name="r"><material name="red"><color rgba="1 0 0 1"/></material>
            <link name="base">{visuals}</link></robot>"#
        )
    }

    #[test]
    fn origin_scale_and_colour_are_applied_and_missing_files_warned() {
        let dir = std::env::temp_dir().join(format!("iktc_mesh_urdf_{}", std::process::id()));
        std::fs::create_dir_all(dir.join("meshes")).unwrap();
        std::fs::write(
            dir.join("meshes/t.stl"),
            one_triangle([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
        )
        .unwrap();
        let text = urdf(
            r#"<visual><origin xyz="0 0 1" rpy="0 0 1.5707963267948966"/>
               <geometry><mesh filename="package://robot_description/meshes/t.stl" scale="0.5 2 1"/></geometry>
               <material name="red"/></visual>
               <visual><geometry><mesh filename="meshes/gone.stl"/></geometry></visual>
               <visual><geometry><mesh filename="meshes/arm.dae"/></geometry></visual>
               <visual><geometry><box size="1 1 1"/></geometry></visual>"#,
        );
        let m = meshes_from_urdf(&text, &dir, 0.001).unwrap();
        assert_eq!(m.set.meshes.len(), 1);
        let lm = &m.set.meshes[0];
        assert_eq!((lm.link.as_str(), lm.color), ("base", [255, 0, 0]));
        // (1,0,0) scaled to (0.5,0,0), turned 90° about z to (0,0.5,0), lifted by 1.
        let v = lm.mesh.vertices();
        let want = [[0.0, 0.0, 1.0], [0.0, 0.5, 1.0], [-2.0, 0.0, 1.0]];
        for (a, b) in v.iter().zip(want) {
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() < 1e-4, "{a:?} vs {b:?}");
            }
        }
        assert_eq!(m.warnings.len(), 2, "{:?}", m.warnings);
        assert!(m.warnings[0].contains("gone.stl") && m.warnings[0].contains("cannot read"));
        assert!(m.warnings[1].contains("arm.dae") && m.warnings[1].contains("Collada"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_malformed_stl_is_a_warning_and_a_malformed_urdf_an_error() {
        let dir = std::env::temp_dir().join(format!("iktc_mesh_bad_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut cut = one_triangle([[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        cut.truncate(100);
        std::fs::write(dir.join("cut.stl"), cut).unwrap();
        let text = urdf(r#"<visual><geometry><mesh filename="cut.stl"/></geometry></visual>"#);
        let m = meshes_from_urdf(&text, &dir, 0.001).unwrap();
        assert!(m.set.meshes.is_empty());
        assert!(m.warnings[0].contains("cut.stl") && m.warnings[0].contains("not an STL"));
        assert!(meshes_from_urdf("<robot", &dir, 0.001).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
