//! The robot's joint centres: the points of its body that stand for the person's hip, knee,
//! ankle, shoulder, elbow and wrist centres, found from the kinematic tree alone.
//!
//! A limb is the chain of moving joints from the branching of the two legs' (arms') chains down
//! to the foot (hand) frame. With `oᵢ` the origin of the limb's joint `i` and `e` the chain's
//! end (the foot or hand frame's origin), all in the neutral posture:
//! * the middle joint (knee, elbow) is the one farthest from both ends,
//!   `m = argmaxᵢ min(|oᵢ − o₁|, |oᵢ − e|)`, and its centre is its origin `oₘ`;
//! * the proximal joints (hip, shoulder) are those before `m` nearer `o₁` than `oₘ`; the distal
//!   ones (ankle, wrist) those after `m` nearer `e` than `oₘ`;
//! * a group's centre is the point nearest all its joints' axes in the least-squares sense,
//!   `x = argmin Σᵢ |(I − aᵢaᵢᵀ)(x − oᵢ)|² + ε|x − ō|²` (`aᵢ` the unit axes, `ō` the mean
//!   origin, `ε` = 10⁻³), which is the axes' intersection where they meet
//!   and the mean origin of a lone joint's axis otherwise; a limb with no distal joint ends at
//!   `e`.
//!
//! Each centre is kept as a point fixed in a link (the group's last joint's child link), so
//! it follows the limb in any posture. Names play no part.

use std::sync::Arc;

use nalgebra::{Isometry3, Matrix3, Point3, Translation3, UnitQuaternion, Vector3};

use super::body::{branch, chain, RobotBody};
use crate::error::{Error, Result};
use crate::model::{JointKind, Kinematics, Robot, State};
use crate::motion::BodyPoint;

/// Weight of the pull toward the mean origin in a joint group's least-squares centre \[–\]
/// (relative to one axis' weight 1): it fixes the point along parallel axes and leaves
/// intersecting ones at their intersection to within about this fraction of the origins'
/// spread.
pub(crate) const AXIS_REGULARISATION: f64 = 1e-3;

/// A point fixed in a link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkPoint {
    /// Index of the link ([`Robot::links`]).
    pub link: usize,
    /// The point in the link's frame \[m\].
    pub offset: Vector3<f64>,
}

impl LinkPoint {
    /// The point in world coordinates at `kin` \[m\].
    pub fn at(&self, kin: &Kinematics) -> Result<Vector3<f64>> {
        let pose = kin.link_pose(self.link).ok_or_else(|| Error::UnknownName {
            kind: "link",
            name: format!("#{}", self.link),
            valid: Vec::new(),
        })?;
        Ok((pose * Point3::from(self.offset)).coords)
    }
}

/// The twelve limb joint centres, in [`JOINT_CENTRES`] order.
pub const JOINT_CENTRES: [BodyPoint; 12] = [
    BodyPoint::LeftHip,
    BodyPoint::LeftKnee,
    BodyPoint::LeftAnkle,
    BodyPoint::RightHip,
    BodyPoint::RightKnee,
    BodyPoint::RightAnkle,
    BodyPoint::LeftShoulder,
    BodyPoint::LeftElbow,
    BodyPoint::LeftWrist,
    BodyPoint::RightShoulder,
    BodyPoint::RightElbow,
    BodyPoint::RightWrist,
];

/// The robot's joint centres (see the module documentation), in [`JOINT_CENTRES`] order.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotJointCentres {
    /// One point per entry of [`JOINT_CENTRES`].
    pub points: [LinkPoint; 12],
}

