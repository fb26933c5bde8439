//! The robot's counterparts of the human body points: which frame of the robot stands for the
//! pelvis, the hips, knees, ankles, shoulders, elbows, wrists and the head.
//!
//! Found from the profile's frames and the kinematic tree, without joint names where possible:
//! the hips are the first links below the branching of the two feet's chains, the shoulders the
//! first links below the branching of the two hands' chains; the knee (elbow) is the link of the
//! chain's joint whose name contains `knee` (`elbow`), else the chain link whose origin is
//! nearest the midpoint of hip and ankle (shoulder and hand) in the start posture. The head is
//! the profile's head frame unless that sits at the pelvis ([`MIN_HEAD_HEIGHT`]).

use nalgebra::Vector3;

use crate::error::{Error, Result};
use crate::model::{FrameId, Kinematics, Robot};
use crate::motion::{BodyPoint, Side};

/// A head frame closer than this to the pelvis frame \[m\] is not taken for the head (some
/// URDFs put a head link's origin at the waist and its geometry higher up). A human head is
/// 0.5–0.7 m above the pelvis; a robot's scaled head several decimetres.
pub(crate) const MIN_HEAD_HEIGHT: f64 = 0.1;

/// The frames of the robot that stand for body points (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct RobotBody {
    /// Robot frame of each body point it has, in [`BodyPoint::ALL`] order.
    pub points: Vec<(BodyPoint, FrameId)>,
    /// The pelvis frame (pose task).
    pub pelvis: FrameId,
    /// The torso frame (orientation task), if the profile names one.
    pub torso: Option<FrameId>,
    /// The foot frames, left then right.
    pub feet: [FrameId; 2],
}

impl RobotBody {
    /// The robot frame of `point`, if the robot has one.
    pub fn frame_of(&self, point: BodyPoint) -> Option<FrameId> {
        self.points
            .iter()
            .find(|(p, _)| *p == point)
            .map(|(_, f)| *f)
    }

    /// The robot frames of the left and right hips, if the robot has both: their middle is where
    /// the quality figures align the robot's body with the scaled human's ([`super::RetargetQuality`]).
    pub fn hips(&self) -> Option<[FrameId; 2]> {
        Some([
            self.frame_of(BodyPoint::LeftHip)?,
            self.frame_of(BodyPoint::RightHip)?,
        ])
    }

    /// The middle of the hips at `kin` \[m\], world; the pelvis frame's origin on a robot
    /// without both hips ([`RobotBody::hips`]).
    pub fn hips_middle(&self, robot: &Robot, kin: &Kinematics) -> Result<Vector3<f64>> {
        Ok(match self.hips() {
            Some([l, r]) => {
                0.5 * (kin.frame_pose(robot, l)?.translation.vector
                    + kin.frame_pose(robot, r)?.translation.vector)
            }
            None => kin.frame_pose(robot, self.pelvis)?.translation.vector,
        })
    }

    /// Finds the frames (see the module documentation) from the named frames of a profile;
    /// `kin` is at the start posture. Errors: an unknown frame name, a chain that does not
    /// reach the pelvis.
    pub fn find(robot: &Robot, kin: &Kinematics, names: &BodyFrameNames) -> Result<Self> {
        let pelvis = robot.frame_id(&names.pelvis)?;
        let torso = names
            .torso
            .as_deref()
            .map(|n| robot.frame_id(n))
            .transpose()?;
        let head = names
            .head
            .as_deref()
            .map(|n| robot.frame_id(n))
            .transpose()?;
        let feet = [
            robot.frame_id(&names.feet[0])?,
            robot.frame_id(&names.feet[1])?,
        ];
        let hands = [
            robot.frame_id(&names.hands[0])?,
            robot.frame_id(&names.hands[1])?,
        ];
        let mut points = vec![(BodyPoint::Pelvis, pelvis)];
        if let Some(h) = head {
            // A head frame at the pelvis (G1's `head_link`) does not mark the head.
            let d = kin.frame_pose(robot, h)?.translation.vector
                - kin.frame_pose(robot, pelvis)?.translation.vector;
            if d.norm() > MIN_HEAD_HEIGHT {
                points.push((BodyPoint::Head, h));
            }
        }
        let leg_chains = [chain(robot, feet[0])?, chain(robot, feet[1])?];
        let arm_chains = [chain(robot, hands[0])?, chain(robot, hands[1])?];
        let legs = branch(&leg_chains);
        let arms = branch(&arm_chains);
        for (i, side) in [Side::Left, Side::Right].into_iter().enumerate() {
            let bp = |limb: &str| point_of(side, limb);
            let (hip, ankle) = (link_frame(robot, leg_chains[i][legs])?, feet[i]);
            let knee = middle(robot, kin, &leg_chains[i][legs..], "knee", hip, ankle)?;
            let (sh, hand) = (link_frame(robot, arm_chains[i][arms])?, hands[i]);
            let elbow = middle(robot, kin, &arm_chains[i][arms..], "elbow", sh, hand)?;
            points.extend([
                (bp("shoulder"), sh),
                (bp("elbow"), elbow),
                (bp("wrist"), hand),
                (bp("hip"), hip),
                (bp("knee"), knee),
                (bp("ankle"), ankle),
            ]);
        }
        points.sort_by_key(|(p, _)| BodyPoint::ALL.iter().position(|a| a == p));
        Ok(Self {
            points,
            pelvis,
            torso,
            feet,
        })
    }
}

