//! A starting profile guessed from a URDF (`iktc profile init`).
//!
//! The URDF is first built as a model ([`Robot::from_urdf_str`](crate::model::Robot)): a URDF
//! the model rejects gets no profile. Then, each guess marked `# guessed` in the written TOML
//! (and each part given instead, marked `# given`, see [`InitOptions`]):
//! * feet, hands, torso, head from the tree's shape at q = 0 (see [`MIN_DROP`](super::MIN_DROP),
//!   [`MIN_LEG_JOINTS`](super::MIN_LEG_JOINTS), [`MIDLINE`](super::MIDLINE),
//!   [`MIN_ARM_JOINTS`](super::MIN_ARM_JOINTS)):
//!   the two leg chains ending lowest, sides from the lateral (y) coordinate, +y left; the
//!   arm chains' far ends; where they meet; the chain going up; when the shape gives no pair of
//!   feet or hands, links named like them (`foot`, `ankle`, `sole`, `toe`; `hand`, `palm`,
//!   `wrist`, …, the side from a `left`/`l_`/`_l`/`_l<digit>` or `right`/… tag);
//! * a hand frame: a link fixed to the arm's last link named like a hand, else that link; an
//!   arm of at most [`FOREARM_JOINTS`] joints ends at a forearm, and a frame (key `frame`) is
//!   added at its far end (the farthest point of its geometry from the elbow, else twice its
//!   centre of mass);
//! * soles and ankle heights from the feet's collision, else visual geometry (boxes, spheres,
//!   cylinders, meshes; the points within [`SOLE_BAND`](super::SOLE_BAND) of the lowest); a
//!   sole narrower than [`NARROW_SOLE`](super::NARROW_SOLE) or longer than
//!   [`LONG_SOLE`](super::LONG_SOLE) gets a comment questioning it;
//! * pelvis: the base (root link), or a link fixed to it named like a pelvis;
//! * base: floating when both feet were found, else fixed;
//! * posture: for a floating biped, the legs bent so that the hips sit [`CROUCH`] of the leg's
//!   length lower, the feet level where they were (as much of the foot's pose as the leg's
//!   joints can hold);
//! * locks: movable joints whose names contain `finger`, `thumb`, `index`, `middle`, `ring`,
//!   `little` or `pinky`, as one glob pattern each.

use crate::model::RobotFiles;
use nalgebra::{DMatrix, DVector, Vector3};

use super::shape::{find_parts, named_frame, named_like, Parts, Tree};
use super::sole::{link_points, questioned, sole_of, SoleGuess};
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

