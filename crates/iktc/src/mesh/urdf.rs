//! The `<visual>` meshes of a URDF, ready for the viewer.
//!
//! For every `<link>`'s `<visual>` with a `<mesh filename=… scale=…>`: the file is found
//! (`package://PKG/REST` is looked up as `REST` and `PKG/REST` in the URDF's folder and its
//! ancestors, `file://` is stripped, a relative path is taken from the URDF's folder), read by
//! its extension as STL ([`super::read_stl`]) or Collada (`.dae`, [`super::read_collada`]: in
//! metres and z up after its `<asset>`, its scene's transforms applied), each vertex mapped into
//! the link frame by `p_link = R·(s ⊙ p) + t` (`s` the scale, `R, t` the visual's `<origin>`,
//! rpy as `Rz·Ry·Rx`; when `s` has an odd number of negative components the mirror turns the
//! triangles clockwise, so two corners of each are swapped back), decimated
//! ([`super::decimate()`]) and quantized ([`super::QuantizedMesh`]). A mesh that cannot be used
//! (missing file, another format, a malformed STL or Collada file) is left out with a warning
//! naming the file and the link; the parts of a Collada file left out (an
//! `<instance_controller>`, …) are warned about the same way.

use std::path::{Path, PathBuf};

use nalgebra::{UnitQuaternion, Vector3};

use super::{decimate, read_collada, read_stl, LinkMesh, MeshSet, QuantizedMesh};
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

/// The mesh formats read, by lower-case file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Stl,
    Collada,
}

impl Format {
    /// The format of the file `path`, by its lower-case extension.
    fn of(path: &Path) -> Option<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("stl") => Some(Format::Stl),
            Some("dae") => Some(Format::Collada),
            _ => None,
        }
    }
}

/// The triangle mesh of the file `path` (STL or Collada by `format`), its vertices mapped into
/// the link frame by `p_link = R·(s ⊙ p) + t` (`s` = `scale`, `R, t` from `origin`) and its
/// triangles turned back counter-clockwise under a mirroring scale; with the warnings about the
/// parts of the file left out.
fn read_in_link(
    path: &Path,
    format: Format,
    scale: [f64; 3],
    origin: &urdf_rs::Pose,
) -> Result<(super::TriMesh, Vec<String>)> {
    let bytes = std::fs::read(path).map_err(|e| Error::Parse {
        source_name: path.display().to_string(),
        line: 0,
        message: format!("cannot read the mesh file: {e}"),
    })?;
    let name = path.display().to_string();
    let (mut mesh, warnings) = match format {
        Format::Stl => (read_stl(&bytes, &name)?.weld(), Vec::new()),
        Format::Collada => {
            let c = read_collada(&bytes, &name)?;
            (c.mesh, c.warnings)
        }
    };
    let r = UnitQuaternion::from_euler_angles(origin.rpy[0], origin.rpy[1], origin.rpy[2]);
    let t = Vector3::from(origin.xyz.0);
    for v in &mut mesh.vertices {
        let p = Vector3::from_fn(|k, _| f64::from(v[k]) * scale[k]);
        let q = r * p + t;
        *v = [q.x as f32, q.y as f32, q.z as f32];
    }
    if scale.iter().product::<f64>() < 0.0 {
        for tri in &mut mesh.triangles {
            tri.swap(1, 2);
        }
    }
    Ok((mesh, warnings))
}

