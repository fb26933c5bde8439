//! Body points found from a skeleton's tree and rest pose when its names are unknown.
//!
//! With `P_j` the rest-pose position of joint `j` (every rotation at identity):
//! 1. the **pelvis** is the first joint from the root with at least three branches (a branch: a
//!    child whose subtree has at least [`MIN_LIMB_JOINTS`] joints); its largest branch is the
//!    spine, the next two are the legs;
//! 2. **up** is the direction from the mean of the legs' joints to the pelvis (the legs hang
//!    down in any rest pose, the arms may not); the standing height `H` is the extent of all
//!    `P_j` along it;
//! 3. the **chest** is the first joint down the spine (following the largest child) with at
//!    least three children with two or more joints each; of those, the **head** chain is the one
//!    reaching highest along up, the **arms** the two largest others;
//! 4. on each limb chain (from the branch to its farthest joint, joints at the same position as
//!    their parent merged into the deeper one), the hip, knee and ankle (shoulder, elbow,
//!    wrist) are the three joints `i < j < k` minimising
//!    `(|P_i P_j|/H − a)² + (|P_j P_k|/H − b)²` with the segment lengths of an average adult
//!    (Drillis & Contini: thigh `a` = 0.245, shank `b` = 0.246; upper arm 0.186, forearm 0.146);
//!    the toe is the joint after the ankle when that segment is more horizontal than vertical;
//! 5. the neck is the head chain's first joint, the head its last joint before the leaf (the
//!    leaf for a chain of two);
//! 6. **forward** is the mean toe direction (ankle to toe, horizontal part), **left** is
//!    `up × forward`; the limb whose hip (shoulder) lies further along left is the left one.

use nalgebra::Vector3;

use super::body_map::{FoundBy, MappedPoint, PointSource};
use super::body_point::{Limb, Side};
use super::{BodyPoint, Skeleton};

/// Fewest joints in a subtree for it to count as a limb or spine branch at the pelvis.
pub(crate) const MIN_LIMB_JOINTS: usize = 3;

/// Thigh length over standing height \[–\] (Drillis & Contini 1966).
const THIGH: f64 = 0.245;
/// Shank length over standing height \[–\].
const SHANK: f64 = 0.246;
/// Upper-arm length over standing height \[–\].
const UPPER_ARM: f64 = 0.186;
/// Forearm length over standing height \[–\].
const FOREARM: f64 = 0.146;

/// Smallest separation of the two limbs along the left direction, relative to the standing
/// height \[–\], for the sides to be told apart (a tenth of a typical hip width, 0.19 H).
const MIN_SIDE_SEPARATION: f64 = 0.02;

struct Tree<'a> {
    skeleton: &'a Skeleton,
    children: Vec<Vec<usize>>,
    size: Vec<usize>,
    rest: Vec<Vector3<f64>>,
}

impl<'a> Tree<'a> {
    fn new(skeleton: &'a Skeleton) -> Self {
        let n = skeleton.len();
        let mut children = vec![Vec::new(); n];
        let mut rest = vec![Vector3::zeros(); n];
        for (j, joint) in skeleton.joints().iter().enumerate() {
            if let Some(p) = joint.parent {
                if let Some(c) = children.get_mut(p) {
                    c.push(j);
                }
                rest[j] = rest[p] + joint.offset;
            }
        }
        let mut size = vec![1usize; n];
        for j in (1..n).rev() {
            if let Some(p) = skeleton.joints()[j].parent {
                size[p] += size[j];
            }
        }
        Self {
            skeleton,
            children,
            size,
            rest,
        }
    }

    fn branches(&self, j: usize, min: usize) -> Vec<usize> {
        let mut b: Vec<usize> = self.children[j]
            .iter()
            .copied()
            .filter(|c| self.size[*c] >= min)
            .collect();
        b.sort_by(|x, y| self.size[*y].cmp(&self.size[*x]));
        b
    }

    /// Joints of the subtree of `j`.
    fn subtree(&self, j: usize) -> Vec<usize> {
        let mut out = vec![j];
        let mut k = 0;
        while let Some(&x) = out.get(k) {
            out.extend(self.children[x].iter().copied());
            k += 1;
        }
        out
    }

    /// The joint of the subtree of `j` farthest from `from`.
    fn farthest(&self, j: usize, from: &Vector3<f64>) -> usize {
        self.subtree(j)
            .into_iter()
            .max_by(|a, b| {
                (self.rest[*a] - from)
                    .norm()
                    .total_cmp(&(self.rest[*b] - from).norm())
            })
            .unwrap_or(j)
    }

    /// The path from `start` down to its descendant `end`, merging zero-length bones into the
    /// deeper joint and dropping joints at `origin`.
    fn chain(&self, start: usize, end: usize, origin: &Vector3<f64>) -> Vec<usize> {
        let mut path = vec![end];
        let mut j = end;
        while j != start {
            match self.skeleton.joints().get(j).and_then(|x| x.parent) {
                Some(p) => {
                    path.push(p);
                    j = p;
                }
                None => break,
            }
        }
        path.reverse();
        let mut out: Vec<usize> = Vec::with_capacity(path.len());
        for j in path {
            if (self.rest[j] - origin).norm() == 0.0 {
                continue;
            }
            if let Some(last) = out.last_mut() {
                if (self.rest[*last] - self.rest[j]).norm() == 0.0 {
                    *last = j;
                    continue;
                }
            }
            out.push(j);
        }
        out
    }
}

