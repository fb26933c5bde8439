//! Body points found on a skeleton or a marker set without a map.
//!
//! **Skeletons, by names** (see [`names`](super::names) for how a name is reduced): on each side,
//! hip, knee, ankle, toe, then shoulder, elbow, wrist, each the first joint of that side whose
//! base word is in the point's word list (most specific word first) and that lies below the
//! previous point of the chain (a knee below its hip, …); the head is a joint named as a head.
//! Then by structure: the pelvis is the lowest common ancestor of the two hips, the chest that of
//! the two shoulders, the neck the first joint from the chest towards the head (absent when the
//! head hangs from the chest directly).
//!
//! **Skeletons, by shape**, when names leave a required point missing: see
//! [`shape`](super::shape).
//!
//! **Markers**: first Plug-in-Gait-like groups (a point is the centroid of its group; a group
//! is used only when all its markers are present), then single markers named like the joints
//! above (`left_wrist`, `LeftHand`, what video pose estimators write); the pelvis falls back to
//! the centroid of the two hip points.

use super::body_map::{BodyMap, FoundBy, MappedPoint, PointSource};
use super::body_point::{Limb, Side};
use super::names::{self, normalise, NormalName};
use super::{BodyPoint, Skeleton};
use crate::error::{Error, Result};

/// Plug-in-Gait-like marker groups (upper-case names, `L`/`R` prefix for the side), tried in
/// order for each point. The hip is the centroid of the pelvis markers of its side, about
/// 5–10 cm above and lateral of the joint centre (Plug-in-Gait's regression is not applied).
const MARKER_TABLE: [(BodyPoint, &[&[&str]]); 18] = [
    (
        BodyPoint::Pelvis,
        &[&["LASI", "RASI", "LPSI", "RPSI"], &["LASI", "RASI", "SACR"]],
    ),
    (
        BodyPoint::Chest,
        &[&["CLAV", "STRN", "C7", "T10"], &["CLAV", "T10"]],
    ),
    (BodyPoint::Neck, &[&["C7", "CLAV"]]),
    (BodyPoint::Head, &[&["LFHD", "RFHD", "LBHD", "RBHD"]]),
    (BodyPoint::LeftShoulder, &[&["LSHO"]]),
    (BodyPoint::LeftElbow, &[&["LELB"]]),
    (BodyPoint::LeftWrist, &[&["LWRA", "LWRB"]]),
    (BodyPoint::LeftHip, &[&["LASI", "LPSI"]]),
    (BodyPoint::LeftKnee, &[&["LKNE"]]),
    (BodyPoint::LeftAnkle, &[&["LANK"]]),
    (BodyPoint::LeftToe, &[&["LTOE"]]),
    (BodyPoint::RightShoulder, &[&["RSHO"]]),
    (BodyPoint::RightElbow, &[&["RELB"]]),
    (BodyPoint::RightWrist, &[&["RWRA", "RWRB"]]),
    (BodyPoint::RightHip, &[&["RASI", "RPSI"]]),
    (BodyPoint::RightKnee, &[&["RKNE"]]),
    (BodyPoint::RightAnkle, &[&["RANK"]]),
    (BodyPoint::RightToe, &[&["RTOE"]]),
];

/// Names of the built-in body maps ([`builtin_body_map`]).
pub const BUILTIN_BODY_MAP_NAMES: [&str; 2] = ["plug_in_gait", "deepmimic"];

/// A built-in body map: `plug_in_gait` (the marker groups used for Plug-in-Gait-like marker
/// sets) or `deepmimic` (the DeepMimic character's joints).
pub fn builtin_body_map(name: &str) -> Result<BodyMap> {
    match name {
        "plug_in_gait" => BodyMap::new(
            name,
            MARKER_TABLE
                .iter()
                .filter_map(|(p, groups)| {
                    groups.first().map(|g| MappedPoint {
                        point: *p,
                        source: PointSource::Markers(g.iter().map(|s| s.to_string()).collect()),
                        found_by: FoundBy::MarkerTable,
                    })
                })
                .collect(),
        ),
        "deepmimic" => {
            let mut map = recognise_skeleton(&super::deepmimic_skeleton()?, name)?;
            map.name = name.to_string();
            Ok(map)
        }
        _ => Err(Error::UnknownName {
            kind: "built-in body map",
            name: name.to_string(),
            valid: BUILTIN_BODY_MAP_NAMES
                .iter()
                .map(|s| s.to_string())
                .collect(),
        }),
    }
}

