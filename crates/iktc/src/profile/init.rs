//! A starting profile guessed from a URDF's tree (`iktc profile init`).
//!
//! Guesses, each marked `# guessed` in the written TOML:
//! * feet: per side, the deepest link whose name contains `foot`, `ankle`, `sole` or `toe`
//!   (the side from a `left`/`l_`/`_l`/`_l<digit>` or `right`/`r_`/`_r`/`_r<digit>` in its
//!   name); their sole rectangle and ankle height from the collision boxes and spheres of that
//!   link and of the links fixed to it (the bounding rectangle of their footprints, the ankle
//!   height from the lowest point), else, when the URDF's folder is
//!   known ([`init_profile_toml_at`]), from its collision meshes, else its visual meshes (the
//!   ankle height from the lowest vertex, the sole the bounding rectangle of the vertices within
//!   [`SOLE_BAND`] of it); a link that gives no sole and is fixed to its parent (a toe or heel
//!   contact point) hands the foot to the link the last movable joint above it moves, when
//!   that one gives a sole (the contact points fixed to it); else a placeholder;
//! * pelvis: the first link (from the root) whose name contains `pelvis`, else the root link;
//! * torso (`torso`, `chest`, `trunk`) and head (`head`, `neck`): the matching link nearest the
//!   root; hands (`hand`, `palm`, `wrist`, `end_effector`, `eef`): the deepest matching link
//!   per side; a side without
//!   one gets a frame added (key `frame`) at the far end of its deepest `elbow`/`forearm` link
//!   (the farthest vertex of its meshes from the elbow, else twice its centre of mass);
//! * base: floating when both feet were found, else fixed;
//! * posture: for a floating biped with six leg joints per side, the legs bent so that the
//!   hips sit [`CROUCH`] of the leg's length lower, the feet level where they were;
//! * locks: movable joints whose names contain `finger`, `thumb`, `index`, `middle`, `ring`,
//!   `little` or `pinky`, as one glob pattern each.

use nalgebra::{DMatrix, DVector, Isometry3, Vector3};

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
    // `_l_`, or `_l` before a digit (`zarm_l7_link`, `leg_l6_link`).
    let tagged = |c: char| {
        lower.contains(&format!("_{c}_"))
            || lower
                .match_indices(&format!("_{c}"))
                .any(|(i, _)| lower[i + 2..].starts_with(|d: char| d.is_ascii_digit()))
    };
    if lower.contains("left") || has(&["l_", "l-"]) || tagged('l') {
        Some(Side::Left)
    } else if lower.contains("right") || has(&["r_", "r-"]) || tagged('r') {
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

/// The collision shapes of link `name` and of every link attached to it through fixed joints
/// (contact points at a sole's corners, a sole plate), each with its pose in `name`'s frame.
fn fixed_subtree<'a>(
    u: &'a urdf_rs::Robot,
    name: &str,
) -> Vec<(Isometry3<f64>, &'a urdf_rs::Collision)> {
    let mut out = Vec::new();
    let mut open = vec![(name.to_string(), Isometry3::identity())];
    while let Some((link, at)) = open.pop() {
        if let Some(l) = u.links.iter().find(|l| l.name == link) {
            out.extend(
                l.collision
                    .iter()
                    .map(|c| (at * crate::model::urdf_pose(&c.origin), c)),
            );
        }
        for j in u
            .joints
            .iter()
            .filter(|j| j.parent.link == link && matches!(j.joint_type, urdf_rs::JointType::Fixed))
        {
            open.push((
                j.child.link.clone(),
                at * crate::model::urdf_pose(&j.origin),
            ));
        }
    }
    out
}

