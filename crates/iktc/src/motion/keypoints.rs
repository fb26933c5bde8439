//! Body keypoints: named body points per frame, in metres, Z up, at the source's rate — the one
//! representation every motion source is reduced to.
//!
//! From a skeleton (by forward kinematics, [`Skeleton::world_transforms`](super::Skeleton::world_transforms)), with `s` the unit's
//! metres per file unit and `C` the rotation to the Z-up world ([`to_z_up`]):
//! `p_k(t) = s · C · p_j(t)` for the point's joint `j`, and its orientation, the rotation of the
//! joint's frame since the rest pose, `R_k(t) = C · R_j(t) · R_j(rest)ᵀ · Cᵀ` (identity in the
//! rest pose; the frames of BVH, ASF and DeepMimic skeletons are parallel to the root's at rest).
//!
//! From markers: `p_k(t) = s · C · (1/|G|) Σ_{m ∈ G} p_m(t)`, the centroid of the point's marker
//! group `G` after each marker's gaps are filled ([`MarkerSet::filled_track`]); no orientation.

use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use super::body_map::{BodyMap, PointSource};
use super::markers::{FilledGap, MarkerSet};
use super::units::{to_z_up, UnitsDecision, UpDecision};
use super::{BodyPoint, Clip};
use crate::error::{Error, Result};

/// Body points per frame (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Keypoints {
    /// The source (file) they were computed from.
    pub source: String,
    /// The points present, in [`BodyPoint::ALL`] order.
    pub points: Vec<BodyPoint>,
    /// Time of every frame \[s\].
    pub times: Vec<f64>,
    /// Frame-major positions \[m\], Z up: frame `f`, point `k` at `f · points.len() + k`.
    pub positions: Vec<Vector3<f64>>,
    /// Orientations since the rest pose, laid out like `positions` (skeleton sources only).
    pub orientations: Option<Vec<UnitQuaternion<f64>>>,
    /// The unit used and how it was decided.
    pub units: UnitsDecision,
    /// The up axis of the source and how it was decided.
    pub up: UpDecision,
    /// Marker gaps that were filled.
    pub filled_gaps: Vec<FilledGap>,
}

impl Keypoints {
    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.times.len()
    }

    /// Position of `point` at frame `frame` \[m\], if both exist.
    pub fn position(&self, frame: usize, point: BodyPoint) -> Option<Vector3<f64>> {
        let k = self.points.iter().position(|p| *p == point)?;
        self.positions.get(frame * self.points.len() + k).copied()
    }

    /// Orientation of `point` at frame `frame`, where the source has one.
    pub fn orientation(&self, frame: usize, point: BodyPoint) -> Option<UnitQuaternion<f64>> {
        let k = self.points.iter().position(|p| *p == point)?;
        self.orientations
            .as_ref()?
            .get(frame * self.points.len() + k)
            .copied()
    }

    /// A few lines for a run summary: frames, rate, units, up axis, filled gaps.
    pub fn summary(&self) -> String {
        let n = self.frame_count();
        let duration = self.times.last().unwrap_or(&0.0) - self.times.first().unwrap_or(&0.0);
        let rate = if n > 1 && duration > 0.0 {
            format!("{:.2} Hz", (n - 1) as f64 / duration)
        } else {
            "single frame".to_string()
        };
        format!(
            "{}: {n} frames, {duration:.3} s, {rate}, {} body points\nunits: {}\nup axis: {}\nfilled marker gaps: {}",
            self.source,
            self.points.len(),
            self.units,
            self.up,
            self.filled_gaps.len()
        )
    }
}

/// The joint index of every mapped point of a skeleton map, in `BodyPoint::ALL` order.
fn joint_indices(clip: &Clip, map: &BodyMap) -> Result<Vec<(BodyPoint, usize)>> {
    map.points
        .iter()
        .map(|p| match &p.source {
            PointSource::Joint(name) => Ok((p.point, clip.skeleton().index_of(name)?)),
            PointSource::Markers(m) => Err(Error::InvalidSetting {
                name: format!("body map `{}`, point {}", map.name, p.point),
                value: format!("markers {m:?}"),
                expected: format!(
                    "a joint name: `{}` is a skeleton, it has no markers",
                    clip.name()
                ),
            }),
        })
        .collect()
}