impl RobotJointCentres {
    /// Finds the centres of the limbs ending at `body`'s feet and wrists.
    /// Errors: a limb with no moving joint.
    pub fn find(robot: &Robot, body: &RobotBody) -> Result<Self> {
        let kin = Kinematics::new(robot, &State::neutral(robot))?;
        let hand = |p| {
            body.frame_of(p).ok_or_else(|| Error::Profile {
                key: "frames.left_hand / frames.right_hand".into(),
                value: crate::profile::MISSING.into(),
                message: "the joint centres need both hands".into(),
            })
        };
        let hands = [hand(BodyPoint::LeftWrist)?, hand(BodyPoint::RightWrist)?];
        let legs = [chain(robot, body.feet[0])?, chain(robot, body.feet[1])?];
        let arms = [chain(robot, hands[0])?, chain(robot, hands[1])?];
        let (lb, ab) = (branch(&legs), branch(&arms));
        let mut points = Vec::with_capacity(12);
        for (i, f) in body.feet.iter().enumerate() {
            let end = kin.frame_pose(robot, *f)?.translation.vector;
            let foot_link = robot.frames()[f.0].link;
            points.extend(limb(robot, &kin, &legs[i][lb..], end, foot_link)?);
        }
        for (i, h) in hands.iter().enumerate() {
            let end = kin.frame_pose(robot, *h)?.translation.vector;
            let hand_link = robot.frames()[h.0].link;
            points.extend(limb(robot, &kin, &arms[i][ab..], end, hand_link)?);
        }
        let points: [LinkPoint; 12] = points.try_into().map_err(|_| Error::Profile {
            key: "feet / frames".into(),
            value: String::new(),
            message: "every limb must give three joint centres".into(),
        })?;
        Ok(Self { points })
    }

    /// `robot` with a frame at every centre (named `centre:<point>`, e.g. `centre:left_hip`),
    /// and `body` with those frames for its hips, knees, shoulders, elbows and wrists (its
    /// ankles stay the feet's frames, which the foot tasks and soles are given in): the
    /// points a retargeting tracks are then the points its fidelity is measured at. Errors:
    /// a name taken.
    pub fn frames(
        &self,
        robot: &Arc<Robot>,
        mut body: RobotBody,
    ) -> Result<(Arc<Robot>, RobotBody)> {
        let mut r = Robot::clone(robot);
        let mut ids = Vec::with_capacity(12);
        for (p, lp) in JOINT_CENTRES.iter().zip(&self.points) {
            let name = format!("centre:{}", p.name());
            let link = r
                .links()
                .get(lp.link)
                .map(|l| l.name.clone())
                .unwrap_or_default();
            let at = r.frame_id(&link)?;
            // The frame is given in the link's frame: undo the link frame's own offset.
            let offset = r.frames()[at.0].offset.inverse()
                * Isometry3::from_parts(Translation3::from(lp.offset), UnitQuaternion::identity());
            if r.frame_id(&name).is_err() {
                r = r.with_frame(&name, &link, offset)?;
            }
            ids.push((*p, r.frame_id(&name)?));
        }
        for (p, id) in ids {
            if matches!(p, BodyPoint::LeftAnkle | BodyPoint::RightAnkle) {
                continue;
            }
            if let Some(slot) = body.points.iter_mut().find(|(q, _)| *q == p) {
                slot.1 = id;
            }
        }
        Ok((Arc::new(r), body))
    }

    /// The centres in world coordinates at `kin` \[m\], in [`JOINT_CENTRES`] order.
    pub fn at(&self, kin: &Kinematics) -> Result<[Vector3<f64>; 12]> {
        let mut out = [Vector3::zeros(); 12];
        for (o, p) in out.iter_mut().zip(&self.points) {
            *o = p.at(kin)?;
        }
        Ok(out)
    }
}

/// One joint of a limb in the neutral posture: world origin and unit axis (none for a
/// prismatic joint), and its child link.
struct LimbJoint {
    origin: Vector3<f64>,
    axis: Option<Vector3<f64>>,
    child: usize,
}

