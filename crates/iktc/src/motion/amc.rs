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

/// The frames of an AMC file read so far, with the frame being read.
struct AmcReader<'a> {
    asf: &'a Asf,
    source: &'a str,
    /// Joints of the ASF's skeleton.
    skeleton_len: usize,
    /// Angles in degrees (else radians).
    degrees: bool,
    /// Values per slot: slot 0 the root, slot b + 1 bone b.
    dof_count: Vec<usize>,
    /// Name per slot.
    names: Vec<&'a str>,
    frames: Vec<super::Pose>,
    /// Time of each frame \[s\].
    times: Vec<f64>,
    /// The frame being read: (number, line, values per slot).
    current: Option<Pending>,
}

impl<'a> AmcReader<'a> {
    /// A reader with no frame yet, in the ASF's angle unit.
    fn new(asf: &'a Asf, source: &'a str, skeleton_len: usize) -> Self {
        AmcReader {
            asf,
            source,
            skeleton_len,
            degrees: asf.degrees,
            dof_count: std::iter::once(asf.root_order.len())
                .chain(asf.bones.iter().map(|b| b.dofs.len()))
                .collect(),
            names: std::iter::once("root")
                .chain(asf.bones.iter().map(|b| b.name.as_str()))
                .collect(),
            frames: Vec::new(),
            times: Vec::new(),
            current: None,
        }
    }

    /// A parse error at `line`.
    fn error(&self, line: usize, message: String) -> Error {
        Error::Parse {
            source_name: self.source.to_string(),
            line,
            message,
        }
    }

    /// Takes one non-blank line: a header keyword, a frame number or a value line.
    fn line(&mut self, line: usize, l: &str, frame_rate: f64) -> Result<()> {
        if l.starts_with(':') {
            match l.to_ascii_uppercase().as_str() {
                ":DEGREES" => self.degrees = true,
                ":RADIANS" => self.degrees = false,
                _ => {}
            }
            return Ok(());
        }
        let tokens: Vec<&str> = l.split_whitespace().collect();
        if tokens.len() == 1 && tokens[0].parse::<u64>().is_ok() {
            self.finish_frame(line)?;
            self.times.push(self.frames.len() as f64 / frame_rate);
            self.current = Some((tokens[0].to_string(), line, vec![None; self.names.len()]));
            return Ok(());
        }
        self.value_line(line, &tokens)
    }

    /// Reads `name v_1 … v_n` into the frame being read, checking count, range and repetition.
    fn value_line(&mut self, line: usize, tokens: &[&str]) -> Result<()> {
        if self.current.is_none() {
            return Err(self.error(
                line,
                format!("`{}` before the first frame number", tokens[0]),
            ));
        }
        let slot = self
            .names
            .iter()
            .position(|n| *n == tokens[0])
            .ok_or_else(|| {
                self.error(
                    line,
                    format!(
                        "unknown bone `{}`; the skeleton `{}` has: {}",
                        tokens[0],
                        self.asf.source,
                        crate::error::name_list(&self.names)
                    ),
                )
            })?;
        if tokens.len() - 1 != self.dof_count[slot] {
            return Err(self.error(
                line,
                format!(
                    "`{}` has {} values; its degrees of freedom need {}",
                    tokens[0],
                    tokens.len() - 1,
                    self.dof_count[slot]
                ),
            ));
        }
        if self.current.as_ref().is_some_and(|c| c.2[slot].is_some()) {
            return Err(self.error(line, format!("`{}` given twice in one frame", tokens[0])));
        }
        let parsed = tokens[1..]
            .iter()
            .map(|t| {
                t.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| self.error(line, format!("`{t}` is not a finite number")))
            })
            .collect::<Result<Vec<f64>>>()?;
        self.check_values(line, tokens[0], slot, &parsed)?;
        if let Some((_, _, values)) = self.current.as_mut() {
            values[slot] = Some(parsed);
        }
        Ok(())
    }

    /// Checks the values of slot `slot` (named `name`) are plausible angles and coordinates.
    fn check_values(&self, line: usize, name: &str, slot: usize, parsed: &[f64]) -> Result<()> {
        let dofs = if slot == 0 {
            &self.asf.root_order
        } else {
            &self.asf.bones[slot - 1].dofs
        };
        for (v, dof) in parsed.iter().zip(dofs) {
            let at = || format!("line {line}, frame {}, {name} {dof:?}", self.frames.len());
            match dof {
                AsfDof::Rotation(_) if self.degrees => plausible::check_angle(self.source, at, *v)?,
                AsfDof::Rotation(_) => plausible::check_angle(self.source, at, v.to_degrees())?,
                AsfDof::Translation(_) => plausible::check_coordinate(self.source, at, *v)?,
            }
        }
        Ok(())
    }

    /// Ends the frame being read, if any, at `end_line`: every slot with dofs must have values.
    fn finish_frame(&mut self, end_line: usize) -> Result<()> {
        let Some((number, line, values)) = self.current.take() else {
            return Ok(());
        };
        if let Some(missing) =
            (0..self.names.len()).find(|s| self.dof_count[*s] > 0 && values[*s].is_none())
        {
            return Err(self.error(
                end_line,
                format!(
                    "frame {number} (line {line}) has no values for `{}` (truncated frame?)",
                    self.names[missing]
                ),
            ));
        }
        let root = values[0].clone().unwrap_or_default();
        let bones: Vec<Vec<f64>> = values[1..]
            .iter()
            .map(|v| v.clone().unwrap_or_default())
            .collect();
        self.frames.push(
            self.asf
                .pose(&root, &bones, self.skeleton_len, self.degrees),
        );
        Ok(())
    }
}

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
    let skeleton = asf.skeleton()?;
    let mut reader = AmcReader::new(asf, source, skeleton.len());
    let last_line = text.lines().count();
    for (line, l) in super::asf::acclaim_lines(text) {
        reader.line(line, l, frame_rate)?;
    }
    if reader.current.is_none() {
        return Err(reader.error(last_line, "no frame".to_string()));
    }
    reader.finish_frame(last_line)?;
    let AmcReader {
        mut frames, times, ..
    } = reader;
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
