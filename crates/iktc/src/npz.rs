//! The arrays of a NumPy `.npz` archive: a zip (members *stored* or *deflated*) of `.npy`
//! files, opened with the `zip` crate, each member's header and data read with `npyz`.
//!
//! Numbers of any float, signed or unsigned integer dtype of 1–8 bytes, either byte order,
//! C or Fortran order, are read as `f64` in C order (row-major: the last index fastest).
//! Strings (`'<U…'` unicode or `'|S…'` bytes) are read for optional text such as a gender.
//! Every error names the archive and the array.

use std::io::{Read, Seek};

use npyz::{DType, NpyFile, Order, TypeChar};
use zip::ZipArchive;

use crate::error::{Error, Result};

/// An open `.npz` archive.
pub(crate) struct Npz<R: Read + Seek> {
    zip: ZipArchive<R>,
    source: String,
}

/// A numeric array read whole: its shape and its values in C order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Array {
    /// The shape (`[]` for a scalar).
    pub shape: Vec<usize>,
    /// The values, as many as the shape's product, C order.
    pub values: Vec<f64>,
}

/// The C-order strides of `shape` (the last index's is 1).
fn c_strides(shape: &[usize]) -> Vec<usize> {
    let mut strides = vec![1; shape.len()];
    for i in (0..shape.len().saturating_sub(1)).rev() {
        strides[i] = strides[i + 1] * shape[i + 1];
    }
    strides
}

/// The C-order index of the element stored at position `k` of an array of `shape` stored in
/// Fortran order (the first index fastest); `strides` are [`c_strides`] of `shape`.
fn fortran_to_c(mut k: usize, shape: &[usize], strides: &[usize]) -> usize {
    let mut c = 0;
    for (d, s) in shape.iter().zip(strides) {
        let d = (*d).max(1);
        c += (k % d) * s;
        k /= d;
    }
    c
}

impl<R: Read + Seek> Npz<R> {
    /// Opens the archive (reads its central directory only).
    ///
    /// Errors: [`Error::Parse`] when `reader` is not a whole zip archive (a truncated file
    /// lacks the directory at its end).
    pub fn new(reader: R, source: &str) -> Result<Self> {
        let zip = ZipArchive::new(reader).map_err(|e| Error::Parse {
            source_name: source.to_string(),
            line: 0,
            message: format!(
                "not a readable NPZ (zip) archive: {e}; a file cut short lacks the archive's \
                 directory at its end"
            ),
        })?;
        Ok(Self {
            zip,
            source: source.to_string(),
        })
    }

    /// The array names (members without `.npy`), sorted.
    pub fn names(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .zip
            .file_names()
            .filter_map(|n| n.strip_suffix(".npy"))
            .map(str::to_string)
            .collect();
        v.sort();
        v
    }

    /// The array names (members ending in `.npy`, without it) in the archive's order.
    pub fn names_in_order(&self) -> Vec<String> {
        self.zip
            .file_names()
            .filter_map(|n| n.strip_suffix(".npy"))
            .map(str::to_string)
            .collect()
    }

    /// Whether the archive holds the array `name`.
    pub fn has(&self, name: &str) -> bool {
        self.zip.index_for_name(&format!("{name}.npy")).is_some()
    }

    /// Opens the array `name`: its `.npy` header read, its data next.
    fn open(&mut self, name: &str) -> Result<NpyFile<zip::read::ZipFile<'_, R>>> {
        if !self.has(name) {
            let names = self.names();
            return Err(Error::Parse {
                source_name: self.source.clone(),
                line: 0,
                message: format!(
                    "no array `{name}` in the archive; it holds: {}",
                    if names.is_empty() {
                        "nothing".to_string()
                    } else {
                        names.join(", ")
                    }
                ),
            });
        }
        let source = self.source.clone();
        let member = self
            .zip
            .by_name(&format!("{name}.npy"))
            .map_err(|e| Error::Parse {
                source_name: source.clone(),
                line: 0,
                message: format!("array `{name}`: cannot open the member: {e}"),
            })?;
        NpyFile::new(member).map_err(|e| Error::Parse {
            source_name: source,
            line: 0,
            message: format!("array `{name}`: not a NumPy .npy array: {e}"),
        })
    }

    /// Reads the member of the array `name` to its end, which makes the `zip` crate compare its
    /// data with its CRC-32 (a typed read stops at the last element and never gets there).
    ///
    /// Errors: [`Error::Parse`] naming the array when the data is damaged or cut short.
    fn verify(&mut self, name: &str) -> Result<()> {
        let source = self.source.clone();
        let mut member = self
            .zip
            .by_name(&format!("{name}.npy"))
            .map_err(|e| array_error(&source, name, format!("cannot open the member: {e}")))?;
        std::io::copy(&mut member, &mut std::io::sink()).map_err(|e| {
            array_error(
                &source,
                name,
                format!("its data is damaged or cut short (CRC-32 or length): {e}"),
            )
        })?;
        Ok(())
    }

    /// The shape of the array `name` (its header only).
    pub fn shape(&mut self, name: &str) -> Result<Vec<usize>> {
        let npy = self.open(name)?;
        let shape = npy.shape().to_vec();
        drop(npy);
        usize_shape(&self.source, name, &shape)
    }

    fn error(&self, name: &str, message: String) -> Error {
        array_error(&self.source, name, message)
    }
}

