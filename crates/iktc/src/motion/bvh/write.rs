//! BVH writer.

use std::fmt::Write as _;

use super::types::{BvhClip, BvhWriteOptions};
use crate::error::{Error, Result};

/// Writes a [`BvhClip`] as BVH text: offsets and positions divided by the length unit's metres
/// per unit, angles in degrees, tab-indented hierarchy, one line per frame.
///
/// With `decimals: None` numbers are written in the shortest form that reads back to the same
/// `f64`, so `read_bvh(write_bvh(x))` equals `x` up to the rounding of the unit and degree
/// conversions (about 1e-16 relative), provided `x`'s angle tracks are unwrapped (as
/// [`read_bvh`](super::read_bvh) and [`BvhClip::from_clip`] make them); otherwise the reader
/// unwraps them. Errors: an invalid length unit, or a joint name that BVH cannot carry (empty,
/// containing `{`, `}` or whitespace other than single spaces between words).
pub fn write_bvh(clip: &BvhClip, options: &BvhWriteOptions) -> Result<String> {
    options.length_unit.validate()?;
    let scale = options.length_unit.metres_per_unit();
    for j in clip.joints().iter().filter(|j| !j.end_site) {
        let normal = j.name.split_whitespace().collect::<Vec<_>>().join(" ");
        if j.name.is_empty() || normal != j.name || j.name.contains(['{', '}']) {
            return Err(Error::InvalidSetting {
                name: "BVH joint name".to_string(),
                value: format!("`{}`", j.name),
                expected: "a non-empty name without braces, tabs, newlines or repeated spaces"
                    .to_string(),
            });
        }
    }
    let num = |v: f64| match options.decimals {
        Some(d) => format!("{v:.d$}"),
        None => format!("{v}"),
    };
    let mut out = String::from("HIERARCHY\n");
    // Joints are in depth-first order: close blocks until the parent is on top of the stack.
    let mut stack: Vec<usize> = Vec::new();
    for (i, joint) in clip.joints().iter().enumerate() {
        while let Some(&top) = stack.last() {
            if Some(top) == joint.parent {
                break;
            }
            stack.pop();
            let _ = writeln!(out, "{}}}", "\t".repeat(stack.len()));
        }
        let indent = "\t".repeat(stack.len());
        let header = match (joint.parent, joint.end_site) {
            (None, _) => format!("ROOT {}", joint.name),
            (Some(_), true) => "End Site".to_string(),
            (Some(_), false) => format!("JOINT {}", joint.name),
        };
        let _ = writeln!(out, "{indent}{header}\n{indent}{{");
        let o = joint.offset / scale;
        let _ = writeln!(
            out,
            "{indent}\tOFFSET {} {} {}",
            num(o.x),
            num(o.y),
            num(o.z)
        );
        if !joint.end_site {
            let mut line = format!("{indent}\tCHANNELS {}", joint.channels.len());
            for c in &joint.channels {
                line.push(' ');
                line.push_str(c.name());
            }
            let _ = writeln!(out, "{line}");
        }
        stack.push(i);
    }
    while stack.pop().is_some() {
        let _ = writeln!(out, "{}}}", "\t".repeat(stack.len()));
    }
    let _ = writeln!(
        out,
        "MOTION\nFrames: {}\nFrame Time: {}",
        clip.frame_count(),
        clip.frame_time()
    );
    let kinds: Vec<bool> = clip
        .joints()
        .iter()
        .flat_map(|j| j.channels.iter().map(|c| c.is_rotation()))
        .collect();
    for f in 0..clip.frame_count() {
        let Some(values) = clip.frame(f) else { break };
        let line: Vec<String> = values
            .iter()
            .zip(&kinds)
            .map(|(v, rot)| num(if *rot { v.to_degrees() } else { v / scale }))
            .collect();
        let _ = writeln!(out, "{}", line.join(" "));
    }
    Ok(out)
}

/// Writes a [`Clip`](crate::motion::Clip) as BVH text: [`BvhClip::from_clip`] then
/// [`write_bvh`].
pub fn write_clip_bvh(
    clip: &crate::motion::Clip,
    export: &super::BvhExportOptions,
    options: &BvhWriteOptions,
) -> Result<String> {
    write_bvh(&BvhClip::from_clip(clip, export)?, options)
}
