//! Length units and up axes of motion files, given or decided from the subject's standing height.
//!
//! `auto` units: the subject's standing height `h` in file units (the extent of the rest pose,
//! or of the first complete marker frame, along the up axis) is converted by every candidate
//! unit (m, cm, mm, inch, CMU's 1/0.45 inch); the unit for which `h · metres_per_unit` lies in
//! [`HUMAN_HEIGHT_MIN`, `HUMAN_HEIGHT_MAX`] is chosen. The candidate ranges do not overlap
//! (CMU 21–37 units, inch 47–83, cm 120–210, mm 1200–2100), so at most one fits; none is an
//! error asking for an explicit unit.
//!
//! `auto` up axis: the direction from the mean of the two ankles to the head in the rest pose
//! (first complete frame for markers); the coordinate axis with the largest component is up,
//! and it must be +Y or +Z.

use std::str::FromStr;

use nalgebra::Vector3;

use super::bvh::LengthUnit;
use super::UpAxis;
use crate::error::{Error, Result};

/// CMU's length unit \[m/unit\]: 1/0.45 inch (the ASF files say `length 0.45`).
pub const CMU_METRES_PER_UNIT: f64 = 0.0254 / 0.45;

/// Shortest standing height accepted as human by `auto` units \[m\]. Lower accepts children and
/// partial skeletons, and brings the candidate units' ranges closer to overlapping.
pub const HUMAN_HEIGHT_MIN: f64 = 1.2;

/// Tallest standing height accepted as human by `auto` units \[m\].
pub const HUMAN_HEIGHT_MAX: f64 = 2.1;

/// The length unit of a motion file: a given one or `Auto`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Units {
    /// Decide from the subject's standing height (see the module documentation).
    #[default]
    Auto,
    /// This unit.
    Fixed(LengthUnit),
}

/// The candidate units of [`Units::Auto`], with their names.
const CANDIDATES: [(&str, LengthUnit); 5] = [
    ("m", LengthUnit::Metres),
    ("cm", LengthUnit::Centimetres),
    ("mm", LengthUnit::Millimetres),
    ("inch", LengthUnit::Inches),
    (
        "cmu",
        LengthUnit::Custom {
            metres_per_unit: CMU_METRES_PER_UNIT,
        },
    ),
];

/// A short name of a length unit (`m`, `cm`, `mm`, `inch`, `cmu`, or `x m` for another scale).
pub fn unit_name(unit: LengthUnit) -> String {
    CANDIDATES
        .iter()
        .find(|(_, u)| u.metres_per_unit() == unit.metres_per_unit())
        .map_or_else(
            || format!("{} m", unit.metres_per_unit()),
            |(n, _)| (*n).to_string(),
        )
}

impl FromStr for Units {
    type Err = Error;

    /// `auto`, `m`, `cm`, `mm`, `inch` or `cmu` (1/0.45 inch).
    fn from_str(s: &str) -> Result<Self> {
        let s = s.trim();
        if s.eq_ignore_ascii_case("auto") {
            return Ok(Units::Auto);
        }
        CANDIDATES
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(s))
            .map(|(_, u)| Units::Fixed(*u))
            .ok_or_else(|| Error::InvalidSetting {
                name: "units".to_string(),
                value: s.to_string(),
                expected: "one of m, cm, mm, inch, cmu (1/0.45 inch), auto".to_string(),
            })
    }
}

/// The up axis of a motion file: a given one or `Auto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpChoice {
    /// Decide from the rest pose (see the module documentation).
    #[default]
    Auto,
    /// This axis.
    Fixed(UpAxis),
}

impl FromStr for UpChoice {
    type Err = Error;

    /// `auto`, `y` or `z`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(UpChoice::Auto),
            "y" => Ok(UpChoice::Fixed(UpAxis::Y)),
            "z" => Ok(UpChoice::Fixed(UpAxis::Z)),
            _ => Err(Error::InvalidSetting {
                name: "up".to_string(),
                value: s.to_string(),
                expected: "one of y, z, auto".to_string(),
            }),
        }
    }
}

/// What unit was used and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitsDecision {
    /// The unit.
    pub unit: LengthUnit,
    /// Whether it was decided automatically.
    pub automatic: bool,
    /// The standing height in file units it was decided from (`None` if given or stated by
    /// the format).
    pub standing_height: Option<f64>,
}

impl std::fmt::Display for UnitsDecision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let name = unit_name(self.unit);
        let m = self.unit.metres_per_unit();
        match (self.automatic, self.standing_height) {
            (true, Some(h)) => write!(
                f,
                "{name} ({m:.6} m/unit), decided from the standing height {h:.4} units = {:.3} m",
                h * m
            ),
            (true, None) => write!(f, "{name} ({m:.6} m/unit), stated by the format"),
            _ => write!(f, "{name} ({m:.6} m/unit), given"),
        }
    }
}

/// What up axis was used and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpDecision {
    /// The axis.
    pub up: UpAxis,
    /// Whether it was decided automatically.
    pub automatic: bool,
    /// What an automatic decision was measured on: the skeleton's rest pose, else (a rest pose
    /// that does not stand along +Y or +Z, e.g. a rig lying along +X at rest) its first frame,
    /// or a marker file's most complete frame.
    pub measured_on: Measured,
}