/// The vertices \[m\] of the mesh geometry `geometry` of a link (a `<visual>` or
/// `<collision>` with the `<origin>` `origin`), in the link frame, its file found from the
/// URDF's folder `dir` as the viewer finds it. `Ok(None)` for a geometry that is not a mesh.
///
/// # Errors
/// A file that cannot be found or read, in another format than STL or Collada, or malformed.
pub fn mesh_vertices(
    geometry: &urdf_rs::Geometry,
    origin: &urdf_rs::Pose,
    dir: &Path,
) -> Result<Option<Vec<Vector3<f64>>>> {
    let urdf_rs::Geometry::Mesh { filename, scale } = geometry else {
        return Ok(None);
    };
    let path = resolve(filename, dir);
    let format = Format::of(&path).ok_or_else(|| Error::Parse {
        source_name: path.display().to_string(),
        line: 0,
        message: "this mesh format is not supported (STL or Collada .dae only)".into(),
    })?;
    let s = scale.as_ref().map(|s| s.0).unwrap_or([1.0; 3]);
    let (mesh, _) = read_in_link(&path, format, s, origin)?;
    Ok(Some(
        mesh.vertices
            .iter()
            .map(|v| Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])))
            .collect(),
    ))
}

/// One visual mesh read from `path`, in the link frame, decimated on `cell` \[m\]; `None`
/// when decimation leaves nothing (a part smaller than a cell). Also returns the warnings
/// about parts of the file left out.
fn link_mesh(
    path: &Path,
    format: Format,
    scale: [f64; 3],
    origin: &urdf_rs::Pose,
    cell: f64,
) -> Result<(Option<QuantizedMesh>, Vec<String>)> {
    let (mesh, warnings) = read_in_link(path, format, scale, origin)?;
    let d = decimate(&mesh, cell)?;
    if d.triangles.is_empty() {
        return Ok((None, warnings));
    }
    Ok((Some(QuantizedMesh::new(&d)?), warnings))
}

