//! A captured motion clip: a skeleton and one pose per frame, with sampling at any time.

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::Skeleton;
use crate::error::{Error, Result};

/// Which world axis points up in a clip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// +Y is up (DeepMimic, most BVH files).
    #[default]
    Y,
    /// +Z is up (robotics, the rest of this library).
    Z,
}

/// The pose of a skeleton at one instant.
///
/// Indexed like [`Skeleton::joints`]. The root's entries of `rotations` and `translations` are
/// not used (its pose is `root_position`, `root_orientation`); readers set them to identity and
/// zero.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Position of the root joint in the world \[m\].
    pub root_position: Vector3<f64>,
    /// Orientation of the root joint's frame in the world.
    pub root_orientation: UnitQuaternion<f64>,
    /// Local rotation of every joint relative to its parent's frame (a hinge's is a rotation
    /// about its axis; a fixed joint's is the identity).
    pub rotations: Vec<UnitQuaternion<f64>>,
    /// Extra local translation of every joint \[m\], added to its rest offset (BVH position
    /// channels on non-root joints); zero for most joints.
    pub translations: Vec<Vector3<f64>>,
}

/// A captured motion: a [`Skeleton`], the time of every frame \[s\] and one [`Pose`] per frame.
///
/// Invariants (checked by [`Clip::new`]): at least one frame; times finite and strictly
/// increasing; every pose sized for the skeleton and finite.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    name: String,
    skeleton: Skeleton,
    times: Vec<f64>,
    frames: Vec<Pose>,
    up_axis: UpAxis,
}

/// The rotation that turns a Y-up world into a Z-up one: +90° about x, mapping
/// `(x, y, z) ↦ (x, −z, y)`, so +Y becomes +Z and +Z becomes −Y (a character facing +X with its
/// right side along +Z, as in DeepMimic, ends up facing +X with its left side along +Y).
pub fn y_up_to_z_up() -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2)
}

impl Clip {
    /// Checks and assembles a clip.
    pub fn new(
        name: impl Into<String>,
        skeleton: Skeleton,
        times: Vec<f64>,
        frames: Vec<Pose>,
        up_axis: UpAxis,
    ) -> Result<Self> {
        if frames.is_empty() {
            return Err(Error::InsufficientData {
                what: "motion clip".to_string(),
                message: "a clip needs at least one frame".to_string(),
            });
        }
        crate::error::check_dim("clip frame times", frames.len(), times.len())?;
        for (i, t) in times.iter().enumerate() {
            crate::error::check_finite(|| format!("time of frame {i}"), *t)?;
            if i > 0 && times[i - 1] >= *t {
                return Err(Error::InvalidSetting {
                    name: format!("time of frame {i}"),
                    value: t.to_string(),
                    expected: format!("a time after frame {} ({} s)", i - 1, times[i - 1]),
                });
            }
        }
        for (i, pose) in frames.iter().enumerate() {
            skeleton.check_pose(pose)?;
            let finite = pose.root_position.iter().all(|v| v.is_finite())
                && pose.root_orientation.coords.iter().all(|v| v.is_finite())
                && pose
                    .rotations
                    .iter()
                    .all(|q| q.coords.iter().all(|v| v.is_finite()))
                && pose
                    .translations
                    .iter()
                    .all(|t| t.iter().all(|v| v.is_finite()));
            if !finite {
                return Err(Error::NonFinite {
                    what: format!("pose of frame {i}"),
                    value: f64::NAN,
                });
            }
        }
        Ok(Self {
            name: name.into(),
            skeleton,
            times,
            frames,
            up_axis,
        })
    }

    /// The clip's name (the source it was read from).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The skeleton.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Time of every frame \[s\], strictly increasing (the first is 0 for the built-in readers).
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The poses, one per frame.
    pub fn frames(&self) -> &[Pose] {
        &self.frames
    }

    /// The pose of frame `index`, if it exists.
    pub fn frame(&self, index: usize) -> Option<&Pose> {
        self.frames.get(index)
    }

    /// Which axis is up in the clip's world frame.
    pub fn up_axis(&self) -> UpAxis {
        self.up_axis
    }