/// A guessed sole ([`Sole`]) from collision boxes and spheres posed in the foot's frame (their
/// footprints, ignoring their rotation about z).
fn sole_from_collisions(shapes: &[(Isometry3<f64>, &urdf_rs::Collision)]) -> Option<Sole> {
    let mut points = Vec::new();
    for (o, c) in shapes {
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

/// The sole of link `name`: from the collision boxes and spheres of it and of the links fixed
/// to it, else from its meshes in `dir`, with where it came from.
fn sole_of(
    u: &urdf_rs::Robot,
    name: &str,
    dir: Option<&std::path::Path>,
) -> Option<(Sole, &'static str)> {
    sole_from_collisions(&fixed_subtree(u, name))
        .map(|s| {
            (
                s,
                "from the collision boxes/spheres of the link and the links fixed to it",
            )
        })
        .or_else(|| {
            let link = u.links.iter().find(|l| l.name == name)?;
            sole_from_meshes(link, dir?)
        })
}

/// The foot frame and its sole for the deepest foot-named link `named`: that link with its
/// sole ([`sole_of`]), or, when it gives none and is fixed to its parent (a toe or heel
/// contact point), the link the last movable joint above it moves, if that one gives a sole
/// (the contact points fixed to it then make it). Else `named`, without a sole.
fn foot_guess<'a>(
    u: &'a urdf_rs::Robot,
    named: &'a str,
    dir: Option<&std::path::Path>,
) -> (&'a str, Option<(Sole, &'static str)>) {
    if let Some(sole) = sole_of(u, named, dir) {
        return (named, Some(sole));
    }
    let mut moved = named;
    while let Some(j) = u
        .joints
        .iter()
        .find(|j| j.child.link == moved && matches!(j.joint_type, urdf_rs::JointType::Fixed))
    {
        moved = j.parent.link.as_str();
    }
    match sole_of(u, moved, dir) {
        Some(sole) if moved != named => (moved, Some(sole)),
        _ => (named, None),
    }
}

/// The guessed start posture lowers the hips by this share of the leg's length (hip joint to
/// foot frame) below the straight-legged pose, the feet kept where they were and as they were
/// turned \[–\]: bent knees, away from the stretched leg's singularity and, on a knee whose
/// range ends at 0, from its limit. Without a map the keypoint route also holds the start
/// posture as its posture reference, so the bend is kept small. On the six shared clips
/// (`iktc retarget`, 2026-12-06), mean keypoint error over the clips, straight / 3 % / 8 %:
/// Leju Kuavo S45 16.1 / 14.0 / 14.1 cm (its knees' ranges end at 0), HighTorque Hi 12.5 /
/// 12.9 / 13.2 cm; the deepest sole 1.8 / 0.63 / 1.2 mm and 0.31 / 0.09 / 0.31 mm.
pub const CROUCH: f64 = 0.03;

/// The posture's solve starts with every leg joint this share of the way from 0 (clamped
/// into its range) to the middle of its range \[–\]: a knee whose range is one-sided starts
/// bent the way it bends (a straight leg gives the solve no direction to bend it).
const NUDGE: f64 = 0.3;

/// The posture's solve moves a joint by at most this per iteration \[rad\].
const MAX_STEP: f64 = 0.1;