/// The visual meshes of the URDF (or MJCF: its visual mesh geoms, see
/// [`crate::model::mjcf`]) `text` whose folder is `dir`, decimated on `cell` \[m\].
///
/// # Errors
/// [`Error::Urdf`] when the URDF cannot be parsed; every problem with one mesh is a warning.
pub fn meshes_from_urdf(text: &str, dir: &Path, cell: f64) -> Result<UrdfMeshes> {
    let u =
        crate::model::read_description(text, Some(dir), &crate::resources::ReadLimits::default())?;
    let mut out = UrdfMeshes::default();
    for link in &u.links {
        for v in &link.visual {
            let urdf_rs::Geometry::Mesh { filename, scale } = &v.geometry else {
                continue;
            };
            let path = resolve(filename, dir);
            let Some(format) = Format::of(&path) else {
                out.warnings.push(format!(
                    "link `{}`: mesh {filename}: this format is not supported (STL or Collada \
                     .dae only); the link is drawn without it",
                    link.name
                ));
                continue;
            };
            let s = scale.as_ref().map(|s| s.0).unwrap_or([1.0; 3]);
            match link_mesh(&path, format, s, &v.origin, cell) {
                Ok((mesh, warnings)) => {
                    out.warnings.extend(
                        warnings
                            .into_iter()
                            .map(|w| format!("link `{}`: mesh {filename}: {w}", link.name)),
                    );
                    if let Some(mesh) = mesh {
                        out.set.meshes.push(LinkMesh {
                            link: link.name.clone(),
                            color: color(v, &u.materials),
                            mesh,
                        });
                    }
                }
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
               <visual><geometry><mesh filename="meshes/arm.obj"/></geometry></visual>
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
        assert!(m.warnings[1].contains("arm.obj") && m.warnings[1].contains("not supported"));
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

    /// A Collada file of one counter-clockwise triangle (0,0,0), (1,0,0), (0,1,0) in
    /// millimetres, y up, placed by a node moved by 1000 mm along the file's x, and an
    /// `<instance_node>` naming no node, which the reader leaves out with a warning.
    const TRIANGLE_DAE: &str = r##"<?xml version="1.0"?>
<COLLADA version="1.4.1"><asset><unit meter="0.001"/><up_axis>Y_UP</up_axis></asset>
<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="a" count="9">0 0 0 1000 0 0 0 1000 0</float_array>
<technique_common><accessor source="#a" count="3" stride="3"/></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node><translate>1000 0 0</translate>
<instance_geometry url="#g"/><instance_node url="#other"/></node></visual_scene></library_visual_scenes>
</COLLADA>"##;

    #[test]
    fn a_collada_visual_is_read_and_its_left_out_parts_warned() {
        let dir = std::env::temp_dir().join(format!("iktc_mesh_dae_{}", std::process::id()));
        std::fs::create_dir_all(dir.join("meshes")).unwrap();
        std::fs::write(dir.join("meshes/t.dae"), TRIANGLE_DAE).unwrap();
        std::fs::write(dir.join("meshes/broken.dae"), "<COLLADA><asset>").unwrap();
        let text = urdf(
            r#"<visual><origin xyz="0 0 1"/>
               <geometry><mesh filename="package://robot_description/meshes/t.DAE"/></geometry></visual>"#,
        );
        // `t.DAE`: the extension is matched case-insensitively; the file system here is
        // case-sensitive, so write that name too.
        std::fs::write(dir.join("meshes/t.DAE"), TRIANGLE_DAE).unwrap();
        let m = meshes_from_urdf(&text, &dir, 0.001).unwrap();
        assert_eq!(m.set.meshes.len(), 1, "{:?}", m.warnings);
        // File (x, y, z) mm ↦ (x, −z, y)/1000 m, then lifted by the origin's 1 m:
        // (1000, 0, 0) → (1, 0, 1), (2000, 0, 0) → (2, 0, 1), (1000, 1000, 0) → (1, 0, 2).
        let v = m.set.meshes[0].mesh.vertices();
        let want = [[1.0, 0.0, 1.0], [2.0, 0.0, 1.0], [1.0, 0.0, 2.0]];
        assert_eq!(v.len(), 3);
        for (a, b) in v.iter().zip(want) {
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() < 1e-4, "{a:?} vs {b:?}");
            }
        }
        // The only warning is the reader's, about the <instance_node>: no "not supported".
        assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
        assert!(
            m.warnings[0].contains("link `base`")
                && m.warnings[0].contains("<instance_node url=\"#other\"> names no <node>"),
            "{:?}",
            m.warnings
        );
        // A malformed Collada file is a warning naming it and what is wrong.
        let text =
            urdf(r#"<visual><geometry><mesh filename="meshes/broken.dae"/></geometry></visual>"#);
        let m = meshes_from_urdf(&text, &dir, 0.001).unwrap();
        assert!(m.set.meshes.is_empty());
        assert!(
            m.warnings[0].contains("broken.dae") && m.warnings[0].contains("never closed"),
            "{:?}",
            m.warnings
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The normal `(b−a)×(c−a)` of triangle `t` of `m`'s vertices.
    fn normal(v: &[[f32; 3]], t: [u32; 3]) -> [f32; 3] {
        let [a, b, c] = t.map(|i| v[i as usize]);
        let (u, w) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ]
    }

    #[test]
    fn a_mirroring_scale_keeps_the_triangle_facing_its_mirrored_side() {
        let dir = std::env::temp_dir().join(format!("iktc_mesh_mirror_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Counter-clockwise seen from +z: its outward normal is +z.
        std::fs::write(
            dir.join("t.stl"),
            one_triangle([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
        )
        .unwrap();
        // Mirroring in z turns the outside to −z; mirroring in x keeps it +z.
        for (scale, want_z) in [("1 1 -1", -1.0), ("-1 1 1", 1.0), ("-1 -1 1", 1.0)] {
            let text = urdf(&format!(
                r#"<visual><geometry><mesh filename="t.stl" scale="{scale}"/></geometry></visual>"#
            ));
            let m = meshes_from_urdf(&text, &dir, 0.001).unwrap();
            let mesh = &m.set.meshes[0].mesh;
            let t = mesh.triangles[0].map(u32::from);
            let n = normal(&mesh.vertices(), t);
            assert!(n[2] * want_z > 0.0, "scale {scale}: normal {n:?}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
