//! Reading a [`Robot`] from MuJoCo MJCF (feature `mjcf`, on by default).
//!
//! [`Robot::from_mjcf_file`](super::RobotFiles::from_mjcf_file) and [`Robot::from_mjcf_str`](super::RobotFiles::from_mjcf_str) read the kinematic tree of a
//! `<mujoco>` model so that iktc's q is MuJoCo's qpos (but for the base quaternion's order)
//! and every link pose is MuJoCo's body pose; [`Robot::from_description_file`](super::RobotFiles::from_description_file) reads URDF or
//! MJCF by the document's root element. The subset read:
//!
//! * **Bodies**: one link per `<body>` (named after it; an unnamed body is `body<id>`, its
//!   MuJoCo id), placed by `pos` and one of `quat` (w x y z), `axisangle`, `euler`, `xyaxes`,
//!   `zaxis`; angles in `<compiler angle>` (default **degrees**), Euler angles in
//!   `<compiler eulerseq>` (default `xyz`; lower case about the moving axes, upper case about
//!   the fixed ones). `<frame>`s compose their pose into what they hold. Several
//!   `<worldbody>`s, `<asset>`s, `<default>`s, `<compiler>`s merge as in MuJoCo.
//! * **Joints**: `hinge` (revolute) and `slide` (prismatic) with `axis`, `pos` (a joint off
//!   the body's origin rotates about its own point), `range` (limited per `limited`, or with
//!   `<compiler autolimits="true">`, the default, when a range is given; an unlimited hinge is
//!   continuous) and `ref` (the posture at qpos = ref is the model's as written, so q is
//!   qpos). A body with several joints is a chain of massless links `<body>__<joint>`; a body
//!   without a joint is fixed to its parent (joint `<body>_fixed`). A `free` joint
//!   (`<freejoint>`) of a top-level body is the floating base: the base follows
//!   [`ModelOptions::base`] as for a URDF (a warning says when a free joint is read fixed), and
//!   [`declared_base`](crate::model::declared_base) tells the CLI and Python to float it. A
//!   `ball` joint is an error naming it (replace it by three hinges); so is an unknown type.
//! * **The root**: the top-level body with the free joint (other top-level bodies, e.g. mocap
//!   targets, are left out with a warning); else a lone jointless top-level body at the world
//!   origin; else a massless link `world` the top-level bodies hang from at their poses.
//! * **Classes**: `<default>` classes, nested (a class inherits its parent's attributes),
//!   `class=` on an element, `childclass` on bodies and frames; for joints, geoms, sites,
//!   meshes, inertials, equalities and actuators (the actuator shortcuts share one default).
//! * **`<include file>`**: spliced in, its path relative to the including file's folder (else
//!   the model's); a model read from text without a folder cannot include.
//! * **Inertia**: `<inertial>` `pos`, orientation, `mass`, and `diaginertia` or
//!   `fullinertia` (Ixx Iyy Izz Ixy Ixz Iyz, in the inertial's axes). Without `<inertial>`
//!   (with `inertiafromgeom="auto"`, the default, or `"true"`, which ignores `<inertial>`),
//!   the body's mass is its geoms' as MuJoCo computes it: `mass`, else `density` (default 1000
//!   kg/m³) times the volume of boxes, spheres, capsules, cylinders and ellipsoids, inertias
//!   moved to the common centre; a **mesh** geom's mass is not computed (a warning names the
//!   body): give such bodies an `<inertial>`. With `inertiafromgeom="false"` a body without
//!   `<inertial>` is massless.
//! * **Limits**: MJCF has no joint velocity limit: every joint's is unbounded (+∞), as for a
//!   URDF `<limit>` without `velocity` (one warning), so its acceleration limit is
//!   [`ModelOptions::fallback_acceleration`] unless given. The effort limit \[N·m or N\] is the
//!   joint's `actuatorfrcrange`, else a joint actuator's `forcerange`, else a `<motor>`'s
//!   `ctrlrange` × |`gear`|; +∞ without any. Position actuators' `ctrlrange` (set points) is
//!   not a limit iktc reads.
//! * **Couplings**: `<equality><joint joint1 joint2 polycoef>` with a linear polynomial is
//!   joint1 mimicking joint2 (`q1 = c1·q2 + ref1 + c0 − c1·ref2`); other equalities (weld,
//!   connect, non-linear, one-joint) are left out with a warning.
//! * **Geometry** (for `iktc profile init`'s soles and the viewer, through the same URDF-tree
//!   readers as a URDF's): box, sphere, capsule, cylinder and mesh geoms (`<asset><mesh file
//!   scale>` under `<compiler meshdir>`, from the folder of the file declaring the mesh); geoms that do not collide (`contype` and
//!   `conaffinity` 0) are the visuals when a body has any, the colliding ones the collisions.
//!   A mesh file that is missing is a warning: the model loads for kinematics. `<site>`s are
//!   frames.
//!
//! Not read: tendons, sensors, cameras, lights, flexes, skins, `<replicate>` and `<attach>`
//! (an error), keyframes, MuJoCo's `boundmass`/`boundinertia`, and the dynamics parameters.

