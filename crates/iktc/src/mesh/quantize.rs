//! 16-bit quantization of mesh coordinates across their bounding box, and the packed binary
//! of a set of link meshes (the format the viewer page and the built-in data file share).
//!
//! Coordinate `x` in `[min, max]` is stored as `u = round((x − min) / step)` with
//! `step = (max − min) / 65535` (a zero-width axis has step 0 and stores 0); it reads back as
//! `min + u · step`, within `step / 2` of `x` (plus `f32` rounding).

use super::TriMesh;
use crate::error::{Error, Result};

/// The largest quantized coordinate (16 bits).
const LEVELS: f64 = 65535.0;
/// First bytes of a packed mesh set.
pub const MAGIC: &[u8; 8] = b"IKTCMSH1";

/// A mesh with 16-bit coordinates and indices.
#[derive(Debug, Clone, PartialEq)]
pub struct QuantizedMesh {
    /// Lower corner of the bounding box \[m\].
    pub min: [f32; 3],
    /// Upper corner of the bounding box \[m\].
    pub max: [f32; 3],
    /// Quantized vertices.
    pub positions: Vec<[u16; 3]>,
    /// Triangles (vertex indices).
    pub triangles: Vec<[u16; 3]>,
}

/// One mesh of a link, in the link's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkMesh {
    /// The link's name.
    pub link: String,
    /// Colour (sRGB, 0–255).
    pub color: [u8; 3],
    /// The mesh \[m\], link frame.
    pub mesh: QuantizedMesh,
}

/// The meshes of a robot.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshSet {
    /// One entry per `<visual>` mesh (a link may have several).
    pub meshes: Vec<LinkMesh>,
}

impl MeshSet {
    /// Triangles over all meshes.
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.mesh.triangles.len()).sum()
    }
}

impl QuantizedMesh {
    /// Quantizes `mesh` (only the vertices its triangles use).
    ///
    /// # Errors
    /// [`Error::ResourceLimit`] for more than 65 536 vertices (decimate first);
    /// [`Error::InsufficientData`] for a mesh without triangles.
    pub fn new(mesh: &TriMesh) -> Result<QuantizedMesh> {
        if mesh.vertices.len() > usize::from(u16::MAX) + 1 {
            return Err(Error::ResourceLimit {
                what: "vertices of a quantized mesh".into(),
                value: mesh.vertices.len().to_string(),
                limit: "65536".into(),
                option: "a coarser decimation cell".into(),
            });
        }
        let (min, max) = mesh.bounding_box().ok_or_else(|| Error::InsufficientData {
            what: "a quantized mesh".into(),
            message: "the mesh has no triangles".into(),
        })?;
        let step = step(&min, &max);
        let positions = mesh
            .vertices
            .iter()
            .map(|v| {
                std::array::from_fn(|k| {
                    if step[k] > 0.0 {
                        ((f64::from(v[k]) - f64::from(min[k])) / step[k])
                            .round()
                            .clamp(0.0, LEVELS) as u16
                    } else {
                        0
                    }
                })
            })
            .collect();
        let triangles = mesh.triangles.iter().map(|t| t.map(|i| i as u16)).collect();
        Ok(QuantizedMesh {
            min,
            max,
            positions,
            triangles,
        })
    }

    /// The vertices read back \[m\].
    pub fn vertices(&self) -> Vec<[f32; 3]> {
        let step = step(&self.min, &self.max);
        self.positions
            .iter()
            .map(|p| {
                std::array::from_fn(|k| (f64::from(self.min[k]) + f64::from(p[k]) * step[k]) as f32)
            })
            .collect()
    }
}

/// Quantization step per axis \[m\].
fn step(min: &[f32; 3], max: &[f32; 3]) -> [f64; 3] {
    std::array::from_fn(|k| (f64::from(max[k]) - f64::from(min[k])) / LEVELS)
}