/// Keypoints of a skeleton clip (see the module documentation). The clip is in file units
/// scaled by `units` and has the up axis `up`.
pub fn clip_keypoints(
    clip: &Clip,
    map: &BodyMap,
    units: UnitsDecision,
    up: UpDecision,
) -> Result<Keypoints> {
    let joints = joint_indices(clip, map)?;
    let s = units.unit.metres_per_unit();
    let c = to_z_up(up.up);
    let skeleton = clip.skeleton();
    let mut world = vec![Isometry3::identity(); skeleton.len()];
    skeleton.world_transforms(&skeleton.rest_pose(), &mut world)?;
    let rest_inv: Vec<UnitQuaternion<f64>> = joints
        .iter()
        .map(|(_, j)| world[*j].rotation.inverse())
        .collect();
    let frames = clip.frame_count();
    let mut positions = Vec::with_capacity(frames * joints.len());
    let mut orientations = Vec::with_capacity(frames * joints.len());
    for pose in clip.frames() {
        skeleton.world_transforms(pose, &mut world)?;
        for ((_, j), r0) in joints.iter().zip(&rest_inv) {
            let t = &world[*j];
            positions.push(c * t.translation.vector * s);
            orientations.push(c * t.rotation * r0 * c.inverse());
        }
    }
    Ok(Keypoints {
        source: clip.name().to_string(),
        points: joints.iter().map(|(p, _)| *p).collect(),
        times: clip.times().to_vec(),
        positions,
        orientations: Some(orientations),
        units,
        up,
        filled_gaps: Vec::new(),
    })
}

/// Keypoints of a marker set (see the module documentation); `max_gap` \[s\] is the longest
/// marker gap filled. Errors name the file and the marker: a marker of the map missing from the
/// file, a gap too long.
pub fn marker_keypoints(
    markers: &MarkerSet,
    map: &BodyMap,
    units: UnitsDecision,
    up: UpDecision,
    max_gap: f64,
) -> Result<Keypoints> {
    let s = units.unit.metres_per_unit();
    let c = to_z_up(up.up);
    let frames = markers.frame_count();
    let mut tracks: Vec<(usize, Vec<Vector3<f64>>)> = Vec::new();
    let mut gaps = Vec::new();
    let mut groups: Vec<(BodyPoint, Vec<usize>)> = Vec::new();
    for p in &map.points {
        let names: Vec<&str> = match &p.source {
            PointSource::Markers(m) => m.iter().map(|s| s.as_str()).collect(),
            PointSource::Joint(j) => vec![j.as_str()],
        };
        let mut slots = Vec::with_capacity(names.len());
        for name in names {
            let m = markers.index_of(name).map_err(|e| match e {
                Error::UnknownName { valid, .. } => Error::UnknownName {
                    kind: "marker (missing from the file)",
                    name: format!("{name}` for {} in `{}", p.point, markers.source),
                    valid,
                },
                other => other,
            })?;
            let slot = match tracks.iter().position(|(k, _)| *k == m) {
                Some(s) => s,
                None => {
                    let (track, g) = markers.filled_track(m, max_gap)?;
                    gaps.extend(g);
                    tracks.push((m, track));
                    tracks.len() - 1
                }
            };
            slots.push(slot);
        }
        groups.push((p.point, slots));
    }
    let mut positions = Vec::with_capacity(frames * groups.len());
    for f in 0..frames {
        for (_, slots) in &groups {
            let sum: Vector3<f64> = slots.iter().map(|k| tracks[*k].1[f]).sum();
            positions.push(c * (sum / slots.len() as f64) * s);
        }
    }
    Ok(Keypoints {
        source: markers.source.clone(),
        points: groups.iter().map(|(p, _)| *p).collect(),
        times: markers.times.clone(),
        positions,
        orientations: None,
        units,
        up,
        filled_gaps: gaps,
    })
}
