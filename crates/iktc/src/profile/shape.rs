//! A humanoid's parts found from the shape of its URDF tree at the zero posture (q = 0), for
//! `iktc profile init`; names only break ties.
//!
//! * **ends**: links moved by a movable joint with no movable joint below them (the end of a
//!   chain; links fixed below an end belong to it);
//! * **feet**: the two ends lowest at q = 0 (their lowest point: the origins of the end and of
//!   the links fixed to it) that lie at least [`MIN_DROP`] below the base, whose chains part
//!   with at least [`MIN_LEG_JOINTS`] movable joints each below their common link, and whose
//!   lateral (y) coordinates in the base frame differ; the one at larger y is the left one;
//! * **arms**: of the other ends, outside the legs, those beyond [`MIDLINE`] of the base's x–z
//!   plane; per side the end with the most movable joints above it (then the farther from
//!   the midline) marks the arm; the **torso** is the link where the two arms' chains meet; an
//!   arm is the subtree of the torso's child towards its end, its **hand** link the common link
//!   of every end in it (the palm of a hand with fingers, else the end);
//! * **head**: of the remaining ends (outside legs and arms), the highest above the torso; with
//!   none, a link fixed to the torso (one named like a head first, else the highest above it);
//! * **pelvis**: the base (the root link).

use nalgebra::{Isometry3, Vector3};

/// Feet lie at least this far below the base's origin at q = 0 \[m\]: a fixed-base arm's ends
/// rise above its base.
pub(crate) const MIN_DROP: f64 = 0.1;

/// A leg has at least this many movable joints below the link where the two legs part \[–\].
pub(crate) const MIN_LEG_JOINTS: usize = 3;

/// An arm's end lies farther than this from the base's x–z plane at q = 0 \[m\]; ends nearer
/// to it (a head, a neck) are on the midline.
pub(crate) const MIDLINE: f64 = 0.02;

/// An arm has at least this many movable joints between the torso and its hand link \[–\].
pub(crate) const MIN_ARM_JOINTS: usize = 2;

/// The URDF tree laid out at q = 0: links breadth-first from the root.
pub(super) struct Tree {
    pub names: Vec<String>,
    /// Parent link index and whether the joint to it moves; `None` for the root.
    pub parent: Vec<Option<(usize, bool)>>,
    /// Pose of each link in the root's frame at q = 0.
    pub pose: Vec<Isometry3<f64>>,
}

impl Tree {
    /// The tree of `u` from its root link `root` (links not reached from it are left out).
    pub fn new(u: &urdf_rs::Robot, root: &str) -> Tree {
        let mut t = Tree {
            names: vec![root.to_string()],
            parent: vec![None],
            pose: vec![Isometry3::identity()],
        };
        let mut i = 0;
        while i < t.names.len() {
            let parent = t.names[i].clone();
            for j in u.joints.iter().filter(|j| j.parent.link == parent) {
                if t.names.iter().all(|n| *n != j.child.link) {
                    let movable = !matches!(j.joint_type, urdf_rs::JointType::Fixed);
                    t.names.push(j.child.link.clone());
                    t.parent.push(Some((i, movable)));
                    t.pose.push(t.pose[i] * crate::model::urdf_pose(&j.origin));
                }
            }
            i += 1;
        }
        t
    }

    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    pub fn pos(&self, i: usize) -> Vector3<f64> {
        self.pose[i].translation.vector
    }

    /// Whether `a` is `b` or one of its ancestors.
    pub fn is_ancestor(&self, a: usize, b: usize) -> bool {
        let mut j = Some(b);
        while let Some(i) = j {
            if i == a {
                return true;
            }
            j = self.parent[i].map(|p| p.0);
        }
        false
    }

    /// The lowest common ancestor of `a` and `b`.
    pub fn common(&self, a: usize, b: usize) -> usize {
        let mut j = Some(a);
        while let Some(i) = j {
            if self.is_ancestor(i, b) {
                return i;
            }
            j = self.parent[i].map(|p| p.0);
        }
        0
    }

    /// Movable joints on the path from `a` down to its descendant `b`.
    pub fn movable_between(&self, a: usize, b: usize) -> usize {
        let (mut n, mut i) = (0, b);
        while i != a {
            let Some((p, movable)) = self.parent[i] else {
                break;
            };
            n += usize::from(movable);
            i = p;
        }
        n
    }

    /// The child of `a` on the path down to its strict descendant `b`.
    fn child_towards(&self, a: usize, b: usize) -> usize {
        let mut i = b;
        while let Some((p, _)) = self.parent[i] {
            if p == a {
                return i;
            }
            i = p;
        }
        b
    }

    /// `i` and the links fixed below it (through fixed joints only).
    pub fn fixed_below(&self, i: usize) -> Vec<usize> {
        let mut out = vec![i];
        let mut k = 0;
        while k < out.len() {
            let at = out[k];
            out.extend((0..self.names.len()).filter(|c| self.parent[*c] == Some((at, false))));
            k += 1;
        }
        out
    }

    /// The chain ends (see the module documentation).
    fn ends(&self) -> Vec<usize> {
        let n = self.names.len();
        let mut movable_below = vec![false; n];
        // Children come after their parents: a backwards pass sees every child first.
        for i in (1..n).rev() {
            if let Some((p, movable)) = self.parent[i] {
                if movable || movable_below[i] {
                    movable_below[p] = true;
                }
            }
        }
        (1..n)
            .filter(|i| matches!(self.parent[*i], Some((_, true))) && !movable_below[*i])
            .collect()
    }