/// A start posture for a floating biped whose feet frames are `feet` (see [`CROUCH`]): the
/// movable joints from the root to each foot that are not on both legs' paths (a waist below
/// the hips is held), solved by damped least squares for the foot's pose relative to the
/// base, each within its range. `None` when the URDF does not build, a leg has fewer than six
/// such joints (its foot's pose would be out of its reach), or the solve does not reach the
/// pose within 1 mm and 0.01 rad.
fn crouch_posture(text: &str, u: &urdf_rs::Robot, feet: &[&str]) -> Option<Vec<(String, f64)>> {
    use crate::model::{BaseKind, Kinematics, ModelOptions, Robot, State};
    let options = ModelOptions {
        base: BaseKind::Floating,
        ..ModelOptions::default()
    };
    let robot = Robot::from_urdf_str(text, &options).ok()?;
    let mut state = State::neutral(&robot);
    // Per leg: its foot frame and its joints (name, q index, v index, lower, upper, the link
    // the joint moves), foot first.
    type LegJoint = (String, usize, usize, f64, f64, String);
    let mut chains: Vec<(crate::model::FrameId, Vec<LegJoint>)> = Vec::new();
    for foot in feet {
        let (mut joints, mut link) = (Vec::new(), foot.to_string());
        while let Some(j) = u.joints.iter().find(|j| j.child.link == link) {
            if let Some(a) = robot.active_joints().find(|a| a.name == j.name) {
                let (iq, iv) = (
                    robot.joint_q_index(&a.name).ok()?,
                    robot.joint_v_index(&a.name).ok()?,
                );
                joints.push((
                    a.name.clone(),
                    iq,
                    iv,
                    a.limit.lower,
                    a.limit.upper,
                    j.child.link.clone(),
                ));
            }
            link = j.parent.link.clone();
        }
        chains.push((robot.frame_id(foot).ok()?, joints));
    }
    // A joint on both legs' paths (a waist below the hips) is the body's, not a leg's: held.
    let [(_, a), (_, b)] = chains.as_slice() else {
        return None;
    };
    let shared: Vec<String> = a
        .iter()
        .filter(|x| b.iter().any(|y| y.0 == x.0))
        .map(|x| x.0.clone())
        .collect();
    let mut legs = Vec::new();
    for (foot, mut joints) in chains {
        joints.retain(|j| !shared.contains(&j.0));
        // The hip: the link the leg's first joint from the body moves.
        let hip = robot.frame_id(&joints.last()?.5).ok()?;
        if joints.len() < 6 {
            return None;
        }
        legs.push((foot, joints, hip));
    }
    for (_, joints, _) in &legs {
        for (_, iq, _, lo, hi, _) in joints {
            state.q[*iq] = 0.0_f64.clamp(*lo, *hi);
        }
    }
    let mut kin = Kinematics::new(&robot, &state).ok()?;
    let mut targets = Vec::new();
    for (foot, _, hip) in &legs {
        let (f, h) = (
            kin.frame_pose(&robot, *foot).ok()?,
            kin.frame_pose(&robot, *hip).ok()?,
        );
        let leg = (f.translation.vector - h.translation.vector).norm();
        let mut t = f;
        t.translation.vector.z += CROUCH * leg;
        targets.push(t);
    }
    for (_, joints, _) in &legs {
        for (_, iq, _, lo, hi, _) in joints {
            let z = state.q[*iq];
            if lo.is_finite() && hi.is_finite() {
                state.q[*iq] = z + NUDGE * (0.5 * (lo + hi) - z);
            }
        }
    }
    let mut jac = DMatrix::zeros(6, robot.nv());
    for ((foot, joints, _), target) in legs.iter().zip(&targets) {
        let mut reached = false;
        for _ in 0..500 {
            kin.update(&robot, &state).ok()?;
            let pose = kin.frame_pose(&robot, *foot).ok()?;
            let ep = target.translation.vector - pose.translation.vector;
            let er = (target.rotation * pose.rotation.inverse()).scaled_axis();
            if ep.norm() < 1e-9 && er.norm() < 1e-9 {
                reached = true;
                break;
            }
            kin.frame_jacobian(&robot, *foot, &mut jac).ok()?;
            let j = DMatrix::from_fn(6, joints.len(), |r, c| jac[(r, joints[c].2)]);
            let e = DVector::from_iterator(6, ep.iter().chain(er.iter()).copied());
            let a = &j * j.transpose() + DMatrix::identity(6, 6) * 1e-6;
            let mut dq = j.transpose() * a.lu().solve(&e)?;
            // At most MAX_STEP per joint and iteration: near the straight leg's singularity a
            // full step overshoots into the joints' limits.
            let largest = dq.amax();
            if largest > MAX_STEP {
                dq *= MAX_STEP / largest;
            }
            for ((_, iq, _, lo, hi, _), d) in joints.iter().zip(dq.iter()) {
                state.q[*iq] = (state.q[*iq] + d).clamp(*lo, *hi);
            }
        }
        kin.update(&robot, &state).ok()?;
        let pose = kin.frame_pose(&robot, *foot).ok()?;
        let ep = (target.translation.vector - pose.translation.vector).norm();
        let er = (target.rotation * pose.rotation.inverse()).angle();
        if !(reached || (ep < 1e-3 && er < 1e-2)) {
            return None;
        }
    }
    let mut out = Vec::new();
    for (_, joints, _) in &legs {
        for (name, iq, ..) in joints.iter().rev() {
            // To 1 mrad, and + 0.0 writes −0.0 as 0.0.
            out.push((name.clone(), (state.q[*iq] * 1e3).round() / 1e3 + 0.0));
        }
    }
    Some(out)
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
    let hand_words = ["hand", "palm", "wrist", "end_effector", "eef"];
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
    let mut foot_frames: Vec<&str> = Vec::new();
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
                let (frame, sole) = foot_guess(&u, &link.name, dir);
                foot_frames.push(frame);
                out.push_str(&format!(
                    "[feet.{side}]\nframe = {} # guessed: {}\n",
                    quote(frame),
                    if frame == link.name {
                        format!("deepest link named like a foot on the {side}")
                    } else {
                        format!("the link `{}` (deepest named like a foot on the {side}) is fixed to", link.name)
                    }
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
    out.push_str("\n# Initial joint angles [rad] (joint = angle), e.g. bent knees for a humanoid.\n[posture]\n");
    match (foot_frames.len() == 2)
        .then(|| crouch_posture(text, &u, &foot_frames))
        .flatten()
    {
        Some(posture) => {
            out.push_str(&format!(
                "# guessed: the legs bent so that the hips sit {:.0} % of the leg's length lower than \
                 straight, the feet where and as they were\n",
                100.0 * CROUCH
            ));
            for (name, value) in posture {
                out.push_str(&format!("{} = {value:?}\n", quote(&name)));
            }
        }
        None if foot_frames.len() == 2 => out.push_str(
            "# not guessed: the legs' joints could not bend the knees with the feet in place\n",
        ),
        None => {}
    }
    out.push_str(
        "\n# Default narrowed ranges [rad] (joint = [lower, upper]).\n[narrow]\n\n\
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

    /// A biped whose feet are marked by contact spheres on links fixed below the ankle (toe and
    /// heel points, named like feet), and whose hands are end-effector links named by an arm
    /// index (`zarm_l7_…`), as Leju's Kuavo is described.
    fn contact_point_biped() -> String {
        let inertial = r#"<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>"#;
        let link = |n: &str| format!(r#"<link name="{n}">{inertial}</link>"#);
        let joint = |n: &str, kind: &str, parent: &str, child: &str, xyz: &str| {
            let limit = if kind == "revolute" {
                r#"<axis xyz="0 1 0"/><limit lower="-1" upper="1" velocity="5" effort="10"/>"#
            } else {
                ""
            };
            format!(
                r#"<joint name="{n}" type="{kind}"><origin xyz="{xyz}"/><parent link="{parent}"/><child link="{child}"/>{limit}</joint>"#
            )
        };
        let mut x = String::from(r#"<robot name="contact_biped"><link name="dummy_link"/>"#);
        x += &link("base_link");
        x += &joint("dummy_to_base", "fixed", "dummy_link", "base_link", "0 0 0");
        for (s, y) in [("l", 0.1), ("r", -0.1)] {
            for n in ["1", "6"] {
                x += &link(&format!("leg_{s}{n}_link"));
                x += &link(&format!("zarm_{s}{n}_link"));
            }
            x += &joint(
                &format!("leg_{s}1_joint"),
                "revolute",
                "base_link",
                &format!("leg_{s}1_link"),
                &format!("0 {y} -0.1"),
            );
            x += &joint(
                &format!("leg_{s}6_joint"),
                "revolute",
                &format!("leg_{s}1_link"),
                &format!("leg_{s}6_link"),
                "0 0 -0.6",
            );
            x += &joint(
                &format!("zarm_{s}1_joint"),
                "revolute",
                "base_link",
                &format!("zarm_{s}1_link"),
                &format!("0 {} 0.4", 2.0 * y),
            );
            x += &joint(
                &format!("zarm_{s}6_joint"),
                "revolute",
                &format!("zarm_{s}1_link"),
                &format!("zarm_{s}6_link"),
                "0 0 -0.25",
            );
            x += &format!(r#"<link name="zarm_{s}7_end_effector"/>"#);
            x += &joint(
                &format!("zarm_{s}7_end_joint"),
                "fixed",
                &format!("zarm_{s}6_link"),
                &format!("zarm_{s}7_end_effector"),
                "0 0 -0.2",
            );
            // Contact points 0.06 m below the ankle, spheres of 5 mm: x from −0.07 to 0.17,
            // y ±0.05 about the foot's centre line.
            for (name, px, py) in [
                ("foot_toe", 0.17, 0.0),
                ("foot_heel", -0.07, 0.0),
                ("l_foot_toe", 0.17, 0.05),
                ("r_foot_heel", -0.07, -0.05),
            ] {
                let n = if name.starts_with("foot") {
                    format!("{s}_{name}")
                } else {
                    format!("{s}{name}")
                };
                x += &format!(
                    r#"<link name="{n}"><collision><geometry><sphere radius="0.005"/></geometry></collision></link>"#
                );
                x += &joint(
                    &format!("{n}_joint"),
                    "fixed",
                    &format!("leg_{s}6_link"),
                    &n,
                    &format!("{px} {py} -0.06"),
                );
            }
        }
        x + "</robot>"
    }

    #[test]
    fn a_foot_marked_by_contact_points_is_the_ankle_link_with_the_points_sole() {
        let toml = init_profile_toml(&contact_point_biped(), "b.urdf").unwrap();
        for side in ["l", "r"] {
            // The deepest foot-named link is a contact point fixed to the ankle: the foot is the
            // ankle link, and its sole the points' rectangle, 5 mm (the spheres) lower.
            let name = if side == "l" { "left" } else { "right" };
            let block = toml.split(&format!("[feet.{name}]")).nth(1).unwrap();
            assert!(
                block.starts_with(&format!("\nframe = \"leg_{side}6_link\"")),
                "{block}"
            );
            assert!(block.contains("ankle_height = 0.065 "), "{block}");
            assert!(
                block.contains("sole = { length = 0.24, width = 0.1, offset_x = 0.05 }"),
                "{block}"
            );
        }
        assert!(toml.contains("base = \"floating\""));
        // The hands: end effectors, their sides from the arm index (`zarm_l7_…`).
        assert!(
            toml.contains("left_hand = \"zarm_l7_end_effector\""),
            "{toml}"
        );
        assert!(
            toml.contains("right_hand = \"zarm_r7_end_effector\""),
            "{toml}"
        );
    }

    #[test]
    fn sides_are_read_from_the_usual_tags() {
        for (name, side) in [
            ("left_ankle_roll_link", Some(Side::Left)),
            ("l_foot", Some(Side::Left)),
            ("foot_l", Some(Side::Left)),
            ("leg_l6_link", Some(Side::Left)),
            ("zarm_r7_end_effector", Some(Side::Right)),
            ("arm_r_elbow", Some(Side::Right)),
            ("ankle_link", None),
            ("base_link", None),
            ("torso_l", Some(Side::Left)),
        ] {
            assert!(side_of(name) == side, "{name}");
        }
    }

    /// The guessed posture of G1 and JVRC-1, checked by their kinematics: within every range,
    /// knees bent, each foot as it was turned at the zero posture and `CROUCH` of its leg's
    /// length higher relative to the base.
    #[test]
    fn the_guessed_posture_bends_the_knees_with_the_feet_level() {
        use crate::model::{BaseKind, Kinematics, ModelOptions, Robot, State, G1_URDF, JVRC1_URDF};
        for (urdf, feet, hips, knees) in [
            (
                G1_URDF,
                ["left_ankle_roll_link", "right_ankle_roll_link"],
                ["left_hip_pitch_link", "right_hip_pitch_link"],
                ["left_knee_joint", "right_knee_joint"],
            ),
            (
                JVRC1_URDF,
                ["l_ankle", "r_ankle"],
                ["L_HIP_P_S", "R_HIP_P_S"],
                ["L_KNEE", "R_KNEE"],
            ),
        ] {
            let toml = init_profile_toml(urdf, "r.urdf").unwrap();
            let block = toml
                .split("[posture]\n")
                .nth(1)
                .unwrap()
                .split("\n\n")
                .next()
                .unwrap();
            assert!(block.starts_with("# guessed: the legs bent"), "{block}");
            let values: Vec<(String, f64)> = block
                .lines()
                .skip(1)
                .map(|l| {
                    let (k, v) = l.split_once(" = ").unwrap();
                    (k.trim_matches('"').to_string(), v.parse().unwrap())
                })
                .collect();
            assert_eq!(values.len(), 12, "{block}");
            let options = ModelOptions {
                base: BaseKind::Floating,
                ..ModelOptions::default()
            };
            let robot = Robot::from_urdf_str(urdf, &options).unwrap();
            let zero = State::neutral(&robot);
            let mut bent = zero.clone();
            for (name, v) in &values {
                let j = robot.active_joints().find(|j| j.name == *name).unwrap();
                assert!(j.limit.lower <= *v && *v <= j.limit.upper, "{name} = {v}");
                bent.set_joint(&robot, name, *v).unwrap();
            }
            for k in knees {
                assert!(bent.joint(&robot, k).unwrap() > 0.3, "{k}");
            }
            let (k0, k1) = (
                Kinematics::new(&robot, &zero).unwrap(),
                Kinematics::new(&robot, &bent).unwrap(),
            );
            for (foot, hip) in feet.iter().zip(hips) {
                let (f, h) = (robot.frame_id(foot).unwrap(), robot.frame_id(hip).unwrap());
                let (a, b) = (
                    k0.frame_pose(&robot, f).unwrap(),
                    k1.frame_pose(&robot, f).unwrap(),
                );
                let leg = (a.translation.vector
                    - k0.frame_pose(&robot, h).unwrap().translation.vector)
                    .norm();
                let rise = b.translation.vector - a.translation.vector;
                // The joints are written to 1 mrad: a leg of 0.6–0.9 m moves its foot by
                // under 3 mm and turns it by under 6 mrad for six such roundings.
                assert!(
                    (rise.z - CROUCH * leg).abs() < 3e-3 && rise.xy().norm() < 3e-3,
                    "{foot}: {rise:?} {leg}"
                );
                assert!((a.rotation * b.rotation.inverse()).angle() < 6e-3, "{foot}");
            }
        }
        // Legs of two joints cannot keep a foot's pose: no posture, said so.
        let toml = init_profile_toml(&contact_point_biped(), "b.urdf").unwrap();
        assert!(toml.contains("[posture]\n# not guessed"), "{toml}");
    }
}
