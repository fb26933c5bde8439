//! The named body points every motion source is reduced to, and the sides of the body.

use crate::error::{Error, Result};

/// A side of the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Side {
    /// The subject's left.
    Left,
    /// The subject's right.
    Right,
}

/// A named point of the human body.
///
/// Where a point sits on a skeleton: at the joint (origin of the joint frame) that moves the
/// segment starting there — `LeftElbow` at the forearm's joint, `LeftWrist` at the hand's,
/// `Head` at the skull's (the top of the head where a skeleton has no head joint), `Chest` at
/// the upper-spine joint the arms branch from, `Neck` at the first joint from the chest towards
/// the head, `Pelvis` at the joint the legs branch from. On marker data: the centroid of the
/// markers its map names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BodyPoint {
    /// The pelvis (the legs' branching joint).
    Pelvis,
    /// The upper spine (the arms' branching joint).
    Chest,
    /// The base of the neck.
    Neck,
    /// The head.
    Head,
    /// Left shoulder (the upper arm's joint).
    LeftShoulder,
    /// Left elbow.
    LeftElbow,
    /// Left wrist (the hand's joint).
    LeftWrist,
    /// Left hip (the thigh's joint).
    LeftHip,
    /// Left knee.
    LeftKnee,
    /// Left ankle.
    LeftAnkle,
    /// Left toe (the ball of the foot).
    LeftToe,
    /// Right shoulder.
    RightShoulder,
    /// Right elbow.
    RightElbow,
    /// Right wrist.
    RightWrist,
    /// Right hip.
    RightHip,
    /// Right knee.
    RightKnee,
    /// Right ankle.
    RightAnkle,
    /// Right toe.
    RightToe,
}

/// A limb point without its side (the side is carried by [`Side`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum Limb {
    Shoulder,
    Elbow,
    Wrist,
    Hip,
    Knee,
    Ankle,
    Toe,
}

impl BodyPoint {
    /// Every body point, in the order used by [`Keypoints`](super::Keypoints).
    pub const ALL: [BodyPoint; 18] = [
        BodyPoint::Pelvis,
        BodyPoint::Chest,
        BodyPoint::Neck,
        BodyPoint::Head,
        BodyPoint::LeftShoulder,
        BodyPoint::LeftElbow,
        BodyPoint::LeftWrist,
        BodyPoint::LeftHip,
        BodyPoint::LeftKnee,
        BodyPoint::LeftAnkle,
        BodyPoint::LeftToe,
        BodyPoint::RightShoulder,
        BodyPoint::RightElbow,
        BodyPoint::RightWrist,
        BodyPoint::RightHip,
        BodyPoint::RightKnee,
        BodyPoint::RightAnkle,
        BodyPoint::RightToe,
    ];

    /// The points a body map must give: all but `Chest`, `Neck` and the toes.
    pub const REQUIRED: [BodyPoint; 14] = [
        BodyPoint::Pelvis,
        BodyPoint::Head,
        BodyPoint::LeftShoulder,
        BodyPoint::LeftElbow,
        BodyPoint::LeftWrist,
        BodyPoint::LeftHip,
        BodyPoint::LeftKnee,
        BodyPoint::LeftAnkle,
        BodyPoint::RightShoulder,
        BodyPoint::RightElbow,
        BodyPoint::RightWrist,
        BodyPoint::RightHip,
        BodyPoint::RightKnee,
        BodyPoint::RightAnkle,
    ];

    /// The point's name in files and messages (`pelvis`, `left_wrist`, …).
    pub fn name(self) -> &'static str {
        match self {
            BodyPoint::Pelvis => "pelvis",
            BodyPoint::Chest => "chest",
            BodyPoint::Neck => "neck",
            BodyPoint::Head => "head",
            BodyPoint::LeftShoulder => "left_shoulder",
            BodyPoint::LeftElbow => "left_elbow",
            BodyPoint::LeftWrist => "left_wrist",
            BodyPoint::LeftHip => "left_hip",
            BodyPoint::LeftKnee => "left_knee",
            BodyPoint::LeftAnkle => "left_ankle",
            BodyPoint::LeftToe => "left_toe",
            BodyPoint::RightShoulder => "right_shoulder",
            BodyPoint::RightElbow => "right_elbow",
            BodyPoint::RightWrist => "right_wrist",
            BodyPoint::RightHip => "right_hip",
            BodyPoint::RightKnee => "right_knee",
            BodyPoint::RightAnkle => "right_ankle",
            BodyPoint::RightToe => "right_toe",
        }
    }

    /// The point called `name` (see [`BodyPoint::name`]), or [`Error::UnknownName`].
    pub fn from_name(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| Error::UnknownName {
                kind: "body point",
                name: name.to_string(),
                valid: Self::ALL.iter().map(|p| p.name().to_string()).collect(),
            })
    }

    /// The side of a limb point, `None` for the trunk and head.
    pub fn side(self) -> Option<Side> {
        self.limb().map(|(s, _)| s)
    }

    pub(crate) fn limb(self) -> Option<(Side, Limb)> {
        use BodyPoint as B;
        use Limb as L;
        use Side::{Left, Right};
        Some(match self {
            B::Pelvis | B::Chest | B::Neck | B::Head => return None,
            B::LeftShoulder => (Left, L::Shoulder),
            B::LeftElbow => (Left, L::Elbow),
            B::LeftWrist => (Left, L::Wrist),
            B::LeftHip => (Left, L::Hip),
            B::LeftKnee => (Left, L::Knee),
            B::LeftAnkle => (Left, L::Ankle),
            B::LeftToe => (Left, L::Toe),
            B::RightShoulder => (Right, L::Shoulder),
            B::RightElbow => (Right, L::Elbow),
            B::RightWrist => (Right, L::Wrist),
            B::RightHip => (Right, L::Hip),
            B::RightKnee => (Right, L::Knee),
            B::RightAnkle => (Right, L::Ankle),
            B::RightToe => (Right, L::Toe),
        })
    }

    pub(crate) fn of_limb(side: Side, limb: Limb) -> BodyPoint {
        Self::ALL
            .into_iter()
            .find(|p| p.limb() == Some((side, limb)))
            .unwrap_or(BodyPoint::Pelvis)
    }
}

impl std::fmt::Display for BodyPoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
