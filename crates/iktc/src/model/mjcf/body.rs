//! The `<worldbody>` tree read into links and joints: one link per body, one joint per
//! `hinge` or `slide` (a body with several is a chain of massless links), a fixed joint for a
//! body without one, `<site>`s as frames, `<geom>`s kept per link.

use std::collections::{HashMap, HashSet};

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

use super::defaults::{Attrs, Defaults, MAIN};
use super::geom::{combined, geom, Geom, MeshAsset};
use super::spec::{boolean, numbers, pose, unit, Compiler};
use super::xml::El;
use crate::error::Result;
use crate::model::{JointKind, JointLimit};
use crate::model::{JointSpec, Link};

/// The model read from the body tree, before `<equality>` and `<actuator>`.
#[derive(Debug, Default)]
pub(crate) struct Tree {
    pub links: Vec<Link>,
    pub joints: Vec<JointSpec>,
    /// Sites: name, link, pose in the link.
    pub frames: Vec<(String, String, Isometry3<f64>)>,
    /// Geoms by link name.
    pub geoms: Vec<(String, Geom)>,
    /// The free joint of the root body, if any.
    pub free: Option<String>,
    /// Each hinge or slide joint's `ref` (its qpos at the reference posture) \[rad or m\].
    pub refs: HashMap<String, f64>,
    /// Joints whose `actuatorfrcrange` gave the effort limit.
    pub effort_given: HashSet<String>,
    pub warnings: Vec<String>,
}

/// What the walk needs at hand.
pub(crate) struct Ctx<'a> {
    pub c: &'a Compiler,
    pub defaults: &'a Defaults,
    pub meshes: &'a HashMap<String, MeshAsset>,
    pub materials: &'a HashMap<String, [f64; 4]>,
}

/// The items of a body (or frame), `<frame>`s flattened: each with the pose of the frames
/// around it and the `childclass` in force.
struct Item<'a> {
    el: &'a El,
    pre: Isometry3<f64>,
    class: &'a str,
}

fn items<'a>(
    el: &'a El,
    pre: Isometry3<f64>,
    class: &'a str,
    c: &Compiler,
    d: &'a Defaults,
    out: &mut Vec<Item<'a>>,
) -> Result<()> {
    for ch in &el.children {
        if ch.tag == "frame" {
            let inner = ch.attr("childclass").unwrap_or(class);
            let a = Attrs::new(ch, inner, d)?;
            items(ch, pre * pose(&a, c)?, inner, c, d, out)?;
        } else {
            out.push(Item { el: ch, pre, class });
        }
    }
    Ok(())
}

/// Tags inside a body that change its structure in ways iktc does not read.
const UNSUPPORTED: &[&str] = &["replicate", "attach", "composite", "flexcomp"];

impl Tree {
    /// A name not yet used by a link (`base`, else `base_2`, …).
    fn fresh_link(&self, base: &str) -> String {
        fresh(base, |n| self.links.iter().any(|l| l.name == n))
    }

    /// A name not yet used by a joint.
    fn fresh_joint(&self, base: &str) -> String {
        fresh(base, |n| self.joints.iter().any(|j| j.name == n))
    }
}

fn fresh(base: &str, taken: impl Fn(&str) -> bool) -> String {
    if !taken(base) {
        return base.to_string();
    }
    (2..)
        .map(|k| format!("{base}_{k}"))
        .find(|n| !taken(n))
        .unwrap_or_default()
}