/// Finds the body points of a skeleton by names, else by shape (see the module documentation).
/// `source` names the skeleton in the map and in errors.
///
/// Error ([`Error::InsufficientData`]) when neither finds every required point: it lists the
/// points found, those missing, the joints, and the map to write.
pub fn recognise_skeleton(skeleton: &Skeleton, source: &str) -> Result<BodyMap> {
    let by_name = by_names(skeleton);
    if let Ok(map) = BodyMap::new(source, by_name.clone()) {
        return Ok(map);
    }
    match super::shape::by_shape(skeleton) {
        Ok(points) => BodyMap::new(source, points),
        Err(why) => Err(unrecognised(
            source,
            &by_name,
            &format!("joints: {}", joint_list(skeleton)),
            &why,
        )),
    }
}

fn joint_list(skeleton: &Skeleton) -> String {
    crate::error::name_list(
        &skeleton
            .joints()
            .iter()
            .map(|j| j.name.as_str())
            .collect::<Vec<_>>(),
    )
}

fn unrecognised(source: &str, found: &[MappedPoint], what: &str, shape: &str) -> Error {
    let found_text: Vec<String> = found
        .iter()
        .map(|p| match &p.source {
            PointSource::Joint(j) => format!("{}={j}", p.point),
            PointSource::Markers(m) => format!("{}=[{}]", p.point, m.join(" ")),
        })
        .collect();
    let missing: Vec<&str> = BodyPoint::REQUIRED
        .iter()
        .filter(|r| !found.iter().any(|p| p.point == **r))
        .map(|r| r.name())
        .collect();
    Error::InsufficientData {
        what: format!("body points of `{source}`"),
        message: format!(
            "found by name: {}; missing: {}; by shape: {shape}; {what}. Write a body map \
             (`iktc map init --motion FILE` writes one with what was found; see `iktc map show \
             plug_in_gait` for the format), add the missing points and pass it with --map",
            if found_text.is_empty() {
                "nothing".to_string()
            } else {
                found_text.join(", ")
            },
            missing.join(", ")
        ),
    }
}

fn is_ancestor(skeleton: &Skeleton, ancestor: usize, joint: usize) -> bool {
    let mut j = Some(joint);
    while let Some(i) = j {
        if i == ancestor {
            return true;
        }
        j = skeleton.joints().get(i).and_then(|x| x.parent);
    }
    false
}

/// The lowest common ancestor of two joints.
pub(crate) fn common_ancestor(skeleton: &Skeleton, a: usize, b: usize) -> usize {
    let mut j = Some(a);
    while let Some(i) = j {
        if is_ancestor(skeleton, i, b) {
            return i;
        }
        j = skeleton.joints().get(i).and_then(|x| x.parent);
    }
    0
}

/// The first joint after `from` on the path down to `to` (`to` a strict descendant of `from`).
pub(crate) fn first_towards(skeleton: &Skeleton, from: usize, to: usize) -> Option<usize> {
    let mut j = to;
    loop {
        let parent = skeleton.joints().get(j)?.parent?;
        if parent == from {
            return Some(j);
        }
        j = parent;
    }
}

