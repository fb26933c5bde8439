//! The last check before a JSON output is written: every number in it is finite.
//!
//! `serde_json` writes NaN and ±∞ as `null`, so a run gone wrong would leave a summary that looks
//! normal. [`to_json`] walks the value first with a serializer that only looks at numbers and
//! stops at the first non-finite one, naming its path (`summary.json: steps[12].q[3] is NaN`).
//! A quantity that may legitimately be unbounded is written as an `Option` (`null` = unbounded),
//! never as an infinite float.

use serde::ser::{self, Serialize};

/// A non-finite number at `path`.
#[derive(Debug)]
pub struct NonFinite {
    path: String,
    value: f64,
}

impl std::fmt::Display for NonFinite {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} is {}", self.path, self.value)
    }
}

impl std::error::Error for NonFinite {}

impl ser::Error for NonFinite {
    fn custom<T: std::fmt::Display>(msg: T) -> Self {
        NonFinite {
            path: msg.to_string(),
            value: f64::NAN,
        }
    }
}

/// Checks that every number in `value` is finite; the error names `what` and the path.
pub fn check<T: Serialize + ?Sized>(what: &str, value: &T) -> anyhow::Result<()> {
    let mut path = Vec::new();
    value
        .serialize(Checker { path: &mut path })
        .map_err(|e| anyhow::anyhow!("{what}: {e}; nothing non-finite may be written"))
}

/// `value` as pretty JSON, after [`check`].
pub fn to_json<T: Serialize + ?Sized>(what: &str, value: &T) -> anyhow::Result<String> {
    check(what, value)?;
    Ok(serde_json::to_string_pretty(value)?)
}

/// A path element: a field name or an index.
enum Step {
    Field(&'static str),
    Key(String),
    Index(usize),
}

fn render(path: &[Step]) -> String {
    let mut s = String::new();
    for p in path {
        match p {
            Step::Field(f) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(f);
            }
            Step::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Step::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    if s.is_empty() {
        "the value".into()
    } else {
        s
    }
}

struct Checker<'a> {
    path: &'a mut Vec<Step>,
}

type R = Result<(), NonFinite>;

impl Checker<'_> {
    fn float(self, v: f64) -> R {
        if v.is_finite() {
            Ok(())
        } else {
            Err(NonFinite {
                path: render(self.path),
                value: v,
            })
        }
    }

    fn at<T: Serialize + ?Sized>(&mut self, step: Step, v: &T) -> R {
        self.path.push(step);
        let r = v.serialize(Checker {
            path: &mut *self.path,
        });
        self.path.pop();
        r
    }
}

macro_rules! ok_scalars {
    ($($f:ident: $t:ty),*) => {
        $(fn $f(self, _v: $t) -> R { Ok(()) })*
    };
}

impl<'a> ser::Serializer for Checker<'a> {
    type Ok = ();
    type Error = NonFinite;
    type SerializeSeq = Seq<'a>;
    type SerializeTuple = Seq<'a>;
    type SerializeTupleStruct = Seq<'a>;
    type SerializeTupleVariant = Seq<'a>;
    type SerializeMap = Seq<'a>;
    type SerializeStruct = Seq<'a>;
    type SerializeStructVariant = Seq<'a>;

    ok_scalars!(serialize_bool: bool, serialize_i8: i8, serialize_i16: i16, serialize_i32: i32,
        serialize_i64: i64, serialize_u8: u8, serialize_u16: u16, serialize_u32: u32,
        serialize_u64: u64, serialize_char: char, serialize_str: &str, serialize_bytes: &[u8]);

    fn serialize_f32(self, v: f32) -> R {
        self.float(v.into())
    }
    fn serialize_f64(self, v: f64) -> R {
        self.float(v)
    }
    fn serialize_none(self) -> R {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> R {
        v.serialize(self)
    }
    fn serialize_unit(self) -> R {
        Ok(())
    }
    fn serialize_unit_struct(self, _: &'static str) -> R {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> R {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, v: &T) -> R {
        v.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        mut self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        v: &T,
    ) -> R {
        self.at(Step::Field(variant), v)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq::new(self))
    }
    fn serialize_tuple(self, _: usize) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq::new(self))
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq::new(self))
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq::new(self))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq::new(self))
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq::new(self))
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq::new(self))
    }
}

/// Sequences, tuples, maps and structs: each element is checked under its index or name.
struct Seq<'a> {
    checker: Checker<'a>,
    index: usize,
    key: Option<String>,
}

impl<'a> Seq<'a> {
    fn new(checker: Checker<'a>) -> Self {
        Self {
            checker,
            index: 0,
            key: None,
        }
    }

    fn element<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        let i = self.index;
        self.index += 1;
        self.checker.at(Step::Index(i), v)
    }
}

macro_rules! seq_impl {
    ($($tr:ident :: $m:ident),*) => {
        $(impl ser::$tr for Seq<'_> {
            type Ok = ();
            type Error = NonFinite;
            fn $m<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
                self.element(v)
            }
            fn end(self) -> R {
                Ok(())
            }
        })*
    };
}

seq_impl!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field
);

impl ser::SerializeStruct for Seq<'_> {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, name: &'static str, v: &T) -> R {
        self.checker.at(Step::Field(name), v)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeStructVariant for Seq<'_> {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, name: &'static str, v: &T) -> R {
        self.checker.at(Step::Field(name), v)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeMap for Seq<'_> {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, k: &T) -> R {
        // Keys are names (strings or numbers); their text is the path step.
        self.key = Some(
            serde_json::to_string(k)
                .map_or_else(|_| "?".into(), |s| s.trim_matches('"').to_string()),
        );
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        let key = self.key.take().unwrap_or_default();
        self.checker.at(Step::Key(key), v)
    }
    fn end(self) -> R {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::check;

    #[derive(serde::Serialize)]
    struct Inner {
        q: Vec<f64>,
        limit: Option<f64>,
    }

    #[derive(serde::Serialize)]
    struct Outer {
        name: String,
        steps: Vec<Inner>,
        drift: [f64; 2],
    }

    #[test]
    fn names_the_path_of_the_first_non_finite_number() {
        let mut o = Outer {
            name: "x".into(),
            steps: vec![
                Inner {
                    q: vec![1.0, 2.0],
                    limit: None,
                },
                Inner {
                    q: vec![1.0, f64::NAN],
                    limit: Some(1.0),
                },
            ],
            drift: [0.0, 1.0],
        };
        let e = check("summary.json", &o).unwrap_err().to_string();
        assert!(e.contains("steps[1].q[1] is NaN"), "{e}");
        o.steps[1].q[1] = 0.0;
        assert!(check("summary.json", &o).is_ok());
        o.drift[0] = f64::NEG_INFINITY;
        let e = check("summary.json", &o).unwrap_err().to_string();
        assert!(e.contains("drift[0] is -inf"), "{e}");
        let mut m = std::collections::BTreeMap::new();
        m.insert("L_KNEE", f64::INFINITY);
        let e = check("m", &m).unwrap_err().to_string();
        assert!(e.contains("L_KNEE is inf"), "{e}");
    }
}
