//! Python's pickle format written by hand (protocol 4), for the few values a motion file holds:
//! a dict of `str` keys whose values are `int`, `float`, `str`, `None`, lists of those, and
//! NumPy arrays.
//!
//! A NumPy array is written as the call `numpy.reshape(numpy.frombuffer(builtins.bytearray(B),
//! DTYPE), SHAPE)`: `B` the array's bytes in C order, `DTYPE` `'<f8'` (little-endian `f64`) or
//! `'<f4'` (`f32`), `SHAPE` a tuple of ints. Only the public functions `numpy.frombuffer` and
//! `numpy.reshape` are named, so the file loads with NumPy 1.x and 2.x alike (NumPy's own
//! pickles name `numpy.core.multiarray._reconstruct`, which NumPy 2 moved to `numpy._core`);
//! the buffer is a `bytearray`, so the array is writable (a `bytes` buffer would give a
//! read-only array).
//!
//! Opcodes used (Python's `pickletools` names): `PROTO`, `EMPTY_DICT`, `MARK`, `SETITEMS`,
//! `EMPTY_LIST`, `APPENDS`, `SHORT_BINUNICODE`/`BINUNICODE`, `BININT`, `BINFLOAT`, `NONE`,
//! `GLOBAL`, `BINBYTES`/`BINBYTES8`, `TUPLE`, `TUPLE1`, `TUPLE2`, `REDUCE`, `STOP`. No memo:
//! nothing is shared.

use crate::error::{Error, Result};

/// The element type of a NumPy array in the pickle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PyDtype {
    /// `'<f8'`: little-endian 64-bit floats.
    F64,
    /// `'<f4'`: little-endian 32-bit floats (values rounded to nearest).
    F32,
}

impl PyDtype {
    /// NumPy's type string.
    pub fn descr(self) -> &'static str {
        match self {
            PyDtype::F64 => "<f8",
            PyDtype::F32 => "<f4",
        }
    }
}

/// A Python value as the pickle writes it.
#[derive(Debug, Clone, PartialEq)]
pub enum PyValue {
    /// `None`.
    None,
    /// `int` (32-bit range).
    Int(i32),
    /// `float`.
    Float(f64),
    /// `str`.
    Str(String),
    /// `list`.
    List(Vec<PyValue>),
    /// A NumPy array of `dtype`, `shape` (C order) and `data` (as many values as the shape's
    /// product).
    Array {
        /// Element type written.
        dtype: PyDtype,
        /// Shape.
        shape: Vec<usize>,
        /// Values, C order.
        data: Vec<f64>,
    },
}

/// The pickle (protocol 4) of a dict whose keys are `entries`' names, in that order.
///
/// Errors: [`Error::DimensionMismatch`] for an array whose data's length is not its shape's
/// product, [`Error::ResourceLimit`] for a dimension beyond the 32-bit range.
pub fn pickle_dict(entries: &[(&str, PyValue)]) -> Result<Vec<u8>> {
    let mut out = vec![0x80, 4]; // PROTO 4
    out.push(b'}'); // EMPTY_DICT
    if !entries.is_empty() {
        out.push(b'('); // MARK
        for (key, value) in entries {
            str_op(&mut out, key);
            value_op(&mut out, key, value)?;
        }
        out.push(b'u'); // SETITEMS
    }
    out.push(b'.'); // STOP
    Ok(out)
}

fn str_op(out: &mut Vec<u8>, s: &str) {
    let b = s.as_bytes();
    match u8::try_from(b.len()) {
        Ok(n) => {
            out.push(0x8c); // SHORT_BINUNICODE
            out.push(n);
        }
        Err(_) => {
            out.push(b'X'); // BINUNICODE (a motion file's strings are far below 4 GiB)
            out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        }
    }
    out.extend_from_slice(b);
}

fn int_op(out: &mut Vec<u8>, i: i32) {
    out.push(b'J'); // BININT
    out.extend_from_slice(&i.to_le_bytes());
}

