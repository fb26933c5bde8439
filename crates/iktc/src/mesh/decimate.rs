//! Vertex clustering (Rossignac & Borrel, 1993): every vertex is moved to the mean of the
//! vertices in its grid cube of side `cell`, triangles with two corners in one cube are
//! dropped, and so are duplicates (the same three cubes).

use std::collections::{HashMap, HashSet};

use super::TriMesh;
use crate::error::{Error, Result};

/// The decimated `mesh` on a grid of cube side `cell` (the mesh's unit, e.g. \[m\]).
///
/// # Errors
/// [`Error::InvalidSetting`] when `cell` is not finite and > 0.
pub fn decimate(mesh: &TriMesh, cell: f64) -> Result<TriMesh> {
    if !(cell.is_finite() && cell > 0.0) {
        return Err(Error::InvalidSetting {
            name: "decimation cell".into(),
            value: cell.to_string(),
            expected: "a finite length > 0 [m]".into(),
        });
    }
    let key = |v: &[f32; 3]| v.map(|x| (f64::from(x) / cell).floor() as i64);
    // Cube of every vertex, and each cube's vertex sum and count.
    let mut cube_of = Vec::with_capacity(mesh.vertices.len());
    let mut cubes: HashMap<[i64; 3], u32> = HashMap::new();
    let mut sums: Vec<([f64; 3], u32)> = Vec::new();
    for v in &mesh.vertices {
        let c = *cubes.entry(key(v)).or_insert_with(|| {
            sums.push(([0.0; 3], 0));
            (sums.len() - 1) as u32
        });
        let s = &mut sums[c as usize];
        for (acc, x) in s.0.iter_mut().zip(v) {
            *acc += f64::from(*x);
        }
        s.1 += 1;
        cube_of.push(c);
    }
    // Kept triangles, over cube indices; vertices renumbered in order of first use.
    let mut seen: HashSet<[u32; 3]> = HashSet::new();
    let mut new_index: Vec<Option<u32>> = vec![None; sums.len()];
    let mut out = TriMesh::default();
    for t in &mesh.triangles {
        let Some(c) = t
            .iter()
            .map(|&i| cube_of.get(i as usize).copied())
            .collect::<Option<Vec<u32>>>()
        else {
            continue;
        };
        let (a, b, d) = (c[0], c[1], c[2]);
        if a == b || b == d || a == d {
            continue;
        }
        // The same three cubes in any rotation (orientation kept) is a duplicate.
        let m = *c.iter().min().unwrap_or(&a);
        let canon = match c.iter().position(|&x| x == m) {
            Some(1) => [b, d, a],
            Some(2) => [d, a, b],
            _ => [a, b, d],
        };
        if !seen.insert(canon) {
            continue;
        }
        let mut tri = [0u32; 3];
        for (k, &ci) in [a, b, d].iter().enumerate() {
            tri[k] = *new_index[ci as usize].get_or_insert_with(|| {
                let (s, n) = sums[ci as usize];
                out.vertices.push(s.map(|x| (x / f64::from(n)) as f32));
                (out.vertices.len() - 1) as u32
            });
        }
        out.triangles.push(tri);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed box `size` \[m\] centred at `c`, each face an `n`×`n` grid of quads.
    fn fine_box(size: [f32; 3], c: [f32; 3], n: usize) -> TriMesh {
        let mut m = TriMesh::default();
        for axis in 0..3 {
            for side in [-1.0f32, 1.0] {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let base = m.vertices.len() as u32;
                for i in 0..=n {
                    for j in 0..=n {
                        let mut p = [0f32; 3];
                        p[axis] = c[axis] + side * size[axis] / 2.0;
                        p[u] = c[u] + size[u] * (i as f32 / n as f32 - 0.5);
                        p[v] = c[v] + size[v] * (j as f32 / n as f32 - 0.5);
                        m.vertices.push(p);
                    }
                }
                let at = |i: usize, j: usize| base + (i * (n + 1) + j) as u32;
                for i in 0..n {
                    for j in 0..n {
                        m.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                        m.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
                    }
                }
            }
        }
        m
    }

    #[test]
    fn clustering_drops_triangles_and_keeps_the_box_within_a_cell() {
        let cell = 0.01;
        for (size, centre) in [
            ([0.2, 0.1, 0.3], [0.0, 0.0, 0.0]),
            ([0.05, 0.31, 0.12], [0.123, -0.456, 0.789]),
        ] {
            let m = fine_box(size, centre, 60);
            let d = decimate(&m, cell).unwrap();
            assert!(
                d.triangles.len() * 4 < m.triangles.len(),
                "{} of {} triangles kept",
                d.triangles.len(),
                m.triangles.len()
            );
            assert!(!d.triangles.is_empty());
            let (lo, hi) = m.bounding_box().unwrap();
            let (dlo, dhi) = d.bounding_box().unwrap();
            for k in 0..3 {
                // A vertex moves to the mean of its cube, inside the cube: at most one cell
                // per axis (plus f32 rounding).
                let slack = cell + 1e-6;
                assert!((dlo[k] - lo[k]).abs() as f64 <= slack, "axis {k} min");
                assert!((dhi[k] - hi[k]).abs() as f64 <= slack, "axis {k} max");
            }
            // Every vertex index is in range and no triangle is degenerate.
            for t in &d.triangles {
                assert!(t.iter().all(|&i| (i as usize) < d.vertices.len()));
                assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
            }
        }
    }

    #[test]
    fn a_mesh_coarser_than_the_cell_is_kept_whole() {
        let m = fine_box([1.0, 1.0, 1.0], [0.5, 0.5, 0.5], 2);
        // Vertices 0.5 m apart, cubes of 1 mm, none shared except the box's own seams.
        let d = decimate(&m, 0.001).unwrap();
        assert_eq!(d.triangles.len(), m.triangles.len());
    }

    #[test]
    fn a_bad_cell_is_an_error() {
        let m = fine_box([1.0, 1.0, 1.0], [0.0; 3], 1);
        for c in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = decimate(&m, c).unwrap_err().to_string();
            assert!(e.contains("decimation cell"), "{e}");
        }
    }
}