    /// The lowest height of end `i` at q = 0: its origin's and those of the links fixed to it
    /// \[m\].
    fn low(&self, i: usize) -> f64 {
        self.fixed_below(i)
            .iter()
            .map(|k| self.pos(*k).z)
            .fold(f64::INFINITY, f64::min)
    }
}

/// The parts found (link indices into the [`Tree`]); `[left, right]` pairs.
#[derive(Debug, Default, Clone, PartialEq)]
pub(super) struct Parts {
    pub feet: Option<[usize; 2]>,
    pub hands: Option<[usize; 2]>,
    /// Movable joints from the torso to each hand link \[–\].
    pub arm_joints: [usize; 2],
    pub torso: Option<usize>,
    pub head: Option<usize>,
}

/// Finds the parts of `t` (see the module documentation).
pub(super) fn find_parts(t: &Tree) -> Parts {
    let ends = t.ends();
    let mut parts = Parts::default();
    let feet = find_feet(t, &ends);
    parts.feet = feet;
    let in_legs = |e: usize| {
        feet.is_some_and(|[l, r]| {
            let top = t.common(l, r);
            [l, r]
                .iter()
                .any(|f| t.is_ancestor(t.child_towards(top, *f), e))
        })
    };
    let others: Vec<usize> = ends.iter().copied().filter(|e| !in_legs(*e)).collect();
    let arm_end = |sign: f64| {
        others
            .iter()
            .copied()
            .filter(|e| sign * t.pos(*e).y > MIDLINE)
            .max_by(|a, b| {
                (t.movable_between(0, *a), sign * t.pos(*a).y)
                    .partial_cmp(&(t.movable_between(0, *b), sign * t.pos(*b).y))
                    .unwrap_or(std::cmp::Ordering::Equal)
            })
    };
    let mut arms_top = None;
    if let (Some(l), Some(r)) = (arm_end(1.0), arm_end(-1.0)) {
        let torso = t.common(l, r);
        let hand = |e: usize| {
            let arm = t.child_towards(torso, e);
            others
                .iter()
                .copied()
                .filter(|x| t.is_ancestor(arm, *x))
                .fold(e, |h, x| t.common(h, x))
        };
        let (hl, hr) = (hand(l), hand(r));
        let joints = [t.movable_between(torso, hl), t.movable_between(torso, hr)];
        if joints.iter().all(|n| *n >= MIN_ARM_JOINTS) {
            parts.hands = Some([hl, hr]);
            parts.arm_joints = joints;
            parts.torso = Some(torso);
            arms_top = Some([t.child_towards(torso, l), t.child_towards(torso, r)]);
        }
    }
    let in_arms =
        |e: usize| arms_top.is_some_and(|a: [usize; 2]| a.iter().any(|x| t.is_ancestor(*x, e)));
    let above = parts.torso.unwrap_or(0);
    parts.head = others
        .iter()
        .copied()
        .filter(|e| !in_arms(*e) && t.is_ancestor(above, *e) && t.pos(*e).z > t.pos(above).z)
        .max_by(|a, b| t.pos(*a).z.total_cmp(&t.pos(*b).z))
        .or_else(|| {
            // A link named like a head wherever it is fixed (its origin may sit at the
            // torso's), else the highest above the torso.
            let fixed: Vec<usize> = t
                .fixed_below(above)
                .into_iter()
                .filter(|k| *k != above)
                .collect();
            fixed
                .iter()
                .copied()
                .find(|k| named_like(&t.names[*k], &["head", "neck"]))
                .or_else(|| {
                    fixed
                        .into_iter()
                        .filter(|k| t.pos(*k).z > t.pos(above).z)
                        .max_by(|a, b| t.pos(*a).z.total_cmp(&t.pos(*b).z))
                })
        });
    parts
}

/// Whether `name`, lower-cased, contains one of `words`.
pub(super) fn named_like(name: &str, words: &[&str]) -> bool {
    let lower = name.to_lowercase();
    words.iter().any(|w| lower.contains(w))
}

/// The feet `[left, right]` among `ends` (see the module documentation).
fn find_feet(t: &Tree, ends: &[usize]) -> Option<[usize; 2]> {
    let mut low: Vec<(usize, f64)> = ends
        .iter()
        .map(|e| (*e, t.low(*e)))
        .filter(|(_, z)| *z < t.pos(0).z - MIN_DROP)
        .collect();
    low.sort_by(|a, b| a.1.total_cmp(&b.1));
    for (k, (a, _)) in low.iter().enumerate() {
        for (b, _) in &low[k + 1..] {
            let top = t.common(*a, *b);
            let (ya, yb) = (t.pos(*a).y, t.pos(*b).y);
            if t.movable_between(top, *a) >= MIN_LEG_JOINTS
                && t.movable_between(top, *b) >= MIN_LEG_JOINTS
                && ya != yb
            {
                return Some(if ya > yb { [*a, *b] } else { [*b, *a] });
            }
        }
    }
    None
}

/// The frame to name for the part link `i`: a link fixed below it named with one of `words`
/// (the deepest such), else `i`.
pub(super) fn named_frame(t: &Tree, i: usize, words: &[&str]) -> usize {
    t.fixed_below(i)
        .into_iter()
        .rev()
        .find(|k| named_like(&t.names[*k], words))
        .unwrap_or(i)
}
