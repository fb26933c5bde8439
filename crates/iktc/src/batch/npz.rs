//! NumPy's `.npz` format for the batch's outputs (`motion.npz`, the mjlab motion file) and for
//! reading trajectories back ([`read_npz`], `iktc evaluate`): a zip archive of `.npy` arrays,
//! readable by `numpy.load`.
//!
//! Each `.npy` member is written by `npyz` (NumPy's format 1.0: the magic `\x93NUMPY`, a header
//! dict `{'descr', 'fortran_order': False, 'shape'}` padded so that the data starts on a
//! multiple of 64 bytes, then the data in C order): little-endian `f64` (`'<f8'`) or
//! fixed-width UTF-32 strings (`'<UN'`, N the longest string's length). The archive is
//! written by the `zip` crate with every member *stored*, as `numpy.savez` does; reading takes
//! stored or deflated members (`numpy.savez_compressed`) through the reader AMASS archives use (`npyz` and `zip`).

use std::io::{Cursor, Write};

use npyz::{DType, TypeStr, WriterBuilder};
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

use crate::error::{Error, Result};

/// The values of one array.
#[derive(Debug, Clone, PartialEq)]
pub enum NpyData {
    /// 64-bit floats (`'<f8'`).
    F64(Vec<f64>),
    /// Unicode strings (`'<UN'`, N the longest string's length in characters).
    Str(Vec<String>),
}

/// One named array of an `.npz` archive.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyArray {
    /// Member name without `.npy` (the key `numpy.load(...)[name]`).
    pub name: String,
    /// Shape, C order; `[]` for a scalar.
    pub shape: Vec<usize>,
    /// Values, as many as the shape's product.
    pub data: NpyData,
}

/// An error of `npyz` or `zip` while assembling an array or archive in memory, named.
fn io_error(what: String, e: std::io::Error) -> Error {
    Error::Parse {
        source_name: what,
        line: 0,
        message: format!("could not be written: {e}"),
    }
}

impl NpyArray {
    /// A float array; its length must equal the product of `shape`.
    pub fn f64(name: &str, shape: Vec<usize>, data: Vec<f64>) -> Self {
        Self {
            name: name.into(),
            shape,
            data: NpyData::F64(data),
        }
    }

    /// A one-dimensional array of strings.
    pub fn strings(name: &str, data: Vec<String>) -> Self {
        Self {
            name: name.into(),
            shape: vec![data.len()],
            data: NpyData::Str(data),
        }
    }

    /// The `.npy` file of this array.
    ///
    /// Errors: [`Error::DimensionMismatch`] when the data's length is not the shape's product.
    pub fn npy_bytes(&self) -> Result<Vec<u8>> {
        let count: usize = self.shape.iter().product();
        let len = match &self.data {
            NpyData::F64(v) => v.len(),
            NpyData::Str(v) => v.len(),
        };
        if len != count {
            return Err(Error::DimensionMismatch {
                what: format!("npy array `{}` (shape {:?})", self.name, self.shape),
                expected: count,
                got: len,
            });
        }
        let shape: Vec<u64> = self.shape.iter().map(|d| *d as u64).collect();
        let what = || format!("npy array `{}`", self.name);
        let mut out = Vec::new();
        match &self.data {
            NpyData::F64(v) => {
                let mut w = npyz::WriteOptions::<f64>::new()
                    .default_dtype()
                    .shape(&shape)
                    .writer(&mut out)
                    .begin_nd()
                    .map_err(|e| io_error(what(), e))?;
                w.extend(v.iter().copied())
                    .map_err(|e| io_error(what(), e))?;
                w.finish().map_err(|e| io_error(what(), e))?;
            }
            NpyData::Str(v) => {
                let descr = format!("<U{}", str_width(v));
                let type_str: TypeStr = descr.parse().map_err(|e| Error::InvalidSetting {
                    name: what(),
                    value: descr.clone(),
                    expected: format!("a NumPy unicode dtype ({e})"),
                })?;
                let mut w = npyz::WriteOptions::<String>::new()
                    .dtype(DType::Plain(type_str))
                    .shape(&shape)
                    .writer(&mut out)
                    .begin_nd()
                    .map_err(|e| io_error(what(), e))?;
                w.extend(v.iter().cloned())
                    .map_err(|e| io_error(what(), e))?;
                w.finish().map_err(|e| io_error(what(), e))?;
            }
        }
        Ok(out)
    }
}

/// Characters per string of a `'<UN'` array: the longest string's, at least 1.
fn str_width(v: &[String]) -> usize {
    v.iter()
        .map(|s| s.chars().count())
        .max()
        .unwrap_or(0)
        .max(1)
}

