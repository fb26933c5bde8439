//! BVH reader.

use std::iter::Enumerate;
use std::str::Lines;

use nalgebra::Vector3;

use super::types::{BvhChannel, BvhClip, BvhJoint, BvhReadOptions};
use crate::error::{Error, Result};
use crate::motion::plausible;

/// Reads a Biovision hierarchy (BVH) file.
///
/// Accepted: one `ROOT`, any tree of `JOINT`s and `End Site`s, `OFFSET`, `CHANNELS` with any
/// number and order of `Xposition Yposition Zposition Xrotation Yrotation Zrotation` on any joint
/// (before its children), then `MOTION`, `Frames: n`, `Frame Time: dt` and `n` lines of values
/// (degrees for rotations, the file's length unit for positions). Offsets and positions are
/// scaled by [`BvhReadOptions::length_unit`] to metres, angles converted to radians, and every
/// rotation track is unwrapped (see [`unwrap_track`](crate::motion::unwrap_track)). End sites are
/// named `<parent>_end`.
///
/// Errors are [`Error::Parse`] naming `source_name` and the 1-based line: missing `{` or `}`,
/// an unknown keyword or channel name, a `CHANNELS` count that does not match the names, a
/// non-numeric or non-finite value, a frame line with fewer or more values than channels, zero
/// frames, more or fewer frame lines than `Frames:` says, a file that ends early, more frames or
/// a longer duration (`Frame Time` × (frames − 1)) than [`BvhReadOptions::limits`] allow.
pub fn read_bvh(text: &str, source_name: &str, options: &BvhReadOptions) -> Result<BvhClip> {
    options.length_unit.validate()?;
    let text = crate::motion::strip_bom(text);
    Reader::new(text, source_name).read(options)
}

struct Reader<'a> {
    source_name: &'a str,
    text_len: usize,
    lines: Enumerate<Lines<'a>>,
    tokens: Vec<&'a str>,
    pos: usize,
    line: usize,
}

/// The numbers after `MOTION`.
#[derive(Clone, Copy)]
struct MotionHeader {
    /// Line of `Frames:`.
    frames_line: usize,
    /// Frames declared.
    frame_count: usize,
    /// Time between frames \[s\].
    frame_time: f64,
}

/// A joint whose `{ … }` block is open.
struct Open {
    index: usize,
    has_offset: bool,
    has_children: bool,
}

impl<'a> Reader<'a> {
    fn new(text: &'a str, source_name: &'a str) -> Self {
        Self {
            source_name,
            text_len: text.len(),
            lines: text.lines().enumerate(),
            tokens: Vec::new(),
            pos: 0,
            line: 0,
        }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::Parse {
            source_name: self.source_name.to_string(),
            line,
            message: message.into(),
        }
    }

    /// The next whitespace-separated token and its line.
    fn next_token(&mut self) -> Option<(&'a str, usize)> {
        loop {
            if let Some(t) = self.tokens.get(self.pos) {
                self.pos += 1;
                return Some((t, self.line));
            }
            let (i, l) = self.lines.next()?;
            self.tokens = l.split_whitespace().collect();
            self.pos = 0;
            self.line = i + 1;
        }
    }

