//! NumPy's `.npz` format written by hand: a zip archive (every member *stored*, no
//! compression) of `.npy` arrays, readable by `numpy.load`.
//!
//! An `.npy` member is the magic `\x93NUMPY`, version 1.0, a little-endian `u16` header length,
//! the header — a Python dict literal `{'descr': …, 'fortran_order': False, 'shape': (…), }`
//! padded with spaces and ended by `\n` so that the data starts on a multiple of 64 bytes — and
//! the data in C order: little-endian `f64` (`'<f8'`) or fixed-width UTF-32 strings (`'<UN'`).
//! The zip container follows PKWARE's APPNOTE: one local header and data per member, then the
//! central directory and its end record; each member's CRC-32 is the IEEE polynomial
//! `0xEDB88320` (reflected), as zip requires.

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
        let (descr, len) = match &self.data {
            NpyData::F64(v) => ("<f8".to_string(), v.len()),
            NpyData::Str(v) => (format!("<U{}", str_width(v)), v.len()),
        };
        if len != count {
            return Err(Error::DimensionMismatch {
                what: format!("npy array `{}` (shape {:?})", self.name, self.shape),
                expected: count,
                got: len,
            });
        }
        let shape = match self.shape.len() {
            0 => "()".to_string(),
            1 => format!("({},)", self.shape[0]),
            _ => format!(
                "({})",
                self.shape
                    .iter()
                    .map(|d| d.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        let mut header =
            format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        // magic (6) + version (2) + length (2) + header + '\n' ≡ 0 (mod 64)
        let unpadded = 10 + header.len() + 1;
        header.push_str(&" ".repeat((64 - unpadded % 64) % 64));
        header.push('\n');
        let mut out = Vec::with_capacity(10 + header.len() + 8 * count);
        out.extend_from_slice(b"\x93NUMPY\x01\x00");
        let hlen = u16::try_from(header.len()).map_err(|_| Error::ResourceLimit {
            what: format!("npy header of `{}`", self.name),
            value: header.len().to_string(),
            limit: u16::MAX.to_string(),
            option: "fewer dimensions".into(),
        })?;
        out.extend_from_slice(&hlen.to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        match &self.data {
            NpyData::F64(v) => v
                .iter()
                .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
            NpyData::Str(v) => {
                let width = str_width(v);
                for s in v {
                    let n = s.chars().count();
                    for c in s.chars() {
                        out.extend_from_slice(&u32::from(c).to_le_bytes());
                    }
                    out.resize(out.len() + 4 * (width - n), 0);
                }
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

/// The CRC-32 table of the reflected IEEE polynomial.
const CRC_TABLE: [u32; 256] = {
    let mut t = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
};

/// CRC-32 (IEEE, as zip and gzip use it) of `data`.
pub fn crc32(data: &[u8]) -> u32 {
    !data.iter().fold(!0u32, |c, b| {
        CRC_TABLE[((c ^ u32::from(*b)) & 0xFF) as usize] ^ (c >> 8)
    })
}

/// The largest archive or member this writer produces \[bytes\]: zip without its 64-bit
/// extension stores sizes and offsets in 32 bits.
pub const MAX_ZIP_BYTES: usize = u32::MAX as usize;

/// A zip archive of `members` (name, content), every member stored uncompressed, dated
/// 1980-01-01 00:00 (the format's epoch: the archive depends only on its content).
///
/// Errors: [`Error::ResourceLimit`] beyond [`MAX_ZIP_BYTES`] or 65 535 members.
pub fn zip_stored(members: &[(String, Vec<u8>)]) -> Result<Vec<u8>> {
    let too_big = |what: &str, value: usize, limit: usize| Error::ResourceLimit {
        what: what.into(),
        value: value.to_string(),
        limit: limit.to_string(),
        option: "shorter clips or a lower --rate".into(),
    };
    let total: usize = members
        .iter()
        .map(|(n, d)| 76 + 2 * n.len() + d.len())
        .sum();
    if total + 22 > MAX_ZIP_BYTES {
        return Err(too_big(
            "zip archive size [bytes]",
            total + 22,
            MAX_ZIP_BYTES,
        ));
    }
    let count = u16::try_from(members.len())
        .map_err(|_| too_big("zip members", members.len(), usize::from(u16::MAX)))?;
    let mut out = Vec::with_capacity(total + 22);
    let mut central = Vec::new();
    // DOS date of 1980-01-01: ((1980 - 1980) << 9) | (1 << 5) | 1.
    const DOS_DATE: u16 = (1 << 5) | 1;
    for (name, data) in members {
        // Both fit: the whole archive was checked against u32 above.
        let (offset, size, nlen) = (out.len() as u32, data.len() as u32, name.len() as u16);
        let crc = crc32(data);
        let common = |v: &mut Vec<u8>| {
            v.extend_from_slice(&20u16.to_le_bytes()); // version needed: 2.0
            v.extend_from_slice(&0u16.to_le_bytes()); // flags
            v.extend_from_slice(&0u16.to_le_bytes()); // method: stored
            v.extend_from_slice(&0u16.to_le_bytes()); // time
            v.extend_from_slice(&DOS_DATE.to_le_bytes());
            v.extend_from_slice(&crc.to_le_bytes());
            v.extend_from_slice(&size.to_le_bytes()); // compressed
            v.extend_from_slice(&size.to_le_bytes()); // uncompressed
            v.extend_from_slice(&nlen.to_le_bytes());
            v.extend_from_slice(&0u16.to_le_bytes()); // extra length
        };
        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        common(&mut out);
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(data);
        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&20u16.to_le_bytes()); // version made by
        common(&mut central);
        central.extend_from_slice(&0u16.to_le_bytes()); // comment length
        central.extend_from_slice(&0u16.to_le_bytes()); // disk number
        central.extend_from_slice(&0u16.to_le_bytes()); // internal attributes
        central.extend_from_slice(&0u32.to_le_bytes()); // external attributes
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(name.as_bytes());
    }
    let cd_offset = out.len() as u32;
    let cd_size = central.len() as u32;
    out.extend_from_slice(&central);
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes()); // this disk
    out.extend_from_slice(&0u16.to_le_bytes()); // disk of the central directory
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&cd_size.to_le_bytes());
    out.extend_from_slice(&cd_offset.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes()); // comment length
    Ok(out)
}

/// The `.npz` archive of `arrays` (members `NAME.npy`).
///
/// Errors: those of [`NpyArray::npy_bytes`] and [`zip_stored`].
pub fn npz_bytes(arrays: &[NpyArray]) -> Result<Vec<u8>> {
    let members = arrays
        .iter()
        .map(|a| Ok((format!("{}.npy", a.name), a.npy_bytes()?)))
        .collect::<Result<Vec<_>>>()?;
    zip_stored(&members)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_of_the_standard_check_string() {
        // The CRC catalogue's check value of CRC-32/ISO-HDLC for "123456789".
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
    }

    #[test]
    fn npy_header_aligns_the_data_on_64_bytes() {
        for shape in [vec![], vec![3], vec![2, 5], vec![4, 3, 3]] {
            let n: usize = shape.iter().product();
            let a = NpyArray::f64("x", shape.clone(), vec![1.5; n]);
            let b = a.npy_bytes().unwrap();
            let hlen = u16::from_le_bytes([b[8], b[9]]) as usize;
            assert_eq!((10 + hlen) % 64, 0, "shape {shape:?}");
            assert_eq!(b.len(), 10 + hlen + 8 * n);
            assert_eq!(b[10 + hlen - 1], b'\n');
        }
    }

    #[test]
    fn wrong_length_is_an_error_naming_the_array() {
        let e = NpyArray::f64("q", vec![2, 3], vec![0.0; 5])
            .npy_bytes()
            .unwrap_err();
        assert!(e.to_string().contains("`q`"), "{e}");
    }
}