/// The frame names a [`RobotBody`] is found from (a robot profile's `feet` and `frames`).
#[derive(Debug, Clone, PartialEq)]
pub struct BodyFrameNames {
    /// Pelvis frame.
    pub pelvis: String,
    /// Torso frame, if any.
    pub torso: Option<String>,
    /// Head frame, if any.
    pub head: Option<String>,
    /// Foot (ankle) frames, left then right.
    pub feet: [String; 2],
    /// Hand (wrist) frames, left then right.
    pub hands: [String; 2],
}

fn point_of(side: Side, limb: &str) -> BodyPoint {
    let name = format!(
        "{}_{limb}",
        if side == Side::Left { "left" } else { "right" }
    );
    BodyPoint::from_name(&name).unwrap_or(BodyPoint::Pelvis)
}

/// The links from the root down to the link of frame `f` (root first).
pub(super) fn chain(robot: &Robot, f: FrameId) -> Result<Vec<usize>> {
    let frame = robot.frames().get(f.0).ok_or_else(|| Error::UnknownName {
        kind: "frame",
        name: format!("#{}", f.0),
        valid: Vec::new(),
    })?;
    let mut links = vec![frame.link];
    let mut link = frame.link;
    while let Some(j) = robot.joints().iter().find(|j| j.child == link) {
        link = j.parent;
        if links.len() > robot.links().len() {
            break;
        }
        links.push(link);
    }
    links.reverse();
    Ok(links)
}

/// The index, in both chains, of the first link after their common part.
pub(super) fn branch(chains: &[Vec<usize>; 2]) -> usize {
    let common = chains[0]
        .iter()
        .zip(&chains[1])
        .take_while(|(a, b)| a == b)
        .count();
    common.min(chains[0].len().saturating_sub(1))
}

fn link_frame(robot: &Robot, link: usize) -> Result<FrameId> {
    let name = robot
        .links()
        .get(link)
        .map(|l| l.name.as_str())
        .unwrap_or_default();
    robot.frame_id(name)
}

/// The middle joint of a limb chain (see the module documentation).
fn middle(
    robot: &Robot,
    kin: &Kinematics,
    links: &[usize],
    word: &str,
    start: FrameId,
    end: FrameId,
) -> Result<FrameId> {
    for &l in links {
        if let Some(j) = robot.joints().iter().find(|j| j.child == l) {
            if j.name.to_lowercase().contains(word) {
                return link_frame(robot, l);
            }
        }
    }
    let a = kin.frame_pose(robot, start)?.translation.vector;
    let b = kin.frame_pose(robot, end)?.translation.vector;
    let mid: Vector3<f64> = 0.5 * (a + b);
    let mut best = (f64::INFINITY, start);
    for &l in links {
        let f = link_frame(robot, l)?;
        let d = (kin.frame_pose(robot, f)?.translation.vector - mid).norm();
        if d < best.0 {
            best = (d, f);
        }
    }
    Ok(best.1)
}