fn by_names(skeleton: &Skeleton) -> Vec<MappedPoint> {
    let normal: Vec<NormalName> = skeleton
        .joints()
        .iter()
        .map(|j| normalise(&j.name))
        .collect();
    let mut found: Vec<(BodyPoint, usize, FoundBy)> = Vec::new();
    let used = |found: &[(BodyPoint, usize, FoundBy)], j: usize| found.iter().any(|f| f.1 == j);
    for side in [Side::Left, Side::Right] {
        for chain in [
            &[Limb::Hip, Limb::Knee, Limb::Ankle, Limb::Toe][..],
            &[Limb::Shoulder, Limb::Elbow, Limb::Wrist][..],
        ] {
            let mut above: Option<usize> = None;
            for limb in chain {
                let pick = names::limb_words(*limb).iter().find_map(|word| {
                    normal.iter().enumerate().position(|(j, n)| {
                        n.side == Some(side)
                            && n.base == *word
                            && !used(&found, j)
                            && above.is_none_or(|a| a != j && is_ancestor(skeleton, a, j))
                    })
                });
                if let Some(j) = pick {
                    found.push((BodyPoint::of_limb(side, *limb), j, FoundBy::Name));
                    above = Some(j);
                }
            }
        }
    }
    let index = |found: &[(BodyPoint, usize, FoundBy)], p: BodyPoint| {
        found.iter().find(|f| f.0 == p).map(|f| f.1)
    };
    let head = names::HEAD_WORDS.iter().find_map(|word| {
        normal
            .iter()
            .position(|n| n.side.is_none() && n.base == *word)
    });
    if let (Some(l), Some(r)) = (
        index(&found, BodyPoint::LeftHip),
        index(&found, BodyPoint::RightHip),
    ) {
        found.push((
            BodyPoint::Pelvis,
            common_ancestor(skeleton, l, r),
            FoundBy::Structure,
        ));
    }
    let chest = match (
        index(&found, BodyPoint::LeftShoulder),
        index(&found, BodyPoint::RightShoulder),
    ) {
        (Some(l), Some(r)) => {
            let c = common_ancestor(skeleton, l, r);
            found.push((BodyPoint::Chest, c, FoundBy::Structure));
            Some(c)
        }
        _ => None,
    };
    if let Some(h) = head {
        found.push((BodyPoint::Head, h, FoundBy::Name));
        if let Some(n) = chest
            .filter(|c| *c != h && is_ancestor(skeleton, *c, h))
            .and_then(|c| first_towards(skeleton, c, h))
            .filter(|n| *n != h)
        {
            found.push((BodyPoint::Neck, n, FoundBy::Structure));
        }
    }
    found
        .into_iter()
        .filter_map(|(point, j, found_by)| {
            skeleton.joints().get(j).map(|joint| MappedPoint {
                point,
                source: PointSource::Joint(joint.name.clone()),
                found_by,
            })
        })
        .collect()
}

/// Finds the body points of a marker set by the marker table, then by names (see the module
/// documentation). `markers` are the file's marker (or point) names.
pub fn recognise_markers(markers: &[String], source: &str) -> Result<BodyMap> {
    let plain: Vec<String> = markers
        .iter()
        .map(|m| {
            m.rsplit([':', '|'])
                .next()
                .unwrap_or(m)
                .trim()
                .to_ascii_uppercase()
        })
        .collect();
    let normal: Vec<NormalName> = markers.iter().map(|m| normalise(m)).collect();
    let mut found: Vec<MappedPoint> = Vec::new();
    for (point, groups) in MARKER_TABLE {
        let group = groups.iter().find_map(|g| {
            g.iter()
                .map(|want| plain.iter().position(|p| p.as_str() == *want))
                .collect::<Option<Vec<usize>>>()
        });
        if let Some(idx) = group {
            found.push(MappedPoint {
                point,
                source: PointSource::Markers(idx.iter().map(|i| markers[*i].clone()).collect()),
                found_by: FoundBy::MarkerTable,
            });
        }
    }
    let named = |side: Option<Side>, words: &[&str]| {
        words.iter().find_map(|w| {
            normal
                .iter()
                .position(|n| n.side == side && n.base == *w)
                .map(|i| markers[i].clone())
        })
    };
    for point in BodyPoint::ALL {
        if found.iter().any(|p| p.point == point) {
            continue;
        }
        let hit = match point.limb() {
            Some((side, limb)) => named(Some(side), names::limb_words(limb)),
            None => named(
                None,
                match point {
                    BodyPoint::Pelvis => &names::PELVIS_WORDS[..],
                    BodyPoint::Chest => &names::CHEST_WORDS[..],
                    BodyPoint::Neck => &names::NECK_WORDS[..],
                    _ => &names::HEAD_WORDS[..],
                },
            ),
        };
        if let Some(m) = hit {
            found.push(MappedPoint {
                point,
                source: PointSource::Markers(vec![m]),
                found_by: FoundBy::Name,
            });
        }
    }
    if !found.iter().any(|p| p.point == BodyPoint::Pelvis) {
        let hips: Vec<String> = [BodyPoint::LeftHip, BodyPoint::RightHip]
            .iter()
            .filter_map(|h| found.iter().find(|p| p.point == *h))
            .filter_map(|p| match &p.source {
                PointSource::Markers(m) => Some(m.clone()),
                PointSource::Joint(_) => None,
            })
            .flatten()
            .collect();
        if hips.len() >= 2 {
            found.push(MappedPoint {
                point: BodyPoint::Pelvis,
                source: PointSource::Markers(hips),
                found_by: FoundBy::Structure,
            });
        }
    }
    BodyMap::new(source, found.clone()).map_err(|_| {
        unrecognised(
            source,
            &found,
            &format!("markers: {}", crate::error::name_list(markers)),
            "not applicable to markers",
        )
    })
}
