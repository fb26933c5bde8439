//! Acclaim skeleton files (ASF), as used by the CMU motion-capture database.
//!
//! Supported: `:units` (`length`, `angle deg|rad`; `mass` ignored), `:root` (`order`, `axis`,
//! `position`, `orientation`), `:bonedata` (`begin … end` blocks with `id`, `name`,
//! `direction`, `length`, `axis x y z ORDER`, `dof` of `rx ry rz tx ty tz`, `limits` ignored),
//! `:hierarchy` (`begin`, lines `parent child…`, `end`); `:version`, `:name` and
//! `:documentation` are skipped. Not supported: the `l` (length) degree of freedom.
//!
//! Conventions (Acclaim, as in CMU's viewer): a list of rotations about axes `a_1 … a_n`
//! (an `axis` order or the `dof` order) is applied in the listed order about fixed axes,
//! `R = Rot(a_n) ··· Rot(a_1)`. Bone `b` has the rest frame `C_b` (its `axis`) and the motion
//! rotation `M_b` (its AMC values); in a frame parallel to the world at rest its local rotation
//! is `Q_b = C_b M_b C_bᵀ`. Bone `b` starts at the end of its parent, whose rest vector is
//! `direction · length` (the root's children start at the root).

use nalgebra::{Unit, UnitQuaternion, Vector3};

use super::{Clip, JointKind, Pose, Skeleton, SkeletonJoint, UpAxis};
use crate::error::{Error, Result};

/// A degree of freedom of a bone or the root.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AsfDof {
    /// Rotation about x, y or z (0, 1, 2).
    Rotation(usize),
    /// Translation along x, y or z (0, 1, 2).
    Translation(usize),
}

/// One bone of an ASF skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct AsfBone {
    /// The bone's name.
    pub name: String,
    /// Rest vector from its start to its end \[file units\]: `direction · length`.
    pub vector: Vector3<f64>,
    /// Rest frame `C_b` of its degrees of freedom.
    pub axis: UnitQuaternion<f64>,
    /// Degrees of freedom, in AMC value order.
    pub dofs: Vec<AsfDof>,
    /// Parent bone index, `None` for a child of the root.
    pub parent: Option<usize>,
}

/// An ASF skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct Asf {
    /// The file name (for messages).
    pub source: String,
    /// Whether angles (axis, AMC values) are in degrees (`:units angle deg`, the default).
    pub degrees: bool,
    /// The root's AMC value order.
    pub root_order: Vec<AsfDof>,
    /// The root's rest frame `C_root`.
    pub root_axis: UnitQuaternion<f64>,
    /// The root's rest position \[file units\].
    pub root_position: Vector3<f64>,
    /// Bones, parents before children.
    pub bones: Vec<AsfBone>,
}

/// `Rot(a_n) ··· Rot(a_1)` for axes listed `a_1 … a_n` with angles \[rad\].
pub(crate) fn fixed_axes_rotation(axes: &[usize], angles: &[f64]) -> UnitQuaternion<f64> {
    let mut q = UnitQuaternion::identity();
    for (a, v) in axes.iter().zip(angles) {
        let axis = Unit::new_unchecked(Vector3::ith(*a, 1.0));
        q = UnitQuaternion::from_axis_angle(&axis, *v) * q;
    }
    q
}

fn axis_index(c: char) -> Option<usize> {
    match c.to_ascii_lowercase() {
        'x' => Some(0),
        'y' => Some(1),
        'z' => Some(2),
        _ => None,
    }
}

/// The lines of an ASF or AMC file that are not blank or `#` comments: (1-based line, trimmed).
pub(crate) fn acclaim_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
}

struct Parser<'a> {
    source: &'a str,
}

