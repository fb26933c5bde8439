//! The one parser of `NAME=VALUE` lists, used by every flag that takes them (`--lock`,
//! `--accel`, `--posture`, `--narrow`).

use anyhow::{Context, Result};

/// Parses `NAME=VALUE` assignments: every item of `items` is one assignment or a
/// comma-separated list of them; blank items are skipped and `none` alone stands for no
/// assignment. `flag` names the flag in errors, `shape` says what a value looks like (e.g.
/// "a number [rad]"), and `value` reads one value (`None` if it is not of that shape).
pub fn parse_assignments<T>(
    flag: &str,
    items: &[String],
    shape: &str,
    value: impl Fn(&str) -> Option<T>,
) -> Result<Vec<(String, T)>> {
    if let [only] = items {
        if only.trim() == "none" {
            return Ok(Vec::new());
        }
    }
    items
        .iter()
        .flat_map(|s| s.split(','))
        .filter(|s| !s.trim().is_empty())
        .map(|item| {
            let (name, text) = item
                .split_once('=')
                .with_context(|| format!("{flag} `{item}`: expected NAME=VALUE, VALUE {shape}"))?;
            let name = name.trim();
            if name.is_empty() {
                anyhow::bail!("{flag} `{item}`: the name before `=` is empty");
            }
            let v = value(text.trim())
                .with_context(|| format!("{flag} `{item}`: `{}` is not {shape}", text.trim()))?;
            Ok((name.to_string(), v))
        })
        .collect()
}

/// A value of [`parse_assignments`]: one finite number.
pub fn number(text: &str) -> Option<f64> {
    text.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// A value of [`parse_assignments`]: a range `lo:hi` of two finite numbers.
pub fn range(text: &str) -> Option<[f64; 2]> {
    let (lo, hi) = text.split_once(':')?;
    Some([number(lo.trim())?, number(hi.trim())?])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strings(s: &[&str]) -> Vec<String> {
        s.iter().map(|x| x.to_string()).collect()
    }

    #[test]
    fn repeated_and_comma_separated_items_give_the_same_list() {
        let a =
            parse_assignments("--x", &strings(&["A=1", "B = -2.5"]), "a number", number).unwrap();
        let b = parse_assignments("--x", &strings(&["A=1,B = -2.5"]), "a number", number).unwrap();
        assert_eq!(a, b);
        assert_eq!(a, vec![("A".to_string(), 1.0), ("B".to_string(), -2.5)]);
    }

    #[test]
    fn none_and_blanks_give_nothing() {
        for items in [
            strings(&["none"]),
            strings(&[" none "]),
            strings(&["", " , "]),
        ] {
            assert!(parse_assignments("--x", &items, "a number", number)
                .unwrap()
                .is_empty());
        }
    }

    #[test]
    fn ranges_are_read_as_two_numbers() {
        let r = parse_assignments("--narrow", &strings(&["K=0.55:0.95"]), "lo:hi", range).unwrap();
        assert_eq!(r, vec![("K".to_string(), [0.55, 0.95])]);
    }

    #[test]
    fn errors_name_the_flag_the_item_and_the_shape() {
        let cases: [(&str, &[&str]); 5] = [
            ("K", &["--x `K`", "expected NAME=VALUE"]),
            ("K=abc", &["--x `K=abc`", "`abc` is not a number"]),
            ("K=inf", &["`inf` is not a number"]),
            ("=1", &["the name before `=` is empty"]),
            ("K=1:", &["`1:` is not a number"]),
        ];
        for (item, needles) in cases {
            let e = parse_assignments("--x", &strings(&[item]), "a number", number)
                .unwrap_err()
                .to_string();
            for n in needles {
                assert!(e.contains(n), "{item}: `{e}` lacks `{n}`");
            }
        }
        let e = parse_assignments("--narrow", &strings(&["K=1"]), "lo:hi", range)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`1` is not lo:hi"), "{e}");
    }
}