/// Reads the bodies of every `<worldbody>` under `root`.
///
/// The root link: the one top-level body with a free joint (other top-level bodies are left
/// out with a warning), else a top-level body alone at the world origin without joints, else
/// a massless link `world` that the top-level bodies hang from.
///
/// Errors: several top-level bodies with a free joint, a free joint below the top level or
/// with other joints in its body, a ball joint, an unknown joint type, a bad number.
pub(crate) fn read(root: &El, x: &Ctx) -> Result<Tree> {
    let mut t = Tree::default();
    let tops = top_bodies(root, x)?;
    let free = free_body(&tops, x)?;
    if tops.is_empty() {
        return Err(crate::error::Error::Urdf {
            message: "MJCF: <worldbody> has no <body>; expected the robot's root body".into(),
        });
    }
    let mut ids = 0usize;
    if let Some(f) = free {
        let kept = &tops[f];
        for other in tops.iter().filter(|o| !std::ptr::eq(o.el, kept.el)) {
            t.warnings.push(format!(
                "MJCF: top-level body `{}` left out: the robot is the body with the free joint, `{}`",
                item_name(other),
                item_name(kept)
            ));
        }
        t.body(
            kept.el,
            None,
            &Isometry3::identity(),
            kept.class,
            x,
            &mut ids,
        )?;
        return Ok(t);
    }
    if alone_at_origin(&tops, x)? {
        t.body(
            tops[0].el,
            None,
            &Isometry3::identity(),
            tops[0].class,
            x,
            &mut ids,
        )?;
        return Ok(t);
    }
    let world = t.fresh_link("world");
    t.links.push(Link::massless(world.clone()));
    for b in &tops {
        t.body(b.el, Some(&world), &b.pre, b.class, x, &mut ids)?;
    }
    Ok(t)
}

/// The top-level bodies of every `<worldbody>` under `root`, `<frame>`s flattened.
fn top_bodies<'a>(root: &'a El, x: &Ctx<'a>) -> Result<Vec<Item<'a>>> {
    let mut tops: Vec<Item> = Vec::new();
    for wb in root.elements("worldbody") {
        let mut all = Vec::new();
        items(wb, Isometry3::identity(), MAIN, x.c, x.defaults, &mut all)?;
        tops.extend(all.into_iter().filter(|i| i.el.tag == "body"));
    }
    Ok(tops)
}

/// The name of a body item, `(unnamed)` without one.
fn item_name(i: &Item) -> String {
    i.el.attr("name").unwrap_or("(unnamed)").to_string()
}