impl Parser<'_> {
    fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::Parse {
            source_name: self.source.to_string(),
            line,
            message: message.into(),
        }
    }

    fn numbers<const N: usize>(
        &self,
        line: usize,
        what: &str,
        tokens: &[&str],
    ) -> Result<[f64; N]> {
        let mut out = [0.0; N];
        if tokens.len() < N {
            return Err(self.error(
                line,
                format!("`{what}` needs {N} numbers, found {}", tokens.len()),
            ));
        }
        for (o, t) in out.iter_mut().zip(tokens) {
            *o = t
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    self.error(line, format!("`{what}`: `{t}` is not a finite number"))
                })?;
        }
        Ok(out)
    }

    fn dof(&self, line: usize, token: &str) -> Result<AsfDof> {
        let lower = token.to_ascii_lowercase();
        let mut chars = lower.chars();
        let kind = chars.next();
        let axis = chars.next().and_then(axis_index);
        match (kind, axis, chars.next()) {
            (Some('r'), Some(a), None) => Ok(AsfDof::Rotation(a)),
            (Some('t'), Some(a), None) => Ok(AsfDof::Translation(a)),
            _ => Err(self.error(
                line,
                format!("unsupported degree of freedom `{token}`; expected rx ry rz tx ty tz"),
            )),
        }
    }

    fn axis_order(&self, line: usize, token: &str) -> Result<Vec<usize>> {
        let order: Option<Vec<usize>> = token.chars().map(axis_index).collect();
        match order {
            Some(o) if o.len() == 3 => Ok(o),
            _ => Err(self.error(line, format!("axis order `{token}`; expected e.g. XYZ"))),
        }
    }
}

#[derive(Default)]
struct RawBone {
    name: String,
    line: usize,
    direction: Vector3<f64>,
    length: f64,
    axis: [f64; 3],
    order: Vec<usize>,
    dofs: Vec<AsfDof>,
}

/// What the sections of an ASF file say, gathered line by line before the bones are ordered.
struct AsfScan<'a> {
    p: Parser<'a>,
    degrees: bool,
    root_order: Vec<AsfDof>,
    root_axis_order: Vec<usize>,
    /// The root's `orientation` in the file's angle unit.
    root_orientation: [f64; 3],
    root_position: Vector3<f64>,
    bones: Vec<RawBone>,
    /// `:hierarchy` links: (1-based line, parent name, child name).
    links: Vec<(usize, String, String)>,
    section: String,
    current: Option<RawBone>,
    hierarchy_seen: bool,
    in_limits: bool,
}

impl<'a> AsfScan<'a> {
    /// An empty scan: degrees, root axis order XYZ, root at the origin.
    fn new(source: &'a str) -> Self {
        AsfScan {
            p: Parser { source },
            degrees: true,
            root_order: Vec::new(),
            root_axis_order: vec![0, 1, 2],
            root_orientation: [0.0; 3],
            root_position: Vector3::zeros(),
            bones: Vec::new(),
            links: Vec::new(),
            section: String::new(),
            current: None,
            hierarchy_seen: false,
            in_limits: false,
        }
    }

    /// Takes one non-blank line: a section header or a line of the current section.
    fn line(&mut self, line: usize, l: &str) -> Result<()> {
        let tokens: Vec<&str> = l.split_whitespace().collect();
        let key = tokens[0].to_ascii_lowercase();
        if key.starts_with(':') {
            return self.section_header(line, key);
        }
        let args = &tokens[1..];
        match self.section.as_str() {
            ":units" if key == "angle" => {
                self.degrees = match args.first().map(|a| a.to_ascii_lowercase()) {
                    Some(a) if a.starts_with("deg") => true,
                    Some(a) if a.starts_with("rad") => false,
                    _ => return Err(self.p.error(line, "`angle` must be deg or rad")),
                };
            }
            ":root" => self.root_field(line, &key, args)?,
            ":bonedata" => self.bonedata_line(line, &key, args)?,
            ":hierarchy" => match key.as_str() {
                "begin" | "end" => {}
                _ => {
                    for child in args {
                        self.links
                            .push((line, tokens[0].to_string(), child.to_string()));
                    }
                }
            },
            _ => {}
        }
        Ok(())
    }

