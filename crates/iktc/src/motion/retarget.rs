//! Retargeting a captured clip to robot references (Section 5.3): joint trajectories for the
//! joints a [`RetargetMap`] names, the pelvis height change and the pelvis attitude, then
//! resampling to the control rate with continuous velocity and acceleration.

use nalgebra::{Isometry3, Rotation3, UnitQuaternion, Vector3};

use super::angles::unwrap_track;
use super::decompose::decompose_rotation;
use super::retarget_map::{JointMap, RetargetMap, RootMap};
use super::spline::CubicSpline;
use super::{Clip, Pose, Skeleton};
use crate::error::{check_finite, Error, Result};
use crate::model::{JointKind, Kinematics, Robot, State};
use crate::resources::RunLimits;

/// Robot references at the clip's frame times (before resampling).
#[derive(Debug, Clone, PartialEq)]
pub struct Retargeted {
    /// Frame times \[s\], from the clip.
    pub times: Vec<f64>,
    /// Robot joint names, in the map's order (driven joints, then held ones).
    pub joint_names: Vec<String>,
    /// Joint angle tracks \[rad\], `joint_angles[j][frame]`, unwrapped.
    pub joint_angles: Vec<Vec<f64>>,
    /// Pelvis height change from the first frame \[m\], scaled by the map's `height_scale`.
    pub pelvis_height: Vec<f64>,
    /// Pelvis attitude as Z-Y-X angles (yaw, pitch, roll) \[rad\] of the source root in the
    /// robot's Z-up world, minus those of the first frame, each scaled by the map; the attitude is
    /// `Rz(yaw) Ry(pitch) Rx(roll)` relative to the robot's initial pelvis attitude.
    pub pelvis_angles: [Vec<f64>; 3],
    /// Largest decomposition residual of each joint map over the clip \[rad\]: 0 when the source
    /// rotations are exactly representable by the robot joints.
    pub residuals: Vec<f64>,
}

/// One resampled track: value, rate and acceleration per control tick.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Track {
    /// Values (\[rad\] or \[m\]).
    pub position: Vec<f64>,
    /// Rates (\[rad/s\] or \[m/s\]).
    pub velocity: Vec<f64>,
    /// Accelerations (\[rad/s²\] or \[m/s²\]).
    pub acceleration: Vec<f64>,
}

impl Track {
    fn from_spline(s: &CubicSpline, times: &[f64]) -> Self {
        let mut t = Track::default();
        for &time in times {
            let [p, v, a] = s.eval(time);
            t.position.push(p);
            t.velocity.push(v);
            t.acceleration.push(a);
        }
        t
    }
}

/// References at the control rate, ready to be read tick by tick without allocation.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotReferences {
    /// Control period Δt \[s\].
    pub dt: f64,
    /// Tick times `k Δt` \[s\], from 0 to the clip's duration.
    pub times: Vec<f64>,
    /// Robot joint names (see [`Retargeted::joint_names`]).
    pub joint_names: Vec<String>,
    /// One track per joint \[rad\].
    pub joints: Vec<Track>,
    /// Pelvis height change from the start \[m\].
    pub height: Track,
    /// Pelvis (yaw, pitch, roll) changes \[rad\].
    pub angles: [Track; 3],
    /// Pelvis attitude `Rz(yaw) Ry(pitch) Rx(roll)` relative to the initial one.
    pub attitude: Vec<UnitQuaternion<f64>>,
    /// Pelvis angular velocity \[rad/s\] (world axes).
    pub angular_velocity: Vec<Vector3<f64>>,
    /// Pelvis angular acceleration \[rad/s²\] (world axes).
    pub angular_acceleration: Vec<Vector3<f64>>,
}