/// The proximal, middle and distal centres of the limb whose links are `links` (from the
/// branching down) and whose chain ends at `end` in `end_link`.
fn limb(
    robot: &Robot,
    kin: &Kinematics,
    links: &[usize],
    end: Vector3<f64>,
    end_link: usize,
) -> Result<[LinkPoint; 3]> {
    let mut joints = Vec::new();
    for &l in links {
        let Some(j) = robot.joints().iter().find(|j| j.child == l) else {
            continue;
        };
        let axis = match j.kind {
            JointKind::Revolute { axis } => Some(axis.into_inner()),
            JointKind::Prismatic { .. } => None,
            JointKind::Fixed => continue,
        };
        let parent = kin.link_pose(j.parent).copied().unwrap_or_default() * j.origin;
        joints.push(LimbJoint {
            origin: parent.translation.vector,
            axis: axis.map(|a| parent.rotation * a),
            child: j.child,
        });
    }
    let first = joints.first().ok_or_else(|| Error::Profile {
        key: "feet / frames".into(),
        value: robot
            .links()
            .get(end_link)
            .map_or_else(String::new, |l| l.name.clone()),
        message: "a limb chain has no moving joint below the branching of the two limbs".into(),
    })?;
    let o1 = first.origin;
    let m = (0..joints.len())
        .max_by(|&a, &b| {
            let reach = |i: usize| {
                (joints[i].origin - o1)
                    .norm()
                    .min((joints[i].origin - end).norm())
            };
            reach(a).total_cmp(&reach(b))
        })
        .unwrap_or(0);
    let om = joints[m].origin;
    let proximal: Vec<&LimbJoint> = joints[..m]
        .iter()
        .filter(|j| (j.origin - o1).norm() < (j.origin - om).norm())
        .chain(if m == 0 { Some(&joints[0]) } else { None })
        .collect();
    let distal: Vec<&LimbJoint> = joints[m + 1..]
        .iter()
        .filter(|j| (j.origin - end).norm() < (j.origin - om).norm())
        .collect();
    let in_link = |link: usize, x: Vector3<f64>| -> LinkPoint {
        let pose = kin.link_pose(link).copied().unwrap_or_default();
        LinkPoint {
            link,
            offset: pose.inverse_transform_point(&Point3::from(x)).coords,
        }
    };
    let group = |g: &[&LimbJoint]| -> Option<LinkPoint> {
        let last = g.last()?;
        Some(in_link(
            last.child,
            axes_point(g.iter().map(|j| (j.origin, j.axis))),
        ))
    };
    let hip = group(&proximal).unwrap_or_else(|| in_link(joints[0].child, o1));
    let knee = in_link(joints[m].child, om);
    let ankle = group(&distal).unwrap_or_else(|| in_link(end_link, end));
    Ok([hip, knee, ankle])
}

/// The point nearest the lines through `origin` along `axis` in the least-squares sense, pulled
/// toward the mean origin with weight 10⁻³ (module documentation); a
/// joint without an axis counts as a point.
pub fn axes_point(
    lines: impl Iterator<Item = (Vector3<f64>, Option<Vector3<f64>>)>,
) -> Vector3<f64> {
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    let (mut mean, mut n) = (Vector3::zeros(), 0.0);
    for (o, axis) in lines {
        let p = match axis {
            Some(u) => {
                Matrix3::identity() - u * u.transpose() / u.norm_squared().max(f64::MIN_POSITIVE)
            }
            None => Matrix3::identity(),
        };
        a += p;
        b += p * o;
        mean += o;
        n += 1.0;
    }
    if n == 0.0 {
        return Vector3::zeros();
    }
    let mean = mean / n;
    let eps = AXIS_REGULARISATION * n;
    a += Matrix3::identity() * eps;
    b += mean * eps;
    a.lu().solve(&b).unwrap_or(mean)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three axes through (1, 2, 3) along x, y and z meet there; one axis alone gives the
    /// projection of its origin (itself); two parallel axes give the midpoint of the origins.
    #[test]
    fn the_axes_point_is_the_intersection() {
        let c = Vector3::new(1.0, 2.0, 3.0);
        let x = axes_point(
            [
                (c + Vector3::new(0.3, 0.0, 0.0), Some(Vector3::x())),
                (c + Vector3::new(0.0, -0.2, 0.0), Some(Vector3::y())),
                (c + Vector3::new(0.0, 0.0, 0.5), Some(Vector3::z())),
            ]
            .into_iter(),
        );
        // The pull toward the mean origin (0.1, −0.067, 0.167 from c) moves the point by
        // about ε/(2 + ε) of it per axis.
        assert!((x - c).norm() < 1e-3, "{x}");
        let lone = axes_point([(c, Some(Vector3::z()))].into_iter());
        assert!((lone - c).norm() < 1e-12, "{lone}");
        let par = axes_point(
            [
                (Vector3::new(0.0, 0.0, 0.0), Some(Vector3::z())),
                (Vector3::new(0.2, 0.0, 1.0), Some(Vector3::z())),
            ]
            .into_iter(),
        );
        assert!(
            (par.xy() - Vector3::new(0.1, 0.0, 0.0).xy()).norm() < 1e-12,
            "{par}"
        );
        assert!((par.z - 0.5).abs() < 1e-9, "{par}");
    }
}
