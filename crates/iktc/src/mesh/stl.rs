//! Reading STL files, binary and ASCII.
//!
//! Binary STL: an 80-byte header, a little-endian `u32` triangle count `n`, then `n` records of
//! 50 bytes (normal, three vertices, each three `f32`, and a 2-byte attribute). A file is read
//! as binary when its size is exactly `84 + 50·n`, whatever its header says (many exporters
//! start binary headers with `solid`); otherwise as ASCII (`solid … facet normal nx ny nz /
//! outer loop / vertex x y z ×3 / endloop / endfacet … endsolid`).

use super::TriMesh;
use crate::error::{Error, Result};

/// Size of the binary STL header and triangle count \[bytes\].
const BINARY_HEADER: usize = 84;
/// Size of one binary STL triangle record \[bytes\].
const BINARY_RECORD: usize = 50;

/// A triangle soup as read from an STL file (unit: the file's, usually metres or millimetres).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StlMesh {
    /// The facet normals the file states (not recomputed; often zero in exported files).
    pub normals: Vec<[f32; 3]>,
    /// The three corners of every triangle.
    pub triangles: Vec<[[f32; 3]; 3]>,
}

fn bad(name: &str, line: usize, message: impl Into<String>) -> Error {
    Error::Parse {
        source_name: name.into(),
        line,
        message: message.into(),
    }
}

/// Reads an STL file's bytes; `name` names the source in errors.
///
/// # Errors
/// [`Error::Parse`] for a truncated binary file, an ASCII file that is not STL, a facet
/// without three vertices, or a coordinate that is not a finite number.
pub fn read_stl(bytes: &[u8], name: &str) -> Result<StlMesh> {
    if bytes.len() >= BINARY_HEADER {
        let mut n = [0u8; 4];
        n.copy_from_slice(&bytes[80..84]);
        let n = u32::from_le_bytes(n) as usize;
        if n.checked_mul(BINARY_RECORD)
            .and_then(|s| s.checked_add(BINARY_HEADER))
            == Some(bytes.len())
        {
            return read_binary(&bytes[BINARY_HEADER..], n, name);
        }
    }
    let text = std::str::from_utf8(bytes);
    match text {
        // NUL bytes are binary data (a binary STL whose header starts with `solid`).
        Ok(t) if t.trim_start().starts_with("solid") && !t.contains('\0') => read_ascii(t, name),
        _ if bytes.len() >= BINARY_HEADER => Err(bad(
            name,
            0,
            format!(
                "not an STL file: {} bytes is not 84 + 50 × the binary triangle count, and the \
                 text does not start with `solid` (a truncated binary STL?)",
                bytes.len()
            ),
        )),
        _ => Err(bad(
            name,
            0,
            format!(
                "not an STL file: {} bytes, shorter than a binary STL header (84 bytes) and \
                 not ASCII STL",
                bytes.len()
            ),
        )),
    }
}

fn read_binary(body: &[u8], n: usize, name: &str) -> Result<StlMesh> {
    let mut out = StlMesh {
        normals: Vec::with_capacity(n),
        triangles: Vec::with_capacity(n),
    };
    for (i, rec) in body.chunks_exact(BINARY_RECORD).enumerate() {
        let mut f = [0f32; 12];
        for (k, v) in f.iter_mut().enumerate() {
            let mut b = [0u8; 4];
            b.copy_from_slice(&rec[4 * k..4 * k + 4]);
            *v = f32::from_le_bytes(b);
        }
        if let Some(x) = f.iter().find(|x| !x.is_finite()) {
            return Err(bad(
                name,
                0,
                format!("triangle {i}: a coordinate is not finite ({x})"),
            ));
        }
        out.normals.push([f[0], f[1], f[2]]);
        out.triangles
            .push([[f[3], f[4], f[5]], [f[6], f[7], f[8]], [f[9], f[10], f[11]]]);
    }
    Ok(out)
}

fn numbers(words: &[&str], name: &str, line: usize) -> Result<[f32; 3]> {
    let mut v = [0f32; 3];
    if words.len() != 3 {
        return Err(bad(
            name,
            line,
            format!("expected three numbers, got {}", words.len()),
        ));
    }
    for (k, w) in words.iter().enumerate() {
        v[k] = w
            .parse::<f32>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| bad(name, line, format!("`{w}` is not a finite number")))?;
    }
    Ok(v)
}

