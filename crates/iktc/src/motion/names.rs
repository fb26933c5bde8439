//! Joint and marker names reduced to a side and a base word, and the words each naming family
//! uses for each body point.
//!
//! A name is reduced in four steps: (1) everything up to the last `:` or `|` is dropped (subject
//! and rig prefixes: `Subject:LASI`, `mixamorig:LeftArm`, `Root|Hips`); (2) a rig prefix is
//! dropped (`DEF-`, `ORG-`, `mixamorig`, `Bip01 `, `m_avg_`, …); (3) the side is read from a
//! prefix (`Left`, `left_`, `L_`, `l.`, `L `, or one letter glued to a body word: `lfemur`,
//! `RThumb`) or a suffix (`.L`, `_l`, `-L`, ` L`, `_left`); (4) what remains is lower-cased and
//! stripped of everything but letters and digits (`upper_arm.L.001` → left, `upperarm001`).

use super::body_point::{Limb, Side};

/// A name reduced to its side and base word.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct NormalName {
    pub side: Option<Side>,
    pub base: String,
}

const RIG_PREFIXES: [&str; 9] = [
    "def-",
    "org-",
    "mch-",
    "mixamorig_",
    "mixamorig",
    "bip01 ",
    "bip01_",
    "bip001 ",
    "m_avg_",
];

/// Body words that may follow a one-letter side glued to them (`lfemur`, `RHipJoint`, `lhand`).
const GLUED_WORDS: [&str; 30] = [
    "femur", "tibia", "foot", "toes", "toe", "toebase", "hipjoint", "hip", "hand", "humerus",
    "radius", "wrist", "clavicle", "fingers", "thumb", "knee", "ankle", "shoulder", "elbow", "arm",
    "forearm", "leg", "upleg", "thigh", "shin", "calf", "collar", "heel", "uparm", "upperarm",
];

/// Reduces a joint or marker name (see the module documentation).
pub(crate) fn normalise(name: &str) -> NormalName {
    let after = name.rsplit([':', '|']).next().unwrap_or(name).trim();
    let mut s = after.to_lowercase();
    for p in RIG_PREFIXES {
        if let Some(rest) = s.strip_prefix(p) {
            s = rest.to_string();
            break;
        }
    }
    // A trailing segment number (`.001`, `_01`) is kept in the base, after the side is read.
    let (stem, number) = split_number(&s);
    let (side, rest) = read_side(stem);
    let mut base: String = rest.chars().filter(|c| c.is_ascii_alphanumeric()).collect();
    base.push_str(number);
    NormalName { side, base }
}

fn split_number(s: &str) -> (&str, &str) {
    let trimmed = s.trim_end_matches(|c: char| c.is_ascii_digit());
    let digits = &s[trimmed.len()..];
    match trimmed.strip_suffix(['.', '_', '-']) {
        Some(stem) if !digits.is_empty() && !stem.is_empty() => (stem, digits),
        _ => (s, ""),
    }
}

fn read_side(s: &str) -> (Option<Side>, &str) {
    const SEPARATORS: [char; 4] = ['_', '.', '-', ' '];
    for (word, side) in [("left", Side::Left), ("right", Side::Right)] {
        if let Some(rest) = s.strip_prefix(word) {
            if !rest.is_empty() {
                return (Some(side), rest.trim_start_matches(SEPARATORS));
            }
        }
        if let Some(rest) = s.strip_suffix(word) {
            let rest = rest.trim_end_matches(SEPARATORS);
            if !rest.is_empty() {
                return (Some(side), rest);
            }
        }
    }
    for (letter, side) in [('l', Side::Left), ('r', Side::Right)] {
        let mut chars = s.chars();
        if chars.next() == Some(letter) {
            let rest = chars.as_str();
            if let Some(r) = rest.strip_prefix(SEPARATORS) {
                if !r.is_empty() {
                    return (Some(side), r);
                }
            }
            if GLUED_WORDS.contains(&rest) {
                return (Some(side), rest);
            }
        }
        for sep in SEPARATORS {
            let suffix: String = [sep, letter].iter().collect();
            if let Some(rest) = s.strip_suffix(suffix.as_str()) {
                if !rest.is_empty() {
                    return (Some(side), rest);
                }
            }
        }
    }
    (None, s)
}