fn array_error(source: &str, name: &str, message: String) -> Error {
    Error::Parse {
        source_name: source.to_string(),
        line: 0,
        message: format!("array `{name}`: {message}"),
    }
}

/// The element count of `shape`, at most `max_len`.
fn checked_len(source: &str, name: &str, shape: &[usize], max_len: usize) -> Result<usize> {
    let len = shape
        .iter()
        .try_fold(1usize, |n, d| n.checked_mul(*d))
        .filter(|n| *n <= max_len)
        .ok_or_else(|| {
            array_error(
                source,
                name,
                format!("shape {shape:?} holds more than the {max_len} elements expected"),
            )
        })?;
    Ok(len)
}

fn usize_shape(source: &str, name: &str, shape: &[u64]) -> Result<Vec<usize>> {
    shape
        .iter()
        .map(|d| usize::try_from(*d))
        .collect::<std::result::Result<Vec<usize>, _>>()
        .map_err(|_| array_error(source, name, format!("shape {shape:?} is too large")))
}

impl<R: Read + Seek> Npz<R> {
    /// Reads the numeric array `name` element by element, calling `visit(c_index, value)` for
    /// each (in storage order), after checking that it holds at most `max_len` elements.
    /// Returns its shape.
    ///
    /// Errors: [`Error::Parse`] for a missing array, a header that cannot be read, a dtype that
    /// is not a number (strings, objects, structured records), data cut short, more than
    /// `max_len` elements.
    pub fn visit(
        &mut self,
        name: &str,
        max_len: usize,
        mut visit: impl FnMut(usize, f64),
    ) -> Result<Vec<usize>> {
        let source = self.source.clone();
        let err = |message: String| Error::Parse {
            source_name: source.clone(),
            line: 0,
            message: format!("array `{name}`: {message}"),
        };
        let npy = self.open(name)?;
        let shape_u64 = npy.shape().to_vec();
        let order = npy.order();
        let dtype = npy.dtype();
        let shape = usize_shape(&source, name, &shape_u64)?;
        let len = checked_len(&source, name, &shape, max_len)?;
        let strides = c_strides(&shape);
        let place = |k: usize| match order {
            Order::C => k,
            Order::Fortran => fortran_to_c(k, &shape, &strides),
        };
        let kind = match &dtype {
            DType::Plain(t) => Some((t.type_char(), t.size_field())),
            _ => None,
        };
        macro_rules! read_as {
            ($t:ty) => {{
                let data = npy
                    .data::<$t>()
                    .map_err(|e| err(format!("cannot read its values: {e}")))?;
                for (k, v) in data.enumerate() {
                    let v = v.map_err(|e| {
                        err(format!(
                            "cut short or unreadable at element {k} of {len}: {e}"
                        ))
                    })?;
                    visit(place(k), v as f64);
                }
            }};
        }
        match kind {
            Some((TypeChar::Float, 8)) => read_as!(f64),
            Some((TypeChar::Float, 4)) => read_as!(f32),
            Some((TypeChar::Int, 8)) => read_as!(i64),
            Some((TypeChar::Int, 4)) => read_as!(i32),
            Some((TypeChar::Int, 2)) => read_as!(i16),
            Some((TypeChar::Int, 1)) => read_as!(i8),
            Some((TypeChar::Uint, 8)) => read_as!(u64),
            Some((TypeChar::Uint, 4)) => read_as!(u32),
            Some((TypeChar::Uint, 2)) => read_as!(u16),
            Some((TypeChar::Uint, 1)) => read_as!(u8),
            _ => {
                return Err(err(format!(
                    "dtype `{}` is not a number (expected a float or integer array{})",
                    dtype.descr(),
                    if dtype.uses_pickled_array() {
                        "; a pickled object, such as a sparse matrix, must be saved as a dense \
                         array"
                    } else {
                        ""
                    }
                )))
            }
        }
        self.verify(name)?;
        Ok(shape)
    }