    /// The tokens left on the current line.
    fn rest_of_line(&mut self) -> Vec<&'a str> {
        let rest = self.tokens.get(self.pos..).unwrap_or(&[]).to_vec();
        self.pos = self.tokens.len();
        rest
    }

    /// The next line that is not blank, as tokens, with its number.
    fn next_line(&mut self) -> Option<(Vec<&'a str>, usize)> {
        for (i, l) in self.lines.by_ref() {
            self.line = i + 1;
            let tokens: Vec<&str> = l.split_whitespace().collect();
            if !tokens.is_empty() {
                return Some((tokens, i + 1));
            }
        }
        None
    }

    fn number(&self, token: &str, line: usize, what: &str) -> Result<f64> {
        self.number_of(token, line, || what.to_string())
    }

    /// [`Self::number`] with the description made only for an error (a frame's values are
    /// read by the million).
    fn number_of(&self, token: &str, line: usize, what: impl FnOnce() -> String) -> Result<f64> {
        match token.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.error(line, format!("{}: `{token}` is not finite", what()))),
            Err(_) => Err(self.error(line, format!("{}: `{token}` is not a number", what()))),
        }
    }

    fn read(mut self, options: &BvhReadOptions) -> Result<BvhClip> {
        let scale = options.length_unit.metres_per_unit();
        match self.next_token() {
            Some((t, _)) if t.eq_ignore_ascii_case("HIERARCHY") => {}
            Some((t, l)) => return Err(self.error(l, format!("expected `HIERARCHY`, found `{t}`"))),
            None => return Err(self.error(0, "the file is empty (truncated file)")),
        }
        let joints = self.read_hierarchy(scale)?;
        let channel_count: usize = joints.iter().map(|j| j.channels.len()).sum();
        self.read_motion_keyword(channel_count)?;
        let header = self.read_motion_header(options)?;
        let mut values = self.read_frames(&joints, channel_count, &header)?;
        convert_units(&joints, &mut values, channel_count, scale);
        BvhClip::new(
            self.source_name,
            joints,
            header.frame_time,
            header.frame_count,
            values,
            options.up_axis,
        )
    }

    /// Reads `MOTION` after the root's closing brace; the hierarchy must declare a channel.
    fn read_motion_keyword(&mut self, channel_count: usize) -> Result<()> {
        match self.next_token() {
            Some(("MOTION", l)) => {
                if let Some(t) = self.rest_of_line().first() {
                    return Err(self.error(l, format!("unexpected `{t}` after `MOTION`")));
                }
                if channel_count == 0 {
                    return Err(self.error(l, "the hierarchy declares no channel"));
                }
                Ok(())
            }
            Some(("ROOT", l)) => Err(self.error(
                l,
                "a second `ROOT` is not supported (one skeleton per file)",
            )),
            Some((t, l)) => Err(self.error(l, format!("expected `MOTION`, found `{t}`"))),
            None => Err(self.error(self.line, "the file ends before `MOTION` (truncated file)")),
        }
    }

    /// Reads `Frames:` and `Frame Time:`, checking the count, the capture rate and the limits.
    fn read_motion_header(&mut self, options: &BvhReadOptions) -> Result<MotionHeader> {
        let (frames_line, frame_count) = self.read_header_number("Frames")?;
        let frame_count = frame_count.parse::<usize>().map_err(|_| {
            self.error(
                frames_line,
                format!("`Frames: {frame_count}` is not a frame count"),
            )
        })?;
        if frame_count == 0 {
            return Err(self.error(frames_line, "zero frames"));
        }
        let (time_line, frame_time) = self.read_header_number("Frame Time")?;
        let frame_time = self.number(&frame_time, time_line, "Frame Time")?;
        let (shortest, longest) = (
            1.0 / plausible::MAX_CAPTURE_RATE,
            1.0 / plausible::MIN_CAPTURE_RATE,
        );
        if !(shortest..=longest).contains(&frame_time) {
            return Err(self.error(
                time_line,
                format!(
                    "Frame Time {} s; expected {shortest} to {longest} s (capture rates {} to {} \
                     Hz, motion::MIN_CAPTURE_RATE / MAX_CAPTURE_RATE)",
                    crate::resources::fmt_value(frame_time),
                    plausible::MIN_CAPTURE_RATE,
                    plausible::MAX_CAPTURE_RATE
                ),
            ));
        }
        options
            .limits
            .check_clip(
                self.source_name,
                frame_count,
                frame_time * (frame_count - 1) as f64,
            )
            .map_err(|e| self.error(time_line, e.to_string()))?;
        Ok(MotionHeader {
            frames_line,
            frame_count,
            frame_time,
        })
    }

    /// Reads the frame lines: exactly `frame_count` lines of `channel_count` plausible values
    /// each (in the file's units), frame after frame.
    fn read_frames(
        &mut self,
        joints: &[BvhJoint],
        channel_count: usize,
        header: &MotionHeader,
    ) -> Result<Vec<f64>> {
        let MotionHeader {
            frames_line,
            frame_count,
            ..
        } = *header;
        // Reserve no more than the text can hold (at least two bytes per value).
        let capacity = frame_count
            .saturating_mul(channel_count)
            .min(self.text_len / 2);
        let mut values = Vec::with_capacity(capacity);
        let mut read = 0usize;
        let channels: Vec<(&str, BvhChannel)> = joints
            .iter()
            .flat_map(|j| j.channels.iter().map(move |c| (j.name.as_str(), *c)))
            .collect();
        while let Some((tokens, line)) = self.next_line() {
            if read == frame_count {
                return Err(self.error(
                    line,
                    format!(
                        "more frame lines than the {frame_count} declared at line {frames_line}"
                    ),
                ));
            }
            if tokens.len() != channel_count {
                let relation = if tokens.len() < channel_count {
                    "fewer"
                } else {
                    "more"
                };
                return Err(self.error(
                    line,
                    format!(
                        "frame {read} has {} values, {relation} than the {channel_count} channels declared",
                        tokens.len()
                    ),
                ));
            }
            for (k, (t, (joint, channel))) in tokens.iter().zip(&channels).enumerate() {
                let v = self.number_of(t, line, || format!("frame {read}, value {}", k + 1))?;
                let at = || format!("line {line}, frame {read}, channel {joint} {channel:?}");
                if channel.is_rotation() {
                    plausible::check_angle(self.source_name, at, v)?;
                } else {
                    plausible::check_coordinate(self.source_name, at, v)?;
                }
                values.push(v);
            }
            read += 1;
        }
        if read < frame_count {
            return Err(self.error(
                self.line,
                format!(
                    "truncated file: {frame_count} frames declared at line {frames_line}, {read} found"
                ),
            ));
        }
        Ok(values)
    }

    /// Reads `<key>: value` (or `<key> : value`) on the next non-blank line.
    fn read_header_number(&mut self, key: &str) -> Result<(usize, String)> {
        let Some((tokens, line)) = self.next_line() else {
            return Err(self.error(
                self.line,
                format!("the file ends before `{key}:` (truncated file)"),
            ));
        };
        let joined = tokens.join(" ");
        let value = joined
            .strip_prefix(key)
            .map(str::trim_start)
            .and_then(|r| r.strip_prefix(':'))
            .map(str::trim);
        match value {
            Some(v) if !v.is_empty() => Ok((line, v.to_string())),
            _ => Err(self.error(
                line,
                format!("expected `{key}: <number>`, found `{joined}`"),
            )),
        }
    }

    fn read_hierarchy(&mut self, scale: f64) -> Result<Vec<BvhJoint>> {
        let mut stack: Vec<Open> = Vec::new();
        // A joint header waiting for its `{`: (index, line of the header).
        let mut pending: Option<(usize, usize)> = None;
        let mut joints = vec![self.read_root(&mut pending)?];
        loop {
            let Some((token, line)) = self.next_token() else {
                let name = stack
                    .last()
                    .and_then(|o| joints.get(o.index))
                    .or(joints.last())
                    .map_or("", |j| j.name.as_str());
                return Err(self.error(
                    self.line,
                    format!("the file ends inside joint `{name}`: missing `}}` (truncated file)"),
                ));
            };
            if let Some((index, header_line)) = pending {
                if token != "{" {
                    let name = joints.get(index).map_or("", |j| j.name.as_str());
                    return Err(self.error(
                        line,
                        format!(
                            "missing `{{` after `{name}` (line {header_line}), found `{token}`"
                        ),
                    ));
                }
                pending = None;
                stack.push(Open {
                    index,
                    has_offset: false,
                    has_children: false,
                });
                continue;
            }
            let Some(open) = stack.last_mut() else {
                return Err(self.error(line, format!("unexpected `{token}`")));
            };
            let current = open.index;
            let name = || joints.get(current).map_or("", |j| j.name.as_str());
            match token {
                "}" => {
                    if !open.has_offset {
                        return Err(self.error(line, format!("joint `{}` has no OFFSET", name())));
                    }
                    stack.pop();
                    if stack.is_empty() {
                        if let Some(t) = self.rest_of_line().first() {
                            return Err(self.error(line, format!("unexpected `{t}` after `}}`")));
                        }
                        return Ok(joints);
                    }
                }
                "OFFSET" => self.read_offset(line, open, &mut joints, scale)?,
                "CHANNELS" => self.read_joint_channels(line, open, &mut joints)?,
                "JOINT" | "End" => self.read_child(token, line, open, &mut joints, &mut pending)?,
                "MOTION" | "ROOT" => {
                    return Err(self.error(
                        line,
                        format!(
                            "missing `}}`: joint `{}` is not closed before `{token}`",
                            name()
                        ),
                    ));
                }
                "{" => return Err(self.error(line, "unexpected `{`")),
                other => {
                    return Err(self.error(
                        line,
                        format!(
                        "unexpected `{other}`; expected OFFSET, CHANNELS, JOINT, End Site or `}}`"
                    ),
                    ))
                }
            }
        }
    }

    /// Reads `ROOT <name>`, the first token of the hierarchy, leaving its block to open.
    fn read_root(&mut self, pending: &mut Option<(usize, usize)>) -> Result<BvhJoint> {
        match self.next_token() {
            Some(("ROOT", l)) => {
                let name = self.header_name(l, "ROOT", pending, 0)?;
                Ok(BvhJoint {
                    name,
                    parent: None,
                    offset: Vector3::zeros(),
                    channels: Vec::new(),
                    end_site: false,
                })
            }
            Some((t, l)) => Err(self.error(l, format!("expected `ROOT`, found `{t}`"))),
            None => Err(self.error(self.line, "the file ends before `ROOT` (truncated file)")),
        }
    }

    /// Reads the open joint's `OFFSET x y z` (file units), stored scaled by `scale` \[m/unit\].
    fn read_offset(
        &mut self,
        line: usize,
        open: &mut Open,
        joints: &mut [BvhJoint],
        scale: f64,
    ) -> Result<()> {
        if open.has_offset {
            return Err(self.error(line, "a second OFFSET in the same joint"));
        }
        open.has_offset = true;
        let rest = self.rest_of_line();
        if rest.len() != 3 {
            return Err(self.error(
                line,
                format!("OFFSET needs 3 numbers, found {}", rest.len()),
            ));
        }
        let mut offset = Vector3::zeros();
        for (o, t) in offset.iter_mut().zip(&rest) {
            *o = self.number(t, line, "OFFSET")? * scale;
        }
        if let Some(j) = joints.get_mut(open.index) {
            j.offset = offset;
        }
        Ok(())
    }

    /// Reads the open joint's `CHANNELS`: once, not in an End Site, before the children.
    fn read_joint_channels(
        &mut self,
        line: usize,
        open: &Open,
        joints: &mut [BvhJoint],
    ) -> Result<()> {
        if joints.get(open.index).is_some_and(|j| j.end_site) {
            return Err(self.error(line, "an End Site cannot have CHANNELS"));
        }
        if open.has_children {
            return Err(self.error(line, "CHANNELS must come before the joint's children"));
        }
        let channels = self.channels(line)?;
        if let Some(j) = joints.get_mut(open.index) {
            if !j.channels.is_empty() {
                return Err(self.error(line, "a second CHANNELS in the same joint"));
            }
            j.channels = channels;
        }
        Ok(())
    }

    /// Reads a child of the open joint, `JOINT <name>` or `End Site` (after `token`), leaving
    /// its block to open; a name used twice is an error.
    fn read_child(
        &mut self,
        token: &str,
        line: usize,
        open: &mut Open,
        joints: &mut Vec<BvhJoint>,
        pending: &mut Option<(usize, usize)>,
    ) -> Result<()> {
        let current = open.index;
        if joints.get(current).is_some_and(|j| j.end_site) {
            return Err(self.error(line, "an End Site cannot have children"));
        }
        open.has_children = true;
        let end_site = token == "End";
        let name = if end_site {
            self.end_site_name(line, joints, current, pending)?
        } else {
            self.header_name(line, "JOINT", pending, joints.len())?
        };
        if joints.iter().any(|j| j.name == name) {
            return Err(self.error(line, format!("joint name `{name}` is used twice")));
        }
        joints.push(BvhJoint {
            name,
            parent: Some(current),
            offset: Vector3::zeros(),
            channels: Vec::new(),
            end_site,
        });
        Ok(())
    }

    /// The name after `ROOT`/`JOINT` (the rest of the line, a trailing `{` opening the block).
    fn header_name(
        &mut self,
        line: usize,
        keyword: &str,
        pending: &mut Option<(usize, usize)>,
        index: usize,
    ) -> Result<String> {
        let mut rest = self.rest_of_line();
        let brace_on_line = rest.last() == Some(&"{");
        if brace_on_line {
            rest.pop();
        }
        if rest.is_empty() || rest.iter().any(|t| t.contains('{') || t.contains('}')) {
            return Err(self.error(line, format!("`{keyword}` needs a name")));
        }
        *pending = Some((index, line));
        if brace_on_line {
            // Re-inject the brace so that the main loop opens the block.
            self.tokens = vec!["{"];
            self.pos = 0;
        }
        Ok(rest.join(" "))
    }

    fn end_site_name(
        &mut self,
        line: usize,
        joints: &[BvhJoint],
        parent: usize,
        pending: &mut Option<(usize, usize)>,
    ) -> Result<String> {
        let mut rest = self.rest_of_line();
        let brace_on_line = rest.last() == Some(&"{");
        if brace_on_line {
            rest.pop();
        }
        if rest != ["Site"] {
            return Err(self.error(line, "expected `End Site`"));
        }
        *pending = Some((joints.len(), line));
        if brace_on_line {
            self.tokens = vec!["{"];
            self.pos = 0;
        }
        let base = format!(
            "{}_end",
            joints.get(parent).map_or("joint", |j| j.name.as_str())
        );
        let mut name = base.clone();
        let mut k = 2;
        while joints.iter().any(|j| j.name == name) {
            name = format!("{base}{k}");
            k += 1;
        }
        Ok(name)
    }

    fn channels(&mut self, line: usize) -> Result<Vec<BvhChannel>> {
        let rest = self.rest_of_line();
        let Some((count, names)) = rest.split_first() else {
            return Err(self.error(line, "CHANNELS needs a count"));
        };
        let count: usize = count
            .parse()
            .map_err(|_| self.error(line, format!("CHANNELS count `{count}` is not a number")))?;
        if names.len() != count {
            return Err(self.error(
                line,
                format!(
                    "CHANNELS declares {count} channels but lists {}",
                    names.len()
                ),
            ));
        }
        let mut channels: Vec<BvhChannel> = Vec::with_capacity(count);
        for n in names {
            let c = BvhChannel::from_name(n).ok_or_else(|| {
                self.error(
                    line,
                    format!(
                        "unknown channel `{n}`; valid channels are Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation"
                    ),
                )
            })?;
            if channels.contains(&c) {
                return Err(self.error(line, format!("channel `{n}` listed twice")));
            }
            channels.push(c);
        }
        Ok(channels)
    }
}

/// Scales positions to metres, unwraps every rotation track (in degrees, period 360) and converts
/// it to radians.
fn convert_units(joints: &[BvhJoint], values: &mut [f64], channel_count: usize, scale: f64) {
    let kinds: Vec<bool> = joints
        .iter()
        .flat_map(|j| j.channels.iter().map(|c| c.is_rotation()))
        .collect();
    if channel_count == 0 {
        return;
    }
    for (c, is_rotation) in kinds.iter().enumerate() {
        let mut previous: Option<f64> = None;
        for v in values.iter_mut().skip(c).step_by(channel_count) {
            if *is_rotation {
                if let Some(p) = previous {
                    *v += 360.0 * ((p - *v) / 360.0).round();
                }
                previous = Some(*v);
            } else {
                *v *= scale;
            }
        }
        if *is_rotation {
            for v in values.iter_mut().skip(c).step_by(channel_count) {
                *v = v.to_radians();
            }
        }
    }
}