/// The foot frame and its sole for the foot link `named` (index into `t`): that link with its
/// sole ([`sole_of`]), or, when it gives none and is fixed to its parent (a toe or heel
/// contact point), the link the last movable joint above it moves, if that one gives a sole
/// (the contact points fixed to it then make it). Else `named`, without a sole.
fn foot_guess(
    u: &urdf_rs::Robot,
    t: &Tree,
    named: usize,
    dir: Option<&std::path::Path>,
) -> (usize, Option<(SoleGuess, &'static str)>) {
    if let Some(sole) = sole_of(u, t, named, dir) {
        return (named, Some(sole));
    }
    let mut moved = named;
    while let Some((p, false)) = t.parent[moved] {
        moved = p;
    }
    match sole_of(u, t, moved, dir) {
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
pub(crate) const CROUCH: f64 = 0.03;

/// The posture's solve starts with every leg joint this share of the way from 0 (clamped
/// into its range) to the middle of its range \[–\]: a knee whose range is one-sided starts
/// bent the way it bends (a straight leg gives the solve no direction to bend it).
const NUDGE: f64 = 0.3;

/// The posture's solve moves a joint by at most this per iteration \[rad\].
const MAX_STEP: f64 = 0.1;

/// The rows of a foot's pose error (position x, y, z, then rotation about x, y, z in the
/// base's frame) a leg of `joints` movable joints can hold: all six with six or more joints;
/// with five, all but the turn about the vertical (the foot kept level); with three or four,
/// the position; none with fewer.
fn foot_rows(joints: usize) -> &'static [usize] {
    match joints {
        6.. => &[0, 1, 2, 3, 4, 5],
        5 => &[0, 1, 2, 3, 4],
        3 | 4 => &[0, 1, 2],
        _ => &[],
    }
}

/// The position and rotation errors `ep`, `er` with the rows a leg of `joints` joints cannot
/// hold ([`foot_rows`]) set to zero.
fn held(joints: usize, ep: Vector3<f64>, er: Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let rows = foot_rows(joints);
    let keep = |v: Vector3<f64>, first: usize| {
        Vector3::from_fn(|i, _| {
            if rows.contains(&(first + i)) {
                v[i]
            } else {
                0.0
            }
        })
    };
    (keep(ep, 0), keep(er, 3))
}

/// A leg's joint: name, q index, v index, lower and upper bound, the link the joint moves.
type LegJoint = (String, usize, usize, f64, f64, String);

/// Per leg: its foot frame and its movable joints from the foot up to the root, foot first.
fn leg_chains(
    robot: &crate::model::Robot,
    u: &urdf_rs::Robot,
    feet: &[&str],
) -> Option<Vec<(crate::model::FrameId, Vec<LegJoint>)>> {
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
    Some(chains)
}

/// Solves one leg's joints by damped least squares (at most 500 iterations) for the held rows
/// of `foot`'s `target` pose; `None` when the result is not within 1 mm and 0.01 rad.
fn solve_leg(
    robot: &crate::model::Robot,
    kin: &mut crate::model::Kinematics,
    state: &mut crate::model::State,
    jac: &mut DMatrix<f64>,
    foot: crate::model::FrameId,
    joints: &[LegJoint],
    target: &nalgebra::Isometry3<f64>,
) -> Option<()> {
    let mut reached = false;
    for _ in 0..500 {
        kin.update(robot, state).ok()?;
        let pose = kin.frame_pose(robot, foot).ok()?;
        let ep = target.translation.vector - pose.translation.vector;
        let er = (target.rotation * pose.rotation.inverse()).scaled_axis();
        let (ep, er) = held(joints.len(), ep, er);
        if ep.norm() < 1e-9 && er.norm() < 1e-9 {
            reached = true;
            break;
        }
        kin.frame_jacobian(robot, foot, jac).ok()?;
        let rows = foot_rows(joints.len());
        let m = rows.len();
        let j = DMatrix::from_fn(m, joints.len(), |r, c| jac[(rows[r], joints[c].2)]);
        let full: Vec<f64> = ep.iter().chain(er.iter()).copied().collect();
        let e = DVector::from_iterator(m, rows.iter().map(|r| full[*r]));
        let a = &j * j.transpose() + DMatrix::identity(m, m) * 1e-6;
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
    kin.update(robot, state).ok()?;
    let pose = kin.frame_pose(robot, foot).ok()?;
    let (ep, er) = held(
        joints.len(),
        target.translation.vector - pose.translation.vector,
        (target.rotation * pose.rotation.inverse()).scaled_axis(),
    );
    if !(reached || (ep.norm() < 1e-3 && er.norm() < 1e-2)) {
        return None;
    }
    Some(())
}

/// A start posture for a floating biped whose feet frames are `feet` (see [`CROUCH`]): the
/// movable joints from the root to each foot that are not on both legs' paths (a waist below
/// the hips is held), solved by damped least squares for the rows of the foot's pose relative
/// to the base that the leg can hold ([`foot_rows`]), each joint within its range. `None` when
/// the URDF does not build, a leg has fewer than three such joints, or the solve does not
/// reach the held rows within 1 mm and 0.01 rad.
fn crouch_posture(
    text: &str,
    dir: Option<&std::path::Path>,
    u: &urdf_rs::Robot,
    feet: &[&str],
) -> Option<Vec<(String, f64)>> {
    use crate::model::{BaseKind, Kinematics, ModelOptions, Robot, State};
    let options = ModelOptions {
        base: BaseKind::Floating,
        ..ModelOptions::default()
    };
    let robot = Robot::from_description_str(text, dir, &options).ok()?;
    let mut state = State::neutral(&robot);
    let chains = leg_chains(&robot, u, feet)?;
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
        if foot_rows(joints.len()).is_empty() {
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
        solve_leg(
            &robot, &mut kin, &mut state, &mut jac, *foot, joints, target,
        )?;
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

/// An arm of at most this many movable joints from the torso ends at a forearm (three at the
/// shoulder, one at the elbow), not a hand \[–\]: a frame is added at its far end.
pub(crate) const FOREARM_JOINTS: usize = 4;

/// The far end of the forearm link `i` of `t`, in its frame \[m\], and where it came from:
/// the point of its visual (else collision) geometry (with the links fixed to it) farthest
/// from its origin (the elbow), else twice its centre of mass (the end of a uniform rod from
/// the elbow). `None` when neither reaches [`MIN_FOREARM`].
fn hand_point(
    u: &urdf_rs::Robot,
    t: &Tree,
    i: usize,
    dir: Option<&std::path::Path>,
) -> Option<(Vector3<f64>, &'static str)> {
    let far = |collision| -> Option<Vector3<f64>> {
        link_points(u, t, i, dir, collision)
            .into_iter()
            .max_by(|a, b| a.norm().total_cmp(&b.norm()))
            .filter(|b| b.norm() >= MIN_FOREARM)
    };
    let link = u.links.iter().find(|l| l.name == t.names[i])?;
    far(false)
        .map(|p| (p, "the farthest point of its visual geometry"))
        .or_else(|| far(true).map(|p| (p, "the farthest point of its collision geometry")))
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

/// Parts of the robot given to [`init_profile_toml_with`] instead of guessed (`iktc profile
/// init --feet … --hands … --head … --torso … --pelvis … --sole …`): link names of the URDF.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InitOptions {
    /// The foot links, `[left, right]`.
    pub feet: Option<[String; 2]>,
    /// The hand links (or frames fixed to them), `[left, right]`.
    pub hands: Option<[String; 2]>,
    /// The head link.
    pub head: Option<String>,
    /// The torso link.
    pub torso: Option<String>,
    /// The pelvis link.
    pub pelvis: Option<String>,
    /// The sole of both feet \[m\] (the ankle height is still guessed from the geometry).
    pub sole: Option<super::Sole>,
}

/// Writes a starting profile for the URDF `text`, whose path relative to where the profile
/// will be written is `urdf_path`. Every guessed value is marked `# guessed`; the result parses
/// as a [`RobotProfile`](super::RobotProfile) (keys it could not guess are left out or
/// commented).
///
/// Errors: a URDF the model loader rejects ([`Robot::from_urdf_str`](crate::model::Robot)'s
/// error), or one without a single root link.
pub fn init_profile_toml(text: &str, urdf_path: &str) -> Result<String> {
    init_profile_toml_at(text, urdf_path, None)
}

/// [`init_profile_toml`] for a URDF in the folder `dir`: feet without primitive shapes have
/// their soles guessed from their meshes there (see the module documentation).
pub fn init_profile_toml_at(
    text: &str,
    urdf_path: &str,
    dir: Option<&std::path::Path>,
) -> Result<String> {
    init_profile_toml_with(text, urdf_path, dir, &InitOptions::default())
}

/// A part's link (index into the tree) and why it was chosen.
type Chosen = (usize, String);

/// The link called `name` in `t`, or an error naming the flag's key and the links.
fn given(t: &Tree, key: &str, name: &str) -> Result<usize> {
    t.index(name).ok_or_else(|| Error::UnknownName {
        kind: "link",
        name: format!("{name}` (given for `{key}`"),
        valid: t.names.clone(),
    })
}

/// Checks a given sole: length and width finite and > 0, offset finite \[m\].
fn check_sole(s: &super::Sole) -> Result<()> {
    let ok = s.length.is_finite() && s.length > 0.0 && s.width.is_finite() && s.width > 0.0;
    if ok && s.offset_x.is_finite() {
        return Ok(());
    }
    Err(Error::InvalidSetting {
        name: "sole".into(),
        value: format!("{}, {}, {}", s.length, s.width, s.offset_x),
        expected: "a length and width > 0 and a finite offset_x [m]".into(),
    })
}

/// [`init_profile_toml_at`] with the parts in `options` given instead of guessed (each link
/// name checked against the URDF).
pub fn init_profile_toml_with(
    text: &str,
    urdf_path: &str,
    dir: Option<&std::path::Path>,
    options: &InitOptions,
) -> Result<String> {
    // The model first: a URDF it rejects gets no profile.
    let robot = crate::model::Robot::from_description_str(
        text,
        dir,
        &crate::model::ModelOptions::default(),
    )?;
    let u = crate::model::read_description(text, dir, &crate::resources::ReadLimits::default())?;
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
    if let Some(s) = &options.sole {
        check_sole(s)?;
    }
    let t = Tree::new(&u, &root.name);
    let parts = find_parts(&t);
    let guess = Guessed::new(&t, &parts, options, dir, &u)?;
    Ok(write_profile(
        text, &robot, &u, &t, &guess, options, urdf_path, dir,
    ))
}

/// Everything guessed or given, ready to write.
struct Guessed {
    feet: Option<[Chosen; 2]>,
    hands: [Option<Chosen>; 2],
    /// Per side, a frame to add at the far end of a bare forearm: its parent link, its
    /// position there \[m\], and where that came from.
    hand_ends: [Option<(usize, Vector3<f64>, &'static str)>; 2],
    torso: Option<Chosen>,
    head: Option<Chosen>,
    pelvis: Chosen,
}

/// A link fixed this near to another's origin (\[m\]) and turned this little from it (\[rad\])
/// is an alias of its frame.
const ALIAS: f64 = 1e-6;

/// Whether links `a` and `b` of `t` are posed alike (see [`ALIAS`]).
fn alias(t: &Tree, a: usize, b: usize) -> bool {
    let d = t.pose[a].inverse() * t.pose[b];
    d.translation.vector.norm() < ALIAS && d.rotation.angle() < ALIAS
}

/// Link words naming a foot frame.
const FOOT_WORDS: [&str; 3] = ["foot", "ankle", "sole"];

/// Link words naming a hand frame.
const HAND_WORDS: [&str; 7] = ["hand", "palm", "wrist", "end_effector", "eef", "tcp", "tip"];

/// A frame to add at the far end of a bare forearm: its parent link, its position there \[m\],
/// and where that came from.
type HandEnd = (usize, Vector3<f64>, &'static str);

/// Per side, the hand frame, or the frame to add at a bare forearm's far end.
type HandGuess = ([Option<Chosen>; 2], [Option<HandEnd>; 2]);

/// The feet: given by the flags, else the leg chains' lowest ends (or a link named like a
/// foot at such an end's origin), else the deepest links named like a foot on each side.
fn guess_feet(
    t: &Tree,
    parts: &Parts,
    o: &InitOptions,
    dir: Option<&std::path::Path>,
    u: &urdf_rs::Robot,
    links: &[TreeLink],
) -> Result<Option<[Chosen; 2]>> {
    let by_name = |l: Option<&TreeLink>| l.and_then(|l| t.index(&l.name));
    let side_name = ["left", "right"];
    Ok(match &o.feet {
        Some([l, r]) => Some([
            (given(t, "feet.left.frame", l)?, "given".to_string()),
            (given(t, "feet.right.frame", r)?, "given".to_string()),
        ]),
        None => {
            match parts.feet {
                Some(f) => Some(f.map(|i| {
                    // A link named like a foot at the end's own origin (an alias of its
                    // frame), not a contact point fixed away from it.
                    let frame = Some(named_frame(t, i, &FOOT_WORDS))
                        .filter(|f| alias(t, *f, i))
                        .unwrap_or(i);
                    let why = format!(
                        "the lowest end of a leg chain at q = 0, y = {:+.3} m in the base's frame",
                        t.pos(i).y
                    );
                    if frame == i {
                        (i, why)
                    } else {
                        (
                            frame,
                            format!("named like a foot, fixed to {} ({why})", t.names[i]),
                        )
                    }
                })),
                None => {
                    let words = [FOOT_WORDS[0], FOOT_WORDS[1], FOOT_WORDS[2], "toe"];
                    let l = by_name(deepest(links, &words, Some(Side::Left)));
                    let r = by_name(deepest(links, &words, Some(Side::Right)));
                    l.zip(r).map(|(l, r)| {
                    [(l, 0), (r, 1)].map(|(i, s)| {
                        let (frame, _) = foot_guess(u, t, i, dir);
                        let why = if frame == i {
                            format!("deepest link named like a foot on the {}", side_name[s])
                        } else {
                            format!("the link `{}` (deepest named like a foot on the {}) is fixed to", t.names[i], side_name[s])
                        };
                        (frame, why)
                    })
                })
                }
            }
        }
    })
}

/// Per side, the hand frame or, on a bare forearm, the frame to add at its far end (parent
/// link, position \[m\], source): given by the flags, else the arm chains' far ends, else the
/// deepest links named like a hand (or a forearm).
fn guess_hands(
    t: &Tree,
    parts: &Parts,
    o: &InitOptions,
    dir: Option<&std::path::Path>,
    u: &urdf_rs::Robot,
    links: &[TreeLink],
) -> Result<HandGuess> {
    let by_name = |l: Option<&TreeLink>| l.and_then(|l| t.index(&l.name));
    let side_name = ["left", "right"];
    let mut hands: [Option<Chosen>; 2] = [None, None];
    let mut hand_ends = [None, None];
    match (&o.hands, parts.hands) {
        (Some([l, r]), _) => {
            hands = [
                Some((given(t, "frames.left_hand", l)?, "given".to_string())),
                Some((given(t, "frames.right_hand", r)?, "given".to_string())),
            ];
        }
        (None, Some(h)) => {
            for s in 0..2 {
                let frame = named_frame(t, h[s], &HAND_WORDS);
                let bare = parts.arm_joints[s] <= FOREARM_JOINTS
                    && !named_like(&t.names[frame], &HAND_WORDS);
                match bare.then(|| hand_point(u, t, h[s], dir)).flatten() {
                    Some((xyz, why)) => hand_ends[s] = Some((h[s], xyz, why)),
                    None => {
                        hands[s] = Some((
                            frame,
                            format!(
                                "the far end of the arm chain on the {} ({} joints from the torso)",
                                side_name[s], parts.arm_joints[s]
                            ),
                        ));
                    }
                }
            }
        }
        (None, None) => {
            for (s, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                if let Some(i) = by_name(deepest(links, &HAND_WORDS, Some(side))) {
                    hands[s] = Some((i, "a link named like it".to_string()));
                    continue;
                }
                let forearm = ["elbow", "forearm", "lower_arm", "lowerarm"];
                if let Some(i) = by_name(deepest(links, &forearm, Some(side))) {
                    hand_ends[s] = hand_point(u, t, i, dir).map(|(xyz, why)| (i, xyz, why));
                }
            }
        }
    }
    Ok((hands, hand_ends))
}

/// The pelvis: given by the flag, else a link named like a pelvis fixed to the base, else the
/// base.
fn guess_pelvis(t: &Tree, o: &InitOptions) -> Result<Chosen> {
    Ok(match &o.pelvis {
        Some(n) => (given(t, "frames.pelvis", n)?, "given".to_string()),
        None => t
            .fixed_below(0)
            .into_iter()
            .find(|i| named_like(&t.names[*i], &["pelvis"]))
            .map(|i| {
                let why = if i == 0 {
                    "the base (the root link)"
                } else {
                    "named like a pelvis, fixed to the base"
                };
                (i, why.to_string())
            })
            .unwrap_or((0, "the base (the root link)".to_string())),
    })
}

impl Guessed {
    fn new(
        t: &Tree,
        parts: &Parts,
        o: &InitOptions,
        dir: Option<&std::path::Path>,
        u: &urdf_rs::Robot,
    ) -> Result<Guessed> {
        let links: Vec<TreeLink> = t
            .names
            .iter()
            .enumerate()
            .map(|(i, n)| TreeLink {
                name: n.clone(),
                lower: n.to_lowercase(),
                depth: depth(t, i),
            })
            .collect();
        let by_name = |l: Option<&TreeLink>| l.and_then(|l| t.index(&l.name));
        let feet = guess_feet(t, parts, o, dir, u, &links)?;
        let (hands, hand_ends) = guess_hands(t, parts, o, dir, u, &links)?;
        let pick_part = |key: &str,
                         given_name: &Option<String>,
                         shape: Option<usize>,
                         what: &str,
                         words: &[&str]|
         -> Result<Option<Chosen>> {
            Ok(match given_name {
                Some(n) => Some((given(t, key, n)?, "given".to_string())),
                None => match shape {
                    Some(i) => Some((i, what.to_string())),
                    None => by_name(pick(&links, words, None, true))
                        .map(|i| (i, "a link named like it".to_string())),
                },
            })
        };
        let torso = pick_part(
            "frames.torso",
            &o.torso,
            parts.torso,
            "the link where the arm chains meet",
            &["torso", "chest", "trunk"],
        )?;
        let head = pick_part(
            "frames.head",
            &o.head,
            parts.head,
            "the end of the chain going up from the torso (or the highest link fixed to it)",
            &["head", "neck"],
        )?;
        let pelvis = guess_pelvis(t, o)?;
        Ok(Guessed {
            feet,
            hands,
            hand_ends,
            torso,
            head,
            pelvis,
        })
    }
}

/// The depth of link `i` in `t` (links from the root).
fn depth(t: &Tree, i: usize) -> usize {
    let (mut d, mut j) = (0, i);
    while let Some((p, _)) = t.parent[j] {
        d += 1;
        j = p;
    }
    d
}

/// `# given` or `# guessed: why`.
fn mark(why: &str) -> String {
    if why == "given" {
        "# given".to_string()
    } else {
        format!("# guessed: {why}")
    }
}

/// A foot's sole length, width, forward offset and ankle height \[m\], and where they came from.
type FootGeometry = (f64, f64, f64, f64, String);

/// The `[feet.*]` tables of `g` (with their soles), and the foot frames.
fn write_feet(
    out: &mut String,
    u: &urdf_rs::Robot,
    t: &Tree,
    g: &Guessed,
    o: &InitOptions,
    dir: Option<&std::path::Path>,
) -> Vec<String> {
    let Some(feet) = &g.feet else {
        out.push_str(
            "# No pair of feet found (two leg chains ending below the base, nor links named \
             foot/ankle/sole/toe with a left/right tag):\n\
             # add [feet.left] and [feet.right] (frame, ankle_height, sole) for a standing robot, \
             or pass --feet LEFT,RIGHT.\n\n",
        );
        return Vec::new();
    };
    let both = both_feet_geometry(u, t, feet, dir);
    let mut frames = Vec::new();
    for (side, (i, why)) in ["left", "right"].iter().zip(feet) {
        frames.push(t.names[*i].clone());
        out.push_str(&format!(
            "[feet.{side}]\nframe = {} {}\n",
            quote(&t.names[*i]),
            mark(why)
        ));
        let (ankle, ankle_why) = match &both {
            Some((.., a, why)) => (tenth_mm(*a), why.clone()),
            None => (
                0.1,
                "PLACEHOLDER, no geometry below the link: measure the robot".to_string(),
            ),
        };
        let (len, wid, off, sole_why) = match (&o.sole, &both) {
            (Some(s), _) => (s.length, s.width, s.offset_x, "given".to_string()),
            (None, Some((a, b, c, _, why))) => {
                (tenth_mm(*a), tenth_mm(*b), tenth_mm(*c), why.clone())
            }
            (None, None) => (0.2, 0.1, 0.0, ankle_why.clone()),
        };
        out.push_str(&format!(
            "ankle_height = {ankle:?} # guessed: {ankle_why}\n"
        ));
        if o.sole.is_none() {
            if let Some(q) = questioned(len, wid) {
                out.push_str(&q);
            }
        }
        out.push_str(&format!(
            "sole = {{ length = {len:?}, width = {wid:?}, offset_x = {off:?} }} {}\n\n",
            mark(&sole_why)
        ));
    }
    frames
}

/// The sole and ankle height the profile gives both feet: each foot's geometry from its body
/// (an alias fixed at the foot link's origin gives the sole of the whole foot body); a foot
/// without geometry takes the other's, and two that differ take their mean.
fn both_feet_geometry(
    u: &urdf_rs::Robot,
    t: &Tree,
    feet: &[(usize, String)],
    dir: Option<&std::path::Path>,
) -> Option<FootGeometry> {
    let geometry: Vec<Option<FootGeometry>> = feet
        .iter()
        .map(|(i, _)| {
            let mut body = *i;
            while let Some((p, false)) = t.parent[body] {
                if !alias(t, p, *i) {
                    break;
                }
                body = p;
            }
            sole_of(u, t, body, dir).map(|((a, b, c, h), why)| (a, b, c, h, why.to_string()))
        })
        .collect();
    match (&geometry[0], &geometry[1]) {
        (Some(l), Some(r)) if (l.0, l.1, l.2, l.3) == (r.0, r.1, r.2, r.3) => Some(l.clone()),
        (Some(l), Some(r)) => Some((
            0.5 * (l.0 + r.0),
            0.5 * (l.1 + r.1),
            0.5 * (l.2 + r.2),
            0.5 * (l.3 + r.3),
            format!(
                "the mean of both feet's geometry (left {:.4} x {:.4} m, right {:.4} x {:.4} m)",
                l.0, l.1, r.0, r.1
            ),
        )),
        (Some(g), None) | (None, Some(g)) => Some((
            g.0,
            g.1,
            g.2,
            g.3,
            format!("{} (one foot's: the other has no geometry)", g.4),
        )),
        (None, None) => None,
    }
}

/// The profile's header: its name and URDF, and the base (floating when two feet were found).
fn write_header(out: &mut String, u: &urdf_rs::Robot, g: &Guessed, urdf_path: &str) {
    let name = if u.name.is_empty() { "robot" } else { &u.name };
    out.push_str(&format!(
        "# Robot profile of `{name}`, written by `iktc profile init`: check every value marked\n\
         # `# guessed` (and the comments) before use.\nname = {}\nurdf = {}\n",
        quote(name),
        quote(urdf_path)
    ));
    out.push_str(&format!(
        "base = \"{}\" # guessed: {}\n",
        if g.feet.is_some() {
            "floating"
        } else {
            "fixed"
        },
        if g.feet.is_some() {
            "two feet were found"
        } else {
            "no pair of feet was found"
        }
    ));
}

/// A `[[lock]]` at 0 for each movable joint named like a finger.
fn write_finger_locks(out: &mut String, u: &urdf_rs::Robot) {
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
}

/// The profile's text (see [`init_profile_toml_with`]).
#[allow(clippy::too_many_arguments)]
fn write_profile(
    text: &str,
    robot: &crate::model::Robot,
    u: &urdf_rs::Robot,
    t: &Tree,
    g: &Guessed,
    o: &InitOptions,
    urdf_path: &str,
    dir: Option<&std::path::Path>,
) -> String {
    let mut out = String::new();
    write_header(&mut out, u, g, urdf_path);
    write_finger_locks(&mut out, u);
    out.push('\n');
    let foot_frames = write_feet(&mut out, u, t, g, o, dir);
    for (key, end) in ["left_hand", "right_hand"].iter().zip(&g.hand_ends) {
        if let Some((parent, xyz, why)) = end {
            out.push_str(&format!(
                "[[frame]] # guessed: no hand link; the far end of the forearm ({why})\n\
                 name = {}\nparent = {}\nxyz = [{:?}, {:?}, {:?}]\n\n",
                quote(key),
                quote(&t.names[*parent]),
                tenth_mm(xyz.x),
                tenth_mm(xyz.y),
                tenth_mm(xyz.z),
            ));
        }
    }
    out.push_str("[frames]\n");
    let (p, why) = &g.pelvis;
    out.push_str(&format!("pelvis = {} {}\n", quote(&t.names[*p]), mark(why)));
    for (key, found, end) in [
        ("torso", &g.torso, &None),
        ("head", &g.head, &None),
        ("left_hand", &g.hands[0], &g.hand_ends[0]),
        ("right_hand", &g.hands[1], &g.hand_ends[1]),
    ] {
        match (found, end) {
            (Some((i, why)), _) => {
                out.push_str(&format!("{key} = {} {}\n", quote(&t.names[*i]), mark(why)))
            }
            (None, Some((parent, _, _))) => out.push_str(&format!(
                "{key} = {} # guessed: the frame added at the end of `{}` above\n",
                quote(key),
                t.names[*parent]
            )),
            (None, None) => out.push_str(&format!(
                "# {key} = \"...\" # not found: pass --{}\n",
                match key {
                    "left_hand" | "right_hand" => "hands LEFT,RIGHT",
                    k => k,
                }
            )),
        }
    }
    write_posture(&mut out, text, dir, u, &foot_frames);
    write_velocity(&mut out, robot);
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
    out
}

/// Velocity limit written by `profile init` for the joints whose file gives none \[rad/s\]:
/// about G1's knee (20 rad/s in its URDF; its other joints 22–37 rad/s, H1's 9–23 rad/s).
/// With the profile's default ratio its acceleration limit is 200 rad/s².
pub const GUESSED_VELOCITY: f64 = 20.0;

/// The `[velocity]` table when some movable joint of `robot` (built from the file with the
/// default options) has no velocity limit (MJCF never gives one): `default =
/// GUESSED_VELOCITY`, marked as guessed and naming how many joints it covers. Nothing when
/// every joint has one.
fn write_velocity(out: &mut String, robot: &crate::model::Robot) {
    let unlimited: Vec<&str> = robot
        .active_joints()
        .filter(|j| !j.limit.velocity.is_finite())
        .map(|j| j.name.as_str())
        .collect();
    if unlimited.is_empty() {
        return;
    }
    out.push_str(&format!(
        "\n# Velocity limits [rad/s] of the joints the file gives none (velocity.limits = {{ joint = limit }}\n\
         # for each joint); the acceleration limits follow (acceleration.per_velocity).\n\
         [velocity]\ndefault = {GUESSED_VELOCITY:.1} # guessed: the file gives no velocity limit for {} of {} joints (the first: {}); set your robot's\n",
        unlimited.len(),
        robot.n_active(),
        unlimited[0]
    ));
}

/// The `[posture]` table: the crouch for a floating biped ([`crouch_posture`]).
fn write_posture(
    out: &mut String,
    text: &str,
    dir: Option<&std::path::Path>,
    u: &urdf_rs::Robot,
    feet: &[String],
) {
    out.push_str(
        "\n# Initial joint angles [rad] (joint = angle), e.g. bent knees for a humanoid.\n[posture]\n",
    );
    let names: Vec<&str> = feet.iter().map(String::as_str).collect();
    match (names.len() == 2)
        .then(|| crouch_posture(text, dir, u, &names))
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
        None if names.len() == 2 => out.push_str(
            "# not guessed: the legs' joints could not bend the knees with the feet in place\n",
        ),
        None => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
