//! Robot meshes for the viewer: reading STL and Collada, decimating, quantizing and packing
//! them.
//!
//! The pipeline, one file a step:
//!
//! * [`stl`] reads binary and ASCII STL into a triangle soup, then welds it into an indexed
//!   [`TriMesh`] (vertices at bit-identical positions become one, [`TriMesh::weld`]).
//! * [`collada`] (feature `urdf`) reads a Collada (`.dae`) file's triangles, polygons, fans and
//!   strips, places them by the `<visual_scene>`'s node transforms, converts them to metres and
//!   z up after the file's `<asset>`, keeps the triangles counter-clockwise under mirroring
//!   transforms, and welds the result the same way.
//! * [`decimate()`] simplifies a mesh by vertex clustering: space is cut into cubes of side `c`
//!   \[m\]; every vertex is replaced by the mean of the vertices in its cube, and triangles whose
//!   corners fall into fewer than three distinct cubes are dropped (Rossignac & Borrel, 1993).
//!   Every kept vertex moves by less than the cube's diagonal `√3·c`, so the bounding box moves
//!   by at most `c` per axis.
//! * [`quantize`] stores each coordinate as a 16-bit integer across the mesh's bounding box:
//!   `u = round((x − min) / (max − min) · 65535)`, so the round trip `x' = min + u·step` with
//!   `step = (max − min) / 65535` is within `step / 2` of `x`; it also packs a set of meshes into
//!   the little-endian binary the viewer page reads, triangle indices as varints against a
//!   high-water mark (format in [`quantize::pack`]).
//! * [`urdf`] (feature `urdf`) finds the `<visual>` meshes of a URDF, resolves their paths,
//!   applies the visual's `<origin>` and `scale`, and runs the steps above; [`builtin`] holds the
//!   built-in G1's meshes, prepared that way from Unitree's STL files.

use std::collections::HashMap;

pub mod base64;
pub mod builtin;
#[cfg(feature = "urdf")]
pub mod collada;
pub mod decimate;
pub mod quantize;
pub mod stl;
#[cfg(feature = "urdf")]
pub mod urdf;
#[cfg(feature = "urdf")]
mod xml;

#[cfg(feature = "urdf")]
pub use collada::{read_collada, ColladaMesh};
pub use decimate::decimate;
pub use quantize::{pack, unpack, LinkMesh, MeshSet, QuantizedMesh};
pub use stl::{read_stl, StlMesh};

/// The cube side of the vertex clustering used for robot meshes in the viewer \[m\]: 12 mm
/// keeps the links' shapes readable at a whole-robot view and the built-in G1 at 160
/// KB.
pub const VIEWER_CELL: f64 = 0.012;

/// An indexed triangle mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions \[m\] (or the file's unit before scaling).
    pub vertices: Vec<[f32; 3]>,
    /// Triangles: three vertex indices each, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// The indexed mesh of a triangle soup: corners at bit-identical positions become one
    /// vertex; triangles keep their order and their corners' order.
    pub fn weld(soup: &[[[f32; 3]; 3]]) -> TriMesh {
        let mut index: HashMap<[u32; 3], u32> = HashMap::new();
        let mut mesh = TriMesh::default();
        for t in soup {
            let mut tri = [0u32; 3];
            for (k, p) in t.iter().enumerate() {
                let key = p.map(f32::to_bits);
                tri[k] = *index.entry(key).or_insert_with(|| {
                    mesh.vertices.push(*p);
                    (mesh.vertices.len() - 1) as u32
                });
            }
            mesh.triangles.push(tri);
        }
        mesh
    }

    /// The axis-aligned bounding box `(min, max)` of the vertices used by a triangle; `None`
    /// for a mesh without triangles.
    pub fn bounding_box(&self) -> Option<([f32; 3], [f32; 3])> {
        let mut it = self
            .triangles
            .iter()
            .flatten()
            .filter_map(|&i| self.vertices.get(i as usize));
        let first = *it.next()?;
        Some(it.fold((first, first), |(mut lo, mut hi), v| {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
            (lo, hi)
        }))
    }
}
