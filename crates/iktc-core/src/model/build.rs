//! [`RobotBuilder::build`]: the builder's links, joints and frames checked and put in the
//! model's order, in steps: the options, the links, the tree (one root, depth-first order), the
//! per-joint options (locks and limits by name), the joints' roles and limits, the mimics, the
//! frames. Each step's errors name the link, joint or frame and what was expected; the steps
//! run in this order, so the first error met is the one reported.

use std::collections::HashMap;

use nalgebra::{Isometry3, Vector3};

use super::joint::{Joint, JointKind, JointRole};
use super::robot::{BaseKind, Frame, JointSpec, MimicPolicy, ModelOptions, Robot, RobotBuilder};
use crate::error::{check_all_finite, check_finite, name_list, Error, Result};

fn finite_vec(what: &str, v: &Vector3<f64>) -> Result<()> {
    check_all_finite(what, v.as_slice())
}

pub(super) fn finite_iso(what: &str, t: &Isometry3<f64>) -> Result<()> {
    finite_vec(what, &t.translation.vector)?;
    check_all_finite(what, t.rotation.coords.as_slice())
}

/// The checked robot of builder `b` under `options`.
pub(super) fn robot(b: RobotBuilder, options: &ModelOptions) -> Result<Robot> {
    check_options(options)?;
    let links = Names::links(&b)?;
    let tree = Tree::new(&b, &links)?;
    let overrides = Overrides::new(&b, &tree, options)?;
    let nbase_v = if options.base == BaseKind::Floating {
        6
    } else {
        0
    };
    let (mut joints, active) = ordered_joints(&b, &tree, &links, &overrides, options)?;
    resolve_mimics(&b, &tree, &overrides, options, &mut joints)?;
    let drive = joints
        .iter()
        .map(|j| match j.role {
            JointRole::Active { index } => Some((nbase_v + index, 1.0)),
            JointRole::Mimic {
                master, multiplier, ..
            } => Some((nbase_v + master, multiplier)),
            _ => None,
        })
        .collect();
    let mut parent_joint = vec![None; b.links.len()];
    for (k, j) in joints.iter().enumerate() {
        parent_joint[j.child] = Some(k);
    }
    let frames = frames(&b, &links)?;
    let root = tree.root;
    let total_mass = b.links.iter().map(|l| l.mass).sum();
    Ok(Robot {
        name: b.name,
        base: options.base,
        links: b.links,
        joints,
        root,
        frames,
        active,
        drive,
        parent_joint,
        total_mass,
        warnings: b.warnings,
    })
}

/// The options' rates and fallbacks: `acceleration_per_velocity` finite and > 0 \[1/s\],
/// `fallback_velocity` > 0 \[rad/s or m/s\] and `jerk_per_acceleration` > 0 \[1/s\] (both may
/// be +inf).
fn check_options(options: &ModelOptions) -> Result<()> {
    check_finite(
        || "ModelOptions::acceleration_per_velocity".into(),
        options.acceleration_per_velocity,
    )?;
    if options.acceleration_per_velocity <= 0.0 {
        return Err(Error::InvalidSetting {
            name: "acceleration_per_velocity".into(),
            value: options.acceleration_per_velocity.to_string(),
            expected: "a positive number [1/s]".into(),
        });
    }
    if options.fallback_velocity.is_nan() || options.fallback_velocity <= 0.0 {
        return Err(Error::InvalidSetting {
            name: "fallback_velocity".into(),
            value: options.fallback_velocity.to_string(),
            expected: "a positive velocity limit [rad/s or m/s], or +inf for none".into(),
        });
    }
    if options.jerk_per_acceleration.is_nan() || options.jerk_per_acceleration <= 0.0 {
        return Err(Error::InvalidSetting {
            name: "jerk_per_acceleration".into(),
            value: options.jerk_per_acceleration.to_string(),
            expected: "a positive number [1/s], or +inf for no default jerk limit".into(),
        });
    }
    Ok(())
}

/// The index of each link or joint by name, for lookups whose error lists the valid names.
struct Names<'a> {
    kind: &'static str,
    index: HashMap<&'a str, usize>,
    names: Vec<&'a str>,
}