impl RobotReferences {
    /// Number of ticks.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Whether there is no tick (never, for references made by [`Retargeted::resample`]).
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// Checks that every track has one finite sample per tick and that there is one track per
    /// joint name (the fields are public: references may be built by hand).
    pub fn validate(&self) -> Result<()> {
        let n = self.times.len();
        if n == 0 {
            return Err(Error::InsufficientData {
                what: "robot references".into(),
                message: "no tick".into(),
            });
        }
        crate::error::check_dim(
            "reference joint tracks",
            self.joint_names.len(),
            self.joints.len(),
        )?;
        let tracks = self
            .joints
            .iter()
            .zip(&self.joint_names)
            .map(|(t, n)| (t, n.as_str()))
            .chain([(&self.height, "pelvis height")])
            .chain(self.angles.iter().map(|t| (t, "pelvis angles")));
        for (t, name) in tracks {
            for v in [&t.position, &t.velocity, &t.acceleration] {
                crate::error::check_dim(&format!("samples of the `{name}` reference"), n, v.len())?;
                crate::error::check_all_finite(&format!("`{name}` reference"), v)?;
            }
        }
        crate::error::check_dim("attitude samples", n, self.attitude.len())?;
        crate::error::check_dim("angular velocity samples", n, self.angular_velocity.len())?;
        crate::error::check_dim(
            "angular acceleration samples",
            n,
            self.angular_acceleration.len(),
        )?;
        let finite = self
            .attitude
            .iter()
            .all(|q| q.coords.iter().all(|c| c.is_finite()))
            && self
                .angular_velocity
                .iter()
                .chain(&self.angular_acceleration)
                .all(|w| w.iter().all(|c| c.is_finite()));
        if !finite {
            return Err(Error::NonFinite {
                what: "pelvis attitude reference".into(),
                value: f64::NAN,
            });
        }
        Ok(())
    }
}

/// One joint map with everything resolved against the skeleton and the robot.
struct ResolvedJoint {
    source: usize,
    /// Parent link's world rotation at the neutral state.
    parent: Rotation3<f64>,
    parent_rest: Rotation3<f64>,
    rest: Rotation3<f64>,
    axes: Vec<Vector3<f64>>,
    sign_scale: Vec<f64>,
    offset: Vec<f64>,
}

/// Retargets `clip` to `robot` with `map`.
///
/// For every joint map, every frame: the source joint's local rotation `Q` (relative to its
/// parent, source coordinates) is taken to the robot's coordinates and to the frame of the
/// parent link `P` of the first target joint (at the neutral state), with the rest rotations:
///
/// ```text
/// R = R_parent_restᵀ · Pᵀ B Q Bᵀ P · R_rest
/// ```
///
/// then decomposed ([`decompose_rotation`], nearest to the previous frame's angles, tracks
/// unwrapped) about the target joints' axes in `P` (their zero-configuration axes, read from
/// the model): `R ≈ Rot(a_1, θ_1) ⋯ Rot(a_k, θ_k)`, and `q_i = offset_i + sign_i · scale_i · θ_i`
/// \[rad\]. Held joints get their constant value.
///
/// Pelvis: the source root's world pose `(p, Q_root)` (or the map's root source joint's) becomes
/// `B p` and `R = B Q_root Bᵀ` in the robot's Z-up world; the height change is
/// `height_scale · ((B p)_z − (B p_0)_z)` \[m\], and the attitude the Z-Y-X angles of `R` minus
/// those of the first frame, scaled by `yaw_scale`, `pitch_scale`, `roll_scale`.
///
/// Errors: a source joint or robot joint that does not exist, a robot joint that is not an
/// active revolute joint, targets of one map entry that do not form a serial chain (each the
/// child of the previous one's link), and the errors of [`decompose_rotation`].
pub fn retarget_joint_angles(clip: &Clip, robot: &Robot, map: &RetargetMap) -> Result<Retargeted> {
    let skeleton = clip.skeleton();
    let state = State::neutral(robot);
    let kin = Kinematics::new(robot, &state)?;
    let resolved = map
        .joints
        .iter()
        .map(|jm| resolve_joint(jm, skeleton, robot, &kin))
        .collect::<Result<Vec<_>>>()?;
    for h in &map.holds {
        robot.active_joint_index(&h.joint)?;
    }
    let root = match &map.root.source {
        Some(name) => skeleton.index_of(name)?,
        None => 0,
    };

    let n = clip.frame_count();
    let joint_names = map.robot_joints();
    let mut joints = JointTracks::new(joint_names.len(), resolved.len(), n);
    let mut pelvis = PelvisTracks::new(skeleton.len(), n);
    for pose in clip.frames() {
        joints.push_frame(&resolved, pose, map)?;
        pelvis.push_frame(skeleton, pose, root, &map.basis)?;
    }
    let JointTracks {
        mut joint_angles,
        residuals,
        ..
    } = joints;
    for track in joint_angles.iter_mut() {
        unwrap_track(track, std::f64::consts::TAU);
    }
    let (pelvis_height, pelvis_angles) = pelvis.finish(&map.root);
    Ok(Retargeted {
        times: clip.times().to_vec(),
        joint_names,
        joint_angles,
        pelvis_height,
        pelvis_angles,
        residuals,
    })
}