    /// Starts the section `key` (lowercase, with its `:`); an unknown one is an error.
    fn section_header(&mut self, line: usize, key: String) -> Result<()> {
        self.in_limits = false;
        match key.as_str() {
            ":version" | ":name" | ":units" | ":documentation" | ":root" | ":bonedata" => {}
            ":hierarchy" => self.hierarchy_seen = true,
            other => return Err(self.p.error(line, format!("unknown section `{other}`"))),
        }
        self.section = key;
        Ok(())
    }

    /// One field of `:root`: `order`, `axis`, `position` or `orientation`.
    fn root_field(&mut self, line: usize, key: &str, args: &[&str]) -> Result<()> {
        let p = &self.p;
        match key {
            "order" => {
                self.root_order = args
                    .iter()
                    .map(|t| p.dof(line, t))
                    .collect::<Result<Vec<_>>>()?
            }
            "axis" => {
                self.root_axis_order = p.axis_order(line, args.first().copied().unwrap_or(""))?
            }
            "position" => {
                self.root_position = Vector3::from(p.numbers::<3>(line, "position", args)?)
            }
            "orientation" => self.root_orientation = p.numbers::<3>(line, "orientation", args)?,
            _ => return Err(p.error(line, format!("unknown root field `{key}`"))),
        }
        Ok(())
    }

    /// One line of `:bonedata`: `begin`/`end` of a bone block or a field of the open bone.
    fn bonedata_line(&mut self, line: usize, key: &str, args: &[&str]) -> Result<()> {
        if self.in_limits && key.starts_with('(') {
            return Ok(());
        }
        self.in_limits = false;
        let p = &self.p;
        match (key, self.current.as_mut()) {
            ("begin", None) => {
                self.current = Some(RawBone {
                    line,
                    order: vec![0, 1, 2],
                    ..RawBone::default()
                })
            }
            ("end", Some(_)) => {
                if let Some(b) = self.current.take() {
                    if b.name.is_empty() {
                        return Err(p.error(b.line, "a bone without `name`"));
                    }
                    self.bones.push(b);
                }
            }
            ("id", Some(_)) => {}
            ("name", Some(b)) => b.name = args.first().map(|s| s.to_string()).unwrap_or_default(),
            ("direction", Some(b)) => {
                b.direction = Vector3::from(p.numbers::<3>(line, "direction", args)?)
            }
            ("length", Some(b)) => b.length = p.numbers::<1>(line, "length", args)?[0],
            ("axis", Some(b)) => {
                b.axis = p.numbers::<3>(line, "axis", args)?;
                b.order = p.axis_order(line, args.get(3).copied().unwrap_or("XYZ"))?;
            }
            ("dof", Some(b)) => {
                b.dofs = args
                    .iter()
                    .map(|t| p.dof(line, t))
                    .collect::<Result<Vec<_>>>()?
            }
            ("limits", Some(_)) => self.in_limits = true,
            (k, Some(_)) if k.starts_with("bodymass") || k.starts_with("cofmass") => {}
            (other, _) => return Err(p.error(line, format!("unexpected `{other}` in :bonedata"))),
        }
        Ok(())
    }

    /// Checks the end of the file: no open bone block, a non-empty `:hierarchy` whose parents
    /// are all `root` or bones; `last_line` is the file's line count.
    fn check_complete(&self, last_line: usize) -> Result<()> {
        let p = &self.p;
        if let Some(b) = &self.current {
            return Err(p.error(b.line, "bone block without `end` (truncated file)"));
        }
        if !self.hierarchy_seen || self.links.is_empty() {
            return Err(p.error(
                last_line,
                "no `:hierarchy` section (or an empty one): the bones' parents are unknown",
            ));
        }
        // Every parent is the root or a bone, as every child must be a bone.
        if let Some((line, parent, child)) = self.links.iter().find(|(_, parent, _)| {
            parent != "root" && !self.bones.iter().any(|b| &b.name == parent)
        }) {
            return Err(p.error(
                *line,
                format!("`:hierarchy` names unknown bone `{parent}` (parent of `{child}`)"),
            ));
        }
        Ok(())
    }

