//! A starting profile guessed from a URDF's tree (`iktc profile init`).
//!
//! Guesses, each marked `# guessed` in the written TOML:
//! * feet: per side, the deepest link whose name contains `foot`, `ankle`, `sole` or `toe`
//!   (the side from a `left`/`l_`/`_l` or `right`/`r_`/`_r` in its name); their sole rectangle
//!   and ankle height from the link's collision boxes and spheres (the bounding rectangle of
//!   their footprints, the ankle height from the lowest point), else, when the URDF's folder is
//!   known ([`init_profile_toml_at`]), from its collision meshes, else its visual meshes (the
//!   ankle height from the lowest vertex, the sole the bounding rectangle of the vertices within
//!   [`SOLE_BAND`] of it), else a placeholder;
//! * pelvis: the first link (from the root) whose name contains `pelvis`, else the root link;
//! * torso (`torso`, `chest`, `trunk`) and head (`head`, `neck`): the matching link nearest the
//!   root; hands (`hand`, `palm`, `wrist`): the deepest matching link per side; a side without
//!   one gets a frame added (key `frame`) at the far end of its deepest `elbow`/`forearm` link
//!   (the farthest vertex of its meshes from the elbow, else twice its centre of mass);
//! * base: floating when both feet were found, else fixed;
//! * locks: movable joints whose names contain `finger`, `thumb`, `index`, `middle`, `ring`,
//!   `little` or `pinky`, as one glob pattern each.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::error::{Error, Result};

/// A link of the parsed tree: name, parent link index, depth from the root.
struct TreeLink {
    name: String,
    lower: String,
    depth: usize,
}

#[derive(Clone, Copy, PartialEq)]
enum Side {
    Left,
    Right,
}

fn side_of(lower: &str) -> Option<Side> {
    let has = |tags: &[&str]| {
        tags.iter()
            .any(|t| lower.starts_with(t) || lower.ends_with(&t.chars().rev().collect::<String>()))
    };
    if lower.contains("left") || has(&["l_", "l-"]) || lower.contains("_l_") {
        Some(Side::Left)
    } else if lower.contains("right") || has(&["r_", "r-"]) || lower.contains("_r_") {
        Some(Side::Right)
    } else {
        None
    }
}

/// The deepest (or, with `shallow`, the shallowest) link, then the first, whose lowercase name
/// contains one of `words`, on `side`.
fn pick<'a>(
    links: &'a [TreeLink],
    words: &[&str],
    side: Option<Side>,
    shallow: bool,
) -> Option<&'a TreeLink> {
    links
        .iter()
        .filter(|l| words.iter().any(|w| l.lower.contains(w)))
        .filter(|l| side.is_none() || side_of(&l.lower) == side)
        .fold(None, |best: Option<&TreeLink>, l| match best {
            Some(b) if (b.depth >= l.depth) != shallow || b.depth == l.depth => Some(b),
            _ => Some(l),
        })
}

fn deepest<'a>(links: &'a [TreeLink], words: &[&str], side: Option<Side>) -> Option<&'a TreeLink> {
    pick(links, words, side, false)
}

/// A guessed sole: `(length, width, offset_x, ankle_height)` \[m\].
type Sole = (f64, f64, f64, f64);

/// The sole over the footprint points `footprint` (link frame) \[m\]: their bounding rectangle
/// in x and y, the ankle height `−zmin` from the lowest point `zmin` \[m\] below the link's
/// origin. `None` for a rectangle without length or width, or `zmin ≥ 0`.
fn rectangle<'a>(footprint: impl Iterator<Item = &'a Vector3<f64>>, zmin: f64) -> Option<Sole> {
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in footprint {
        xmin = xmin.min(p.x);
        xmax = xmax.max(p.x);
        ymin = ymin.min(p.y);
        ymax = ymax.max(p.y);
    }
    let (l, w) = (xmax - xmin, ymax - ymin);
    (l > 0.0 && w > 0.0 && zmin < 0.0).then(|| (l, w, 0.5 * (xmin + xmax), -zmin))
}

/// The lowest height of `points` \[m\] (`+∞` for none).
fn lowest(points: &[Vector3<f64>]) -> f64 {
    points.iter().map(|p| p.z).fold(f64::INFINITY, f64::min)
}