/// The three chain joints `i < j < k` best matching the segment ratios `(a, b)` of height `h`.
fn fit_three(
    tree: &Tree,
    chain: &[usize],
    h: f64,
    a: f64,
    b: f64,
) -> Option<(usize, usize, usize)> {
    let d = |x: usize, y: usize| (tree.rest[chain[x]] - tree.rest[chain[y]]).norm() / h;
    let n = chain.len();
    let mut best: Option<(f64, (usize, usize, usize))> = None;
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let cost = (d(i, j) - a).powi(2) + (d(j, k) - b).powi(2);
                if best.is_none_or(|(c, _)| cost < c) {
                    best = Some((cost, (i, j, k)));
                }
            }
        }
    }
    best.map(|(_, t)| t)
}

struct Limbs {
    top: usize,
    mid: usize,
    end: usize,
    toe: Option<usize>,
}

/// The skeleton's vertical at rest: its up direction and standing height.
struct Upright {
    /// Unit vector from the legs to the pelvis.
    up: Vector3<f64>,
    /// Extent of the rest pose along `up` \[skeleton units\].
    h: f64,
}

/// Step 1: the first joint from the root with at least three branches.
fn find_pelvis(tree: &Tree) -> std::result::Result<usize, String> {
    let mut pelvis = 0usize;
    loop {
        let b = tree.branches(pelvis, MIN_LIMB_JOINTS);
        if b.len() >= 3 {
            return Ok(pelvis);
        }
        match b.first() {
            Some(c) if b.len() == 1 => pelvis = *c,
            _ => return Err("no joint with two legs and a spine branching from it".to_string()),
        }
    }
}

/// Step 2: up from the mean of the `legs`' joints to the pelvis, and the height along it.
fn upright(tree: &Tree, pelvis: usize, legs: [usize; 2]) -> std::result::Result<Upright, String> {
    let leg_joints: Vec<usize> = legs.iter().flat_map(|l| tree.subtree(*l)).collect();
    let below: Vector3<f64> = leg_joints
        .iter()
        .map(|j| tree.rest[*j])
        .sum::<Vector3<f64>>()
        / leg_joints.len() as f64;
    let up = (tree.rest[pelvis] - below)
        .try_normalize(0.0)
        .ok_or("the legs do not hang from the pelvis at rest")?;
    let heights: Vec<f64> = tree.rest.iter().map(|p| p.dot(&up)).collect();
    let h = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - heights.iter().copied().fold(f64::INFINITY, f64::min);
    if !(h.is_finite() && h > 0.0) {
        return Err("the rest pose has no height".to_string());
    }
    Ok(Upright { up, h })
}

/// Step 3, the chest: down the spine along the largest child to three branches of two joints.
fn find_chest(tree: &Tree, spine: usize) -> std::result::Result<usize, String> {
    let mut chest = spine;
    loop {
        if tree.branches(chest, 2).len() >= 3 {
            return Ok(chest);
        }
        match tree.children[chest].iter().max_by_key(|c| tree.size[**c]) {
            Some(c) => chest = *c,
            None => return Err("no upper-spine joint with two arms and a head".to_string()),
        }
    }
}

/// Step 3, at the chest: the head branch (reaching highest along `up`) and up to two arms.
fn head_and_arms(
    tree: &Tree,
    chest: usize,
    up: &Vector3<f64>,
) -> std::result::Result<(usize, Vec<usize>), String> {
    let pc = tree.rest[chest];
    let upper = tree.branches(chest, 2);
    let head_branch = upper
        .iter()
        .copied()
        .max_by(|a, b| {
            let ha = tree.rest[tree.farthest(*a, &pc)].dot(up);
            let hb = tree.rest[tree.farthest(*b, &pc)].dot(up);
            ha.total_cmp(&hb)
        })
        .ok_or("no head branch")?;
    let arms: Vec<usize> = upper
        .iter()
        .copied()
        .filter(|b| *b != head_branch)
        .take(2)
        .collect();
    Ok((head_branch, arms))
}

/// Step 4 for the leg branch `l` at the pelvis (at `p0`): hip, knee, ankle and toe.
fn fit_leg(
    tree: &Tree,
    l: usize,
    p0: &Vector3<f64>,
    body: &Upright,
) -> std::result::Result<Limbs, String> {
    let up = body.up;
    let chain = tree.chain(l, tree.farthest(l, p0), p0);
    let (i, j, k) =
        fit_three(tree, &chain, body.h, THIGH, SHANK).ok_or("a leg has fewer than three joints")?;
    let toe = chain.get(k + 1).copied().filter(|t| {
        let s = tree.rest[*t] - tree.rest[chain[k]];
        let vertical = s.dot(&up).abs();
        (s - up * s.dot(&up)).norm() > vertical
    });
    Ok(Limbs {
        top: chain[i],
        mid: chain[j],
        end: chain[k],
        toe,
    })
}