    /// Reads the numeric array `name` whole, C order, after checking that it holds at most
    /// `max_len` elements (see [`Npz::visit`]).
    pub fn array(&mut self, name: &str, max_len: usize) -> Result<Array> {
        let shape = self.shape(name)?;
        let len = checked_len(&self.source, name, &shape, max_len)?;
        let mut values = vec![0.0; len];
        let mut count = 0;
        let shape = self.visit(name, max_len, |i, v| {
            if let Some(x) = values.get_mut(i) {
                *x = v;
                count += 1;
            }
        })?;
        if count != len {
            return Err(self.error(name, format!("{count} values for {len} elements")));
        }
        Ok(Array { shape, values })
    }

    /// Whether the array `name` holds unicode strings (`'<U…'`).
    ///
    /// Errors: those of opening it ([`Npz::shape`]).
    pub fn is_unicode(&mut self, name: &str) -> Result<bool> {
        let npy = self.open(name)?;
        Ok(matches!(npy.dtype(), DType::Plain(t) if t.type_char() == TypeChar::UnicodeStr))
    }

    /// Reads the unicode string array `name` (`'<U…'`, C order), each string trimmed of its NUL
    /// padding, after checking that it holds at most `max_len` strings.
    ///
    /// Errors: [`Error::Parse`] for a missing array, another dtype, data cut short or a
    /// character that is not a Unicode scalar value, more than `max_len` strings.
    pub fn strings(&mut self, name: &str, max_len: usize) -> Result<(Vec<usize>, Vec<String>)> {
        let source = self.source.clone();
        let npy = self.open(name)?;
        let shape = usize_shape(&source, name, npy.shape())?;
        let len = checked_len(&source, name, &shape, max_len)?;
        let unicode =
            matches!(npy.dtype(), DType::Plain(t) if t.type_char() == TypeChar::UnicodeStr);
        if !unicode || npy.order() != Order::C && shape.len() > 1 {
            return Err(array_error(
                &source,
                name,
                format!(
                    "dtype `{}` is not a C-order unicode string array ('<U…')",
                    npy.dtype().descr()
                ),
            ));
        }
        let mut out = Vec::with_capacity(len);
        let data = npy
            .data::<String>()
            .map_err(|e| array_error(&source, name, format!("cannot read its strings: {e}")))?;
        for (k, v) in data.enumerate() {
            let v = v.map_err(|e| {
                array_error(
                    &source,
                    name,
                    format!("cut short or unreadable at string {k} of {len}: {e}"),
                )
            })?;
            out.push(v.trim_end_matches(char::from(0)).to_string());
        }
        if out.len() != len {
            return Err(array_error(
                &source,
                name,
                format!("{} strings for {len} elements", out.len()),
            ));
        }
        self.verify(name)?;
        Ok((shape, out))
    }

    /// The text of the array `name` if it is a string scalar or a one-element string array
    /// (unicode or bytes), trimmed of NUL padding; `None` when it is absent, not a string or
    /// unreadable.
    pub fn text(&mut self, name: &str) -> Option<String> {
        let npy = self.open(name).ok()?;
        if npy.len() != 1 {
            return None;
        }
        let char_kind = match npy.dtype() {
            DType::Plain(t) => t.type_char(),
            _ => return None,
        };
        let s = match char_kind {
            TypeChar::UnicodeStr => npy.data::<String>().ok()?.next()?.ok()?,
            TypeChar::ByteStr => {
                let b = npy.data::<Vec<u8>>().ok()?.next()?.ok()?;
                String::from_utf8_lossy(&b).into_owned()
            }
            _ => return None,
        };
        Some(s.trim_matches(char::from(0)).trim().to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::{c_strides, fortran_to_c};

    #[test]
    fn fortran_positions_map_to_row_major_indices() {
        // A 2×3 array stored column by column: a00 a10 a01 a11 a02 a12.
        let s = c_strides(&[2, 3]);
        assert_eq!(s, [3, 1]);
        let c: Vec<usize> = (0..6).map(|k| fortran_to_c(k, &[2, 3], &s)).collect();
        assert_eq!(c, [0, 3, 1, 4, 2, 5]);
        assert_eq!(fortran_to_c(0, &[], &[]), 0);
    }
}