/// A guessed sole ([`Sole`]) from the collision boxes and spheres of `link` (their footprints
/// in the link frame, ignoring their rotation about z).
fn sole_from_collisions(link: &urdf_rs::Link) -> Option<Sole> {
    let mut points = Vec::new();
    for c in &link.collision {
        let o = Isometry3::from_parts(
            Translation3::new(c.origin.xyz[0], c.origin.xyz[1], c.origin.xyz[2]),
            UnitQuaternion::from_euler_angles(c.origin.rpy[0], c.origin.rpy[1], c.origin.rpy[2]),
        );
        match &c.geometry {
            urdf_rs::Geometry::Sphere { radius } => {
                // The footprint is the contact point; the sphere reaches `radius` lower.
                points.push(o.translation.vector - Vector3::z() * *radius);
            }
            urdf_rs::Geometry::Box { size } => {
                let h = Vector3::new(size[0], size[1], size[2]) * 0.5;
                for sx in [-1.0, 1.0] {
                    for sy in [-1.0, 1.0] {
                        for sz in [-1.0, 1.0] {
                            let corner = h.component_mul(&Vector3::new(sx, sy, sz));
                            points.push((o * nalgebra::Point3::from(corner)).coords);
                        }
                    }
                }
            }
            _ => {}
        }
    }
    rectangle(points.iter(), lowest(&points))
}

/// Vertices of a foot mesh up to this height above its lowest one make its sole \[m\]: the
/// flat underside of a foot, not the toe's upward curve or the ankle's housing above it.
pub const SOLE_BAND: f64 = 0.01;

/// A guessed sole ([`Sole`]) from the mesh vertices `v` of a foot link, in its frame (see the
/// module documentation).
fn sole_from_vertices(v: &[Vector3<f64>]) -> Option<Sole> {
    let zmin = lowest(v);
    rectangle(v.iter().filter(|p| p.z <= zmin + SOLE_BAND), zmin)
}

/// The vertices \[m\] of every collision (`collision`) or visual mesh of `link`, in its frame,
/// read from the URDF's folder `dir`; `None` when one of those shapes is not a mesh or cannot
/// be read.
fn link_vertices(
    link: &urdf_rs::Link,
    collision: bool,
    dir: &std::path::Path,
) -> Option<Vec<Vector3<f64>>> {
    let parts: Vec<(&urdf_rs::Geometry, &urdf_rs::Pose)> = if collision {
        link.collision
            .iter()
            .map(|c| (&c.geometry, &c.origin))
            .collect()
    } else {
        link.visual
            .iter()
            .map(|v| (&v.geometry, &v.origin))
            .collect()
    };
    let mut all = Vec::new();
    for (g, o) in parts {
        all.extend(crate::mesh::urdf::mesh_vertices(g, o, dir).ok()??);
    }
    Some(all)
}

/// The sole of `link` from its collision meshes, else its visual meshes, read from the URDF's
/// folder `dir`, with which of the two it came from. `None` when neither gives one (no mesh,
/// a mesh that cannot be read, or one that does not reach below the link's origin).
fn sole_from_meshes(link: &urdf_rs::Link, dir: &std::path::Path) -> Option<(Sole, &'static str)> {
    let sole = |collision| sole_from_vertices(&link_vertices(link, collision, dir)?);
    sole(true)
        .map(|s| (s, "from the link's collision meshes"))
        .or_else(|| sole(false).map(|s| (s, "from the link's visual meshes")))
}

/// Links shorter than this from their origin to their far end \[m\] give no hand point.
const MIN_FOREARM: f64 = 0.05;

