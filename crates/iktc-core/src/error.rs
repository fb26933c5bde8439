//! The one error type of the library.
//!
//! Errors are for *bad input*: a malformed file, an unknown name, a non-finite number, a
//! dimension that does not match, an inconsistent limit or setting. A well-formed problem that
//! happens to be hard (an infeasible QP, an empty acceleration box) is not an error: it is
//! reported as a *status* in the solution. The one exception is [`Error::RunFailed`]: a
//! scenario run whose robot fell, gave up its feet or diverged stops with it by default.

pub mod health;

use crate::resources::fmt_value;

/// Most names an error lists \[names\]; the rest are counted ([`name_list`]).
pub const MAX_LISTED_NAMES: usize = 10;

/// `names` joined by commas, the first [`MAX_LISTED_NAMES`] of them and then `… N more`.
pub fn name_list<S: AsRef<str>>(names: &[S]) -> String {
    let mut out = names
        .iter()
        .take(MAX_LISTED_NAMES)
        .map(AsRef::as_ref)
        .collect::<Vec<&str>>()
        .join(", ");
    if names.len() > MAX_LISTED_NAMES {
        out.push_str(&format!(", … {} more", names.len() - MAX_LISTED_NAMES));
    }
    out
}

/// The number of single-character insertions, deletions and substitutions that turn `a` into
/// `b` (Levenshtein distance).
pub fn edits(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (row[j + 1] + 1)
                .min(row[j] + 1)
                .min(diagonal + usize::from(ca != *cb));
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// [`name_list`] of `valid` with the names nearest `name` first (fewest edits, ignoring case;
/// ties in their order), so that a misspelt name's intended one is among those listed.
pub fn nearest_names<S: AsRef<str>>(name: &str, valid: &[S]) -> String {
    let lower = name.to_lowercase();
    let mut sorted: Vec<(usize, usize, &str)> = valid
        .iter()
        .enumerate()
        .map(|(i, v)| (edits(&lower, &v.as_ref().to_lowercase()), i, v.as_ref()))
        .collect();
    sorted.sort();
    let names: Vec<&str> = sorted.into_iter().map(|(_, _, v)| v).collect();
    name_list(&names)
}

/// Everything that can be wrong with the input given to iktc.
///
/// Every variant names what is wrong and, where it helps, what was expected.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A robot description (URDF) could not be read or is inconsistent.
    #[error("invalid robot description: {message}")]
    Urdf {
        /// What is wrong, in words.
        message: String,
    },
    /// A joint, link, frame or other named item does not exist.
    #[error(
        "unknown {kind} `{name}`; valid names are (nearest first): {}",
        nearest_names(name, valid)
    )]
    UnknownName {
        /// What kind of name it is ("joint", "frame", "link", ...).
        kind: &'static str,
        /// The name that was asked for.
        name: String,
        /// The names that exist.
        valid: Vec<String>,
    },
    /// A number that must be finite is NaN or infinite.
    #[error("{what} is not finite (got {})", fmt_value(*value))]
    NonFinite {
        /// Which quantity, with its index if any.
        what: String,
        /// The offending value.
        value: f64,
    },
    /// A vector or matrix has the wrong size.
    #[error("dimension mismatch in {what}: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Which quantity.
        what: String,
        /// The size that was expected.
        expected: usize,
        /// The size that was given.
        got: usize,
    },
    /// A state (the start of a run) puts a joint outside its limits: its position outside its
    /// range or its speed above its velocity limit.
    #[error(
        "{joint} is outside its limits: {quantity} {} not in [{}, {}]; \
         change the start state or the limits, or ask for recovery (OutsideLimits::Recover)",
        fmt_value(*value),
        fmt_value(*lower),
        fmt_value(*upper)
    )]
    StateOutsideLimits {
        /// The joint (or dof) name.
        joint: String,
        /// Which quantity, with its unit: `position [rad]` or `velocity [rad/s]`.
        quantity: String,
        /// Its value.
        value: f64,
        /// The lower end of the allowed interval.
        lower: f64,
        /// The upper end of the allowed interval.
        upper: f64,
    },
    /// A task handle given to a controller other than the one whose builder made it.
    #[error(
        "{kind} handle of controller #{owner} given to controller #{controller}: a handle works \
         only with the controller whose builder returned it (or a clone of that controller)"
    )]
    ForeignHandle {
        /// The kind of task ("frame", "COM", "joints").
        kind: &'static str,
        /// The identity of the controller the handle belongs to.
        owner: u64,
        /// The identity of the controller it was given to.
        controller: u64,
    },
    /// A limit has its lower end above its upper end, or is otherwise unusable.
    #[error("invalid limit for {what}: lower {} > upper {}", fmt_value(*lower), fmt_value(*upper))]
    InvalidLimit {
        /// Which joint or quantity.
        what: String,
        /// The lower end.
        lower: f64,
        /// The upper end.
        upper: f64,
    },
    /// A setting or parameter is out of its valid range.
    #[error("invalid setting {name} = {value}: expected {expected}")]
    InvalidSetting {
        /// The setting's name.
        name: String,
        /// Its value, as text.
        value: String,
        /// What would have been valid.
        expected: String,
    },
    /// A text file (motion capture, mapping, configuration) is malformed.
    #[error("{source_name}:{line}: {message}")]
    Parse {
        /// The file's name or a description of the source.
        source_name: String,
        /// The 1-based line the problem was found on (0 if unknown).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// An input asks for more than a stated maximum (ticks, frames, duration, nesting depth):
    /// checked before anything is allocated.
    #[error("{what} = {value} exceeds the limit {limit}; raise it with {option}")]
    ResourceLimit {
        /// What is counted or measured.
        what: String,
        /// The amount asked for.
        value: String,
        /// The stated maximum.
        limit: String,
        /// The setting (and CLI option, if any) that raises the maximum.
        option: String,
    },
    /// A scenario run went wrong and was stopped (the feet drifted past their tolerance, the
    /// state stopped being finite, the ZMP left the support polygon): the one kind of error
    /// that is not about bad input, because the run's results would be meaningless. Its
    /// settings (`HealthSettings::keep_going` of the scenarios) can ask for the run to continue
    /// and mark the failure instead.
    #[error("run failed: {0}")]
    RunFailed(Box<health::HealthIssue>),
    /// Input data are insufficient for the requested computation (too few points, ...).
    #[error("insufficient data for {what}: {message}")]
    InsufficientData {
        /// Which computation.
        what: String,
        /// What was missing.
        message: String,
    },
    /// A robot profile's key holds a value that does not fit the robot (an unknown frame or
    /// joint, a glob that matches nothing, a bad number) or a needed key is missing.
    #[error("profile key `{key}` = `{value}`: {message}")]
    Profile {
        /// The key, dotted as in the TOML file (`feet.left.frame`, `lock[0].joints`).
        key: String,
        /// The value found, as text (`(missing)` if the key is absent).
        value: String,
        /// What is wrong and what would be valid (e.g. the names that exist).
        message: String,
    },
    /// An error met inside a run, with where it was met: the run and its input file, the
    /// phase and the tick with its time ([`Error::at`]).
    #[error("{context}: {error}")]
    During {
        /// Where: e.g. ``keypoint retargeting of `clip.bvh`, tick 12 (t = 0.06 s)``.
        context: String,
        /// The error met.
        error: Box<Error>,
    },
}

