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

/// The `.npz` archive `bytes` (from `source`, for errors) read back: every member whose name
/// ends in `.npy`, as an array named without it. Members must be *stored* (`numpy.savez` and
/// iktc write them so; `numpy.savez_compressed`'s deflated members are an error); sizes may be
/// given in a zip64 extra field (`numpy.savez` asks for one). Arrays: `'<f8'` floats of any
/// shape (C order) and `'<UN'` strings of one dimension.
///
/// Errors: [`Error::Parse`] naming the member for a truncated archive, a compressed member, a
/// CRC-32 that does not match, an `.npy` header that is not NumPy's, or another data type.
pub fn read_npz(bytes: &[u8], source: &str) -> Result<Vec<NpyArray>> {
    let bad = |message: String| Error::Parse {
        source_name: source.into(),
        line: 0,
        message,
    };
    let u16_at = |o: usize| -> Result<usize> {
        bytes
            .get(o..o + 2)
            .map(|b| usize::from(u16::from_le_bytes([b[0], b[1]])))
            .ok_or_else(|| bad(format!("truncated zip archive at byte {o}")))
    };
    let u32_at = |o: usize| -> Result<u32> {
        bytes
            .get(o..o + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| bad(format!("truncated zip archive at byte {o}")))
    };
    let mut out = Vec::new();
    let mut at = 0;
    while u32_at(at).ok() == Some(0x0403_4b50) {
        let (flags, method) = (u16_at(at + 6)?, u16_at(at + 8)?);
        let crc = u32_at(at + 14)?;
        let mut size = u32_at(at + 18)? as u64;
        let (nlen, xlen) = (u16_at(at + 26)?, u16_at(at + 28)?);
        let name_bytes = bytes
            .get(at + 30..at + 30 + nlen)
            .ok_or_else(|| bad("truncated zip member name".into()))?;
        let name = String::from_utf8_lossy(name_bytes).to_string();
        let extra = bytes
            .get(at + 30 + nlen..at + 30 + nlen + xlen)
            .ok_or_else(|| bad(format!("member `{name}`: truncated extra field")))?;
        if method != 0 {
            return Err(bad(format!(
                "member `{name}` is compressed (zip method {method}); only stored members are \
                 read (numpy.savez, not savez_compressed)"
            )));
        }
        if flags & 0x8 != 0 {
            return Err(bad(format!(
                "member `{name}` gives its size after its data (zip flag 3); expected sizes in \
                 its header"
            )));
        }
        if size == u64::from(u32::MAX) {
            // The zip64 extra field (id 1): uncompressed size, then compressed size.
            let mut e = 0;
            while e + 4 <= extra.len() {
                let id = u16::from_le_bytes([extra[e], extra[e + 1]]);
                let len = usize::from(u16::from_le_bytes([extra[e + 2], extra[e + 3]]));
                if id == 1 && len >= 8 && e + 12 <= extra.len() {
                    let mut b = [0u8; 8];
                    b.copy_from_slice(&extra[e + 4..e + 12]);
                    size = u64::from_le_bytes(b);
                }
                e += 4 + len;
            }
        }
        let start = at + 30 + nlen + xlen;
        let data = usize::try_from(size)
            .ok()
            .and_then(|n| bytes.get(start..start.checked_add(n)?))
            .ok_or_else(|| bad(format!("member `{name}`: truncated data ({size} bytes)")))?;
        if crc32(data) != crc {
            return Err(bad(format!(
                "member `{name}`: CRC-32 does not match its data"
            )));
        }
        if let Some(stem) = name.strip_suffix(".npy") {
            out.push(read_npy(stem, data).map_err(|m| bad(format!("member `{name}`: {m}")))?);
        }
        at = start + data.len();
    }
    if out.is_empty() {
        return Err(bad("no .npy member: not an .npz archive".into()));
    }
    Ok(out)
}

/// One `.npy` file named `name` (module documentation); the error in words.
fn read_npy(name: &str, b: &[u8]) -> std::result::Result<NpyArray, String> {
    if b.len() < 10 || &b[..6] != b"\x93NUMPY" {
        return Err("not an .npy array (no \\x93NUMPY magic)".into());
    }
    let (hlen, hstart) = match b[6] {
        1 => (usize::from(u16::from_le_bytes([b[8], b[9]])), 10),
        2 | 3 if b.len() >= 12 => (u32::from_le_bytes([b[8], b[9], b[10], b[11]]) as usize, 12),
        v => return Err(format!(".npy version {v} is not read (1, 2 or 3 expected)")),
    };
    let header = b
        .get(hstart..hstart + hlen)
        .map(|h| String::from_utf8_lossy(h).to_string())
        .ok_or("truncated .npy header")?;
    let field = |key: &str| -> Option<String> {
        let i = header.find(&format!("'{key}'"))? + key.len() + 2;
        let rest = header[i..].trim_start().strip_prefix(':')?.trim_start();
        Some(rest.to_string())
    };
    let descr = field("descr")
        .and_then(|r| {
            r.strip_prefix('\'')
                .and_then(|r| r.split('\'').next().map(String::from))
        })
        .ok_or("no 'descr' in the .npy header")?;
    if field("fortran_order").is_some_and(|r| r.starts_with("True")) {
        return Err("Fortran-ordered arrays are not read (C order expected)".into());
    }
    let shape_text = field("shape")
        .and_then(|r| {
            r.strip_prefix('(')
                .and_then(|r| r.split(')').next().map(String::from))
        })
        .ok_or("no 'shape' in the .npy header")?;
    let shape = shape_text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<usize>()
                .map_err(|_| format!("shape ({shape_text}) is not sizes"))
        })
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let count = shape
        .iter()
        .try_fold(1usize, |a, d| a.checked_mul(*d))
        .ok_or("shape too large")?;
    let data = &b[hstart + hlen..];
    let array = if descr == "<f8" {
        let need = count.checked_mul(8).ok_or("shape too large")?;
        if data.len() < need {
            return Err(format!("{} data bytes, expected {need}", data.len()));
        }
        let v = data[..need]
            .chunks_exact(8)
            .map(|c| {
                let mut x = [0u8; 8];
                x.copy_from_slice(c);
                f64::from_le_bytes(x)
            })
            .collect();
        NpyData::F64(v)
    } else if let Some(w) = descr.strip_prefix("<U") {
        let w: usize = w.parse().map_err(|_| format!("dtype {descr}"))?;
        if shape.len() != 1 {
            return Err(format!(
                "string arrays of shape {shape:?} are not read (one dimension)"
            ));
        }
        let need = count.checked_mul(4 * w).ok_or("shape too large")?;
        if data.len() < need || w == 0 && count > 0 {
            return Err(format!("{} data bytes, expected {need}", data.len()));
        }
        let v = data[..need]
            .chunks_exact(4 * w)
            .map(|s| {
                s.chunks_exact(4)
                    .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .take_while(|&c| c != 0)
                    .map(|c| char::from_u32(c).ok_or(format!("code point {c} is not a character")))
                    .collect::<std::result::Result<String, String>>()
            })
            .collect::<std::result::Result<Vec<_>, _>>()?;
        NpyData::Str(v)
    } else {
        return Err(format!(
            "dtype {descr} is not read ('<f8' or '<UN' expected)"
        ));
    };
    Ok(NpyArray {
        name: name.into(),
        shape,
        data: array,
    })
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