/// Base words naming each limb point, most specific first. A word naming two points in
/// different families is listed for both and resolved by the order of the search and the chain
/// (Mixamo's `LeftArm` is the shoulder joint, its `LeftShoulder` the clavicle; SMPL's
/// `left_foot` is the toe because `left_ankle` exists).
pub(crate) fn limb_words(limb: Limb) -> &'static [&'static str] {
    match limb {
        Limb::Hip => &["upleg", "upperleg", "thigh", "femur", "hip"],
        Limb::Knee => &["knee", "shin", "calf", "lowerleg", "lowleg", "tibia", "leg"],
        Limb::Ankle => &["ankle", "foot"],
        Limb::Toe => &[
            "toebase",
            "toe",
            "toes",
            "ball",
            "toe0",
            "bigtoe",
            "footindex",
            "foot",
        ],
        Limb::Shoulder => &["upperarm", "uparm", "humerus", "arm", "shoulder"],
        Limb::Elbow => &["forearm", "lowerarm", "elbow", "radius"],
        Limb::Wrist => &["wrist", "hand"],
    }
}

/// Base words naming the head, most specific first (`spine006` is Rigify's head bone).
pub(crate) const HEAD_WORDS: [&str; 5] = ["head", "headtop", "headend", "spine006", "nose"];

/// Base words naming the pelvis on marker data (skeletons use the legs' branching joint).
pub(crate) const PELVIS_WORDS: [&str; 5] = ["pelvis", "hips", "hip", "midhip", "root"];

/// Base words naming the chest on marker data.
pub(crate) const CHEST_WORDS: [&str; 5] = ["chest", "thorax", "upperchest", "spine2", "spine3"];

/// Base words naming the neck on marker data.
pub(crate) const NECK_WORDS: [&str; 2] = ["neck", "lowerneck"];

/// Qualifier words a marker name adds before or after its body word to tell the markers of a
/// pair or family apart (front/back, inner/outer, medial/lateral, upper/lower, Plug-in-Gait's
/// `A`/`B`, …): `LShoulderFront`, `LWristIn`, `LKNEM`, `LWRA`, `LFSHO`.
pub(crate) const QUALIFIERS: [&str; 30] = [
    "front",
    "back",
    "inner",
    "outer",
    "inside",
    "outside",
    "in",
    "out",
    "medial",
    "lateral",
    "med",
    "lat",
    "anterior",
    "posterior",
    "ant",
    "post",
    "top",
    "upper",
    "lower",
    "high",
    "low",
    "side",
    "mid",
    "tip",
    "a",
    "b",
    "f",
    "i",
    "o",
    "m",
];

/// A name split into lower-case words at separators (`_`, `-`, `.`, spaces) and case changes
/// (`WaistLFront` → `waist`, `l`, `front`; `LWRA` stays one word).
fn words(s: &str) -> Vec<String> {
    let chars: Vec<char> = s.chars().collect();
    let mut out = Vec::new();
    let mut cur = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if !c.is_ascii_alphanumeric() {
            if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
            continue;
        }
        let prev = i.checked_sub(1).map(|k| chars[k]);
        let next = chars.get(i + 1);
        let boundary = c.is_ascii_uppercase()
            && (prev.is_some_and(|p| p.is_ascii_lowercase() || p.is_ascii_digit())
                || (prev.is_some_and(|p| p.is_ascii_uppercase())
                    && next.is_some_and(|n| n.is_ascii_lowercase())));
        if boundary && !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
        cur.push(c.to_ascii_lowercase());
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// The ways a marker name can be read as a side and a stem (lower-case letters and digits):
/// after dropping everything up to the last `:` or `|` (`Skeleton:LShoulder`), a side word
/// `l`/`left`/`r`/`right` anywhere among its words (`WaistLFront`, `HeadL`, `L_Wrist_In`), a
/// leading or trailing `left`/`right`, a leading `L`/`R` letter (`LSHO`, `LFArm`), or no side.
pub(crate) fn marker_readings(name: &str) -> Vec<(Option<Side>, String)> {
    let plain = name.rsplit([':', '|']).next().unwrap_or(name).trim();
    let w = words(plain);
    let mut out = Vec::new();
    if w.len() > 1 {
        for (tags, side) in [(["l", "left"], Side::Left), (["r", "right"], Side::Right)] {
            if let Some(k) = w.iter().position(|t| tags.contains(&t.as_str())) {
                let rest: String = w
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| *i != k)
                    .map(|(_, t)| t.as_str())
                    .collect();
                out.push((Some(side), rest));
            }
        }
    }
    let joined: String = w.concat();
    for (word, side) in [("left", Side::Left), ("right", Side::Right)] {
        for rest in [joined.strip_prefix(word), joined.strip_suffix(word)]
            .into_iter()
            .flatten()
        {
            if !rest.is_empty() {
                out.push((Some(side), rest.to_string()));
            }
        }
    }
    for (letter, side) in [('l', Side::Left), ('r', Side::Right)] {
        if let Some(rest) = joined.strip_prefix(letter).filter(|r| !r.is_empty()) {
            out.push((Some(side), rest.to_string()));
        }
    }
    out.push((None, joined));
    out
}