/// Packs `set` (little endian): [`MAGIC`], `u32` mesh count; per mesh `u16` name length, the
/// link name (UTF-8), colour `u8 ×3`, `min`, `max` (`f32 ×3` each), `u32` vertex count, `u32`
/// triangle count, the positions (`u16 ×3` each) and the triangles (`u16 ×3` each).
pub fn pack(set: &MeshSet) -> Vec<u8> {
    let mut b = MAGIC.to_vec();
    b.extend((set.meshes.len() as u32).to_le_bytes());
    for m in &set.meshes {
        let name = &m.link.as_bytes()[..m.link.len().min(usize::from(u16::MAX))];
        b.extend((name.len() as u16).to_le_bytes());
        b.extend(name);
        b.extend(m.color);
        for x in m.mesh.min.iter().chain(&m.mesh.max) {
            b.extend(x.to_le_bytes());
        }
        b.extend((m.mesh.positions.len() as u32).to_le_bytes());
        b.extend((m.mesh.triangles.len() as u32).to_le_bytes());
        for x in m.mesh.positions.iter().chain(&m.mesh.triangles).flatten() {
            b.extend(x.to_le_bytes());
        }
    }
    b
}

/// A cursor over packed bytes; every read names what was cut short.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize, what: &str) -> Result<&[u8]> {
        let s = self
            .at
            .checked_add(n)
            .and_then(|end| self.bytes.get(self.at..end))
            .ok_or_else(|| Error::Parse {
                source_name: "packed meshes".into(),
                line: 0,
                message: format!("truncated at byte {} while reading {what}", self.at),
            })?;
        self.at += n;
        Ok(s)
    }
    fn u16(&mut self, what: &str) -> Result<u16> {
        let s = self.take(2, what)?;
        Ok(u16::from_le_bytes([s[0], s[1]]))
    }
    fn u32(&mut self, what: &str) -> Result<u32> {
        let s = self.take(4, what)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn f32(&mut self, what: &str) -> Result<f32> {
        let s = self.take(4, what)?;
        Ok(f32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn u16x3(&mut self, n: u32, what: &str) -> Result<Vec<[u16; 3]>> {
        // Checked against the bytes left before allocating.
        self.take(0, what)?;
        if (n as usize).saturating_mul(6) > self.bytes.len() - self.at {
            return Err(Error::Parse {
                source_name: "packed meshes".into(),
                line: 0,
                message: format!("{n} {what} do not fit in the bytes left"),
            });
        }
        (0..n)
            .map(|_| Ok([self.u16(what)?, self.u16(what)?, self.u16(what)?]))
            .collect()
    }
}

/// Reads what [`pack`] wrote.
///
/// # Errors
/// [`Error::Parse`] for a wrong magic, truncated data, a triangle index past the vertices or a
/// non-finite bounding box.
pub fn unpack(bytes: &[u8]) -> Result<MeshSet> {
    let bad = |message: String| Error::Parse {
        source_name: "packed meshes".into(),
        line: 0,
        message,
    };
    let mut r = Reader { bytes, at: 0 };
    if r.take(MAGIC.len(), "the magic")? != MAGIC {
        return Err(bad("not a packed mesh set (wrong magic)".into()));
    }
    let n = r.u32("the mesh count")?;
    let mut set = MeshSet::default();
    for i in 0..n {
        let len = r.u16("a link name's length")?;
        let link = String::from_utf8(r.take(len.into(), "a link name")?.to_vec())
            .map_err(|_| bad(format!("mesh {i}: the link name is not UTF-8")))?;
        let c = r.take(3, "a colour")?;
        let color = [c[0], c[1], c[2]];
        let mut bx = [0f32; 6];
        for x in &mut bx {
            *x = r.f32("a bounding box")?;
        }
        if bx.iter().any(|x| !x.is_finite()) {
            return Err(bad(format!("mesh {i} ({link}): bounding box not finite")));
        }
        let nv = r.u32("a vertex count")?;
        let nt = r.u32("a triangle count")?;
        let positions = r.u16x3(nv, "vertices")?;
        let triangles = r.u16x3(nt, "triangles")?;
        if let Some(t) = triangles.iter().flatten().find(|&&k| u32::from(k) >= nv) {
            return Err(bad(format!(
                "mesh {i} ({link}): triangle index {t} past its {nv} vertices"
            )));
        }
        set.meshes.push(LinkMesh {
            link,
            color,
            mesh: QuantizedMesh {
                min: [bx[0], bx[1], bx[2]],
                max: [bx[3], bx[4], bx[5]],
                positions,
                triangles,
            },
        });
    }
    Ok(set)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_mesh(rng: &mut ChaCha8Rng, nv: usize) -> TriMesh {
        let scale: [f32; 3] = std::array::from_fn(|_| rng.random_range(0.01..0.5));
        let vertices = (0..nv)
            .map(|_| std::array::from_fn(|k| rng.random_range(-1.0..1.0) * scale[k] + 0.3))
            .collect();
        let triangles = (0..nv as u32 - 2).map(|i| [i, i + 1, i + 2]).collect();
        TriMesh {
            vertices,
            triangles,
        }
    }

    #[test]
    fn round_trip_is_within_half_a_step() {
        let mut rng = ChaCha8Rng::seed_from_u64(15);
        for _ in 0..20 {
            let m = random_mesh(&mut rng, 500);
            let q = QuantizedMesh::new(&m).unwrap();
            let (lo, hi) = m.bounding_box().unwrap();
            assert_eq!((q.min, q.max), (lo, hi));
            for (a, b) in m.vertices.iter().zip(q.vertices()) {
                for k in 0..3 {
                    let step = (f64::from(hi[k]) - f64::from(lo[k])) / 65535.0;
                    // Half a step, plus the f32 rounding of the value read back.
                    let tol = step / 2.0 + f64::from(f32::EPSILON) * f64::from(a[k].abs());
                    let err = (f64::from(a[k]) - f64::from(b[k])).abs();
                    assert!(err <= tol, "error {err} > {tol}");
                }
            }
        }
    }

    #[test]
    fn a_flat_axis_quantizes_to_its_value() {
        let m = TriMesh {
            vertices: vec![[0.0, 0.0, 0.25], [1.0, 0.0, 0.25], [0.0, 1.0, 0.25]],
            triangles: vec![[0, 1, 2]],
        };
        let q = QuantizedMesh::new(&m).unwrap();
        assert_eq!(q.vertices(), m.vertices);
    }

    #[test]
    fn pack_and_unpack_are_inverse_and_bad_bytes_are_errors() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let set = MeshSet {
            meshes: (0..3)
                .map(|i| LinkMesh {
                    link: format!("link_{i}_é"),
                    color: [i as u8, 100, 200],
                    mesh: QuantizedMesh::new(&random_mesh(&mut rng, 40)).unwrap(),
                })
                .collect(),
        };
        let b = pack(&set);
        assert_eq!(unpack(&b).unwrap(), set);
        for cut in [0, 5, 12, 20, b.len() - 1] {
            let e = unpack(&b[..cut]).unwrap_err().to_string();
            assert!(e.contains("truncated") || e.contains("do not fit"), "{e}");
        }
        let mut wrong = b.clone();
        wrong[0] = b'X';
        assert!(unpack(&wrong).unwrap_err().to_string().contains("magic"));
        // A triangle index past the vertices: the last u16 of the first... last mesh.
        let mut past = b;
        let n = past.len();
        past[n - 2..].copy_from_slice(&1000u16.to_le_bytes());
        assert!(unpack(&past).unwrap_err().to_string().contains("past its"));
    }

    #[test]
    fn too_many_vertices_and_no_triangles_are_errors() {
        let big = TriMesh {
            vertices: vec![[0.0; 3]; 70_000],
            triangles: vec![[0, 1, 2]],
        };
        assert!(QuantizedMesh::new(&big)
            .unwrap_err()
            .to_string()
            .contains("65536"));
        let empty = TriMesh::default();
        assert!(QuantizedMesh::new(&empty)
            .unwrap_err()
            .to_string()
            .contains("no triangles"));
    }
}
