//! A first pass over a URDF's raw XML, before `urdf-rs` builds its tree.
//!
//! It streams the document once (no recursion, no tree) and checks what the typed parse
//! cannot see or would not survive:
//!
//! * the nesting depth, against [`ReadLimits::max_xml_depth`] (the tree parser recurses once per
//!   level: 20 000 nested elements overflow the stack);
//! * the elements inside each `<joint>` and `<inertial>` of the robot (a misspelled `<limit>`
//!   would otherwise leave a revolute joint with the range \[0, 0\]; a misspelled `<mass>` a
//!   massless link), and the attributes of `<limit>`; an element inside `<joint>` that
//!   misspells none URDF defines is an exporter's extension and is ignored with a warning;
//! * which `<limit>` attributes are written at all, so that a missing value and an explicit 0
//!   can be told apart (the typed parse gives 0 for both);
//! * where a `<material>` has no `name`: URDF requires one, `urdf-rs` rejects the document
//!   without it, and exporters leave it out (Unitree's H1-2 description has 55 such
//!   materials); the reader then names them `""` ([`unnamed_materials_named`]), which is what
//!   a name-less material means to a kinematic reader (materials only colour the visuals).

use std::collections::HashMap;

use quick_xml::events::{BytesStart, Event};

use crate::error::{Error, Result};
use crate::resources::ReadLimits;

/// Elements URDF allows inside `<joint>`.
pub(crate) const JOINT_CHILDREN: [&str; 9] = [
    "origin",
    "parent",
    "child",
    "axis",
    "calibration",
    "dynamics",
    "limit",
    "mimic",
    "safety_controller",
];

/// An element inside `<joint>` that URDF does not define is a misspelling of one it does (an
/// error) when its name is within this many single-character edits of that name, or contains
/// it (`<limits>`, `<joint_limit>`); otherwise it is an exporter's extension
/// (`<joint_properties>` of onshape-to-robot), ignored with a warning.
const MISSPELLING_EDITS: usize = 2;

use crate::error::edits;

/// The element URDF defines inside `<joint>` that `tag` looks like a misspelling of, if any.
fn misspelled_joint_child(tag: &str) -> Option<&'static str> {
    let lower = tag.to_ascii_lowercase();
    JOINT_CHILDREN
        .into_iter()
        .find(|known| lower.contains(known) || edits(&lower, known) <= MISSPELLING_EDITS)
}

/// Elements URDF allows inside `<inertial>`.
const INERTIAL_CHILDREN: [&str; 3] = ["origin", "mass", "inertia"];

/// Attributes URDF (up to 1.2) allows on `<limit>`.
const LIMIT_ATTRIBUTES: [&str; 7] = [
    "lower",
    "upper",
    "effort",
    "velocity",
    "acceleration",
    "deceleration",
    "jerk",
];

/// What the raw pass saw of one `<joint>` of the robot.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct RawJoint {
    /// Its `<limit>` attributes as written (name, text), or `None` without a `<limit>`.
    pub limit: Option<Vec<(String, String)>>,
}

