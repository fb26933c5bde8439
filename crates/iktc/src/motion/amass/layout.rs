//! The two joint layouts of AMASS archives, SMPL-H (52 joints) and SMPL-X (55 joints), and
//! their joint names in the body models' order.

/// The body joints both layouts start with (SMPL's first 22), in the models' order.
const BODY: [&str; 22] = [
    "pelvis",
    "left_hip",
    "right_hip",
    "spine1",
    "left_knee",
    "right_knee",
    "spine2",
    "left_ankle",
    "right_ankle",
    "spine3",
    "left_foot",
    "right_foot",
    "neck",
    "left_collar",
    "right_collar",
    "head",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
];

/// SMPL-X's face joints, between the body and the hands.
const FACE: [&str; 3] = ["jaw", "left_eye_smplhf", "right_eye_smplhf"];

/// The finger joints of one hand, in the models' order (the side is prefixed).
const FINGERS: [&str; 15] = [
    "index1", "index2", "index3", "middle1", "middle2", "middle3", "pinky1", "pinky2", "pinky3",
    "ring1", "ring2", "ring3", "thumb1", "thumb2", "thumb3",
];

/// The joint layout of a SMPL-family body model and of the poses written for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SmplLayout {
    /// SMPL+H: 22 body joints, then 15 per hand (52 joints; 156 pose values per frame).
    SmplH,
    /// SMPL-X: 22 body joints, the jaw and the eyes, then 15 per hand (55 joints; 165 pose
    /// values per frame).
    SmplX,
}

impl SmplLayout {
    /// The layout with `joints` joints, if any.
    pub fn from_joint_count(joints: usize) -> Option<Self> {
        match joints {
            52 => Some(SmplLayout::SmplH),
            55 => Some(SmplLayout::SmplX),
            _ => None,
        }
    }

    /// Its name: `SMPL-H` or `SMPL-X`.
    pub fn name(self) -> &'static str {
        match self {
            SmplLayout::SmplH => "SMPL-H",
            SmplLayout::SmplX => "SMPL-X",
        }
    }

    /// Number of joints (the root included).
    pub fn joint_count(self) -> usize {
        self.joint_names().len()
    }

    /// The joint names, in the model's order: SMPL's names (`pelvis`, `left_hip`, …,
    /// `right_wrist`), SMPL-X's `jaw`, `left_eye_smplhf`, `right_eye_smplhf`, then
    /// `left_index1` … `left_thumb3`, `right_index1` … `right_thumb3`.
    pub fn joint_names(self) -> Vec<String> {
        let face: &[&str] = match self {
            SmplLayout::SmplH => &[],
            SmplLayout::SmplX => &FACE,
        };
        let hand = |side: &'static str| FINGERS.iter().map(move |f| format!("{side}_{f}"));
        BODY.iter()
            .chain(face)
            .map(|s| s.to_string())
            .chain(hand("left"))
            .chain(hand("right"))
            .collect()
    }

    /// The body model files of this layout, as their authors name them (`SMPLX_FEMALE.npz`,
    /// …), and where they are distributed.
    pub fn model_files(self) -> (&'static str, &'static str) {
        match self {
            SmplLayout::SmplH => (
                "the SMPL+H model of its gender (`male/model.npz`, `female/model.npz` or \
                 `neutral/model.npz` of the extended SMPL+H model used by AMASS)",
                "the MANO website (mano.is.tue.mpg.de, after registering)",
            ),
            SmplLayout::SmplX => (
                "the SMPL-X model of its gender (`SMPLX_MALE.npz`, `SMPLX_FEMALE.npz` or \
                 `SMPLX_NEUTRAL.npz`)",
                "the SMPL-X website (smpl-x.is.tue.mpg.de, after registering)",
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::SmplLayout;

    #[test]
    fn layouts_have_the_models_joint_counts_and_unique_names() {
        for (layout, n) in [(SmplLayout::SmplH, 52), (SmplLayout::SmplX, 55)] {
            let names = layout.joint_names();
            assert_eq!(names.len(), n);
            assert_eq!(SmplLayout::from_joint_count(n), Some(layout));
            let mut sorted = names.clone();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), n, "{names:?}");
            assert_eq!(names[21], "right_wrist");
        }
        assert_eq!(SmplLayout::SmplH.joint_names()[22], "left_index1");
        assert_eq!(SmplLayout::SmplX.joint_names()[22], "jaw");
        assert_eq!(SmplLayout::SmplX.joint_names()[54], "right_thumb3");
        assert_eq!(SmplLayout::from_joint_count(24), None);
    }
}
