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

/// The limb joints found by name (`normal`: the joints' normalised names), leg then arm on
/// each side, each joint below the one found before it on its chain: (point, joint, how).
fn limb_joints_by_name(
    skeleton: &Skeleton,
    normal: &[NormalName],
) -> Vec<(BodyPoint, usize, FoundBy)> {
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
    found
}

fn by_names(skeleton: &Skeleton) -> Vec<MappedPoint> {
    let normal: Vec<NormalName> = skeleton
        .joints()
        .iter()
        .map(|j| normalise(&j.name))
        .collect();
    let mut found = limb_joints_by_name(skeleton, &normal);
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

/// Marker families per body point, tried in order: the first family with a marker gives the
/// point, the centroid of all its markers (pairs such as front/back, inner/outer,
/// medial/lateral on either side of a joint, read by [`names::stem_is`]). Limb points take the
/// markers of their side; the pelvis, chest, neck and head markers of any side.
fn marker_families(point: BodyPoint) -> &'static [&'static [&'static str]] {
    match point {
        BodyPoint::Pelvis => &[
            &["pelvis", "hips", "midhip", "root"],
            &["asi", "psi", "asis", "psis", "waist"],
            &["asi", "asis", "sacr", "sacrum"],
            &["hip"],
        ],
        BodyPoint::Chest => &[&[
            "clav", "strn", "c7", "t10", "t8", "sternum", "clavicle", "chest", "xiphoid",
            "backtop", "spinetop",
        ]],
        BodyPoint::Neck => &[&["neck", "lowerneck"], &["c7", "clav"]],
        BodyPoint::Head => &[
            &["fhd", "bhd", "head", "headtop", "forehead", "vertex"],
            &["nose"],
        ],
        _ => match point.limb().map(|(_, l)| l) {
            Some(Limb::Shoulder) => &[
                &["shoulder", "sho", "shou", "acromion", "acr"],
                &["uarm", "upperarm", "humerus"],
            ],
            Some(Limb::Elbow) => &[
                &["elbow", "elb", "epicondyle"],
                &["farm", "forearm", "lowerarm"],
            ],
            Some(Limb::Wrist) => &[
                &[
                    "wrist", "wri", "wr", "wra", "wrb", "styloid", "radius", "ulna",
                ],
                &["hand"],
            ],
            Some(Limb::Hip) => &[
                &["hip", "hipjoint"],
                &["asi", "psi", "asis", "psis", "waist"],
                &["thigh", "upleg"],
            ],
            Some(Limb::Knee) => &[&["knee", "kne", "kn", "knm"], &["shin", "lowerleg"]],
            Some(Limb::Ankle) => &[&["ankle", "ank", "malleolus", "mal", "mma"], &["foot"]],
            Some(Limb::Toe) => &[&[
                "toe", "toes", "mt", "mth", "meta", "forefoot", "ball", "bigtoe",
            ]],
            None => &[],
        },
    }
}

/// The markers of `markers` in the first family of `point` that has any
/// ([`marker_families`]), with that family's index and the stems they matched by.
fn family_markers(
    markers: &[String],
    point: BodyPoint,
) -> Option<(usize, Vec<String>, std::collections::BTreeSet<String>)> {
    let side = point.limb().map(|(s, _)| s);
    let readings: Vec<_> = markers.iter().map(|m| names::marker_readings(m)).collect();
    marker_families(point)
        .iter()
        .enumerate()
        .find_map(|(k, family)| {
            let mut stems = std::collections::BTreeSet::new();
            let mut hit = Vec::new();
            for (m, r) in markers.iter().zip(&readings) {
                let matched = r.iter().find(|(s, stem)| {
                    (side.is_none() || *s == side) && family.iter().any(|w| names::stem_is(stem, w))
                });
                if let Some((_, stem)) = matched {
                    stems.insert(stem.clone());
                    hit.push(m.clone());
                }
            }
            (!hit.is_empty()).then_some((k, hit, stems))
        })
}

/// The markers of a family for `point` ([`family_markers`]), unless the other side's point
/// has the same family with more of its markers (a pair missing one marker on this side, as
/// `LWRA` without `LWRB` when the right has both): its centroid would be off the joint.
fn family_point(markers: &[String], point: BodyPoint) -> Option<Vec<String>> {
    let (k, hit, stems) = family_markers(markers, point)?;
    if let Some((side, limb)) = point.limb() {
        let other = match side {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        };
        if let Some((ko, _, so)) = family_markers(markers, BodyPoint::of_limb(other, limb)) {
            if ko == k && so.len() > stems.len() && stems.is_subset(&so) {
                return None;
            }
        }
    }
    Some(hit)
}

/// The body points the Plug-in-Gait table finds on `markers`.
fn table_points(markers: &[String]) -> Vec<MappedPoint> {
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
    found
}

/// The single marker named like `point`'s joint, if any.
fn named_marker(markers: &[String], normal: &[NormalName], point: BodyPoint) -> Option<String> {
    let named = |side: Option<Side>, words: &[&str]| {
        words.iter().find_map(|w| {
            normal
                .iter()
                .position(|n| n.side == side && n.base == *w)
                .map(|i| markers[i].clone())
        })
    };
    match point.limb() {
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
    }
}

/// The pelvis from the hips' markers, when both hips are found on markers.
fn pelvis_from_hips(found: &[MappedPoint]) -> Option<MappedPoint> {
    let hips: Vec<String> = [BodyPoint::LeftHip, BodyPoint::RightHip]
        .iter()
        .filter_map(|h| found.iter().find(|p| p.point == *h))
        .filter_map(|p| match &p.source {
            PointSource::Markers(m) => Some(m.clone()),
            PointSource::Joint(_) => None,
        })
        .flatten()
        .collect();
    (hips.len() >= 2).then_some(MappedPoint {
        point: BodyPoint::Pelvis,
        source: PointSource::Markers(hips),
        found_by: FoundBy::Structure,
    })
}

/// The body points found on a marker set, possibly not all required ones: the Plug-in-Gait
/// table, then marker families (a joint's markers in pairs or groups, front/back, inner/outer,
/// medial/lateral: their centroid), then single markers named like a joint;
/// the pelvis falls back to the hips' markers.
pub fn marker_points(markers: &[String]) -> Vec<MappedPoint> {
    let normal: Vec<NormalName> = markers.iter().map(|m| normalise(m)).collect();
    let mut found = table_points(markers);
    for point in BodyPoint::ALL {
        if found.iter().all(|p| p.point != point) {
            if let Some(m) = family_point(markers, point) {
                found.push(MappedPoint {
                    point,
                    source: PointSource::Markers(m),
                    found_by: FoundBy::Name,
                });
            }
        }
    }
    for point in BodyPoint::ALL {
        if found.iter().any(|p| p.point == point) {
            continue;
        }
        if let Some(m) = named_marker(markers, &normal, point) {
            found.push(MappedPoint {
                point,
                source: PointSource::Markers(vec![m]),
                found_by: FoundBy::Name,
            });
        }
    }
    if !found.iter().any(|p| p.point == BodyPoint::Pelvis) {
        found.extend(pelvis_from_hips(&found));
    }
    found.sort_by_key(|p| p.point);
    found
}

/// Finds the body points of a marker set ([`marker_points`]). `markers` are the file's marker
/// (or point) names.
///
/// Error ([`Error::InsufficientData`]) when a required point is missing: it lists the points
/// found, those missing, the markers, and the map to write.
pub fn recognise_markers(markers: &[String], source: &str) -> Result<BodyMap> {
    let found = marker_points(markers);
    BodyMap::new(source, found.clone()).map_err(|_| {
        unrecognised(
            source,
            &found,
            &format!("markers: {}", crate::error::name_list(markers)),
            "not applicable to markers",
        )
    })
}

/// The body points found on a skeleton, possibly not all required ones: by names, or by
/// shape when that finds them all (see [`recognise_skeleton`]).
pub fn skeleton_points(skeleton: &Skeleton) -> Vec<MappedPoint> {
    match recognise_skeleton(skeleton, "") {
        Ok(map) => map.points,
        Err(_) => by_names(skeleton),
    }
}

/// A body map to edit (TOML) named `name` from the points `found` (possibly not all required
/// ones): each found point as a map entry with how it was found; each point not found as a
/// commented entry to fill in, marked `REQUIRED` or `optional`; then the names available
/// (`what`: "markers" or "joints", `available`), as comments.
pub fn draft_body_map_toml(
    name: &str,
    found: &[MappedPoint],
    what: &str,
    available: &[String],
) -> String {
    let quote = |s: &str| toml::Value::String(s.to_string()).to_string();
    let mut out = String::from(
        "# Body map: the skeleton joint (a name) or the markers (a list: their centroid)
         # giving each body point. Fill in the commented entries, then pass it with --map.
",
    );
    out.push_str(&format!(
        "name = {}

[points]
",
        quote(name)
    ));
    for point in BodyPoint::ALL {
        match found.iter().find(|p| p.point == point) {
            Some(p) => {
                let value = match &p.source {
                    PointSource::Joint(j) => quote(j),
                    PointSource::Markers(m) => format!(
                        "[{}]",
                        m.iter().map(|s| quote(s)).collect::<Vec<_>>().join(", ")
                    ),
                };
                out.push_str(&format!(
                    "{} = {value}  # {}
",
                    point.name(),
                    p.found_by.describe()
                ));
            }
            None => out.push_str(&format!(
                "# {} = [\"...\"]  # {}: not found, fill in\n",
                point.name(),
                if BodyPoint::REQUIRED.contains(&point) {
                    "REQUIRED"
                } else {
                    "optional"
                }
            )),
        }
    }
    out.push_str(&format!("\n# The {what} of the file:\n"));
    let mut line = String::from("#");
    for n in available {
        if line.len() + n.len() > 96 {
            out.push_str(&line);
            out.push('\n');
            line = String::from("#");
        }
        line.push(' ');
        line.push_str(n);
    }
    if line.len() > 1 {
        out.push_str(&line);
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;

    /// The joint centres the synthetic marker sets are placed around \[m\] (x forward, y left,
    /// z up); the right side mirrors the left in y.
    fn centre(point: BodyPoint) -> Vector3<f64> {
        let (side, y) = match point.limb() {
            Some((Side::Left, _)) => (1.0, 1.0),
            Some((Side::Right, _)) => (-1.0, 1.0),
            None => (0.0, 0.0),
        };
        let v = |x: f64, yy: f64, z: f64| Vector3::new(x, side * y * yy, z);
        match point.limb().map(|(_, l)| l) {
            Some(Limb::Shoulder) => v(0.0, 0.2, 1.45),
            Some(Limb::Elbow) => v(0.0, 0.2, 1.15),
            Some(Limb::Wrist) => v(0.0, 0.2, 0.9),
            Some(Limb::Hip) => v(0.0, 0.1, 0.95),
            Some(Limb::Knee) => v(0.0, 0.1, 0.5),
            Some(Limb::Ankle) => v(0.0, 0.1, 0.08),
            Some(Limb::Toe) => v(0.15, 0.1, 0.02),
            None => match point {
                BodyPoint::Pelvis => v(0.0, 0.0, 0.95),
                BodyPoint::Chest => v(0.0, 0.0, 1.35),
                BodyPoint::Neck => v(0.0, 0.0, 1.5),
                _ => v(0.0, 0.0, 1.65),
            },
        }
    }

    /// A marker set under construction: names and positions \[m\].
    #[derive(Default)]
    struct Set(Vec<(String, Vector3<f64>)>);

    impl Set {
        /// One marker at `at`.
        fn one(&mut self, name: &str, at: Vector3<f64>) {
            self.0.push((name.to_string(), at));
        }
        /// Two markers on either side of `point`'s centre, `offset` away.
        fn pair(&mut self, a: &str, b: &str, point: BodyPoint, offset: Vector3<f64>) {
            self.one(a, centre(point) + offset);
            self.one(b, centre(point) - offset);
        }
    }

    fn side_point(side: &str, limb: Limb) -> BodyPoint {
        let s = if side == "L" { Side::Left } else { Side::Right };
        BodyPoint::of_limb(s, limb)
    }

    /// Every required point (and the toes) is found, at the centroid of its markers equal to
    /// the centre the markers were placed around.
    fn check(set: &Set, family: &str) {
        let names: Vec<String> = set.0.iter().map(|(n, _)| n.clone()).collect();
        let found = marker_points(&names);
        let map = BodyMap::new(family, found.clone());
        assert!(map.is_ok(), "{family}: {map:?}");
        for point in BodyPoint::REQUIRED
            .into_iter()
            .chain([BodyPoint::LeftToe, BodyPoint::RightToe])
        {
            let p = found.iter().find(|p| p.point == point);
            let Some(PointSource::Markers(m)) = p.map(|p| &p.source) else {
                panic!("{family}: {point} not found");
            };
            let sum: Vector3<f64> = m
                .iter()
                .map(|n| set.0.iter().find(|(k, _)| k == n).unwrap().1)
                .sum();
            let got = sum / m.len() as f64;
            assert!(
                (got - centre(point)).norm() < 1e-12,
                "{family}: {point} from {m:?} at {got:?}, placed around {:?}",
                centre(point)
            );
        }
    }

    /// Head markers around the head's centre: front/back and left/right.
    fn head(set: &mut Set, names: [&str; 4]) {
        let x = Vector3::new(0.1, 0.0, 0.0);
        let y = Vector3::new(0.0, 0.08, 0.0);
        set.pair(names[0], names[1], BodyPoint::Head, x);
        set.pair(names[2], names[3], BodyPoint::Head, y);
    }

    #[test]
    fn vicon_full_body_with_front_back_and_inner_outer_markers() {
        let (x, y) = (Vector3::new(0.05, 0.0, 0.0), Vector3::new(0.0, 0.03, 0.0));
        let mut s = Set::default();
        head(&mut s, ["Head_Front", "Head_Back", "Head_L", "Head_R"]);
        s.pair(
            "Sternum",
            "T8",
            BodyPoint::Chest,
            Vector3::new(0.1, 0.0, 0.0),
        );
        for side in ["L", "R"] {
            let p = |l| side_point(side, l);
            s.pair(
                &format!("{side}_Shoulder_Front"),
                &format!("{side}_Shoulder_Back"),
                p(Limb::Shoulder),
                x,
            );
            s.pair(
                &format!("{side}_Elbow_Lateral"),
                &format!("{side}_Elbow_Medial"),
                p(Limb::Elbow),
                y,
            );
            s.pair(
                &format!("{side}_Wrist_Outer"),
                &format!("{side}_Wrist_Inner"),
                p(Limb::Wrist),
                y,
            );
            s.pair(
                &format!("{side}_ASIS"),
                &format!("{side}_PSIS"),
                p(Limb::Hip),
                2.0 * x,
            );
            s.pair(
                &format!("{side}_Knee_Lateral"),
                &format!("{side}_Knee_Medial"),
                p(Limb::Knee),
                2.0 * y,
            );
            s.pair(
                &format!("{side}_Ankle_Lateral"),
                &format!("{side}_Ankle_Medial"),
                p(Limb::Ankle),
                y,
            );
            s.one(&format!("{side}_Toe"), centre(p(Limb::Toe)));
            s.one(&format!("{side}_Heel"), centre(p(Limb::Ankle)) - 2.0 * x);
        }
        check(&s, "vicon");
    }

    #[test]
    fn plug_in_gait() {
        let (x, y) = (Vector3::new(0.1, 0.0, 0.0), Vector3::new(0.0, 0.02, 0.0));
        let mut s = Set::default();
        s.one(
            "Subject:LFHD",
            centre(BodyPoint::Head) + x + Vector3::new(0.0, 0.08, 0.0),
        );
        s.one(
            "Subject:RFHD",
            centre(BodyPoint::Head) + x - Vector3::new(0.0, 0.08, 0.0),
        );
        s.one(
            "Subject:LBHD",
            centre(BodyPoint::Head) - x + Vector3::new(0.0, 0.08, 0.0),
        );
        s.one(
            "Subject:RBHD",
            centre(BodyPoint::Head) - x - Vector3::new(0.0, 0.08, 0.0),
        );
        s.pair("Subject:CLAV", "Subject:C7", BodyPoint::Chest, x);
        s.pair("Subject:STRN", "Subject:T10", BodyPoint::Chest, 0.5 * x);
        for side in ["L", "R"] {
            let p = |l| side_point(side, l);
            let n = |m: &str| format!("Subject:{side}{m}");
            s.one(&n("SHO"), centre(p(Limb::Shoulder)));
            s.one(&n("ELB"), centre(p(Limb::Elbow)));
            s.pair(&n("WRA"), &n("WRB"), p(Limb::Wrist), y);
            s.pair(&n("ASI"), &n("PSI"), p(Limb::Hip), x);
            s.one(&n("KNE"), centre(p(Limb::Knee)));
            s.one(
                &n("THI"),
                centre(p(Limb::Knee)) + Vector3::new(0.05, 0.0, 0.2),
            );
            s.one(&n("ANK"), centre(p(Limb::Ankle)));
            s.one(
                &n("TIB"),
                centre(p(Limb::Ankle)) + Vector3::new(0.05, 0.0, 0.2),
            );
            s.one(&n("TOE"), centre(p(Limb::Toe)));
            s.one(&n("HEE"), centre(p(Limb::Ankle)) - x);
            s.one(
                &n("FIN"),
                centre(p(Limb::Wrist)) - Vector3::new(0.0, 0.0, 0.08),
            );
        }
        check(&s, "plug-in-gait");
    }

    #[test]
    fn qualisys_animation_names() {
        let (x, y) = (Vector3::new(0.05, 0.0, 0.0), Vector3::new(0.0, 0.03, 0.0));
        let mut s = Set::default();
        head(&mut s, ["HeadFront", "HeadTop", "HeadL", "HeadR"]);
        s.pair("Chest", "SpineTop", BodyPoint::Chest, 2.0 * x);
        s.one(
            "BackL",
            centre(BodyPoint::Chest) + Vector3::new(-0.1, 0.1, -0.1),
        );
        for side in ["L", "R"] {
            let p = |l| side_point(side, l);
            s.pair(
                &format!("{side}ShoulderTop"),
                &format!("{side}ShoulderBack"),
                p(Limb::Shoulder),
                x,
            );
            s.one(
                &format!("{side}Arm"),
                centre(p(Limb::Shoulder)) - Vector3::new(0.0, 0.0, 0.15),
            );
            s.one(&format!("{side}ElbowOut"), centre(p(Limb::Elbow)));
            s.pair(
                &format!("{side}WristOut"),
                &format!("{side}WristIn"),
                p(Limb::Wrist),
                y,
            );
            s.one(
                &format!("{side}HandOut"),
                centre(p(Limb::Wrist)) - Vector3::new(0.0, 0.0, 0.08),
            );
            s.pair(
                &format!("Waist{side}Front"),
                &format!("Waist{side}Back"),
                p(Limb::Hip),
                2.0 * x,
            );
            s.one(
                &format!("{side}Thigh"),
                centre(p(Limb::Hip)) - Vector3::new(0.0, 0.0, 0.2),
            );
            s.one(&format!("{side}KneeOut"), centre(p(Limb::Knee)));
            s.one(
                &format!("{side}Shin"),
                centre(p(Limb::Knee)) - Vector3::new(0.0, 0.0, 0.2),
            );
            s.one(&format!("{side}AnkleOut"), centre(p(Limb::Ankle)));
            s.one(&format!("{side}HeelBack"), centre(p(Limb::Ankle)) - 2.0 * x);
            s.pair(
                &format!("{side}ToeTip"),
                &format!("{side}Forefoot5"),
                p(Limb::Toe),
                x,
            );
        }
        check(&s, "qualisys");
    }

    #[test]
    fn optitrack_motive_markers_and_bones() {
        let (x, y) = (Vector3::new(0.05, 0.0, 0.0), Vector3::new(0.0, 0.03, 0.0));
        let mut s = Set::default();
        let k = |n: &str| format!("Skeleton:{n}");
        s.one(&k("HeadFront"), centre(BodyPoint::Head) + 2.0 * x);
        s.one(
            &k("HeadTop"),
            centre(BodyPoint::Head) - x + Vector3::new(0.0, 0.0, 0.05),
        );
        s.one(
            &k("HeadSide"),
            centre(BodyPoint::Head) - x - Vector3::new(0.0, 0.0, 0.05),
        );
        s.pair(&k("Chest"), &k("BackTop"), BodyPoint::Chest, 2.0 * x);
        s.one(
            &k("BackLeft"),
            centre(BodyPoint::Chest) + Vector3::new(-0.1, 0.1, -0.1),
        );
        for side in ["L", "R"] {
            let p = |l| side_point(side, l);
            let n = |m: &str| k(&format!("{side}{m}"));
            s.pair(&n("ShoulderTop"), &n("ShoulderBack"), p(Limb::Shoulder), x);
            s.one(
                &n("UArmHigh"),
                centre(p(Limb::Shoulder)) - Vector3::new(0.0, 0.0, 0.1),
            );
            s.one(&n("ElbowOut"), centre(p(Limb::Elbow)));
            s.pair(&n("WristOut"), &n("WristIn"), p(Limb::Wrist), y);
            s.one(
                &n("HandOut"),
                centre(p(Limb::Wrist)) - Vector3::new(0.0, 0.0, 0.08),
            );
            s.pair(
                &k(&format!("Waist{side}Front")),
                &k(&format!("Waist{side}Back")),
                p(Limb::Hip),
                2.0 * x,
            );
            s.one(
                &n("Thigh"),
                centre(p(Limb::Hip)) - Vector3::new(0.0, 0.0, 0.2),
            );
            s.one(&n("KneeOut"), centre(p(Limb::Knee)));
            s.one(
                &n("Shin"),
                centre(p(Limb::Knee)) - Vector3::new(0.0, 0.0, 0.2),
            );
            s.one(&n("AnkleOut"), centre(p(Limb::Ankle)));
            s.one(&n("Heel"), centre(p(Limb::Ankle)) - 2.0 * x);
            s.pair(&n("ToeOut"), &n("ToeIn"), p(Limb::Toe), y);
        }
        check(&s, "motive markers");
        // Motive's bones, one point each at its proximal joint.
        let mut b = Set::default();
        for (name, point) in [
            ("Hip", BodyPoint::Pelvis),
            ("Chest", BodyPoint::Chest),
            ("Neck", BodyPoint::Neck),
            ("Head", BodyPoint::Head),
        ] {
            b.one(&k(name), centre(point));
        }
        for side in ["L", "R"] {
            let p = |l| side_point(side, l);
            for (bone, limb) in [
                ("UArm", Limb::Shoulder),
                ("FArm", Limb::Elbow),
                ("Hand", Limb::Wrist),
                ("Thigh", Limb::Hip),
                ("Shin", Limb::Knee),
                ("Foot", Limb::Ankle),
                ("Toe", Limb::Toe),
            ] {
                b.one(&k(&format!("{side}{bone}")), centre(p(limb)));
            }
        }
        check(&b, "motive bones");
    }

    /// A set that lacks the wrists still gives the points it has, and the draft map names the
    /// missing ones as entries to fill in.
    #[test]
    fn a_partial_set_gives_a_draft_with_the_missing_points() {
        let names: Vec<String> = ["LSHO", "RSHO", "LELB", "RELB", "LKNE", "C7"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let found = marker_points(&names);
        assert!(recognise_markers(&names, "x").is_err());
        let text = draft_body_map_toml("x", &found, "markers", &names);
        assert!(text.contains("left_shoulder = [\"LSHO\"]"), "{text}");
        assert!(
            text.contains("# left_wrist = [\"...\"]  # REQUIRED"),
            "{text}"
        );
        assert!(
            text.contains("# left_toe = [\"...\"]  # optional"),
            "{text}"
        );
        assert!(text.contains("# LSHO RSHO LELB RELB LKNE C7"), "{text}");
        // Filled in, it parses.
        let filled = text.replace("# left_wrist = [\"...\"]", "left_wrist = [\"LELB\"]");
        let e = BodyMap::from_toml_str(&filled, "x")
            .unwrap_err()
            .to_string();
        assert!(
            !e.contains("left_wrist") && e.contains("right_wrist"),
            "{e}"
        );
    }
}