impl RawJoint {
    /// The text of `<limit attr="…">`, if written.
    pub fn limit_attr(&self, name: &str) -> Option<&str> {
        self.limit
            .as_ref()?
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

fn error(message: String) -> Error {
    Error::Urdf { message }
}

fn name_of(e: &BytesStart<'_>) -> String {
    String::from_utf8_lossy(e.name().as_ref()).into_owned()
}

fn attributes(e: &BytesStart<'_>) -> Result<Vec<(String, String)>> {
    let tag = name_of(e);
    e.attributes()
        .map(|a| {
            let a = a.map_err(|err| error(format!("cannot parse the URDF: <{tag}>: {err}")))?;
            let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
            let value = a
                .unescape_value()
                .map_err(|err| error(format!("cannot parse the URDF: <{tag} {key}>: {err}")))?
                .into_owned();
            Ok((key, value))
        })
        .collect()
}

/// One open element: its tag and, for a joint or link of the robot, its name.
struct Open {
    tag: String,
    name: String,
}

/// What the raw pass found.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct RawUrdf {
    /// The robot's joints by name.
    pub joints: HashMap<String, RawJoint>,
    /// Byte offsets just past `<material` of every `<material>` without a `name` attribute.
    pub unnamed_materials: Vec<usize>,
    /// Elements inside a joint that URDF does not define and that misspell none it does, as
    /// (joint, tag): ignored (see [`MISSPELLING_EDITS`]).
    pub ignored: Vec<(String, String)>,
    /// The warning of a floating root joint read as the base (`urdf::drop_floating_root`).
    pub floating_root: Option<String>,
}

/// `text` with `name=""` written into each `<material` at the byte offsets `at` (ascending,
/// each just past a `<material` tag name; see [`RawUrdf::unnamed_materials`]).
pub(crate) fn unnamed_materials_named(text: &str, at: &[usize]) -> String {
    let mut out = String::with_capacity(text.len() + 8 * at.len());
    let mut from = 0;
    for &p in at {
        out.push_str(&text[from..p]);
        out.push_str(" name=\"\"");
        from = p;
    }
    out.push_str(&text[from..]);
    out
}

/// Streams `text` once; returns the robot's joints by name and where `<material>` lacks a
/// name, and the elements inside a joint it ignores. Errors: a nesting deeper than
/// `limits.max_xml_depth`, an element URDF does not know inside a robot's `<inertial>`, or
/// inside a `<joint>` one that looks like a misspelling of a known one ([`MISSPELLING_EDITS`]), an unknown `<limit>` attribute, malformed XML.
pub(crate) fn check_raw(text: &str, limits: &ReadLimits) -> Result<RawUrdf> {
    limits.validate()?;
    let mut reader = quick_xml::Reader::from_str(text);
    let mut stack: Vec<Open> = Vec::new();
    let mut raw = RawUrdf::default();
    loop {
        let at = usize::try_from(reader.buffer_position()).unwrap_or(usize::MAX);
        let event = reader.read_event().map_err(|e| {
            error(format!(
                "cannot parse the URDF at byte {}: {e}",
                reader.error_position()
            ))
        })?;
        let (start, empty) = match &event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                stack.pop();
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let tag = name_of(start);
        check_depth(&tag, stack.len() + 1, limits)?;
        let attrs = attributes(start)?;
        let name = attrs
            .iter()
            .find(|(k, _)| k == "name")
            .map(|(_, v)| v.clone())
            .unwrap_or_default();
        raw.element(&stack, &tag, &attrs)?;
        if tag == "material" && !attrs.iter().any(|(k, _)| k == "name") {
            // The event starts at `at` with `<material`; found by search to be sure of it.
            let tail = text.get(at..).unwrap_or("");
            if let Some(i) = tail.find("<material") {
                raw.unnamed_materials.push(at + i + "<material".len());
            }
        }
        if tag == "joint" && stack.len() == 1 {
            raw.joints.entry(name.clone()).or_default();
        }
        if !empty {
            stack.push(Open { tag, name });
        }
    }
    Ok(raw)
}

/// Errors when the element `tag` at nesting `depth` is deeper than `limits.max_xml_depth`.
fn check_depth(tag: &str, depth: usize, limits: &ReadLimits) -> Result<()> {
    if depth > limits.max_xml_depth {
        return Err(Error::ResourceLimit {
            what: format!("XML nesting depth of the URDF (at <{tag}>)"),
            value: depth.to_string(),
            limit: limits.max_xml_depth.to_string(),
            option: "ReadLimits::max_xml_depth (Robot::from_urdf_str_with)".into(),
        });
    }
    Ok(())
}

impl RawUrdf {
    /// Checks the element `tag` with attributes `attrs` inside the open elements `stack`: as a
    /// child of a robot's `<joint>` (recording its `<limit>`) or of a link's `<inertial>`.
    fn element(&mut self, stack: &[Open], tag: &str, attrs: &[(String, String)]) -> Result<()> {
        // Parent and grandparent tags: a robot's joint is `robot › joint`, its children
        // `robot › joint › *`, an inertial's children `robot › link › inertial › *`.
        let parent = stack.last();
        let grandparent = stack.len().checked_sub(2).and_then(|i| stack.get(i));
        let in_robot_joint = parent.is_some_and(|p| p.tag == "joint")
            && grandparent.is_some_and(|g| g.tag == "robot")
            && stack.len() == 2;
        if in_robot_joint {
            let joint = parent.map_or("", |p| p.name.as_str());
            self.joint_child(joint, tag, attrs)?;
        }
        let in_inertial = stack.len() == 3
            && parent.is_some_and(|p| p.tag == "inertial")
            && grandparent.is_some_and(|g| g.tag == "link");
        if in_inertial && !INERTIAL_CHILDREN.contains(&tag) {
            let link = grandparent.map_or("", |g| g.name.as_str());
            return Err(error(format!(
                "link `{link}`: <inertial> contains <{tag}>, which URDF does not define there; expected <origin>, <mass> or <inertia>"
            )));
        }
        Ok(())
    }