fn global_op(out: &mut Vec<u8>, module: &str, name: &str) {
    out.push(b'c'); // GLOBAL
    out.extend_from_slice(module.as_bytes());
    out.push(b'\n');
    out.extend_from_slice(name.as_bytes());
    out.push(b'\n');
}

fn value_op(out: &mut Vec<u8>, key: &str, v: &PyValue) -> Result<()> {
    match v {
        PyValue::None => out.push(b'N'),
        PyValue::Int(i) => int_op(out, *i),
        PyValue::Float(x) => {
            out.push(b'G'); // BINFLOAT, big-endian
            out.extend_from_slice(&x.to_be_bytes());
        }
        PyValue::Str(s) => str_op(out, s),
        PyValue::List(items) => {
            out.push(b']'); // EMPTY_LIST
            if !items.is_empty() {
                out.push(b'(');
                for item in items {
                    value_op(out, key, item)?;
                }
                out.push(b'e'); // APPENDS
            }
        }
        PyValue::Array { dtype, shape, data } => {
            let count: usize = shape.iter().product();
            if count != data.len() {
                return Err(Error::DimensionMismatch {
                    what: format!("pickled array `{key}` (shape {shape:?})"),
                    expected: count,
                    got: data.len(),
                });
            }
            let mut bytes = Vec::with_capacity(8 * count);
            match dtype {
                PyDtype::F64 => data
                    .iter()
                    .for_each(|x| bytes.extend_from_slice(&x.to_le_bytes())),
                PyDtype::F32 => data
                    .iter()
                    .for_each(|x| bytes.extend_from_slice(&(*x as f32).to_le_bytes())),
            }
            global_op(out, "numpy", "reshape");
            global_op(out, "numpy", "frombuffer");
            global_op(out, "builtins", "bytearray");
            match u32::try_from(bytes.len()) {
                Ok(n) => {
                    out.push(b'B'); // BINBYTES
                    out.extend_from_slice(&n.to_le_bytes());
                }
                Err(_) => {
                    out.push(0x8e); // BINBYTES8
                    out.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
                }
            }
            out.extend_from_slice(&bytes);
            out.push(0x85); // TUPLE1
            out.push(b'R'); // REDUCE: bytearray(B)
            str_op(out, dtype.descr());
            out.push(0x86); // TUPLE2
            out.push(b'R'); // REDUCE: frombuffer(…, DTYPE)
            out.push(b'('); // MARK
            for d in shape {
                let d = i32::try_from(*d).map_err(|_| Error::ResourceLimit {
                    what: format!("dimension of the pickled array `{key}`"),
                    value: d.to_string(),
                    limit: i32::MAX.to_string(),
                    option: "shorter clips or a lower --rate".into(),
                })?;
                int_op(out, d);
            }
            out.push(b't'); // TUPLE
            out.push(0x86); // TUPLE2
            out.push(b'R'); // REDUCE: reshape(…, SHAPE)
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_dict_is_the_bytes_python_reads() {
        // Hand-assembled from the opcode table of CPython's Lib/pickletools.py:
        // {'a': 1, 'b': [None, 2.0]}
        let b = pickle_dict(&[
            ("a", PyValue::Int(1)),
            ("b", PyValue::List(vec![PyValue::None, PyValue::Float(2.0)])),
        ])
        .unwrap();
        let mut expected = vec![0x80, 4, b'}', b'(', 0x8c, 1, b'a', b'J', 1, 0, 0, 0];
        expected.extend_from_slice(&[0x8c, 1, b'b', b']', b'(', b'N', b'G']);
        expected.extend_from_slice(&[0x40, 0, 0, 0, 0, 0, 0, 0]); // 2.0, big-endian
        expected.extend_from_slice(b"eu.");
        assert_eq!(b, expected);
    }

    #[test]
    fn wrong_array_length_is_an_error_naming_the_key() {
        let e = pickle_dict(&[(
            "root_pos",
            PyValue::Array {
                dtype: PyDtype::F64,
                shape: vec![2, 3],
                data: vec![0.0; 5],
            },
        )])
        .unwrap_err();
        assert!(e.to_string().contains("`root_pos`"), "{e}");
    }
}
