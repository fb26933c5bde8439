//! Glob patterns over joint names: `*` matches any run of characters (also none), `?` exactly
//! one character, every other character itself (case-sensitive).

/// Whether `name` matches the glob `pattern`.
///
/// Iterative matching with one backtrack point (the last `*`): O(|pattern| · |name|) in the
/// worst case, no allocation.
pub fn glob_match(pattern: &str, name: &str) -> bool {
    let p: Vec<char> = pattern.chars().collect();
    let n: Vec<char> = name.chars().collect();
    let (mut i, mut j) = (0usize, 0usize);
    // (position of the last `*` in p, position in n it was tried at)
    let mut star: Option<(usize, usize)> = None;
    while j < n.len() {
        match p.get(i) {
            Some('*') => {
                star = Some((i, j));
                i += 1;
            }
            Some(c) if *c == '?' || *c == n[j] => {
                i += 1;
                j += 1;
            }
            _ => match star {
                // Let the last `*` swallow one more character and retry.
                Some((si, sj)) => {
                    i = si + 1;
                    j = sj + 1;
                    star = Some((si, sj + 1));
                }
                None => return false,
            },
        }
    }
    p[i.min(p.len())..].iter().all(|c| *c == '*')
}

#[cfg(test)]
mod tests {
    use super::glob_match;

    #[test]
    fn matches_like_a_shell_glob() {
        for (p, n, want) in [
            ("*F??", "R_F12", true),
            ("*F??", "LF1", false),
            ("*_FINGER_*", "L_FINGER_2", true),
            ("*_FINGER_*", "L_FINGER", false),
            ("*", "", true),
            ("", "", true),
            ("", "a", false),
            ("a*b*c", "abbbc", true),
            ("a*b*c", "acb", false),
            ("?_KNEE", "L_KNEE", true),
            ("?_KNEE", "LL_KNEE", false),
            ("**x", "yyx", true),
            ("L_*", "R_KNEE", false),
        ] {
            assert_eq!(glob_match(p, n), want, "{p} vs {n}");
        }
    }
}
