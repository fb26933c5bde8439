//! Acclaim motion files (AMC) on an [`Asf`] skeleton.
//!
//! Layout: comment lines (`#`), header keywords (`:FULLY-SPECIFIED`, `:DEGREES`, `:RADIANS`),
//! then frames: a line holding the frame number, followed by one line `name v_1 … v_n` per
//! moving bone and the root, the values in the bone's `dof` order (the root's in its `order`).
//! Every frame must give the root and every bone with degrees of freedom, each exactly once.
//! AMC files carry no rate: frames are `1 / frame_rate` apart (CMU records at 120 Hz,
//! [`AMC_DEFAULT_RATE`]). `:RADIANS`/`:DEGREES` override the ASF's angle unit.

use super::asf::{Asf, AsfDof};
use super::{plausible, Clip, UpAxis};
use crate::error::{Error, Result};

/// A frame being read: its number, its line and the values given so far per slot.
type Pending = (String, usize, Vec<Option<Vec<f64>>>);

/// Frame rate assumed for AMC files \[Hz\] (the CMU database's).
pub const AMC_DEFAULT_RATE: f64 = 120.0;

/// Reads an AMC file on the skeleton `asf` at `frame_rate` \[Hz\]; `source` names it in errors
/// ([`Error::Parse`] with the line): a value line before the first frame number, an unknown
/// bone, a wrong number of values, a non-finite value, a bone given twice, a frame missing a
/// bone (a truncated frame), no frame.
pub fn read_amc(text: &str, source: &str, asf: &Asf, frame_rate: f64) -> Result<Clip> {
    let text = super::strip_bom(text);
    if !(frame_rate.is_finite() && frame_rate > 0.0) {
        return Err(Error::InvalidSetting {
            name: "AMC frame rate".to_string(),
            value: frame_rate.to_string(),
            expected: "a rate > 0 [Hz]".to_string(),
        });
    }
    let error = |line: usize, message: String| Error::Parse {
        source_name: source.to_string(),
        line,
        message,
    };
    let skeleton = asf.skeleton()?;
    let mut degrees = asf.degrees;
    // Slot 0: the root; slot b + 1: bone b.
    let dof_count: Vec<usize> = std::iter::once(asf.root_order.len())
        .chain(asf.bones.iter().map(|b| b.dofs.len()))
        .collect();
    let names: Vec<&str> = std::iter::once("root")
        .chain(asf.bones.iter().map(|b| b.name.as_str()))
        .collect();
    let mut frames = Vec::new();
    let mut times = Vec::new();
    // The frame being read: (number, line, values per slot).
    let mut current: Option<Pending> = None;
    let finish = |frame: Pending,
                  end_line: usize,
                  degrees: bool,
                  frames: &mut Vec<super::Pose>|
     -> Result<()> {
        let (number, line, values) = frame;
        if let Some(missing) = (0..names.len()).find(|s| dof_count[*s] > 0 && values[*s].is_none())
        {
            return Err(error(
                end_line,
                format!(
                    "frame {number} (line {line}) has no values for `{}` (truncated frame?)",
                    names[missing]
                ),
            ));
        }
        let root = values[0].clone().unwrap_or_default();
        let bones: Vec<Vec<f64>> = values[1..]
            .iter()
            .map(|v| v.clone().unwrap_or_default())
            .collect();
        frames.push(asf.pose(&root, &bones, skeleton.len(), degrees));
        Ok(())
    };
    let last_line = text.lines().count();
    for (line, l) in super::asf::acclaim_lines(text) {
        if l.starts_with(':') {
            match l.to_ascii_uppercase().as_str() {
                ":DEGREES" => degrees = true,
                ":RADIANS" => degrees = false,
                _ => {}
            }
            continue;
        }
        let tokens: Vec<&str> = l.split_whitespace().collect();
        if tokens.len() == 1 && tokens[0].parse::<u64>().is_ok() {
            if let Some(frame) = current.take() {
                finish(frame, line, degrees, &mut frames)?;
            }
            times.push(frames.len() as f64 / frame_rate);
            current = Some((tokens[0].to_string(), line, vec![None; names.len()]));
            continue;
        }
        let Some((_, _, values)) = current.as_mut() else {
            return Err(error(
                line,
                format!("`{}` before the first frame number", tokens[0]),
            ));
        };
        let slot = names.iter().position(|n| *n == tokens[0]).ok_or_else(|| {
            error(
                line,
                format!(
                    "unknown bone `{}`; the skeleton `{}` has: {}",
                    tokens[0],
                    asf.source,
                    crate::error::name_list(&names)
                ),
            )
        })?;
        if tokens.len() - 1 != dof_count[slot] {
            return Err(error(
                line,
                format!(
                    "`{}` has {} values; its degrees of freedom need {}",
                    tokens[0],
                    tokens.len() - 1,
                    dof_count[slot]
                ),
            ));
        }
        if values[slot].is_some() {
            return Err(error(
                line,
                format!("`{}` given twice in one frame", tokens[0]),
            ));
        }
        let parsed = tokens[1..]
            .iter()
            .map(|t| {
                t.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| error(line, format!("`{t}` is not a finite number")))
            })
            .collect::<Result<Vec<f64>>>()?;
        let dofs = if slot == 0 {
            &asf.root_order
        } else {
            &asf.bones[slot - 1].dofs
        };
        for (v, dof) in parsed.iter().zip(dofs) {
            let at = || format!("line {line}, frame {}, {} {dof:?}", frames.len(), tokens[0]);
            match dof {
                AsfDof::Rotation(_) if degrees => plausible::check_angle(source, at, *v)?,
                AsfDof::Rotation(_) => plausible::check_angle(source, at, v.to_degrees())?,
                AsfDof::Translation(_) => plausible::check_coordinate(source, at, *v)?,
            }
        }
        values[slot] = Some(parsed);
    }
    match current.take() {
        Some(frame) => finish(frame, last_line, degrees, &mut frames)?,
        None => return Err(error(last_line, "no frame".to_string())),
    }
    // Translation dofs of the root are absolute positions.
    if !asf
        .root_order
        .iter()
        .any(|d| matches!(d, AsfDof::Translation(_)))
    {
        for pose in &mut frames {
            pose.root_position = asf.root_position;
        }
    }
    Clip::new(source, skeleton, times, frames, UpAxis::Y)
}