impl Error {
    /// This error wrapped in [`Error::During`] with `context` (where it was met).
    pub fn at(self, context: impl FnOnce() -> String) -> Error {
        Error::During {
            context: context(),
            error: Box::new(self),
        }
    }

    /// The innermost error, under every [`Error::During`].
    pub fn innermost(&self) -> &Error {
        match self {
            Error::During { error, .. } => error.innermost(),
            other => other,
        }
    }
}

/// The result type of the library.
pub type Result<T> = std::result::Result<T, Error>;

/// Returns an error naming `what` if `value` is NaN or infinite.
pub fn check_finite(what: impl FnOnce() -> String, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::NonFinite {
            what: what(),
            value,
        })
    }
}

/// True when no entry is NaN or infinite: `x − x` is exactly 0 for a finite `x` and NaN for
/// ±∞ and NaN, so the sum of the `x − x` is 0 exactly when every entry is finite. Four partial
/// sums, so that it vectorises: the solvers run it on every Jacobian every tick.
// `x − x` is the test itself, not a mistake.
#[allow(clippy::eq_op)]
#[inline]
pub fn all_finite(values: &[f64]) -> bool {
    let mut acc = [0.0_f64; 4];
    let chunks = values.chunks_exact(4);
    let tail: f64 = chunks.remainder().iter().map(|x| x - x).sum();
    for c in chunks {
        for k in 0..4 {
            acc[k] += c[k] - c[k];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail == 0.0
}

/// Returns an error naming `what` if any entry of `values` is NaN or infinite.
pub fn check_all_finite(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::NonFinite {
            what: format!("{what}[{i}]"),
            value: values[i],
        }),
    }
}