fn read_ascii(text: &str, name: &str) -> Result<StlMesh> {
    let mut out = StlMesh::default();
    let mut corners: Vec<[f32; 3]> = Vec::with_capacity(3);
    let mut normal = None;
    for (i, line) in text.lines().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["facet", "normal", rest @ ..] => {
                normal = Some(numbers(rest, name, i + 1)?);
                corners.clear();
            }
            ["vertex", rest @ ..] => {
                if normal.is_none() {
                    return Err(bad(name, i + 1, "`vertex` outside a `facet`"));
                }
                corners.push(numbers(rest, name, i + 1)?);
            }
            ["endfacet", ..] => {
                let (Some(nrm), [a, b, c]) = (normal.take(), corners.as_slice()) else {
                    return Err(bad(
                        name,
                        i + 1,
                        format!("a facet needs 3 vertices, this one has {}", corners.len()),
                    ));
                };
                out.normals.push(nrm);
                out.triangles.push([*a, *b, *c]);
            }
            _ => {}
        }
    }
    if normal.is_some() {
        return Err(bad(
            name,
            0,
            "the last facet has no `endfacet` (truncated?)",
        ));
    }
    if out.triangles.is_empty() {
        return Err(bad(
            name,
            0,
            "no `facet` in the ASCII STL (an empty solid, or a truncated binary STL?)",
        ));
    }
    Ok(out)
}

impl StlMesh {
    /// The indexed mesh: corners at bit-identical positions become one vertex
    /// ([`TriMesh::weld`]).
    pub fn weld(&self) -> TriMesh {
        TriMesh::weld(&self.triangles)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of `tris` (normal, corners), with a header starting with `solid`.
    fn binary(tris: &[([f32; 3], [[f32; 3]; 3])]) -> Vec<u8> {
        let mut b = b"solid looks like ascii but is binary".to_vec();
        b.resize(80, b' ');
        b.extend((tris.len() as u32).to_le_bytes());
        for (n, c) in tris {
            for x in n.iter().chain(c.iter().flatten()) {
                b.extend(x.to_le_bytes());
            }
            b.extend([0u8, 0]);
        }
        b
    }

    const TRI_A: ([f32; 3], [[f32; 3]; 3]) = (
        [0.0, 0.0, 1.0],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    );
    const TRI_B: ([f32; 3], [[f32; 3]; 3]) = (
        [0.0, 0.0, 1.0],
        [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
    );

    #[test]
    fn binary_stl_reads_its_triangles_and_normals() {
        let m = read_stl(&binary(&[TRI_A, TRI_B]), "square.stl").unwrap();
        assert_eq!(m.triangles, vec![TRI_A.1, TRI_B.1]);
        assert_eq!(m.normals, vec![TRI_A.0, TRI_B.0]);
        // Two triangles sharing an edge: four distinct vertices.
        let w = m.weld();
        assert_eq!(w.vertices.len(), 4);
        assert_eq!(w.triangles.len(), 2);
        for (t, src) in w.triangles.iter().zip(&m.triangles) {
            for k in 0..3 {
                assert_eq!(w.vertices[t[k] as usize], src[k]);
            }
        }
    }

    #[test]
    fn ascii_stl_reads_its_triangles_and_normals() {
        let text = "solid tri\n facet normal 0 0 -1\n  outer loop\n   vertex 0 0 0\n   \
                    vertex 0 2 0\n   vertex 2e0 0 0\n  endloop\n endfacet\nendsolid tri\n";
        let m = read_stl(text.as_bytes(), "tri.stl").unwrap();
        assert_eq!(m.normals, vec![[0.0, 0.0, -1.0]]);
        assert_eq!(
            m.triangles,
            vec![[[0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]]]
        );
    }

    #[test]
    fn truncated_binary_stl_is_an_error_naming_the_file() {
        let mut b = binary(&[TRI_A, TRI_B]);
        b.truncate(b.len() - 7);
        let e = read_stl(&b, "cut.stl").unwrap_err().to_string();
        assert!(e.contains("cut.stl") && e.contains("truncated"), "{e}");
        // Cut inside the header: text starting with `solid`, but no facet.
        let e = read_stl(&b[..40], "tiny.stl").unwrap_err().to_string();
        assert!(
            e.contains("tiny.stl") && e.contains("truncated binary"),
            "{e}"
        );
        let e = read_stl(&[7u8; 40], "bytes.stl").unwrap_err().to_string();
        assert!(e.contains("bytes.stl") && e.contains("84 bytes"), "{e}");
    }

    #[test]
    fn bad_ascii_stl_is_an_error_naming_the_line() {
        let two = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n\
                   endfacet\nendsolid\n";
        let e = read_stl(two.as_bytes(), "two.stl").unwrap_err().to_string();
        assert!(e.contains("two.stl:7") && e.contains("3 vertices"), "{e}");
        let nan = "solid x\nfacet normal 0 0 1\nvertex 0 nan 0\n";
        let e = read_stl(nan.as_bytes(), "nan.stl").unwrap_err().to_string();
        assert!(e.contains("nan.stl:3") && e.contains("finite"), "{e}");
        let open = "solid x\nfacet normal 0 0 1\nvertex 0 0 0\n";
        let e = read_stl(open.as_bytes(), "open.stl")
            .unwrap_err()
            .to_string();
        assert!(e.contains("endfacet"), "{e}");
        let e = read_stl(b"solid empty\nendsolid empty\n", "empty.stl")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no `facet`"), "{e}");
        let e = read_stl(b"PK\x03\x04", "zip.stl").unwrap_err().to_string();
        assert!(e.contains("not an STL file"), "{e}");
    }
}
