//! A minimal reader of C3D files: the 3D point (marker) trajectories.
//!
//! Supported: the header block (number of points, analog values per frame, first and last
//! frame, scale factor, data start block, frame rate), the parameter section (groups and
//! parameters of any type; `POINT:LABELS` names the points, continued by `POINT:LABELS2`,
//! `POINT:LABELS3`, … past 255 points; `POINT:RATE` overrides the header's rate when present),
//! and the data section with integer (scale factor > 0: every coordinate is `value · scale`) or
//! floating-point (scale factor < 0) samples, for Intel (processor type 84, little-endian),
//! DEC (85: little-endian integers, VAX F-floating numbers) and MIPS/SGI (86, big-endian)
//! files. A point whose residual word is negative is missing in that frame (a gap). Analog
//! samples are skipped.
//!
//! Layout (C3D.org, "The C3D File Format User Guide"): 512-byte blocks; header words are 16-bit;
//! a parameter entry is `[name length (i8, < 0 if locked), group id (i8, < 0 for a group),
//! name, offset to the next entry (i16), …]`, a parameter continuing with
//! `[type (i8: −1 char, 1 byte, 2 int16, 4 float), dimension count, dimensions, data,
//! description length, description]`.

use nalgebra::Vector3;

use super::markers::MarkerSet;
use crate::error::{Error, Result};

const BLOCK: usize = 512;

#[derive(Clone, Copy)]
enum Endian {
    /// Intel: IEEE 754 numbers, little-endian.
    Little,
    /// DEC (VAX): little-endian integers; F-floating numbers, stored as two little-endian
    /// 16-bit words, the one with the sign and exponent first.
    Dec,
    /// MIPS/SGI: IEEE 754 numbers, big-endian.
    Big,
}

struct Reader<'a> {
    bytes: &'a [u8],
    endian: Endian,
    source: &'a str,
}

impl Reader<'_> {
    fn error(&self, offset: usize, message: impl Into<String>) -> Error {
        Error::Parse {
            source_name: self.source.to_string(),
            line: 0,
            message: format!("byte {offset}: {}", message.into()),
        }
    }

    fn get<const N: usize>(&self, at: usize) -> Result<[u8; N]> {
        self.bytes
            .get(at..at + N)
            .and_then(|s| <[u8; N]>::try_from(s).ok())
            .ok_or_else(|| {
                self.error(
                    at,
                    format!("the file ends (it has {} bytes)", self.bytes.len()),
                )
            })
    }

    fn u16(&self, at: usize) -> Result<u16> {
        let b = self.get::<2>(at)?;
        Ok(match self.endian {
            Endian::Little | Endian::Dec => u16::from_le_bytes(b),
            Endian::Big => u16::from_be_bytes(b),
        })
    }

    fn i16(&self, at: usize) -> Result<i16> {
        let b = self.get::<2>(at)?;
        Ok(match self.endian {
            Endian::Little | Endian::Dec => i16::from_le_bytes(b),
            Endian::Big => i16::from_be_bytes(b),
        })
    }

    fn f32(&self, at: usize) -> Result<f32> {
        let b = self.get::<4>(at)?;
        Ok(match self.endian {
            Endian::Little => f32::from_le_bytes(b),
            Endian::Dec => vax_f32(b),
            Endian::Big => f32::from_be_bytes(b),
        })
    }
}

/// A VAX F-floating number from its 4 bytes as a C3D file stores them. With its two 16-bit
/// words swapped it has IEEE single precision's layout (sign, 8-bit exponent, 23-bit
/// fraction), but means `0.1f · 2^(e − 128)` where IEEE means `1.f · 2^(e − 127)`: a quarter of
/// the IEEE reading. Exponent 0 is zero (sign 0) or a reserved operand (sign 1, NaN here).
fn vax_f32(b: [u8; 4]) -> f32 {
    let ieee = f32::from_le_bytes([b[2], b[3], b[0], b[1]]);
    let exponent = (u32::from(b[1] & 0x7f) << 1) | u32::from(b[0] >> 7);
    match (exponent, b[1] >> 7) {
        (0, 0) => 0.0,
        (0, _) => f32::NAN,
        _ => ieee / 4.0,
    }
}

/// One parameter: group name, name, type, dimensions, raw data.
struct Parameter {
    group: String,
    name: String,
    kind: i8,
    dims: Vec<usize>,
    data_at: usize,
}