/// The index of the one top-level body with a free joint, if any.
///
/// Errors: several top-level bodies with a free joint.
fn free_body(tops: &[Item], x: &Ctx) -> Result<Option<usize>> {
    // A free joint: `<freejoint>`, or a `<joint>` whose type (or its class's) is `free`.
    let has_free = |i: &Item| {
        let class = i.el.attr("childclass").unwrap_or(i.class);
        i.el.elements("freejoint").next().is_some()
            || i.el.elements("joint").any(|j| {
                Attrs::new(j, class, x.defaults).is_ok_and(|a| a.get("type") == Some("free"))
            })
    };
    let free: Vec<usize> = (0..tops.len()).filter(|&i| has_free(&tops[i])).collect();
    if free.len() > 1 {
        return Err(crate::error::Error::Urdf {
            message: format!(
                "MJCF: {} top-level bodies have a free joint ({}); iktc models one floating base",
                free.len(),
                free.iter()
                    .map(|&i| item_name(&tops[i]))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        });
    }
    Ok(free.first().copied())
}

/// Whether `tops` is one body at the world origin without joints.
fn alone_at_origin(tops: &[Item], x: &Ctx) -> Result<bool> {
    Ok(tops.len() == 1 && {
        let b = &tops[0];
        let a = Attrs::new(b.el, b.class, x.defaults)?;
        let p = b.pre * pose(&a, x.c)?;
        let no_joint = !b
            .el
            .children
            .iter()
            .any(|c| c.tag == "joint" || c.tag == "freejoint");
        no_joint && p.translation.vector.norm() == 0.0 && p.rotation.angle() == 0.0
    })
}

/// One hinge or slide joint of a body, read.
struct Dof {
    name: String,
    kind: JointKind,
    /// Position of the joint in the body frame \[m\].
    pos: Vector3<f64>,
    limit: JointLimit,
    /// `ref` \[rad or m\].
    reference: f64,
}

impl Tree {
    /// Reads body `el` (MuJoCo body id `*ids + 1`) below the link `parent` (`None` for the
    /// root), the frames around it `pre`, in `childclass`,
    fn body(
        &mut self,
        el: &El,
        parent: Option<&str>,
        pre: &Isometry3<f64>,
        childclass: &str,
        x: &Ctx,
        ids: &mut usize,
    ) -> Result<()> {
        *ids += 1;
        let own = Attrs::new(el, childclass, x.defaults)?;
        let class = el.attr("childclass").unwrap_or(childclass);
        if !x.defaults.has(class) {
            return Err(el.error(format!(
                "childclass `{class}` is not defined by any <default>"
            )));
        }
        let name = match el.attr("name") {
            Some(n) => n.to_string(),
            None => format!("body{ids}"),
        };
        if self.links.iter().any(|l| l.name == name) {
            return Err(el.error(format!("a second body named `{name}`")));
        }
        let placed = pre * pose(&own, x.c)?;
        let mut list = Vec::new();
        items(el, Isometry3::identity(), class, x.c, x.defaults, &mut list)?;
        let dofs = self.body_joints(el, &list, &name, parent, x)?;
        // The body's link, and the chain of joints from the parent to it.
        self.links.push(Link::massless(name.clone()));
        let link_index = self.links.len() - 1;
        if let Some(p) = parent {
            self.chain(p, &name, placed, dofs);
        }
        // Geoms, sites, inertial.
        let mut geoms = Vec::new();
        for it in list.iter().filter(|i| i.el.tag == "geom") {
            let a = Attrs::new(it.el, it.class, x.defaults)?;
            geoms.push(geom(&a, &it.pre, x.c, x.meshes, x.materials)?);
        }
        for it in list.iter().filter(|i| i.el.tag == "site") {
            let a = Attrs::new(it.el, it.class, x.defaults)?;
            let Some(site) = it.el.attr("name") else {
                continue;
            };
            self.frames
                .push((site.to_string(), name.clone(), it.pre * pose(&a, x.c)?));
        }
        self.body_mass(&list, link_index, &geoms, x)?;
        self.geoms
            .extend(geoms.into_iter().map(|g| (name.clone(), g)));
        for it in list.iter() {
            if UNSUPPORTED.contains(&it.el.tag.as_str()) {
                return Err(it.el.error("is not read by iktc (expected bodies, joints, geoms, sites, frames and an inertial)"));
            }
        }
        for it in list.iter().filter(|i| i.el.tag == "body") {
            self.body(it.el, Some(&name), &it.pre, it.class, x, ids)?;
        }
        Ok(())
    }

    /// Reads the joints among the items `list` of body `el`, named `name`, below `parent`:
    /// its hinge and slide joints, in order; a free joint of the root body becomes
    /// [`Tree::free`].
    ///
    /// Errors: a free joint below the top level or with other joints in its body, a ball
    /// joint, an unknown joint type, a bad number.
    fn body_joints(
        &mut self,
        el: &El,
        list: &[Item],
        name: &str,
        parent: Option<&str>,
        x: &Ctx,
    ) -> Result<Vec<Dof>> {
        let mut dofs: Vec<Dof> = Vec::new();
        for it in list
            .iter()
            .filter(|i| i.el.tag == "joint" || i.el.tag == "freejoint")
        {
            let a = Attrs::new(it.el, it.class, x.defaults)?;
            let kind = if it.el.tag == "freejoint" {
                "free"
            } else {
                a.get("type").unwrap_or("hinge")
            };
            let jname = match it.el.attr("name") {
                Some(n) => n.to_string(),
                None => self.fresh_joint(&format!("{name}_joint")),
            };
            match kind {
                "free" => {
                    if parent.is_some() {
                        return Err(it.el.error(format!(
                            "a free joint in body `{name}`, which is not a top-level body; iktc reads a free joint only as the floating base of the root body"
                        )));
                    }
                    self.free = Some(jname);
                }
                "ball" => {
                    return Err(it.el.error(format!(
                        "joint `{jname}` of body `{name}` is a ball joint, which iktc does not read (expected hinge or slide; replace it by three hinges)"
                    )))
                }
                "hinge" | "slide" => dofs.push(self.dof(&a, jname, kind == "hinge", x)?),
                other => {
                    return Err(it.el.error(format!(
                        "joint type=\"{other}\": expected free, ball, slide or hinge"
                    )))
                }
            }
        }
        if self.free.is_some() && parent.is_none() && !dofs.is_empty() {
            return Err(el.error(format!(
                "body `{name}` has a free joint and other joints; a free joint must be its body's only joint"
            )));
        }
        Ok(dofs)
    }

    /// Sets the mass \[kg\], centre of mass \[m\] and inertia \[kg·m²\] of the link at
    /// `link_index` from its body's `geoms` or its `<inertial>` among `list`, as the compiler's
    /// `inertiafromgeom` says.
    fn body_mass(
        &mut self,
        list: &[Item],
        link_index: usize,
        geoms: &[Geom],
        x: &Ctx,
    ) -> Result<()> {
        let inertial = list.iter().find(|i| i.el.tag == "inertial");
        let from_geom = match x.c.from_geom {
            super::spec::FromGeom::Always => true,
            super::spec::FromGeom::Never => false,
            super::spec::FromGeom::Auto => inertial.is_none(),
        };
        let link = &mut self.links[link_index];
        if from_geom {
            let (m, c, i) = combined(geoms);
            (link.mass, link.com, link.inertia) = (m, c, i);
            if geoms.iter().any(|g| g.mass_unknown) {
                let name = &link.name;
                self.warnings.push(format!(
                    "MJCF body `{name}`: no <inertial>, and the mass of its mesh geoms is not computed by iktc: its mass and centre of mass come from its other geoms only (give an <inertial>)"
                ));
            }
        } else if let Some(it) = inertial {
            let a = Attrs::new(it.el, it.class, x.defaults)?;
            let (m, c, i) = inertia(&a, &it.pre, x.c)?;
            let link = &mut self.links[link_index];
            (link.mass, link.com, link.inertia) = (m, c, i);
        }
        Ok(())
    }

    /// Reads one hinge (`hinge`) or slide joint.
    fn dof(&mut self, a: &Attrs, name: String, hinge: bool, x: &Ctx) -> Result<Dof> {
        let el = a.el;
        let axis = unit(a, "axis")?.unwrap_or_else(nalgebra::Vector3::z_axis);
        let pos = super::spec::vec3(a, "pos")?.unwrap_or_default();
        let angle = |v: f64| if hinge { x.c.angle(v) } else { v };
        let range = numbers(a, "range", Some(2))?;
        let limited = match a.get("limited").unwrap_or("auto") {
            "auto" => x.c.autolimits && range.is_some(),
            v => boolean(el, "limited", v)?,
        };
        let mut limit = JointLimit::UNBOUNDED;
        if limited {
            let r = range.unwrap_or_else(|| vec![0.0, 0.0]);
            let (lo, hi) = (angle(r[0]), angle(r[1]));
            if lo >= hi {
                return Err(el.error(format!(
                    "joint `{name}` is limited with range=\"{} {}\": expected lower < upper [{}] (a joint that must not move is locked: ModelOptions::locked, --lock)",
                    r[0],
                    r[1],
                    if hinge { if x.c.degrees { "deg" } else { "rad" } } else { "m" }
                )));
            }
            (limit.lower, limit.upper) = (lo, hi);
        }
        let frc = numbers(a, "actuatorfrcrange", Some(2))?;
        let frc_limited = match a.get("actuatorfrclimited").unwrap_or("auto") {
            "auto" => x.c.autolimits && frc.is_some(),
            v => boolean(el, "actuatorfrclimited", v)?,
        };
        if let (true, Some(f)) = (frc_limited, frc) {
            if f[0] > f[1] {
                return Err(el.error(format!(
                    "actuatorfrcrange=\"{} {}\": expected lower <= upper [N·m or N]",
                    f[0], f[1]
                )));
            }
            limit.effort = f[0].abs().max(f[1].abs());
            self.effort_given.insert(name.clone());
        }
        let reference = angle(numbers(a, "ref", Some(1))?.map_or(0.0, |v| v[0]));
        let kind = if hinge {
            JointKind::Revolute { axis }
        } else {
            JointKind::Prismatic { axis }
        };
        self.refs.insert(name.clone(), reference);
        Ok(Dof {
            name,
            kind,
            pos,
            limit,
            reference,
        })
    }

    /// The joints from link `parent` to the body link `body` placed at `placed` in it: one per
    /// dof, each about its own point of the body, `ref` turned into the origin so that q is
    /// MuJoCo's qpos; massless links between them; a fixed joint when there is no dof or the
    /// last one is off the body's origin.
    fn chain(&mut self, parent: &str, body: &str, placed: Isometry3<f64>, dofs: Vec<Dof>) {
        let mut from = parent.to_string();
        let mut origin = placed;
        let n = dofs.len();
        for (k, d) in dofs.into_iter().enumerate() {
            let at = Translation3::from(d.pos);
            let zero = match d.kind {
                JointKind::Revolute { axis } => Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_axis_angle(&axis, -d.reference),
                ),
                JointKind::Prismatic { axis } => Isometry3::from_parts(
                    Translation3::from(-axis.into_inner() * d.reference),
                    UnitQuaternion::identity(),
                ),
                JointKind::Fixed => Isometry3::identity(),
            };
            let last_at_origin = k + 1 == n && d.pos == Vector3::zeros();
            let child = if last_at_origin {
                body.to_string()
            } else {
                let l = self.fresh_link(&format!("{body}__{}", d.name));
                self.links.push(Link::massless(l.clone()));
                l
            };
            self.joints.push(JointSpec {
                name: d.name,
                parent: from,
                child: child.clone(),
                origin: origin * Isometry3::from_parts(at, UnitQuaternion::identity()) * zero,
                kind: d.kind,
                limit: d.limit,
                mimic: None,
            });
            from = child;
            origin = Isometry3::from_parts(at.inverse(), UnitQuaternion::identity());
        }
        if from != body {
            let name = self.fresh_joint(&format!("{body}_fixed"));
            self.joints.push(JointSpec {
                name,
                parent: from,
                child: body.to_string(),
                origin,
                kind: JointKind::Fixed,
                limit: JointLimit::UNBOUNDED,
                mimic: None,
            });
        }
    }
}

