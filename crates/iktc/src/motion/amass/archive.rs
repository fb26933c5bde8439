//! An AMASS motion archive (`.npz`): axis-angle poses, root translations, shape coefficients,
//! gender and frame rate, as written for SMPL-H (`poses` of 156 values per frame) or SMPL-X
//! (165 values per frame).

use std::io::{Read, Seek};

use nalgebra::Vector3;

use super::SmplLayout;
use crate::error::{Error, Result};
use crate::npz::Npz;
use crate::resources::ReadLimits;

/// The keys AMASS uses for the frame rate \[Hz\]: `mocap_framerate` (SMPL-H releases) and
/// `mocap_frame_rate` (SMPL-X releases).
pub const FRAME_RATE_KEYS: [&str; 2] = ["mocap_framerate", "mocap_frame_rate"];

/// Most shape coefficients accepted in an archive \[–\] (AMASS writes 16).
pub const MAX_BETAS: usize = 4_000;

/// Most pose values per frame accepted \[–\]: 3 per joint, at most
/// [`MAX_MODEL_JOINTS`](super::MAX_MODEL_JOINTS) joints.
const MAX_POSE_WIDTH: usize = 3 * super::MAX_MODEL_JOINTS;

/// An AMASS archive's content (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct AmassArchive {
    /// Frame rate \[Hz\].
    pub frame_rate: f64,
    /// Number of joints per frame, J (a third of the `poses` width).
    pub joint_count: usize,
    /// Axis-angle vectors, frame by frame, joint by joint (`poses`, T×3J): joint `i`'s
    /// rotation in frame `t` is `poses[(t · J + i) · 3 ..][..3]`, its direction the axis and
    /// its norm the angle \[rad\]; joint 0's is the root's orientation in the world.
    pub poses: Vec<f64>,
    /// The root translation of every frame (`trans`) \[m\], Z up.
    pub trans: Vec<Vector3<f64>>,
    /// The body's shape coefficients (`betas`) \[–\]; empty (the mean shape) when the archive
    /// has none.
    pub betas: Vec<f64>,
    /// The subject's gender (`gender`: `male`, `female`, `neutral`), if the archive holds a
    /// readable one.
    pub gender: Option<String>,
}

impl AmassArchive {
    /// Reads an archive; `source` names it in errors.
    ///
    /// Checks: a frame rate under one of [`FRAME_RATE_KEYS`], finite and positive; `poses`
    /// T×3J and `trans` T×3 with the same T ≥ 1; T and the duration `(T − 1) / rate`
    /// within `limits`; every value finite.
    ///
    /// Errors: [`Error::Parse`] naming the archive and the array; [`Error::NonFinite`] naming
    /// the array, frame and column; [`Error::ResourceLimit`] from `limits`.
    pub fn from_reader<R: Read + Seek>(
        reader: R,
        source: &str,
        limits: &ReadLimits,
    ) -> Result<Self> {
        let mut npz = Npz::new(reader, source)?;
        let bad = |message: String| archive_error(source, message);
        let frame_rate = read_frame_rate(&mut npz, source)?;
        let shape = npz.shape("poses")?;
        let (frames, width) = match shape[..] {
            [t, w] if t >= 1 && w >= 3 && w % 3 == 0 && w <= MAX_POSE_WIDTH => (t, w),
            _ => {
                return Err(bad(format!(
                    "`poses` has shape {shape:?}, expected (frames ≥ 1, 3 × joints): 156 for \
                     SMPL-H, 165 for SMPL-X"
                )))
            }
        };
        limits.check_clip(source, frames, (frames - 1) as f64 / frame_rate)?;
        let poses = npz.array("poses", frames * width)?;
        let trans = npz.array("trans", frames * 3)?;
        if trans.shape[..] != [frames, 3] {
            return Err(bad(format!(
                "`trans` has shape {:?}, expected ({frames}, 3): one root translation per \
                 frame of `poses`",
                trans.shape
            )));
        }
        for (name, values, columns) in
            [("poses", &poses.values, width), ("trans", &trans.values, 3)]
        {
            if let Some(k) = values.iter().position(|x| !x.is_finite()) {
                return Err(Error::NonFinite {
                    what: format!(
                        "{source}: `{name}` at frame {} column {}",
                        k / columns,
                        k % columns
                    ),
                    value: values[k],
                });
            }
        }
        let betas = read_betas(&mut npz, source)?;
        Ok(Self {
            frame_rate,
            joint_count: width / 3,
            poses: poses.values,
            trans: trans
                .values
                .chunks_exact(3)
                .map(Vector3::from_column_slice)
                .collect(),
            betas,
            gender: npz.text("gender").filter(|g| !g.is_empty()),
        })
    }

    /// Number of frames T.
    pub fn frame_count(&self) -> usize {
        self.trans.len()
    }

    /// The layout its joint count gives, if AMASS uses it.
    pub fn layout(&self) -> Option<SmplLayout> {
        SmplLayout::from_joint_count(self.joint_count)
    }

    /// The axis-angle vector of joint `joint` in frame `frame` \[rad\] (`None` past the
    /// last frame or joint).
    pub fn axis_angle(&self, frame: usize, joint: usize) -> Option<Vector3<f64>> {
        if joint >= self.joint_count {
            return None;
        }
        let k = (frame * self.joint_count + joint) * 3;
        self.poses.get(k..k + 3).map(Vector3::from_column_slice)
    }
}

/// An [`Error::Parse`] about the archive `source`.
fn archive_error(source: &str, message: String) -> Error {
    Error::Parse {
        source_name: source.to_string(),
        line: 0,
        message,
    }
}

/// The frame rate \[Hz\] under the first of [`FRAME_RATE_KEYS`] the archive holds: one
/// finite number > 0.
fn read_frame_rate<R: Read + Seek>(npz: &mut Npz<R>, source: &str) -> Result<f64> {
    let key = FRAME_RATE_KEYS.iter().find(|k| npz.has(k)).ok_or_else(|| {
        archive_error(
            source,
            format!(
                "no frame rate: an AMASS archive holds `{}` or `{}`; it holds: {}",
                FRAME_RATE_KEYS[0],
                FRAME_RATE_KEYS[1],
                npz.names().join(", ")
            ),
        )
    })?;
    let rate = npz.array(key, 1)?;
    match rate.values[..] {
        [r] if r.is_finite() && r > 0.0 => Ok(r),
        _ => Err(archive_error(
            source,
            format!(
                "`{key}` is {:?}, expected one finite frame rate > 0 [Hz]",
                rate.values
            ),
        )),
    }
}

/// The shape coefficients `betas` (empty when absent), every one finite.
fn read_betas<R: Read + Seek>(npz: &mut Npz<R>, source: &str) -> Result<Vec<f64>> {
    let betas = if npz.has("betas") {
        npz.array("betas", MAX_BETAS)?.values
    } else {
        Vec::new()
    };
    if let Some(k) = betas.iter().position(|x| !x.is_finite()) {
        return Err(Error::NonFinite {
            what: format!("{source}: `betas` at element {k}"),
            value: betas[k],
        });
    }
    Ok(betas)
}