/// The posture the automatic units and up axis were measured on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measured {
    /// The skeleton's rest pose (zero rotations and translations).
    RestPose,
    /// The clip's first frame (the rest pose does not stand).
    FirstFrame,
    /// The marker file's frame with the most markers.
    MostCompleteFrame,
    /// Nothing: the format states it ([`MotionFormat::fixed_frame`](super::MotionFormat::fixed_frame)).
    Format,
}

impl std::fmt::Display for UpDecision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let axis = match self.up {
            UpAxis::Y => "+Y",
            UpAxis::Z => "+Z",
        };
        let how = match (self.automatic, self.measured_on) {
            (false, _) => "given",
            (true, Measured::RestPose) => "decided from the rest pose (ankles to head)",
            (true, Measured::FirstFrame) => {
                "decided from the first frame (ankles to head; the rest pose does not stand)"
            }
            (true, Measured::MostCompleteFrame) => {
                "decided from the most complete frame (ankles to head)"
            }
            (true, Measured::Format) => "stated by the format",
        };
        write!(f, "{axis}, {how}")
    }
}

/// Decides the unit (see the module documentation). `standing_height` \[file units\] is needed
/// for `Auto` only; `source` names the file in errors.
pub fn decide_units(
    units: Units,
    standing_height: Option<f64>,
    source: &str,
) -> Result<UnitsDecision> {
    match units {
        Units::Fixed(unit) => {
            unit.validate()?;
            Ok(UnitsDecision {
                unit,
                automatic: false,
                standing_height: None,
            })
        }
        Units::Auto => {
            let h = standing_height.ok_or_else(|| Error::InsufficientData {
                what: format!("automatic units of {source}"),
                message: "no standing height could be measured; give the units".to_string(),
            })?;
            CANDIDATES
                .iter()
                .find(|(_, u)| {
                    let m = h * u.metres_per_unit();
                    (HUMAN_HEIGHT_MIN..=HUMAN_HEIGHT_MAX).contains(&m)
                })
                .map(|(_, u)| UnitsDecision {
                    unit: *u,
                    automatic: true,
                    standing_height: Some(h),
                })
                .ok_or_else(|| Error::InvalidSetting {
                    name: format!("automatic units of {source}"),
                    value: format!(
                        "standing height {h} file units, i.e. {}",
                        CANDIDATES
                            .iter()
                            .map(|(n, u)| format!("{:.3} m in {n}", h * u.metres_per_unit()))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                    expected: format!(
                        "a human standing height in [{HUMAN_HEIGHT_MIN}, {HUMAN_HEIGHT_MAX}] m in one unit; give the unit (m, cm, mm, inch, cmu)"
                    ),
                })
        }
    }
}

/// Whether the ankles-to-head vector `v` \[file units\] is mostly along +Y or +Z: a subject
/// standing in a supported up axis.
pub fn stands(v: &Vector3<f64>) -> bool {
    let k = v.iamax();
    k > 0 && v[k] > 0.0
}

/// Decides the up axis (see the module documentation) from the vector from the ankles to the
/// head \[file units\] (needed for `Auto` only) measured on `measured_on`.
pub fn decide_up(
    up: UpChoice,
    ankles_to_head: Option<Vector3<f64>>,
    measured_on: Measured,
    source: &str,
) -> Result<UpDecision> {
    match up {
        UpChoice::Fixed(up) => Ok(UpDecision {
            up,
            automatic: false,
            measured_on,
        }),
        UpChoice::Auto => {
            let v = ankles_to_head.ok_or_else(|| Error::InsufficientData {
                what: format!("automatic up axis of {source}"),
                message: "no head and ankles were found; give the up axis".to_string(),
            })?;
            let k = v.iamax();
            let up = match (k, stands(&v)) {
                (1, true) => UpAxis::Y,
                (2, true) => UpAxis::Z,
                _ => {
                    return Err(Error::InvalidSetting {
                        name: format!("automatic up axis of {source}"),
                        value: format!(
                            "ankles-to-head direction ({:.3}, {:.3}, {:.3})",
                            v.x, v.y, v.z
                        ),
                        expected:
                            "a subject standing along +Y or +Z (other axes are not supported)"
                                .to_string(),
                    })
                }
            };
            Ok(UpDecision {
                up,
                automatic: true,
                measured_on,
            })
        }
    }
}

/// The rotation taking a point of a file with up axis `up` to the Z-up world (identity for Z,
/// [`y_up_to_z_up`](super::y_up_to_z_up) for Y).
pub fn to_z_up(up: UpAxis) -> nalgebra::UnitQuaternion<f64> {
    match up {
        UpAxis::Z => nalgebra::UnitQuaternion::identity(),
        UpAxis::Y => super::y_up_to_z_up(),
    }
}

/// The coordinate of `v` along the up axis.
pub(crate) fn height_of(v: &Vector3<f64>, up: UpAxis) -> f64 {
    match up {
        UpAxis::Y => v.y,
        UpAxis::Z => v.z,
    }
}

/// Extent along the up axis of a set of points \[their unit\]; `None` when empty or not finite.
pub(crate) fn extent_along(points: &[Vector3<f64>], up: UpAxis) -> Option<f64> {
    let (lo, hi) = points
        .iter()
        .map(|p| height_of(p, up))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), h| {
            (lo.min(h), hi.max(h))
        });
    (hi - lo).is_finite().then_some(hi - lo)
}