/// The `<inertial>` `a` placed by the frames `pre` around it: mass \[kg\], centre of mass
/// \[m\] and inertia about it in body axes \[kg·m²\] from `diaginertia` (principal moments in
/// the inertial's axes) or `fullinertia` (Ixx Iyy Izz Ixy Ixz Iyz).
///
/// Errors: a missing or negative mass, neither or both of `diaginertia` and `fullinertia`.
fn inertia(
    a: &Attrs,
    pre: &Isometry3<f64>,
    c: &Compiler,
) -> Result<(f64, Vector3<f64>, Matrix3<f64>)> {
    let el = a.el;
    let mass = match numbers(a, "mass", Some(1))? {
        Some(m) if m[0] >= 0.0 => m[0],
        Some(m) => return Err(el.error(format!("mass=\"{}\": expected a mass >= 0 [kg]", m[0]))),
        None => return Err(el.error("has no `mass` (expected the body's mass [kg])")),
    };
    let p = pre * pose(a, c)?;
    let local = match (numbers(a, "diaginertia", Some(3))?, numbers(a, "fullinertia", Some(6))?) {
        (Some(d), None) => Matrix3::from_diagonal(&Vector3::new(d[0], d[1], d[2])),
        (None, Some(f)) => Matrix3::new(f[0], f[3], f[4], f[3], f[1], f[5], f[4], f[5], f[2]),
        _ => {
            return Err(el.error(
                "expected exactly one of diaginertia (3 principal moments) and fullinertia (Ixx Iyy Izz Ixy Ixz Iyz) [kg·m²]",
            ))
        }
    };
    let r = p.rotation.to_rotation_matrix();
    Ok((
        mass,
        p.translation.vector,
        r.matrix() * local * r.matrix().transpose(),
    ))
}