/// Step 4 for the arm branch `a` at the chest (at `pc`): shoulder, elbow and wrist.
fn fit_arm(tree: &Tree, a: usize, pc: &Vector3<f64>, h: f64) -> std::result::Result<Limbs, String> {
    let chain = tree.chain(a, tree.farthest(a, pc), pc);
    let (i, j, k) = fit_three(tree, &chain, h, UPPER_ARM, FOREARM)
        .ok_or("an arm has fewer than three joints")?;
    Ok(Limbs {
        top: chain[i],
        mid: chain[j],
        end: chain[k],
        toe: None,
    })
}

/// Step 6: the unit left direction, `up × forward` with forward the mean horizontal toe segment.
fn left_direction(
    tree: &Tree,
    legs: &[Limbs; 2],
    up: &Vector3<f64>,
) -> std::result::Result<Vector3<f64>, String> {
    let forward: Vector3<f64> = legs
        .iter()
        .filter_map(|l| l.toe.map(|t| tree.rest[t] - tree.rest[l.end]))
        .map(|s| s - up * s.dot(up))
        .sum();
    let forward = forward
        .try_normalize(0.0)
        .ok_or("no toe segment to tell the facing direction, so left and right are unknown")?;
    Ok(up.cross(&forward))
}

/// Whether joint `a` lies further along `left` than joint `b`; too close sideways is an error.
fn is_left_of(
    tree: &Tree,
    left: &Vector3<f64>,
    h: f64,
    a: usize,
    b: usize,
) -> std::result::Result<bool, String> {
    let s = (tree.rest[a] - tree.rest[b]).dot(left) / h;
    if s.abs() < MIN_SIDE_SEPARATION {
        return Err("two limbs are not apart sideways at rest".to_string());
    }
    Ok(s > 0.0)
}

/// Finds the body points by shape (see the module documentation); `Err` says why not.
pub(crate) fn by_shape(skeleton: &Skeleton) -> std::result::Result<Vec<MappedPoint>, String> {
    let tree = Tree::new(skeleton);
    let pelvis = find_pelvis(&tree)?;
    let branches = tree.branches(pelvis, MIN_LIMB_JOINTS);
    let (spine, legs) = (branches[0], [branches[1], branches[2]]);
    let p0 = tree.rest[pelvis];
    let body = upright(&tree, pelvis, legs)?;
    let (up, h) = (body.up, body.h);
    let chest = find_chest(&tree, spine)?;
    let pc = tree.rest[chest];
    let (head_branch, arms) = head_and_arms(&tree, chest, &up)?;
    let legs = [
        fit_leg(&tree, legs[0], &p0, &body)?,
        fit_leg(&tree, legs[1], &p0, &body)?,
    ];
    let arms = match arms.as_slice() {
        [a, b] => [fit_arm(&tree, *a, &pc, h)?, fit_arm(&tree, *b, &pc, h)?],
        _ => return Err("fewer than two arms at the upper spine".to_string()),
    };
    let left = left_direction(&tree, &legs, &up)?;
    let mut out = Vec::new();
    let mut push = |point: BodyPoint, j: usize| {
        if let Some(joint) = skeleton.joints().get(j) {
            out.push(MappedPoint {
                point,
                source: PointSource::Joint(joint.name.clone()),
                found_by: FoundBy::Shape,
            });
        }
    };
    push(BodyPoint::Pelvis, pelvis);
    push(BodyPoint::Chest, chest);
    let head_chain = tree.chain(head_branch, tree.farthest(head_branch, &pc), &pc);
    match head_chain.as_slice() {
        [] => return Err("empty head chain".to_string()),
        [only] => push(BodyPoint::Head, *only),
        [first, second] => {
            push(BodyPoint::Neck, *first);
            push(BodyPoint::Head, *second);
        }
        [first, .., before_leaf, _] => {
            push(BodyPoint::Neck, *first);
            push(BodyPoint::Head, *before_leaf);
        }
    }
    let first_leg_left = is_left_of(&tree, &left, h, legs[0].top, legs[1].top)?;
    let first_arm_left = is_left_of(&tree, &left, h, arms[0].top, arms[1].top)?;
    for (limbs, first_left, names) in [
        (&legs, first_leg_left, [Limb::Hip, Limb::Knee, Limb::Ankle]),
        (
            &arms,
            first_arm_left,
            [Limb::Shoulder, Limb::Elbow, Limb::Wrist],
        ),
    ] {
        for (k, l) in limbs.iter().enumerate() {
            let side = if (k == 0) == first_left {
                Side::Left
            } else {
                Side::Right
            };
            for (limb, j) in names.iter().zip([l.top, l.mid, l.end]) {
                push(BodyPoint::of_limb(side, *limb), j);
            }
            if let Some(t) = l.toe {
                push(BodyPoint::of_limb(side, Limb::Toe), t);
            }
        }
    }
    Ok(out)
}
