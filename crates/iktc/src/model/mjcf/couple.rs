//! What MJCF says about joints outside the body tree: `<equality><joint>` couplings read as
//! mimic joints, `<actuator>` force ranges read as effort limits.

use super::body::Tree;
use super::defaults::{Attrs, Defaults, MAIN};
use super::spec::{boolean, numbers, Compiler};
use super::xml::El;
use crate::error::{Error, Result};

/// Reads every `<equality><joint joint1 joint2 polycoef>` as joint1 mimicking joint2 when the
/// polynomial is linear: MuJoCo's `q1 − ref1 = c0 + c1 (q2 − ref2)` is
/// `q1 = c1 q2 + (ref1 + c0 − c1 ref2)`. A non-linear polynomial, an equality without
/// `joint2` (joint1 held still), one with `active="false"` and the other equality types
/// (connect, weld, tendon, …) are left out with a warning.
///
/// Errors: a `joint1` or `joint2` that names no hinge or slide joint, a bad number.
pub(crate) fn equalities(root: &El, d: &Defaults, t: &mut Tree) -> Result<()> {
    for eq in root.elements("equality") {
        for el in &eq.children {
            if el.tag != "joint" {
                t.warnings.push(format!(
                    "MJCF: {} left out (iktc reads joint equalities as mimic joints only)",
                    el.at()
                ));
                continue;
            }
            let a = Attrs::new(el, MAIN, d)?;
            if let Some(v) = a.get("active") {
                if !boolean(el, "active", v)? {
                    t.warnings
                        .push(format!("MJCF: {} is inactive: left out", el.at()));
                    continue;
                }
            }
            let known = |t: &Tree, attr: &str| -> Result<Option<(String, f64)>> {
                let Some(n) = el.attr(attr) else {
                    return Ok(None);
                };
                match t.refs.get(n) {
                    Some(r) => Ok(Some((n.to_string(), *r))),
                    None => Err(el.error(format!(
                        "{attr}=\"{n}\" names no hinge or slide joint; joints are {}",
                        crate::error::name_list(
                            &t.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>()
                        )
                    ))),
                }
            };
            let Some((j1, r1)) = known(t, "joint1")? else {
                return Err(el.error("has no `joint1` (expected the joint it constrains)"));
            };
            let c =
                numbers(&a, "polycoef", Some(5))?.unwrap_or_else(|| vec![0.0, 1.0, 0.0, 0.0, 0.0]);
            let Some((j2, r2)) = known(t, "joint2")? else {
                t.warnings.push(format!(
                    "MJCF: {} holds `{j1}` still: left out (lock the joint: ModelOptions::locked, --lock)",
                    el.at()
                ));
                continue;
            };
            if c[2..].iter().any(|x| *x != 0.0) {
                t.warnings.push(format!(
                    "MJCF: {}: polycoef=\"{}\" is not linear: left out, `{j1}` moves on its own",
                    el.at(),
                    a.get("polycoef").unwrap_or("")
                ));
                continue;
            }
            let spec = t
                .joints
                .iter_mut()
                .find(|j| j.name == j1)
                .ok_or_else(|| Error::Urdf {
                    message: format!("MJCF: joint `{j1}` is missing from the tree"),
                })?;
            spec.mimic = Some((j2, c[1], r1 + c[0] - c[1] * r2));
        }
    }
    Ok(())
}

/// Reads the effort limit \[N·m or N\] of each joint without `actuatorfrcrange` from the
/// actuators that drive it (`joint=`): `forcerange` when force-limited, else for a `<motor>`
/// its `ctrlrange` times `|gear|` when control-limited; the largest magnitude of the range.
///
/// Errors: a bad number.
pub(crate) fn efforts(root: &El, c: &Compiler, d: &Defaults, t: &mut Tree) -> Result<()> {
    for act in root.elements("actuator") {
        for el in &act.children {
            let a = Attrs::new(el, MAIN, d)?;
            let Some(joint) = a.get("joint") else {
                continue;
            };
            if t.effort_given.contains(joint) {
                continue;
            }
            let limited = |flag: &str, range: &str| -> Result<Option<f64>> {
                let r = numbers(&a, range, Some(2))?;
                let on = match a.get(flag).unwrap_or("auto") {
                    "auto" => c.autolimits && r.is_some(),
                    v => boolean(el, flag, v)?,
                };
                Ok(r.filter(|_| on).map(|r| r[0].abs().max(r[1].abs())))
            };
            let effort = match limited("forcelimited", "forcerange")? {
                Some(f) => Some(f),
                None if el.tag == "motor" => {
                    let gear = numbers(&a, "gear", None)?
                        .and_then(|g| g.first().copied())
                        .unwrap_or(1.0);
                    limited("ctrllimited", "ctrlrange")?.map(|u| u * gear.abs())
                }
                None => None,
            };
            let Some(effort) = effort else { continue };
            if let Some(j) = t.joints.iter_mut().find(|j| j.name == joint) {
                j.limit.effort = effort;
                t.effort_given.insert(joint.to_string());
            }
        }
    }
    Ok(())
}