impl<'a> Names<'a> {
    /// The links of `b`, each checked: a unique name, a finite mass ≥ 0 \[kg\], a finite
    /// centre of mass \[m\] and inertia \[kg m²\], plausible magnitudes.
    fn links(b: &'a RobotBuilder) -> Result<Self> {
        if b.links.is_empty() {
            return Err(Error::Urdf {
                message: "the robot has no link".into(),
            });
        }
        let mut index: HashMap<&str, usize> = HashMap::new();
        for (i, l) in b.links.iter().enumerate() {
            if index.insert(l.name.as_str(), i).is_some() {
                return Err(Error::Urdf {
                    message: format!("duplicate link name `{}`", l.name),
                });
            }
            check_finite(|| format!("mass of link `{}`", l.name), l.mass)?;
            if l.mass < 0.0 {
                return Err(Error::Urdf {
                    message: format!("link `{}` has negative mass {}", l.name, l.mass),
                });
            }
            finite_vec(&format!("centre of mass of link `{}`", l.name), &l.com)?;
            check_all_finite(
                &format!("inertia of link `{}`", l.name),
                l.inertia.as_slice(),
            )?;
            super::plausible::check_link(l)?;
        }
        Ok(Self {
            kind: "link",
            index,
            names: b.links.iter().map(|l| l.name.as_str()).collect(),
        })
    }

    /// The index of `name`, or an unknown-name error of `kind` listing the valid names.
    fn find_as(&self, kind: &'static str, name: &str) -> Result<usize> {
        self.index
            .get(name)
            .copied()
            .ok_or_else(|| Error::UnknownName {
                kind,
                name: name.to_string(),
                valid: self.names.iter().map(|n| n.to_string()).collect(),
            })
    }

    /// The index of `name`, or an unknown-name error of this table's kind.
    fn find(&self, name: &str) -> Result<usize> {
        self.find_as(self.kind, name)
    }
}

/// The kinematic tree: each link's parent joint, each link's child joints, the root link and
/// the joints in depth-first order from it.
struct Tree<'a> {
    joints: Names<'a>,
    root: usize,
    order: Vec<usize>,
}

impl<'a> Tree<'a> {
    /// Checks every joint (unique name, known links, one parent per link, finite origin,
    /// limits) and that they form one tree.
    fn new(b: &'a RobotBuilder, links: &Names<'_>) -> Result<Self> {
        let mut index: HashMap<&str, usize> = HashMap::new();
        let mut parent_of: Vec<Option<usize>> = vec![None; b.links.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); b.links.len()];
        for (j, s) in b.joints.iter().enumerate() {
            if index.insert(s.name.as_str(), j).is_some() {
                return Err(Error::Urdf {
                    message: format!("duplicate joint name `{}`", s.name),
                });
            }
            let p = links.find(&s.parent)?;
            let c = links.find(&s.child)?;
            if let Some(other) = parent_of[c] {
                return Err(Error::Urdf {
                    message: format!(
                        "link `{}` is the child of two joints, `{}` and `{}`",
                        s.child, b.joints[other].name, s.name
                    ),
                });
            }
            parent_of[c] = Some(j);
            children[p].push(j);
            check_joint(s)?;
        }
        let roots: Vec<usize> = (0..b.links.len())
            .filter(|&i| parent_of[i].is_none())
            .collect();
        if roots.len() != 1 {
            return Err(Error::Urdf {
                message: format!(
                    "expected exactly one root link (a link that is no joint's child), found {}: {}",
                    roots.len(),
                    name_list(
                        &roots
                            .iter()
                            .map(|&i| b.links[i].name.as_str())
                            .collect::<Vec<_>>()
                    )
                ),
            });
        }
        let root = roots[0];
        let mut order: Vec<usize> = Vec::with_capacity(b.joints.len());
        let mut stack: Vec<usize> = children[root].iter().rev().copied().collect();
        while let Some(j) = stack.pop() {
            order.push(j);
            let c = links.find(&b.joints[j].child)?;
            stack.extend(children[c].iter().rev().copied());
        }
        if order.len() != b.joints.len() {
            return Err(Error::Urdf {
                message: "the joints do not form a tree: some links are not reachable from the root (a cycle?)".into(),
            });
        }
        let joints = Names {
            kind: "joint",
            index,
            names: b.joints.iter().map(|j| j.name.as_str()).collect(),
        };
        Ok(Self {
            joints,
            root,
            order,
        })
    }
}