/// Resolves the joint map `jm`: its source joint, its targets (checked to be a serial chain of
/// revolute joints) and their axes in the frame of the first target's parent link.
fn resolve_joint(
    jm: &JointMap,
    skeleton: &Skeleton,
    robot: &Robot,
    kin: &Kinematics,
) -> Result<ResolvedJoint> {
    let source = skeleton.index_of(&jm.source)?;
    let mut joints = Vec::with_capacity(jm.targets.len());
    for t in &jm.targets {
        robot.active_joint_index(&t.joint)?;
        let joint = robot
            .joints()
            .iter()
            .find(|j| j.name == t.joint)
            .ok_or_else(|| Error::UnknownName {
                kind: "joint",
                name: t.joint.clone(),
                valid: robot.active_joints().map(|j| j.name.clone()).collect(),
            })?;
        joints.push(joint);
    }
    for w in joints.windows(2) {
        if w[1].parent != w[0].child {
            return Err(Error::InvalidSetting {
                name: format!("targets of `{}`", jm.source),
                value: format!("{} then {}", w[0].name, w[1].name),
                expected: "robot joints forming a serial chain, parent first".into(),
            });
        }
    }
    let first_parent = joints.first().map_or(0, |j| j.parent);
    let parent = kin
        .link_pose(first_parent)
        .map_or(Rotation3::identity(), |p| p.rotation.to_rotation_matrix());
    let mut axes = Vec::with_capacity(joints.len());
    for j in &joints {
        let JointKind::Revolute { axis } = j.kind else {
            return Err(Error::InvalidSetting {
                name: format!("robot joint `{}`", j.name),
                value: j.kind.name().into(),
                expected: "a revolute joint (a captured rotation drives revolute joints)".into(),
            });
        };
        let link = kin
            .link_pose(j.parent)
            .map_or(Rotation3::identity(), |p| p.rotation.to_rotation_matrix());
        let world = link * j.origin.rotation.to_rotation_matrix() * axis.into_inner();
        axes.push(parent.transpose() * world);
    }
    let (parent_rest, rest) = RetargetMap::rest(jm);
    Ok(ResolvedJoint {
        source,
        parent,
        parent_rest,
        rest,
        axes,
        sign_scale: jm.targets.iter().map(|t| t.sign * t.scale).collect(),
        offset: jm.targets.iter().map(|t| t.offset).collect(),
    })
}

/// The robot joints' angle tracks being built frame by frame.
struct JointTracks {
    /// One track per robot joint of the map (targets, then holds) \[rad\].
    joint_angles: Vec<Vec<f64>>,
    /// Largest decomposition residual per joint map.
    residuals: Vec<f64>,
    /// Previous frame's angles per joint map \[rad\].
    previous: Vec<Option<[f64; 3]>>,
}

impl JointTracks {
    /// Empty tracks for `joints` robot joints, `maps` joint maps and `frames` frames.
    fn new(joints: usize, maps: usize, frames: usize) -> Self {
        JointTracks {
            joint_angles: vec![Vec::with_capacity(frames); joints],
            residuals: vec![0.0f64; maps],
            previous: vec![None; maps],
        }
    }

    /// Appends the angles of `pose`: every resolved joint map decomposed, then the held values.
    fn push_frame(
        &mut self,
        resolved: &[ResolvedJoint],
        pose: &Pose,
        map: &RetargetMap,
    ) -> Result<()> {
        let b = map.basis;
        let mut column = 0;
        for (k, r) in resolved.iter().enumerate() {
            let q_src = pose.rotations[r.source].to_rotation_matrix();
            let rot = r.parent_rest.transpose()
                * r.parent.transpose()
                * b
                * q_src
                * b.transpose()
                * r.parent
                * r.rest;
            let m = r.axes.len();
            let mut out = [0.0; 3];
            let report = decompose_rotation(
                &UnitQuaternion::from_rotation_matrix(&rot),
                &r.axes,
                self.previous[k].as_ref().map(|p| &p[..m]),
                &mut out[..m],
            )?;
            self.residuals[k] = self.residuals[k].max(report.residual);
            self.previous[k] = Some(out);
            let tracks = &mut self.joint_angles[column..column + m];
            for (i, track) in tracks.iter_mut().enumerate() {
                track.push(r.offset[i] + r.sign_scale[i] * out[i]);
            }
            column += m;
        }
        for (h, track) in map.holds.iter().zip(self.joint_angles[column..].iter_mut()) {
            track.push(h.value);
        }
        Ok(())
    }
}

