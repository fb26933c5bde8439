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
}