/// The header fields read for points (their byte offsets in the header in brackets).
struct Header {
    /// Points per frame (2).
    points: usize,
    /// Analog samples per frame (4).
    analog_per_frame: usize,
    /// First frame number, from 1 (6).
    first: usize,
    /// Last frame number (8).
    last: usize,
    /// Scale of integer data; negative for floating-point data (12).
    scale: f64,
    /// First block of the data, from 1 (16).
    data_block: usize,
    /// Frame rate \[Hz\] (20).
    rate: f64,
}

/// Checks the file's start and sets `r`'s number format from the processor type; returns the
/// byte offset of the parameter section.
fn read_processor(r: &mut Reader) -> Result<usize> {
    let bytes = r.bytes;
    if bytes.len() < BLOCK || bytes[1] != 0x50 {
        return Err(r.error(
            1,
            format!(
                "not a C3D file: it needs a 512-byte header whose second byte is 0x50 (found {} bytes, second byte {:#04x})",
                bytes.len(),
                bytes.get(1).copied().unwrap_or(0)
            ),
        ));
    }
    let param_block = bytes[0] as usize;
    if param_block < 2 {
        return Err(r.error(0, format!("parameter block {param_block}; expected ≥ 2")));
    }
    let param_at = (param_block - 1) * BLOCK;
    let processor = r.get::<4>(param_at)?[3];
    r.endian = match processor {
        84 => Endian::Little,
        86 => Endian::Big,
        85 => Endian::Dec,
        other => {
            return Err(r.error(
                param_at + 3,
                format!("processor type {other}; expected 84 (Intel), 86 (MIPS) or 85 (DEC)"),
            ))
        }
    };
    Ok(param_at)
}

/// Reads and checks the header: frames `1 ≤ first ≤ last`, a finite non-zero scale, a data
/// block ≥ 2.
fn read_header(r: &Reader) -> Result<Header> {
    let header = Header {
        points: r.u16(2)? as usize,
        analog_per_frame: r.u16(4)? as usize,
        first: r.u16(6)? as usize,
        last: r.u16(8)? as usize,
        scale: r.f32(12)? as f64,
        data_block: r.u16(16)? as usize,
        rate: r.f32(20)? as f64,
    };
    let Header {
        first,
        last,
        scale,
        data_block,
        ..
    } = header;
    if last < first || first == 0 {
        return Err(r.error(
            6,
            format!("frames {first}–{last}; expected 1 ≤ first ≤ last"),
        ));
    }
    if !scale.is_finite() || scale == 0.0 {
        return Err(r.error(
            12,
            format!("scale factor {scale}; expected a finite non-zero number"),
        ));
    }
    if data_block < 2 {
        return Err(r.error(16, format!("data start block {data_block}; expected ≥ 2")));
    }
    Ok(header)
}

/// The parameter `group:name` (case-insensitive), if any.
fn find_parameter<'p>(params: &'p [Parameter], group: &str, name: &str) -> Option<&'p Parameter> {
    params
        .iter()
        .find(|p| p.group.eq_ignore_ascii_case(group) && p.name.eq_ignore_ascii_case(name))
}

/// The names of the `points` points: `POINT:LABELS` (at most 255 names, as a dimension is one
/// byte), continued by `LABELS2`, `LABELS3`, …; a missing or empty name is `P<k>` (from 1).
fn point_names(params: &[Parameter], bytes: &[u8], points: usize) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for k in 1.. {
        let key = if k == 1 {
            "LABELS".to_string()
        } else {
            format!("LABELS{k}")
        };
        match find_parameter(params, "POINT", &key) {
            Some(p) if p.kind == -1 && p.dims.len() == 2 => {
                let (len, count) = (p.dims[0], p.dims[1]);
                names.extend((0..count).map(|j| {
                    let at = p.data_at + j * len;
                    let raw = bytes.get(at..at + len).unwrap_or(&[]);
                    String::from_utf8_lossy(raw).trim().to_string()
                }));
            }
            _ => break,
        }
        if names.len() >= points {
            break;
        }
    }
    names.truncate(points);
    for k in names.len()..points {
        names.push(format!("P{}", k + 1));
    }
    for (k, n) in names.iter_mut().enumerate() {
        if n.is_empty() {
            *n = format!("P{}", k + 1);
        }
    }
    names
}