/// Whether `stem` is the body word `word`, with at most one qualifier ([`QUALIFIERS`]) before
/// and one after it, and trailing digits (a marker's number in a family: `LForefoot5`)
/// dropped when `word` has none.
pub(crate) fn stem_is(stem: &str, word: &str) -> bool {
    let bare = |s: &str| s == word || QUALIFIERS.iter().any(|q| s.strip_suffix(q) == Some(word));
    let check = |s: &str| {
        bare(s)
            || QUALIFIERS
                .iter()
                .any(|q| s.strip_prefix(q).is_some_and(bare))
    };
    let trimmed = stem.trim_end_matches(|c: char| c.is_ascii_digit());
    check(stem) || (trimmed != stem && !trimmed.is_empty() && check(trimmed))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn n(name: &str) -> (Option<Side>, String) {
        let r = normalise(name);
        (r.side, r.base)
    }

    #[test]
    fn families() {
        use Side::{Left as L, Right as R};
        assert_eq!(n("mixamorig:LeftArm"), (Some(L), "arm".into()));
        assert_eq!(n("DEF-upper_arm.L"), (Some(L), "upperarm".into()));
        assert_eq!(n("DEF-upper_arm.L.001"), (Some(L), "upperarm001".into()));
        assert_eq!(n("L_Hip"), (Some(L), "hip".into()));
        assert_eq!(n("right_foot"), (Some(R), "foot".into()));
        assert_eq!(n("lfemur"), (Some(L), "femur".into()));
        assert_eq!(n("RHipJoint"), (Some(R), "hipjoint".into()));
        assert_eq!(n("lowerback"), (None, "lowerback".into()));
        assert_eq!(n("radius"), (None, "radius".into()));
        assert_eq!(n("Subject1:LKNE"), (None, "lkne".into()));
        assert_eq!(n("thigh_l"), (Some(L), "thigh".into()));
        assert_eq!(n("Bip01 R Calf"), (Some(R), "calf".into()));
        assert_eq!(n("Spine2"), (None, "spine2".into()));
        assert_eq!(n("DEF-spine.006"), (None, "spine006".into()));
        assert_eq!(n("HandRight"), (Some(R), "hand".into()));
    }

    #[test]
    fn marker_names_are_read_as_side_and_stem() {
        use Side::{Left as L, Right as R};
        let has = |name: &str, side: Option<Side>, stem: &str| {
            marker_readings(name)
                .iter()
                .any(|(s, t)| *s == side && t == stem)
        };
        assert!(has("WaistLFront", Some(L), "waistfront"));
        assert!(has("Skeleton:LShoulder", Some(L), "shoulder"));
        assert!(has("LFArm", Some(L), "farm"));
        assert!(has("RWRA", Some(R), "wra"));
        assert!(has("HeadL", Some(L), "head"));
        assert!(has("L_Wrist_In", Some(L), "wristin"));
        assert!(has("right_knee_lateral", Some(R), "kneelateral"));
        assert!(has("C7", None, "c7"));
        assert!(stem_is("wristin", "wrist"));
        assert!(stem_is("fsho", "sho"));
        assert!(stem_is("kneelateral", "knee"));
        assert!(stem_is("forefoot5", "forefoot"));
        assert!(stem_is("t10", "t10"));
        assert!(!stem_is("t10", "t8"));
        assert!(!stem_is("shoulderblade", "shoulder"));
        assert!(!stem_is("wrist", "wr"));
    }
}