/// One joint's origin and limits: finite origin, plausible magnitudes, range `lower ≤ upper`
/// (not NaN), velocity and acceleration > 0, effort ≥ 0 (each may be +inf).
fn check_joint(s: &JointSpec) -> Result<()> {
    finite_iso(&format!("origin of joint `{}`", s.name), &s.origin)?;
    super::plausible::check_joint(s)?;
    let l = &s.limit;
    for (what, v) in [("lower", l.lower), ("upper", l.upper)] {
        if v.is_nan() {
            return Err(Error::NonFinite {
                what: format!("{what} limit of joint `{}`", s.name),
                value: v,
            });
        }
    }
    if l.lower > l.upper {
        return Err(Error::InvalidLimit {
            what: format!("joint `{}`", s.name),
            lower: l.lower,
            upper: l.upper,
        });
    }
    for (what, v) in [
        ("velocity", l.velocity),
        ("acceleration", l.acceleration),
        ("effort", l.effort),
    ] {
        if v.is_nan() || v < 0.0 || (what != "effort" && v == 0.0) {
            return Err(Error::InvalidSetting {
                name: format!("{what} limit of joint `{}`", s.name),
                value: v.to_string(),
                expected: "a positive number or +inf".into(),
            });
        }
    }
    Ok(())
}

/// What the options set joint by joint (by the builder's joint index): locked positions
/// \[rad or m\] and velocity, acceleration and jerk limits \[rad/s, rad/s², rad/s³\].
struct Overrides {
    locked: HashMap<usize, f64>,
    velocity: HashMap<usize, f64>,
    acceleration: HashMap<usize, f64>,
    jerk: HashMap<usize, f64>,
}

impl Overrides {
    /// The options' joints looked up by name: a locked joint must move (not fixed) and be
    /// locked inside its range; a limit must be positive or +inf.
    fn new(b: &RobotBuilder, tree: &Tree<'_>, options: &ModelOptions) -> Result<Self> {
        let mut locked: HashMap<usize, f64> = HashMap::new();
        for (name, value) in &options.locked {
            let j = tree.joints.find(name)?;
            check_finite(|| format!("locked value of joint `{name}`"), *value)?;
            if matches!(b.joints[j].kind, JointKind::Fixed) {
                return Err(Error::InvalidSetting {
                    name: format!("locked joint `{name}`"),
                    value: value.to_string(),
                    expected: "a revolute, continuous or prismatic joint (this one is fixed)"
                        .into(),
                });
            }
            let range = b.joints[j].limit;
            if *value < range.lower || *value > range.upper {
                return Err(Error::StateOutsideLimits {
                    joint: name.clone(),
                    quantity: "locked position [rad or m]".into(),
                    value: *value,
                    lower: range.lower,
                    upper: range.upper,
                });
            }
            locked.insert(j, *value);
        }
        let by_joint = |list: &[(String, f64)], what: &str, unit: &str| {
            let mut out: HashMap<usize, f64> = HashMap::new();
            for (name, value) in list {
                let j = tree.joints.find(name)?;
                if value.is_nan() || *value <= 0.0 {
                    return Err(Error::InvalidSetting {
                        name: format!("{what} limit of joint `{name}`"),
                        value: value.to_string(),
                        expected: format!("a positive number [{unit}] or +inf"),
                    });
                }
                out.insert(j, *value);
            }
            Ok(out)
        };
        Ok(Self {
            locked,
            velocity: by_joint(&options.velocity_limits, "velocity", "rad/s")?,
            acceleration: by_joint(&options.acceleration_limits, "acceleration", "rad/s²")?,
            jerk: by_joint(&options.jerk_limits, "jerk", "rad/s³")?,
        })
    }
}

/// The joints in depth-first order with their roles (fixed, locked, active; a mimic is fixed
/// until [`resolve_mimics`]) and limits (the options' overrides, else the file's, else the
/// options' fallbacks), and the active joints' indices in that order.
fn ordered_joints(
    b: &RobotBuilder,
    tree: &Tree<'_>,
    links: &Names<'_>,
    overrides: &Overrides,
    options: &ModelOptions,
) -> Result<(Vec<Joint>, Vec<usize>)> {
    let mut joints: Vec<Joint> = Vec::with_capacity(tree.order.len());
    let mut active: Vec<usize> = Vec::new();
    for (k, &j) in tree.order.iter().enumerate() {
        let s = &b.joints[j];
        let role = if matches!(s.kind, JointKind::Fixed) {
            JointRole::Fixed
        } else if let Some(v) = overrides.locked.get(&j) {
            JointRole::Locked { value: *v }
        } else if s.mimic.is_some() {
            JointRole::Fixed // placeholder, resolved by `resolve_mimics`
        } else {
            active.push(k);
            JointRole::Active {
                index: active.len() - 1,
            }
        };
        joints.push(Joint {
            name: s.name.clone(),
            parent: links.find(&s.parent)?,
            child: links.find(&s.child)?,
            origin: s.origin,
            kind: s.kind,
            limit: joint_limit(j, s, overrides, options),
            role,
        });
    }
    Ok((joints, active))
}