/// A zip archive of `members` (name, bytes), every member stored (no compression), in the
/// order given.
///
/// Errors: [`Error::Parse`] naming the member the `zip` crate could not add.
pub fn zip_stored(members: &[(String, Vec<u8>)]) -> Result<Vec<u8>> {
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Stored)
        .large_file(
            members
                .iter()
                .any(|(_, b)| b.len() as u64 >= u64::from(u32::MAX)),
        );
    for (name, bytes) in members {
        zip.start_file(name.as_str(), options)
            .map_err(|e| io_error(format!("zip member `{name}`"), e.into()))?;
        zip.write_all(bytes)
            .map_err(|e| io_error(format!("zip member `{name}`"), e))?;
    }
    let out = zip
        .finish()
        .map_err(|e| io_error("zip archive".into(), e.into()))?;
    Ok(out.into_inner())
}

/// The `.npz` archive of `arrays` (members `NAME.npy`, stored, in the order given).
///
/// Errors: those of [`NpyArray::npy_bytes`] and [`zip_stored`].
pub fn npz_bytes(arrays: &[NpyArray]) -> Result<Vec<u8>> {
    let members = arrays
        .iter()
        .map(|a| Ok((format!("{}.npy", a.name), a.npy_bytes()?)))
        .collect::<Result<Vec<_>>>()?;
    zip_stored(&members)
}

/// Most elements read from one array of an archive \[–\]: 10⁹ (8 GB of `f64`), beyond any
/// trajectory [`crate::resources`] lets the batch write.
pub const MAX_NPZ_ELEMENTS: usize = 1_000_000_000;

/// The `.npz` archive `bytes` (from `source`, for errors) read back: every member whose name
/// ends in `.npy`, in the archive's order, as an array named without it. Members stored
/// (`numpy.savez`) or deflated (`numpy.savez_compressed`). Arrays: numbers of any float or
/// integer dtype, read as `f64` in C order, and unicode strings (`'<UN'`).
///
/// Errors: [`Error::Parse`] naming the archive and the member for an archive that is not a
/// whole zip, a member whose data does not match its CRC-32 or is cut short, an `.npy` header
/// that is not NumPy's, another data type, more than [`MAX_NPZ_ELEMENTS`] elements.
pub fn read_npz(bytes: &[u8], source: &str) -> Result<Vec<NpyArray>> {
    let mut npz = crate::npz::Npz::new(Cursor::new(bytes), source)?;
    let names = npz.names_in_order();
    if names.is_empty() {
        return Err(Error::Parse {
            source_name: source.into(),
            line: 0,
            message: "no .npy member: not an .npz archive".into(),
        });
    }
    let mut out = Vec::with_capacity(names.len());
    for name in names {
        let array = if npz.is_unicode(&name)? {
            let (shape, v) = npz.strings(&name, MAX_NPZ_ELEMENTS)?;
            NpyArray {
                name,
                shape,
                data: NpyData::Str(v),
            }
        } else {
            let a = npz.array(&name, MAX_NPZ_ELEMENTS)?;
            NpyArray {
                name,
                shape: a.shape,
                data: NpyData::F64(a.values),
            }
        };
        out.push(array);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_header_aligns_the_data_on_64_bytes() {
        for shape in [vec![], vec![3], vec![2, 5], vec![4, 3, 3]] {
            let n: usize = shape.iter().product();
            let a = NpyArray::f64("x", shape.clone(), vec![1.5; n]);
            let b = a.npy_bytes().unwrap();
            assert_eq!(&b[..6], b"\x93NUMPY");
            let hlen = u16::from_le_bytes([b[8], b[9]]) as usize;
            assert_eq!((10 + hlen) % 64, 0, "shape {shape:?}");
            assert_eq!(b.len(), 10 + hlen + 8 * n);
            assert_eq!(b[10 + hlen - 1], b'\n');
            let header = String::from_utf8_lossy(&b[10..10 + hlen]).to_string();
            assert!(header.contains("'descr': '<f8'"), "{header}");
            assert!(header.contains("'fortran_order': False"), "{header}");
        }
    }

    #[test]
    fn strings_are_utf32_padded_to_the_longest() {
        let a = NpyArray::strings("n", vec!["ab".into(), "é".into()]);
        let b = a.npy_bytes().unwrap();
        let hlen = u16::from_le_bytes([b[8], b[9]]) as usize;
        let header = String::from_utf8_lossy(&b[10..10 + hlen]).to_string();
        assert!(header.contains("'descr': '<U2'"), "{header}");
        let data = &b[10 + hlen..];
        let expect: Vec<u8> = ['a', 'b', 'é', '\0']
            .iter()
            .flat_map(|c| u32::from(*c).to_le_bytes())
            .collect();
        assert_eq!(data, expect.as_slice());
    }

    #[test]
    fn wrong_length_is_an_error_naming_the_array() {
        let e = NpyArray::f64("q", vec![2, 3], vec![0.0; 5])
            .npy_bytes()
            .unwrap_err();
        assert!(e.to_string().contains("`q`"), "{e}");
    }
}