/// Returns an error if `got != expected`.
pub fn check_dim(what: &str, expected: usize, got: usize) -> Result<()> {
    if expected == got {
        Ok(())
    } else {
        Err(Error::DimensionMismatch {
            what: what.to_string(),
            expected,
            got,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{all_finite, edits, name_list, nearest_names, Error, MAX_LISTED_NAMES};

    #[test]
    fn long_name_lists_are_capped() {
        let names: Vec<String> = (0..10_000).map(|i| format!("joint_{i}")).collect();
        let text = name_list(&names);
        assert!(text.starts_with("joint_0, joint_1,"), "{text}");
        assert!(
            text.contains("joint_9,") && !text.contains("joint_10,"),
            "{text}"
        );
        assert!(
            text.ends_with(&format!("… {} more", 10_000 - MAX_LISTED_NAMES)),
            "{text}"
        );
        assert_eq!(name_list(&["a", "b"]), "a, b");
        let e = Error::UnknownName {
            kind: "joint",
            name: "x".into(),
            valid: names,
        };
        assert!(e.to_string().len() < 300, "{e}");
    }

    /// A misspelt name's intended one is listed first, however far down the list it is.
    #[test]
    fn the_nearest_names_come_first() {
        let mut valid: Vec<String> = (0..40).map(|i| format!("joint{i:02}")).collect();
        valid.push("LeftElbow".into());
        let list = nearest_names("LeftElbw", &valid);
        assert!(list.starts_with("LeftElbow, "), "{list}");
        assert!(list.ends_with("… 31 more"), "{list}");
        assert_eq!(edits("kitten", "sitting"), 3);
        assert_eq!(edits("", "abc"), 3);
    }

    #[test]
    fn big_numbers_print_compactly() {
        let e = Error::NonFinite {
            what: "x".into(),
            value: f64::NAN,
        };
        assert_eq!(e.to_string(), "x is not finite (got NaN)");
        let e = Error::StateOutsideLimits {
            joint: "j".into(),
            quantity: "position [rad]".into(),
            value: 1e308,
            lower: -1.0,
            upper: 1.0,
        };
        assert!(e.to_string().contains("1e308 not in [-1, 1]"), "{e}");
    }

    #[test]
    fn all_finite_agrees_with_is_finite() {
        let specials = [
            0.0,
            -0.0,
            1.0,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -f64::NAN,
        ];
        for (i, &bad) in specials.iter().enumerate() {
            for len in [1usize, 3, 8, 17] {
                for at in 0..len {
                    let mut v = vec![1.5; len];
                    v[at] = bad;
                    assert_eq!(
                        all_finite(&v),
                        v.iter().all(|x| x.is_finite()),
                        "special {i}, length {len}, at {at}"
                    );
                }
            }
        }
        assert!(all_finite(&[]));
    }
}