    /// The bones parents first, following the hierarchy from the root: (raw bone index, parent
    /// in the returned order); a bone with two parents or out of reach of `root` is an error.
    fn bone_order(&self) -> Result<Vec<(usize, Option<usize>)>> {
        let (p, bones, links) = (&self.p, &self.bones, &self.links);
        let mut order: Vec<(usize, Option<usize>)> = Vec::new();
        let mut frontier: Vec<(String, Option<usize>)> = vec![("root".to_string(), None)];
        while let Some((parent_name, parent_slot)) = frontier.pop() {
            for (line, parent, child) in links.iter().filter(|(_, p, _)| *p == parent_name) {
                let b = bones.iter().position(|b| &b.name == child).ok_or_else(|| {
                    p.error(
                        *line,
                        format!("`:hierarchy` names unknown bone `{child}` (child of `{parent}`)"),
                    )
                })?;
                if order.iter().any(|(o, _)| *o == b) {
                    return Err(p.error(*line, format!("bone `{child}` has two parents")));
                }
                order.push((b, parent_slot));
                frontier.push((child.clone(), Some(order.len() - 1)));
            }
        }
        if let Some(b) = bones
            .iter()
            .find(|b| !order.iter().any(|(o, _)| bones[*o].name == b.name))
        {
            return Err(p.error(
                b.line,
                format!(
                    "bone `{}` is not reachable from `root` in `:hierarchy`",
                    b.name
                ),
            ));
        }
        Ok(order)
    }

    /// The skeleton, bones in `order` (from [`Self::bone_order`]), angles converted to radians.
    fn into_asf(self, order: &[(usize, Option<usize>)]) -> Asf {
        let degrees = self.degrees;
        let angle = |v: f64| if degrees { v.to_radians() } else { v };
        let axis_rotation = |values: [f64; 3], axes: &[usize]| {
            let angles: Vec<f64> = axes.iter().map(|a| angle(values[*a])).collect();
            fixed_axes_rotation(axes, &angles)
        };
        let bones = order
            .iter()
            .map(|(b, parent)| {
                let raw = &self.bones[*b];
                AsfBone {
                    name: raw.name.clone(),
                    vector: raw.direction * raw.length,
                    axis: axis_rotation(raw.axis, &raw.order),
                    dofs: raw.dofs.clone(),
                    parent: *parent,
                }
            })
            .collect();
        Asf {
            source: self.p.source.to_string(),
            degrees,
            root_order: self.root_order,
            root_axis: axis_rotation(self.root_orientation, &self.root_axis_order),
            root_position: self.root_position,
            bones,
        }
    }
}

/// Reads an ASF file; `source` names it in errors ([`Error::Parse`] with the line): an unknown
/// section, a malformed number, a bone without name, a missing `:hierarchy`, a hierarchy naming
/// an unknown bone (as parent or as child) or leaving a bone out. A leading UTF-8 byte-order
/// mark is skipped.
pub fn read_asf(text: &str, source: &str) -> Result<Asf> {
    let text = super::strip_bom(text);
    let mut scan = AsfScan::new(source);
    for (line, l) in acclaim_lines(text) {
        scan.line(line, l)?;
    }
    scan.check_complete(text.lines().count())?;
    let order = scan.bone_order()?;
    Ok(scan.into_asf(&order))
}