use std::path::Path;

use super::{BaseKind, ModelOptions, Robot, RobotBuilder};
use crate::error::{Error, Result};
use crate::resources::ReadLimits;

mod assets;
mod body;
mod couple;
mod defaults;
mod geom;
mod spec;
mod urdf_tree;
mod xml;

#[cfg(test)]
mod tests;

pub(crate) use xml::root_tag;

/// An MJCF model read: its name, tree, mesh assets.
pub(crate) struct Mjcf {
    pub name: String,
    tree: body::Tree,
    meshes: std::collections::HashMap<String, geom::MeshAsset>,
}

impl Mjcf {
    /// Whether the model has a free joint (its root floats in MuJoCo).
    pub fn floats(&self) -> bool {
        self.tree.free.is_some()
    }

    /// The model as a URDF tree, for the readers of geometry.
    pub fn urdf(&self) -> urdf_rs::Robot {
        urdf_tree::urdf_tree(&self.name, &self.tree, &self.meshes)
    }
}

/// Reads the MJCF `text`, called `source` in messages, whose folder is `dir` when known
/// (for `<include>` and to check that mesh files exist).
pub(crate) fn read_mjcf(
    text: &str,
    source: &str,
    dir: Option<&Path>,
    limits: &ReadLimits,
) -> Result<Mjcf> {
    limits.validate()?;
    let root = xml::parse(text, source, dir, limits.max_xml_depth)?;
    let c = spec::Compiler::of(&root)?;
    let d = defaults::Defaults::of(&root)?;
    let (meshes, materials) = assets::read(&root, &c, &d, source, dir)?;
    let x = body::Ctx {
        c: &c,
        defaults: &d,
        meshes: &meshes,
        materials: &materials,
    };
    let mut tree = body::read(&root, &x)?;
    couple::equalities(&root, &d, &mut tree)?;
    couple::efforts(&root, &c, &d, &mut tree)?;
    if tree
        .joints
        .iter()
        .any(|j| !matches!(j.kind, super::JointKind::Fixed))
    {
        tree.warnings.push(
            "MJCF gives no joint velocity limits: every joint's is read as unbounded (ModelOptions::fallback_velocity, or a robot profile's `velocity.default`, which `iktc profile init` writes, sets one; the acceleration limits follow from it)".into(),
        );
    }
    if let Some(dir) = dir {
        let mut used: Vec<&str> = tree
            .geoms
            .iter()
            .filter_map(|(_, g)| match &g.shape {
                geom::Shape::Mesh(m) => meshes.get(m).map(|a| a.file.as_str()),
                _ => None,
            })
            .collect();
        used.sort_unstable();
        used.dedup();
        let missing: Vec<&str> = used
            .into_iter()
            .filter(|f| !dir.join(f).is_file())
            .collect();
        if let Some(first) = missing.first() {
            tree.warnings.push(format!(
                "MJCF: {} mesh file(s) not found under {} (the first: {first}): the model loads for kinematics without their shapes",
                missing.len(),
                dir.display()
            ));
        }
    }
    let name = root
        .attr("model")
        .map(str::to_string)
        .or_else(|| {
            Path::new(source)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
        })
        .unwrap_or_else(|| "robot".into());
    Ok(Mjcf { name, tree, meshes })
}

impl Mjcf {
    /// The model with `options`.
    fn robot(&self, options: &ModelOptions) -> Result<Robot> {
        let t = &self.tree;
        let mut b = RobotBuilder::new(self.name.clone());
        for l in &t.links {
            b = b.link(l.clone());
        }
        for j in &t.joints {
            b = b.joint(j.clone());
        }
        for (name, link, offset) in &t.frames {
            if t.links.iter().any(|l| &l.name == name) {
                b.warn(format!(
                    "MJCF site `{name}` has a body's name: left out of the frames"
                ));
            } else {
                b = b.frame(name.clone(), link.clone(), *offset);
            }
        }
        for w in &t.warnings {
            b.warn(w.clone());
        }
        if let (Some(free), BaseKind::Fixed) = (&t.free, options.base) {
            b.warn(format!(
                "MJCF free joint `{free}`: the base is fixed, as ModelOptions::base says (BaseKind::Floating, --floating, floats it)"
            ));
        }
        b.build(options)
    }
}

// The readers behind `RobotFiles` (its docs say what each checks).
pub(crate) fn from_mjcf_str(text: &str, options: &ModelOptions) -> Result<Robot> {
    from_mjcf_str_with(text, None, options, &ReadLimits::default())
}

pub(crate) fn from_mjcf_str_with(
    text: &str,
    dir: Option<&Path>,
    options: &ModelOptions,
    limits: &ReadLimits,
) -> Result<Robot> {
    read_mjcf(text, "MJCF text", dir, limits)?.robot(options)
}

pub(crate) fn from_mjcf_file(path: &Path, options: &ModelOptions) -> Result<Robot> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::Urdf {
        message: format!("cannot read {}: {e}", path.display()),
    })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    read_mjcf(
        &text,
        &path.display().to_string(),
        Some(dir),
        &ReadLimits::default(),
    )?
    .robot(options)
}