    /// Checks the element `tag` inside the robot's joint `joint`: a misspelled one is an
    /// error, an unknown one is recorded as ignored, a `<limit>` has its attributes checked
    /// and recorded.
    fn joint_child(&mut self, joint: &str, tag: &str, attrs: &[(String, String)]) -> Result<()> {
        if !JOINT_CHILDREN.contains(&tag) {
            match misspelled_joint_child(tag) {
                Some(known) => {
                    return Err(error(format!(
                        "joint `{joint}` contains <{tag}>, which URDF does not define inside <joint> (a misspelled <{known}>?); expected one of {}",
                        JOINT_CHILDREN.map(|t| format!("<{t}>")).join(", ")
                    )))
                }
                None => self.ignored.push((joint.to_string(), tag.to_string())),
            }
        }
        if tag == "limit" {
            if let Some((bad, _)) = attrs
                .iter()
                .find(|(k, _)| !LIMIT_ATTRIBUTES.contains(&k.as_str()))
            {
                return Err(error(format!(
                    "joint `{joint}`: <limit> has the attribute `{bad}`, which URDF does not define; expected {}",
                    LIMIT_ATTRIBUTES.join(", ")
                )));
            }
            self.joints.entry(joint.to_string()).or_default().limit = Some(attrs.to_vec());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edits_count_insertions_deletions_and_substitutions() {
        // Hand-counted: kitten → sitting is s/k, s/e→i, +g.
        assert_eq!(edits("kitten", "sitting"), 3);
        assert_eq!(edits("", "abc"), 3);
        assert_eq!(edits("abc", ""), 3);
        assert_eq!(edits("limit", "limit"), 0);
        assert_eq!(edits("limits", "limit"), 1);
        assert_eq!(edits("lmit", "limit"), 1);
        assert_eq!(edits("origni", "origin"), 2);
        // Symmetric.
        assert_eq!(edits("sitting", "kitten"), 3);
    }

    #[test]
    fn a_misspelling_is_near_a_known_child_and_an_extension_is_not() {
        assert_eq!(misspelled_joint_child("limits"), Some("limit"));
        assert_eq!(misspelled_joint_child("AXIS"), Some("axis"));
        assert_eq!(misspelled_joint_child("mimc"), Some("mimic"));
        assert_eq!(
            misspelled_joint_child("safety_controler"),
            Some("safety_controller")
        );
        assert_eq!(misspelled_joint_child("joint_properties"), None);
        assert_eq!(misspelled_joint_child("gazebo"), None);
        assert_eq!(misspelled_joint_child("transmission"), None);
    }
}