impl Asf {
    /// The motion skeleton: joint 0 `root`, then one joint per bone at the bone's start, then an
    /// end site `<bone>_end` at the end of every bone without children. A bone with 2–3 rotation
    /// dofs is spherical, with 1 a hinge about `C_b e_axis`, with none fixed.
    pub fn skeleton(&self) -> Result<Skeleton> {
        let mut joints = vec![SkeletonJoint {
            name: "root".to_string(),
            parent: None,
            offset: self.root_position,
            kind: JointKind::Root,
        }];
        for b in &self.bones {
            let rotations: Vec<usize> = b
                .dofs
                .iter()
                .filter_map(|d| match d {
                    AsfDof::Rotation(a) => Some(*a),
                    AsfDof::Translation(_) => None,
                })
                .collect();
            let kind = match rotations.as_slice() {
                [] => JointKind::Fixed,
                [a] => JointKind::Hinge {
                    axis: Unit::new_normalize(b.axis * Vector3::ith(*a, 1.0)),
                },
                _ => JointKind::Spherical,
            };
            let (parent, offset) = match b.parent {
                None => (0, Vector3::zeros()),
                Some(p) => (p + 1, self.bones[p].vector),
            };
            joints.push(SkeletonJoint {
                name: b.name.clone(),
                parent: Some(parent),
                offset,
                kind,
            });
        }
        for (i, b) in self.bones.iter().enumerate() {
            if !self.bones.iter().any(|c| c.parent == Some(i)) {
                joints.push(SkeletonJoint {
                    name: format!("{}_end", b.name),
                    parent: Some(i + 1),
                    offset: b.vector,
                    kind: JointKind::Fixed,
                });
            }
        }
        Skeleton::new(joints)
    }

    /// The rest pose as a one-frame clip (Y up, the Acclaim convention).
    pub fn rest_clip(&self) -> Result<Clip> {
        let skeleton = self.skeleton()?;
        let pose = skeleton.rest_pose();
        Clip::new(&self.source, skeleton, vec![0.0], vec![pose], UpAxis::Y)
    }

    /// The pose of the skeleton (see [`Asf::skeleton`]) for one frame's values: `root` holds the
    /// root's values in `root_order`, `bone_values[b]` bone `b`'s in its dof order (angles in
    /// degrees or radians as `degrees` says). Root: position `(TX, TY, TZ)` in the world, orientation
    /// `C_root M_root C_rootᵀ`; a bone's translation dofs `t` move it by `C_b t`.
    pub(crate) fn pose(
        &self,
        root: &[f64],
        bone_values: &[Vec<f64>],
        joints: usize,
        degrees: bool,
    ) -> Pose {
        let angle = |v: f64| if degrees { v.to_radians() } else { v };
        let (q_root, t_root) = self.dof_motion(&self.root_order, root, &self.root_axis, angle);
        let mut pose = Pose {
            root_position: t_root,
            root_orientation: q_root,
            rotations: vec![UnitQuaternion::identity(); joints],
            translations: vec![Vector3::zeros(); joints],
        };
        for (i, (b, values)) in self.bones.iter().zip(bone_values).enumerate() {
            let (q, t) = self.dof_motion(&b.dofs, values, &b.axis, angle);
            if let Some(r) = pose.rotations.get_mut(i + 1) {
                *r = q;
            }
            if let Some(tr) = pose.translations.get_mut(i + 1) {
                *tr = b.axis * t;
            }
        }
        pose
    }

    /// `(C M Cᵀ, t)` for the given dofs and values (`t` in the dofs' own axes).
    fn dof_motion(
        &self,
        dofs: &[AsfDof],
        values: &[f64],
        c: &UnitQuaternion<f64>,
        angle: impl Fn(f64) -> f64,
    ) -> (UnitQuaternion<f64>, Vector3<f64>) {
        let mut axes = Vec::with_capacity(3);
        let mut angles = Vec::with_capacity(3);
        let mut t = Vector3::zeros();
        for (d, v) in dofs.iter().zip(values) {
            match d {
                AsfDof::Rotation(a) => {
                    axes.push(*a);
                    angles.push(angle(*v));
                }
                AsfDof::Translation(a) => t[*a] = *v,
            }
        }
        let m = fixed_axes_rotation(&axes, &angles);
        (c * m * c.inverse(), t)
    }
}