/// The pelvis tracks being built frame by frame, in the robot's Z-up world.
struct PelvisTracks {
    /// World transforms of the skeleton's joints (scratch).
    transforms: Vec<Isometry3<f64>>,
    /// Root height per frame \[skeleton units\].
    heights: Vec<f64>,
    /// Z-Y-X angles of the root per frame \[rad\].
    angles: [Vec<f64>; 3],
    /// Previous frame's Z-Y-X angles \[rad\].
    prev_zyx: Option<[f64; 3]>,
}

impl PelvisTracks {
    /// Empty tracks for a skeleton of `joints` joints and `frames` frames.
    fn new(joints: usize, frames: usize) -> Self {
        PelvisTracks {
            transforms: vec![Isometry3::identity(); joints],
            heights: Vec::with_capacity(frames),
            angles: [Vec::new(), Vec::new(), Vec::new()],
            prev_zyx: None,
        }
    }

    /// Appends the height and Z-Y-X angles of joint `root` of `pose`, through the basis `b`.
    fn push_frame(
        &mut self,
        skeleton: &Skeleton,
        pose: &Pose,
        root: usize,
        b: &Rotation3<f64>,
    ) -> Result<()> {
        let zyx = [Vector3::z(), Vector3::y(), Vector3::x()];
        skeleton.world_transforms(pose, &mut self.transforms)?;
        let root_pose = self.transforms[root];
        let p = b * root_pose.translation.vector;
        self.heights.push(p.z);
        let r_body = b * root_pose.rotation.to_rotation_matrix() * b.transpose();
        let mut a = [0.0; 3];
        decompose_rotation(
            &UnitQuaternion::from_rotation_matrix(&r_body),
            &zyx,
            self.prev_zyx.as_ref().map(|p| &p[..]),
            &mut a,
        )?;
        self.prev_zyx = Some(a);
        for (track, v) in self.angles.iter_mut().zip(a) {
            track.push(v);
        }
        Ok(())
    }

    /// The height change \[m\] and the unwrapped attitude change \[rad\] from the first frame,
    /// scaled by the root map.
    fn finish(self, root: &RootMap) -> (Vec<f64>, [Vec<f64>; 3]) {
        let mut angles = self.angles;
        for track in angles.iter_mut() {
            unwrap_track(track, std::f64::consts::TAU);
        }
        let h0 = self.heights.first().copied().unwrap_or(0.0);
        let pelvis_height = self
            .heights
            .iter()
            .map(|h| root.height_scale * (h - h0))
            .collect();
        let scales = [root.yaw_scale, root.pitch_scale, root.roll_scale];
        for (track, s) in angles.iter_mut().zip(scales) {
            let a0 = track.first().copied().unwrap_or(0.0);
            for v in track.iter_mut() {
                *v = s * (*v - a0);
            }
        }
        (pelvis_height, angles)
    }
}

/// The range `[lower, upper]` \[rad\] shrunk by `margin` \[rad\] on each side,
/// `[lower + margin, upper − margin]`; a range narrower than `2 · margin` becomes its middle
/// `(lower + upper) / 2`. Every clamp of a joint reference into its (narrowed) range uses it.
pub fn shrunk_range(lower: f64, upper: f64, margin: f64) -> (f64, f64) {
    let (lo, hi) = (lower + margin, upper - margin);
    if lo > hi {
        let mid = 0.5 * (lower + upper);
        (mid, mid)
    } else {
        (lo, hi)
    }
}

impl Retargeted {
    /// Clamps every joint track into the robot's position range shrunk by `margin` \[rad\] on
    /// each side (a range narrower than `2 · margin` is clamped to its middle). References
    /// outside the range would only make the joint task push its joint into the limit.
    pub fn clamp_to_limits(&mut self, robot: &Robot, margin: f64) -> Result<()> {
        check_finite(|| "clamp margin".into(), margin)?;
        for (name, track) in self.joint_names.iter().zip(self.joint_angles.iter_mut()) {
            let i = robot.active_joint_index(name)?;
            let lim = robot
                .active_joints()
                .nth(i)
                .map(|j| j.limit)
                .unwrap_or(crate::model::JointLimit::UNBOUNDED);
            let (lo, hi) = shrunk_range(lim.lower, lim.upper, margin);
            for v in track.iter_mut() {
                *v = v.clamp(lo, hi);
            }
        }
        Ok(())
    }

