//! 16-bit quantization of mesh coordinates across their bounding box, and the packed binary
//! of a set of link meshes (the format the viewer page and the built-in data file share).
//!
//! Coordinate `x` in `[min, max]` is stored as `u = round((x − min) / step)` with
//! `step = (max − min) / 65535` (a zero-width axis has step 0 and stores 0); it reads back as
//! `min + u · step`, within `step / 2` of `x` (plus `f32` rounding).
//!
//! Triangle indices are packed against a high-water mark: vertices are numbered in the order
//! the triangles first use them, so an index is either the next new vertex (`hw`, written as
//! 0, then `hw ← hw + 1`) or an earlier one `i < hw` (written as `hw − i`), each a LEB128
//! varint (7 bits a byte, low first); neighbouring triangles share recent vertices, so most
//! indices take one byte instead of two.

use super::TriMesh;
use crate::error::{Error, Result};

/// The largest quantized coordinate (16 bits).
const LEVELS: f64 = 65535.0;
/// First bytes of a packed mesh set.
pub const MAGIC: &[u8; 8] = b"IKTCMSH2";

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
/// triangle count, the positions (`u16 ×3` each, in the order of first use), `u32` byte length
/// of the index stream, and the index stream (module docs). Vertices no triangle uses, and
/// triangles with an index past the vertices, are left out.
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
        let nv = m.mesh.positions.len();
        let tris: Vec<&[u16; 3]> = m
            .mesh
            .triangles
            .iter()
            .filter(|t| t.iter().all(|&i| usize::from(i) < nv))
            .collect();
        // New numbers in the order of first use, and the index stream.
        let mut new_of = vec![u32::MAX; nv];
        let mut order: Vec<usize> = Vec::new();
        let mut stream = Vec::new();
        for &i in tris.iter().copied().flatten() {
            let hw = order.len() as u32;
            let n = &mut new_of[usize::from(i)];
            if *n == u32::MAX {
                *n = hw;
                order.push(usize::from(i));
            }
            let mut d = hw - *n;
            loop {
                let byte = (d & 0x7f) as u8;
                d >>= 7;
                if d == 0 {
                    stream.push(byte);
                    break;
                }
                stream.push(byte | 0x80);
            }
        }
        b.extend((order.len() as u32).to_le_bytes());
        b.extend((tris.len() as u32).to_le_bytes());
        for &i in &order {
            for x in m.mesh.positions[i] {
                b.extend(x.to_le_bytes());
            }
        }
        b.extend((stream.len() as u32).to_le_bytes());
        b.extend(stream);
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
    /// `nt` triangles from an index stream of `len` bytes over `nv` vertices (module docs).
    fn triangles(&mut self, nt: u32, nv: u32, len: u32) -> Result<Vec<[u16; 3]>> {
        let stream = self.take(len as usize, "the index stream")?;
        let bad = |message: String| Error::Parse {
            source_name: "packed meshes".into(),
            line: 0,
            message,
        };
        if (nt as usize).saturating_mul(3) > stream.len() {
            return Err(bad(format!(
                "{nt} triangles do not fit in {len} index bytes"
            )));
        }
        let (mut hw, mut at) = (0u32, 0usize);
        let mut next = || -> Result<u16> {
            let mut d = 0u32;
            for shift in (0..32).step_by(7) {
                let byte = *stream
                    .get(at)
                    .ok_or_else(|| bad("the index stream ends inside a triangle".into()))?;
                at += 1;
                d |= u32::from(byte & 0x7f) << shift;
                if byte & 0x80 == 0 {
                    let i = if d == 0 {
                        hw += 1;
                        hw - 1
                    } else {
                        hw.checked_sub(d).ok_or_else(|| {
                            bad(format!("an index {d} back, past the {hw} vertices seen"))
                        })?
                    };
                    return if i < nv {
                        Ok(i as u16)
                    } else {
                        Err(bad(format!("index {i} past its {nv} vertices")))
                    };
                }
            }
            Err(bad("an index of more than 32 bits".into()))
        };
        let tris = (0..nt)
            .map(|_| Ok([next()?, next()?, next()?]))
            .collect::<Result<Vec<_>>>()?;
        if at != stream.len() {
            return Err(bad(format!(
                "{} bytes left in the index stream after {nt} triangles",
                stream.len() - at
            )));
        }
        Ok(tris)
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
        if nv > u32::from(u16::MAX) + 1 {
            return Err(bad(format!(
                "mesh {i} ({link}): {nv} vertices, at most 65536"
            )));
        }
        let positions = r.u16x3(nv, "vertices")?;
        let len = r.u32("the index stream's length")?;
        let triangles = r
            .triangles(nt, nv, len)
            .map_err(|e| bad(format!("mesh {i} ({link}): {e}")))?;
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
        // The last index (one byte: 1 or 2 back) made to point before the first vertex.
        let mut past = b;
        let n = past.len();
        past[n - 1] = 0x7f;
        let e = unpack(&past).unwrap_err().to_string();
        assert!(e.contains("past the") && e.contains("link_2"), "{e}");
    }

    #[test]
    fn packing_renumbers_vertices_by_first_use_and_drops_unused_ones() {
        let m = TriMesh {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [9.0, 9.0, 9.0],
                [1.0, 1.0, 0.5],
            ],
            // Vertex 3 unused; first use order 2, 1, 0, 4.
            triangles: vec![[2, 1, 0], [0, 4, 2], [4, 1, 2]],
        };
        let mut q = QuantizedMesh::new(&m).unwrap();
        // A triangle past the vertices is dropped too.
        q.triangles.push([0, 1, 7]);
        let set = MeshSet {
            meshes: vec![LinkMesh {
                link: "l".into(),
                color: [0; 3],
                mesh: q.clone(),
            }],
        };
        let back = unpack(&pack(&set)).unwrap();
        let r = &back.meshes[0].mesh;
        assert_eq!(r.positions.len(), 4);
        assert_eq!(r.triangles, vec![[0, 1, 2], [2, 3, 0], [3, 1, 0]]);
        // The same corners, corner by corner.
        for (a, b) in q.triangles.iter().zip(&r.triangles) {
            for k in 0..3 {
                assert_eq!(
                    q.positions[usize::from(a[k])],
                    r.positions[usize::from(b[k])]
                );
            }
        }
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