/// Joint `j`'s limits: velocity, acceleration and jerk from the options' overrides, else the
/// file's, else (for a moving joint) `fallback_velocity`, `acceleration_per_velocity` × the
/// velocity limit (or `fallback_acceleration`) and `jerk_per_acceleration` × the acceleration
/// limit.
fn joint_limit(
    j: usize,
    s: &JointSpec,
    overrides: &Overrides,
    options: &ModelOptions,
) -> super::JointLimit {
    let moving = !matches!(s.kind, JointKind::Fixed);
    let mut limit = s.limit;
    if let Some(v) = overrides.velocity.get(&j) {
        limit.velocity = *v;
    } else if !limit.velocity.is_finite() && moving {
        limit.velocity = options.fallback_velocity;
    }
    if let Some(a) = overrides.acceleration.get(&j) {
        limit.acceleration = *a;
    } else if !limit.acceleration.is_finite() && moving {
        limit.acceleration = if limit.velocity.is_finite() {
            options.acceleration_per_velocity * limit.velocity
        } else {
            options.fallback_acceleration
        };
    }
    if let Some(value) = overrides.jerk.get(&j) {
        limit.jerk = *value;
    } else if moving {
        // inf · a: +inf unless both are finite (0 · inf cannot occur: a > 0).
        limit.jerk = options.jerk_per_acceleration * limit.acceleration;
    }
    limit
}

/// The roles of the mimic joints that are neither locked nor fixed: locked at
/// `multiplier · value + offset` under a locked master, following an active master under
/// [`MimicPolicy::Follow`], an error under [`MimicPolicy::Reject`] or for a master that is
/// fixed or itself a mimic.
fn resolve_mimics(
    b: &RobotBuilder,
    tree: &Tree<'_>,
    overrides: &Overrides,
    options: &ModelOptions,
    joints: &mut [Joint],
) -> Result<()> {
    let mut new_index: Vec<usize> = vec![0; b.joints.len()];
    for (k, &j) in tree.order.iter().enumerate() {
        new_index[j] = k;
    }
    for &j in &tree.order {
        let s = &b.joints[j];
        let Some((master, mult, off)) = &s.mimic else {
            continue;
        };
        if overrides.locked.contains_key(&j) || matches!(s.kind, JointKind::Fixed) {
            continue;
        }
        let m = tree.joints.find_as("joint (mimic master)", master)?;
        check_all_finite(&format!("mimic of joint `{}`", s.name), &[*mult, *off])?;
        let role = match joints[new_index[m]].role {
            JointRole::Locked { value } => JointRole::Locked {
                value: mult * value + off,
            },
            JointRole::Active { index } => match options.mimic {
                MimicPolicy::Follow => JointRole::Mimic {
                    master: index,
                    multiplier: *mult,
                    offset: *off,
                },
                MimicPolicy::Reject => {
                    return Err(Error::Urdf {
                        message: format!(
                            "joint `{}` mimics `{master}`, which is not locked, and the mimic policy is Reject; lock `{master}` or use MimicPolicy::Follow",
                            s.name
                        ),
                    })
                }
            },
            _ => {
                return Err(Error::Urdf {
                    message: format!(
                        "joint `{}` mimics `{master}`, which is fixed or itself a mimic; chains of mimics are not supported",
                        s.name
                    ),
                })
            }
        };
        joints[new_index[j]].role = role;
    }
    Ok(())
}

/// Every link as a frame of its own name, then the builder's extra frames (unique names,
/// finite and plausible offsets, known links).
fn frames(b: &RobotBuilder, links: &Names<'_>) -> Result<Vec<Frame>> {
    let mut frames: Vec<Frame> = b
        .links
        .iter()
        .enumerate()
        .map(|(i, l)| Frame {
            name: l.name.clone(),
            link: i,
            offset: Isometry3::identity(),
        })
        .collect();
    for (name, link, offset) in &b.frames {
        if frames.iter().any(|f| &f.name == name) {
            return Err(Error::Urdf {
                message: format!("duplicate frame name `{name}`"),
            });
        }
        finite_iso(&format!("offset of frame `{name}`"), offset)?;
        super::plausible::check_frame(name, offset)?;
        frames.push(Frame {
            name: name.clone(),
            link: links.find(link)?,
            offset: *offset,
        });
    }
    Ok(frames)
}