    /// The references at the control period `dt` \[s\], from 0 to the clip's duration.
    ///
    /// Method: each track (joint angles, pelvis height, pelvis yaw / pitch / roll) is
    /// interpolated by a natural cubic spline ([`CubicSpline`]: C², so the rates and
    /// accelerations are continuous) through the frame samples and evaluated at `k Δt`. The
    /// pelvis attitude is `R = Rz(ψ) Ry(θ) Rx(φ)`; with the world axes `a_1 = e_z`,
    /// `a_2 = Rz(ψ) e_y`, `a_3 = Rz(ψ) Ry(θ) e_x`, its angular velocity is
    /// `ω = ψ̇ a_1 + θ̇ a_2 + φ̇ a_3` and its angular acceleration
    /// `ω̇ = ψ̈ a_1 + θ̈ a_2 + φ̈ a_3 + (ψ̇ a_1) × (θ̇ a_2) + (ψ̇ a_1 + θ̇ a_2) × (φ̇ a_3)`.
    ///
    /// With the default [`RunLimits`]; see [`Retargeted::resample_with`].
    pub fn resample(&self, dt: f64) -> Result<RobotReferences> {
        self.resample_with(dt, &RunLimits::default())
    }

    /// [`Retargeted::resample`] with explicit [`RunLimits`]: `dt` must be in their range and the
    /// number of samples at most their `max_ticks` (checked before anything is allocated).
    pub fn resample_with(&self, dt: f64, limits: &RunLimits) -> Result<RobotReferences> {
        let t0 = self.times.first().copied().unwrap_or(0.0);
        let duration = self.times.last().copied().unwrap_or(0.0) - t0;
        limits.ticks("the resampled clip", duration, dt)?;
        // The 1e-9 [–] absorbs the rounding of `duration / dt` when the clip's duration is a
        // whole number of periods, so that its last instant is kept.
        let n = ((duration / dt + 1e-9).floor() as usize).saturating_add(1);
        limits.check_ticks("the resampled clip", n)?;
        let times: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let abs: Vec<f64> = times.iter().map(|t| t + t0).collect();
        let spline = |v: &[f64]| -> Result<Track> {
            Ok(Track::from_spline(&CubicSpline::new(&self.times, v)?, &abs))
        };
        let joints = self
            .joint_angles
            .iter()
            .map(|v| spline(v))
            .collect::<Result<Vec<_>>>()?;
        let height = spline(&self.pelvis_height)?;
        let angles = [
            spline(&self.pelvis_angles[0])?,
            spline(&self.pelvis_angles[1])?,
            spline(&self.pelvis_angles[2])?,
        ];
        let mut attitude = Vec::with_capacity(n);
        let mut angular_velocity = Vec::with_capacity(n);
        let mut angular_acceleration = Vec::with_capacity(n);
        for k in 0..n {
            let p = [0, 1, 2].map(|i| angles[i].position[k]);
            let v = [0, 1, 2].map(|i| angles[i].velocity[k]);
            let a = [0, 1, 2].map(|i| angles[i].acceleration[k]);
            let rz = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), p[0]);
            let ry = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), p[1]);
            let rx = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), p[2]);
            let a1 = Vector3::z();
            let a2 = rz * Vector3::y();
            let a3 = rz * ry * Vector3::x();
            let w1 = a1 * v[0];
            let w12 = w1 + a2 * v[1];
            attitude.push(rz * ry * rx);
            angular_velocity.push(w12 + a3 * v[2]);
            angular_acceleration.push(
                a1 * a[0]
                    + a2 * a[1]
                    + a3 * a[2]
                    + w1.cross(&(a2 * v[1]))
                    + w12.cross(&(a3 * v[2])),
            );
        }
        Ok(RobotReferences {
            dt,
            times,
            joint_names: self.joint_names.clone(),
            joints,
            height,
            angles,
            attitude,
            angular_velocity,
            angular_acceleration,
        })
    }
}