    /// Number of frames (at least 1).
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Duration \[s\]: time of the last frame minus time of the first.
    pub fn duration(&self) -> f64 {
        match (self.times.first(), self.times.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }

    /// Mean frame rate \[Hz\], `(n − 1) / duration`; `None` for a single frame.
    pub fn mean_frame_rate(&self) -> Option<f64> {
        let d = self.duration();
        (self.frames.len() > 1 && d > 0.0).then(|| (self.frames.len() - 1) as f64 / d)
    }

    /// The pose at time `t` \[s\]; see [`Clip::sample_into`].
    pub fn sample(&self, t: f64) -> Result<Pose> {
        let mut pose = self.skeleton.rest_pose();
        self.sample_into(t, &mut pose)?;
        Ok(pose)
    }

    /// Writes the pose at time `t` \[s\] into `pose` (resized if needed, so no allocation when it
    /// already fits).
    ///
    /// Between frames `i` and `i+1`, with `α = (t − t_i)/(t_{i+1} − t_i)`: positions and
    /// translations are interpolated linearly, rotations by spherical linear interpolation
    /// (slerp) along the shorter arc. `t` is clamped to the clip's time span. Error if `t` is
    /// not finite.
    pub fn sample_into(&self, t: f64, pose: &mut Pose) -> Result<()> {
        crate::error::check_finite(|| "sample time".to_string(), t)?;
        let n = self.skeleton.len();
        pose.rotations.resize(n, UnitQuaternion::identity());
        pose.translations.resize(n, Vector3::zeros());
        let i = self.times.partition_point(|&x| x <= t);
        let (a, b, alpha) = match (
            i.checked_sub(1).and_then(|k| self.frames.get(k)),
            self.frames.get(i),
        ) {
            (Some(a), Some(b)) => {
                let (ta, tb) = (self.times[i - 1], self.times[i]);
                (a, b, (t - ta) / (tb - ta))
            }
            (Some(a), None) => (a, a, 0.0),
            (None, Some(b)) => (b, b, 0.0),
            (None, None) => {
                return Err(Error::InsufficientData {
                    what: "sampling a clip".to_string(),
                    message: "the clip has no frame".to_string(),
                })
            }
        };
        pose.root_position = a.root_position.lerp(&b.root_position, alpha);
        pose.root_orientation = slerp(&a.root_orientation, &b.root_orientation, alpha);
        for (out, (qa, qb)) in pose
            .rotations
            .iter_mut()
            .zip(a.rotations.iter().zip(&b.rotations))
        {
            *out = slerp(qa, qb, alpha);
        }
        for (out, (pa, pb)) in pose
            .translations
            .iter_mut()
            .zip(a.translations.iter().zip(&b.translations))
        {
            *out = pa.lerp(pb, alpha);
        }
        Ok(())
    }

    /// World positions of all joints at frame `index` \[m\] (forward kinematics, see
    /// [`Skeleton::world_transforms`]).
    pub fn world_positions(&self, index: usize) -> Result<Vec<Vector3<f64>>> {
        let pose = self
            .frames
            .get(index)
            .ok_or_else(|| Error::InvalidSetting {
                name: "frame index".to_string(),
                value: index.to_string(),
                expected: format!("an index below the frame count {}", self.frames.len()),
            })?;
        self.skeleton.world_positions(pose)
    }

    /// The same motion in a Z-up world: root positions and orientations are rotated by
    /// [`y_up_to_z_up`]; local joint rotations and offsets (expressed in the joints' own frames)
    /// are unchanged. A clip that is already Z-up is returned as is.
    pub fn to_z_up(&self) -> Clip {
        let mut clip = self.clone();
        if self.up_axis == UpAxis::Y {
            let q = y_up_to_z_up();
            for pose in &mut clip.frames {
                pose.root_position = q * pose.root_position;
                pose.root_orientation = q * pose.root_orientation;
            }
            clip.up_axis = UpAxis::Z;
        }
        clip
    }
}

/// Spherical linear interpolation along the shorter arc, `q(α) = a (aᵀb')^α` with `b' = ±b` on
/// `a`'s hemisphere, computed as `(sin((1−α)ω) a + sin(αω) b') / sin ω` with
/// `ω = 2·atan2(‖a − b'‖, ‖a + b'‖)` (precise for nearby rotations).
pub(crate) fn slerp(
    a: &UnitQuaternion<f64>,
    b: &UnitQuaternion<f64>,
    alpha: f64,
) -> UnitQuaternion<f64> {
    if alpha == 0.0 {
        return *a;
    }
    if alpha == 1.0 {
        return *b;
    }
    let qa = a.coords;
    let qb = if qa.dot(&b.coords) < 0.0 {
        -b.coords
    } else {
        b.coords
    };
    let omega = 2.0 * (qa - qb).norm().atan2((qa + qb).norm());
    let s = omega.sin();
    let coords = if s == 0.0 {
        qa
    } else {
        qa * (((1.0 - alpha) * omega).sin() / s) + qb * ((alpha * omega).sin() / s)
    };
    UnitQuaternion::new_normalize(Quaternion::from(coords))
}