/// The point positions, frame after frame (`None` for a point with a negative residual), from
/// the data section; a file too short or a non-finite coordinate is an error.
fn read_positions(r: &Reader, h: &Header, names: &[String]) -> Result<Vec<Option<Vector3<f64>>>> {
    let bytes = r.bytes;
    let (points, scale) = (h.points, h.scale);
    let float = scale < 0.0;
    let word = if float { 4 } else { 2 };
    let frame_bytes = (points * 4 + h.analog_per_frame) * word;
    let frames = h.last - h.first + 1;
    let data_at = (h.data_block - 1) * BLOCK;
    let needed = data_at + frames * frame_bytes;
    if bytes.len() < needed {
        return Err(r.error(
            bytes.len(),
            format!(
                "truncated data: {frames} frames of {points} points need {needed} bytes, the file has {}",
                bytes.len()
            ),
        ));
    }
    let mut positions = Vec::with_capacity(frames * points);
    for f in 0..frames {
        for (k, name) in names.iter().enumerate() {
            let at = data_at + f * frame_bytes + k * 4 * word;
            let value = |i: usize| -> Result<f64> {
                Ok(if float {
                    r.f32(at + i * 4)? as f64
                } else {
                    r.i16(at + i * 2)? as f64 * scale
                })
            };
            let residual = value(3)?;
            let p = Vector3::new(value(0)?, value(1)?, value(2)?);
            if residual < 0.0 {
                positions.push(None);
            } else if p.iter().all(|v| v.is_finite()) {
                positions.push(Some(p));
            } else {
                return Err(r.error(
                    at,
                    format!(
                        "frame {}, point `{name}`: a non-finite coordinate",
                        h.first + f
                    ),
                ));
            }
        }
    }
    Ok(positions)
}

/// Reads a C3D file's points (see the module documentation); `source` names it in errors
/// ([`Error::Parse`] with the byte offset).
pub fn read_c3d(bytes: &[u8], source: &str) -> Result<MarkerSet> {
    let mut r = Reader {
        bytes,
        endian: Endian::Little,
        source,
    };
    let param_at = read_processor(&mut r)?;
    let header = read_header(&r)?;
    let params = parameters(&r, param_at)?;
    let names = point_names(&params, bytes, header.points);
    let rate = match find_parameter(&params, "POINT", "RATE") {
        Some(p) if p.kind == 4 => r.f32(p.data_at)? as f64,
        _ => header.rate,
    };
    if !(rate.is_finite() && rate > 0.0) {
        return Err(r.error(20, format!("frame rate {rate} Hz; expected > 0")));
    }
    let positions = read_positions(&r, &header, &names)?;
    let frames = header.last - header.first + 1;
    Ok(MarkerSet {
        source: source.to_string(),
        names,
        times: (0..frames).map(|f| f as f64 / rate).collect(),
        positions,
    })
}

fn parameters(r: &Reader, start: usize) -> Result<Vec<Parameter>> {
    let mut groups: Vec<(u8, String)> = Vec::new();
    let mut raw: Vec<(u8, Parameter)> = Vec::new();
    let mut at = start + 4;
    loop {
        let [len, id] = r.get::<2>(at)?;
        let name_len = (len as i8).unsigned_abs() as usize;
        let id = id as i8;
        if name_len == 0 || id == 0 {
            break;
        }
        let name_bytes = r
            .bytes
            .get(at + 2..at + 2 + name_len)
            .ok_or_else(|| r.error(at, "a parameter name runs past the end of the file"))?;
        let name = String::from_utf8_lossy(name_bytes).to_string();
        let offset_at = at + 2 + name_len;
        let next = r.i16(offset_at)?;
        let body = offset_at + 2;
        if id < 0 {
            groups.push((id.unsigned_abs(), name));
        } else {
            let kind = r.get::<1>(body)?[0] as i8;
            let ndims = r.get::<1>(body + 1)?[0] as usize;
            let dims: Vec<usize> = (0..ndims)
                .map(|d| r.get::<1>(body + 2 + d).map(|b| b[0] as usize))
                .collect::<Result<Vec<_>>>()?;
            raw.push((
                id.unsigned_abs(),
                Parameter {
                    group: String::new(),
                    name,
                    kind,
                    dims,
                    data_at: body + 2 + ndims,
                },
            ));
        }
        if next <= 0 {
            break;
        }
        at = offset_at + next as usize;
    }
    Ok(raw
        .into_iter()
        .map(|(id, mut p)| {
            p.group = groups
                .iter()
                .find(|(g, _)| *g == id)
                .map(|(_, n)| n.clone())
                .unwrap_or_default();
            p
        })
        .collect())
}
