//! Marker trajectories (C3D markers, CSV points): named 3D tracks with gaps, and gap filling.
//!
//! A gap of `g` frames between valid samples `a` (frame `i`) and `b` (frame `i + g + 1`) is
//! filled linearly, `p_{i+k} = a + (b − a)·k/(g + 1)`, when its duration
//! `t_{i+g+1} − t_i` is at most the allowed one; a gap at the start or end of the clip is held
//! at the nearest sample under the same rule (measured from the first or last frame); a longer
//! gap is an error naming the marker and the frames.

use nalgebra::Vector3;

use crate::error::{Error, Result};

/// Named marker trajectories sampled at common frame times.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerSet {
    /// The file they were read from (for messages).
    pub source: String,
    /// Marker names, as in the file.
    pub names: Vec<String>,
    /// Time of every frame \[s\], strictly increasing.
    pub times: Vec<f64>,
    /// Frame-major positions: frame `f`, marker `m` at `f · names.len() + m` \[file units\];
    /// `None` where the marker was not seen.
    pub positions: Vec<Option<Vector3<f64>>>,
}

/// A gap that was filled.
#[derive(Debug, Clone, PartialEq)]
pub struct FilledGap {
    /// The marker.
    pub marker: String,
    /// First missing frame.
    pub first_frame: usize,
    /// Number of missing frames.
    pub frames: usize,
}

/// Default longest gap filled \[s\] (12 frames at 120 Hz). Longer fills invent more motion; shorter
/// rejects more real recordings.
pub const DEFAULT_MAX_GAP: f64 = 0.1;

impl MarkerSet {
    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.times.len()
    }

    /// Index of the marker called `name`, or [`Error::UnknownName`] naming the file.
    pub fn index_of(&self, name: &str) -> Result<usize> {
        self.names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| Error::UnknownName {
                kind: "marker",
                name: format!("{name}` in `{}", self.source),
                valid: self.names.clone(),
            })
    }

    /// The track of marker `m` with its gaps filled (see the module documentation);
    /// `max_gap` \[s\].
    pub fn filled_track(
        &self,
        m: usize,
        max_gap: f64,
    ) -> Result<(Vec<Vector3<f64>>, Vec<FilledGap>)> {
        let n = self.names.len();
        let name = self.names.get(m).cloned().unwrap_or_default();
        let raw: Vec<Option<Vector3<f64>>> = (0..self.frame_count())
            .map(|f| self.positions.get(f * n + m).copied().flatten())
            .collect();
        let frames = raw.len();
        let mut out = vec![Vector3::zeros(); frames];
        let mut gaps = Vec::new();
        let mut f = 0;
        while f < frames {
            if let Some(p) = raw[f] {
                out[f] = p;
                f += 1;
                continue;
            }
            let start = f;
            while f < frames && raw[f].is_none() {
                f += 1;
            }
            let before = start.checked_sub(1).and_then(|b| raw[b].map(|p| (b, p)));
            let after = raw.get(f).copied().flatten().map(|p| (f, p));
            let span = |a: usize, b: usize| self.times[b.min(frames - 1)] - self.times[a];
            // Interpolate between (a, pa) and (b, pb); a = b holds pa.
            let (duration, a, pa, b, pb) = match (before, after) {
                (Some((a, pa)), Some((b, pb))) => (span(a, b), a, pa, b, pb),
                (None, Some((b, pb))) => (span(0, b), b, pb, b, pb),
                (Some((a, pa)), None) => (span(a, frames - 1), a, pa, a, pa),
                (None, None) => {
                    return Err(Error::InsufficientData {
                        what: format!("marker `{name}` in `{}`", self.source),
                        message: "the marker is never seen".to_string(),
                    })
                }
            };
            if duration > max_gap {
                return Err(Error::InsufficientData {
                    what: format!("marker `{name}` in `{}`", self.source),
                    message: format!(
                        "missing in frames {start}–{} ({duration:.4} s); gaps up to {max_gap} s are filled",
                        f - 1
                    ),
                });
            }
            for (k, o) in out.iter_mut().enumerate().take(f).skip(start) {
                *o = if b > a {
                    pa + (pb - pa) * ((k - a) as f64 / (b - a) as f64)
                } else {
                    pa
                };
            }
            gaps.push(FilledGap {
                marker: name.clone(),
                first_frame: start,
                frames: f - start,
            });
        }
        Ok((out, gaps))
    }

    /// The frame with the most markers seen (the first of them), for rest measurements.
    pub(crate) fn most_complete_frame(&self) -> usize {
        let n = self.names.len().max(1);
        (0..self.frame_count())
            .map(|f| {
                let seen = (0..n)
                    .filter(|m| self.positions.get(f * n + m).is_some_and(|p| p.is_some()))
                    .count();
                (f, seen)
            })
            .fold((0, 0), |best, x| if x.1 > best.1 { x } else { best })
            .0
    }
}