/// The far end of a forearm link without a hand link below it, in its frame \[m\], and where
/// it came from: the vertex of its visual (else collision) meshes in `dir` farthest from its
/// origin (the elbow), else twice its centre of mass (the end of a uniform rod from the
/// elbow). `None` when neither reaches [`MIN_FOREARM`].
fn hand_point(
    link: &urdf_rs::Link,
    dir: Option<&std::path::Path>,
) -> Option<(Vector3<f64>, &'static str)> {
    let far = |collision| -> Option<Vector3<f64>> {
        let mut best: Option<Vector3<f64>> = None;
        for v in link_vertices(link, collision, dir?)? {
            if best.is_none_or(|b| v.norm() > b.norm()) {
                best = Some(v);
            }
        }
        best.filter(|b| b.norm() >= MIN_FOREARM)
    };
    far(false)
        .map(|p| (p, "the farthest vertex of its visual meshes"))
        .or_else(|| far(true).map(|p| (p, "the farthest vertex of its collision meshes")))
        .or_else(|| {
            let c = 2.0 * Vector3::from(link.inertial.origin.xyz.0);
            (c.norm() >= MIN_FOREARM).then_some((c, "twice its centre of mass"))
        })
}

/// `x` \[m\] rounded to 0.1 mm.
fn tenth_mm(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

fn quote(s: &str) -> String {
    // TOML basic string: escape backslashes and quotes.
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// The `urdf` key of a profile written to `profile` for the URDF file `urdf`: its path
/// relative to the profile's folder when it lies under it, else absolute; `urdf` as given
/// without a profile file. Errors: a URDF or a folder that does not exist.
pub fn urdf_key(urdf: &std::path::Path, profile: Option<&std::path::Path>) -> Result<String> {
    let Some(profile) = profile else {
        return Ok(urdf.display().to_string());
    };
    let dir = profile
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let canonical = |p: &std::path::Path, what: &str| {
        p.canonicalize().map_err(|e| Error::Urdf {
            message: format!("{what} {}: {e}", p.display()),
        })
    };
    let abs_urdf = canonical(urdf, "cannot read")?;
    let abs_dir = canonical(dir, "cannot find the profile's folder")?;
    Ok(match abs_urdf.strip_prefix(&abs_dir) {
        Ok(rel) => rel.display().to_string(),
        Err(_) => abs_urdf.display().to_string(),
    })
}

/// Writes a starting profile for the URDF `text`, whose path relative to where the profile
/// will be written is `urdf_path`. Every guessed value is marked `# guessed`; the result parses
/// as a [`RobotProfile`](super::RobotProfile) (keys it could not guess are left out or
/// commented).
///
/// Errors: a URDF that does not parse or has no single root link.
pub fn init_profile_toml(text: &str, urdf_path: &str) -> Result<String> {
    init_profile_toml_at(text, urdf_path, None)
}

/// [`init_profile_toml`] for a URDF in the folder `dir`: a foot without collision boxes or
/// spheres has its sole guessed from its meshes there (see the module documentation).
pub fn init_profile_toml_at(
    text: &str,
    urdf_path: &str,
    dir: Option<&std::path::Path>,
) -> Result<String> {
    let (u, _) = crate::model::read_urdf(text, &crate::resources::ReadLimits::default())?;
    let is_child = |name: &str| u.joints.iter().any(|j| j.child.link == name);
    let roots: Vec<&urdf_rs::Link> = u.links.iter().filter(|l| !is_child(&l.name)).collect();
    let [root] = roots.as_slice() else {
        return Err(Error::Urdf {
            message: format!(
                "expected one root link (a link that is no joint's child), found {}: {}",
                roots.len(),
                roots
                    .iter()
                    .map(|l| l.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        });
    };
    // Breadth-first from the root: depth of every link, parents before children.
    let mut links: Vec<TreeLink> = vec![TreeLink {
        name: root.name.clone(),
        lower: root.name.to_lowercase(),
        depth: 0,
    }];
    let mut i = 0;
    while i < links.len() {
        let (parent, depth) = (links[i].name.clone(), links[i].depth);
        for j in u.joints.iter().filter(|j| j.parent.link == parent) {
            if links.iter().all(|l| l.name != j.child.link) {
                links.push(TreeLink {
                    name: j.child.link.clone(),
                    lower: j.child.link.to_lowercase(),
                    depth: depth + 1,
                });
            }
        }
        i += 1;
    }
    let foot_words = ["foot", "ankle", "sole", "toe"];
    let left = deepest(&links, &foot_words, Some(Side::Left));
    let right = deepest(&links, &foot_words, Some(Side::Right));
    let pelvis = links
        .iter()
        .find(|l| l.lower.contains("pelvis"))
        .unwrap_or(&links[0]);
    // The body's own link comes before the sensors and frames attached to it.
    let torso = pick(&links, &["torso", "chest", "trunk"], None, true);
    let head = pick(&links, &["head", "neck"], None, true);
    let hand_words = ["hand", "palm", "wrist"];
    let left_hand = deepest(&links, &hand_words, Some(Side::Left));
    let right_hand = deepest(&links, &hand_words, Some(Side::Right));
    // A side without a hand link: a frame added at the far end of its forearm.
    let forearm_words = ["elbow", "forearm", "lower_arm", "lowerarm"];
    let hand_end = |side: Side, found: Option<&TreeLink>| {
        if found.is_some() {
            return None;
        }
        let forearm = deepest(&links, &forearm_words, Some(side))?;
        let link = u.links.iter().find(|l| l.name == forearm.name)?;
        let (xyz, why) = hand_point(link, dir)?;
        Some((forearm.name.clone(), xyz, why))
    };
    let left_end = hand_end(Side::Left, left_hand);
    let right_end = hand_end(Side::Right, right_hand);

    let mut out = String::new();
    let name = if u.name.is_empty() { "robot" } else { &u.name };
    out.push_str(&format!(
        "# Robot profile of `{name}`, written by `iktc profile init`: check every value marked\n\
         # `# guessed` (and the comments) before use.\nname = {}\nurdf = {}\n",
        quote(name),
        quote(urdf_path)
    ));
    let feet = left.zip(right);
    out.push_str(&format!(
        "base = \"{}\" # guessed: {}\n",
        if feet.is_some() { "floating" } else { "fixed" },
        if feet.is_some() {
            "two feet were found"
        } else {
            "no pair of feet was found"
        }
    ));
    let fingers = [
        "finger", "thumb", "index", "middle", "ring", "little", "pinky",
    ];
    for j in u.joints.iter().filter(|j| {
        !matches!(j.joint_type, urdf_rs::JointType::Fixed)
            && fingers.iter().any(|w| j.name.to_lowercase().contains(w))
    }) {
        out.push_str(&format!(
            "[[lock]] # guessed: a finger joint\njoints = {}\nvalue = 0.0\n",
            quote(&j.name)
        ));
    }
    out.push('\n');
    match feet {
        Some((l, r)) => {
            for (side, link) in [("left", l), ("right", r)] {
                let urdf_link = u.links.iter().find(|x| x.name == link.name);
                let sole = urdf_link
                    .and_then(sole_from_collisions)
                    .map(|s| (s, "from the link's collision boxes/spheres"))
                    .or_else(|| urdf_link.zip(dir).and_then(|(l, d)| sole_from_meshes(l, d)));
                out.push_str(&format!(
                    "[feet.{side}]\nframe = {} # guessed: deepest link named like a foot on the {side}\n",
                    quote(&link.name)
                ));
                let (len, wid, off, ankle, why) = match sole {
                    // To 0.1 mm: meshes are stored in single precision.
                    Some(((a, b, c, d), why)) => (tenth_mm(a), tenth_mm(b), tenth_mm(c), tenth_mm(d), why),
                    None => (
                        0.2,
                        0.1,
                        0.0,
                        0.1,
                        "PLACEHOLDER, no collision box, sphere or readable mesh below the \
                         link: measure the robot",
                    ),
                };
                out.push_str(&format!(
                    "ankle_height = {ankle:?} # guessed: {why}\n\
                     sole = {{ length = {len:?}, width = {wid:?}, offset_x = {off:?} }} # guessed: {why}\n\n"
                ));
            }
        }
        None => out.push_str(
            "# No pair of feet found (links named foot/ankle/sole/toe with a left/right tag):\n\
             # add [feet.left] and [feet.right] (frame, ankle_height, sole) for a standing robot.\n\n",
        ),
    }
    for (key, end) in [("left_hand", &left_end), ("right_hand", &right_end)] {
        if let Some((parent, xyz, why)) = end {
            out.push_str(&format!(
                "[[frame]] # guessed: no hand link; the far end of the forearm ({why})\n\
                 name = {}\nparent = {}\nxyz = [{:?}, {:?}, {:?}]\n\n",
                quote(key),
                quote(parent),
                tenth_mm(xyz.x),
                tenth_mm(xyz.y),
                tenth_mm(xyz.z),
            ));
        }
    }
    out.push_str("[frames]\n");
    out.push_str(&format!(
        "pelvis = {} # guessed: {}\n",
        quote(&pelvis.name),
        if pelvis.lower.contains("pelvis") {
            "named like a pelvis"
        } else {
            "the root link"
        }
    ));
    for (key, found) in [
        ("torso", torso),
        ("head", head),
        ("left_hand", left_hand),
        ("right_hand", right_hand),
    ] {
        let end = match key {
            "left_hand" => left_end.as_ref(),
            "right_hand" => right_end.as_ref(),
            _ => None,
        };
        match (found, end) {
            (Some(l), _) => out.push_str(&format!(
                "{key} = {} # guessed: a link named like it\n",
                quote(&l.name)
            )),
            (None, Some((parent, _, _))) => out.push_str(&format!(
                "{key} = {} # guessed: the frame added at the end of `{parent}` above\n",
                quote(key)
            )),
            (None, None) => out.push_str(&format!("# {key} = \"...\" # not found\n")),
        }
    }
    out.push_str(
        "\n# Initial joint angles [rad] (joint = angle), e.g. bent knees for a humanoid.\n[posture]\n\n\
         # Default narrowed ranges [rad] (joint = [lower, upper]).\n[narrow]\n\n\
         [acceleration]\nper_velocity = 10.0 # guessed: the paper's ratio (180°/s, 1800°/s²)\n\n\
         # Walking settings (`iktc walk`); left out: 0.1 m steps, 4 cm swing, 0.6 s single and\n\
         # 0.1 s double support, a push changing the COM velocity by 0.08 m/s.\n\
         [walk]\n# step_length = 0.1\n# swing_height = 0.04\n# ssp_duration = 0.6\n# dsp_duration = 0.1\n\
         # push = { time = 2.15, impulse = [5.0, 0.0] }\n\n\
         # Retargeting maps per motion format (built-in name or TOML file relative to this file).\n\
         [imitate.maps]\n# deepmimic = \"my_deepmimic_map.toml\"\n",
    );
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box foot 0.2 × 0.08 m whose underside is 0.05 m below the frame, centred 0.03 m ahead
    /// of it, with a toe tip raised 0.02 m (above the sole band) reaching 0.05 m further and an
    /// ankle housing above: the sole is the underside's rectangle.
    #[test]
    fn the_sole_of_a_mesh_is_its_underside() {
        let mut v = Vec::new();
        for x in [-0.07, 0.13] {
            for y in [-0.04, 0.04] {
                v.push(Vector3::new(x, y, -0.05));
                v.push(Vector3::new(x, y, 0.0));
            }
        }
        v.push(Vector3::new(0.18, 0.0, -0.05 + 2.0 * SOLE_BAND));
        v.push(Vector3::new(0.0, 0.06, 0.1));
        let (l, w, off, ankle) = sole_from_vertices(&v).unwrap();
        for (got, want) in [(l, 0.2), (w, 0.08), (off, 0.03), (ankle, 0.05)] {
            assert!((got - want).abs() < 1e-12, "{got} {want}");
        }
        // A mesh entirely above the frame has no sole below it, nor one whose lowest vertex is
        // at the frame's height (an ankle height of 0).
        let above: Vec<_> = v.iter().map(|p| p + Vector3::z()).collect();
        assert!(sole_from_vertices(&above).is_none());
        let level: Vec<_> = v.iter().map(|p| p + 0.05 * Vector3::z()).collect();
        assert!(sole_from_vertices(&level).is_none());
        assert!(sole_from_vertices(&[]).is_none());
        // An underside that is a line (no width) or a point across (no length) is no sole.
        let line = [
            Vector3::new(-0.07, 0.0, -0.05),
            Vector3::new(0.13, 0.0, -0.05),
        ];
        assert!(sole_from_vertices(&line).is_none());
        let across = [
            Vector3::new(0.0, -0.04, -0.05),
            Vector3::new(0.0, 0.04, -0.05),
        ];
        assert!(sole_from_vertices(&across).is_none());
    }
}
