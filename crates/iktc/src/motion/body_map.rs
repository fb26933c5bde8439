//! Body maps: which skeleton joint, or the centroid of which markers, gives each body point (an
//! editable TOML file).
//!
//! ```toml
//! name = "131_01"
//! [points]
//! pelvis = "Hips"                  # a skeleton joint
//! left_wrist = ["LWRA", "LWRB"]    # markers: their centroid
//! ```
//!
//! Keys are [`BodyPoint`] names; every point of [`BodyPoint::REQUIRED`] must be given.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::BodyPoint;
use crate::error::{Error, Result};

/// Where a body point comes from.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(untagged)]
pub enum PointSource {
    /// The origin of this skeleton joint's frame.
    Joint(String),
    /// The centroid of these markers (one or more).
    Markers(Vec<String>),
}

/// How a body point's source was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FoundBy {
    /// From a joint or marker name.
    Name,
    /// From the tree: the legs' or arms' branching joint, the first joint towards the head.
    Structure,
    /// From the tree's shape and rest-pose geometry (names unknown).
    Shape,
    /// From a marker-set table (Plug-in-Gait).
    MarkerTable,
    /// Given in a map file.
    Given,
}

impl FoundBy {
    pub(crate) fn describe(self) -> &'static str {
        match self {
            FoundBy::Name => "name",
            FoundBy::Structure => "structure",
            FoundBy::Shape => "shape",
            FoundBy::MarkerTable => "marker table",
            FoundBy::Given => "given",
        }
    }
}

/// One entry of a [`BodyMap`].
#[derive(Debug, Clone, PartialEq)]
pub struct MappedPoint {
    /// The body point.
    pub point: BodyPoint,
    /// Its source.
    pub source: PointSource,
    /// How it was found.
    pub found_by: FoundBy,
}

/// Which joint or markers give each body point (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct BodyMap {
    /// The map's name.
    pub name: String,
    /// The mapped points, in [`BodyPoint::ALL`] order, each at most once.
    pub points: Vec<MappedPoint>,
}

/// A TOML error as [`Error::Parse`] with the 1-based line of its span (0 if unknown).
pub(crate) fn toml_error(text: &str, source_name: &str, e: &toml::de::Error) -> Error {
    let line = e
        .span()
        .and_then(|s| text.get(..s.start))
        .map(|head| head.matches('\n').count() + 1)
        .unwrap_or(0);
    Error::Parse {
        source_name: source_name.into(),
        line,
        message: e.message().to_string(),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MapFile {
    name: Option<String>,
    points: BTreeMap<String, PointSource>,
}

impl BodyMap {
    /// A map from entries (sorted into [`BodyPoint::ALL`] order); errors if a point is given
    /// twice, a marker group is empty, or a required point is missing.
    pub fn new(name: impl Into<String>, mut points: Vec<MappedPoint>) -> Result<Self> {
        let name = name.into();
        points.sort_by_key(|p| p.point);
        for w in points.windows(2) {
            if w[0].point == w[1].point {
                return Err(Error::InvalidSetting {
                    name: format!("body map `{name}`"),
                    value: w[0].point.to_string(),
                    expected: "each body point given once".to_string(),
                });
            }
        }
        for p in &points {
            if matches!(&p.source, PointSource::Markers(m) if m.is_empty()) {
                return Err(Error::InvalidSetting {
                    name: format!("body map `{name}`, point {}", p.point),
                    value: "[]".to_string(),
                    expected: "a joint name or a non-empty list of marker names".to_string(),
                });
            }
        }
        let map = Self { name, points };
        let missing = map.missing();
        if !missing.is_empty() {
            return Err(Error::InsufficientData {
                what: format!("body map `{}`", map.name),
                message: format!(
                    "missing required points: {}",
                    missing
                        .iter()
                        .map(|p| p.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
        Ok(map)
    }

    /// The required points the map does not give.
    pub fn missing(&self) -> Vec<BodyPoint> {
        BodyPoint::REQUIRED
            .into_iter()
            .filter(|r| self.get(*r).is_none())
            .collect()
    }

    /// The source of `point`, if mapped.
    pub fn get(&self, point: BodyPoint) -> Option<&PointSource> {
        self.points
            .iter()
            .find(|p| p.point == point)
            .map(|p| &p.source)
    }

    /// Parses a map file (see the module documentation); `source_name` names it in errors.
    pub fn from_toml_str(text: &str, source_name: &str) -> Result<Self> {
        let file: MapFile = toml::from_str(text).map_err(|e| toml_error(text, source_name, &e))?;
        let mut points = Vec::with_capacity(file.points.len());
        for (key, source) in file.points {
            points.push(MappedPoint {
                point: BodyPoint::from_name(&key)?,
                source,
                found_by: FoundBy::Given,
            });
        }
        Self::new(file.name.unwrap_or_else(|| source_name.to_string()), points)
    }

    /// The map as an editable TOML file, one line per point with how it was found as a comment.
    pub fn to_toml_string(&self) -> String {
        let quote = |s: &str| toml::Value::String(s.to_string()).to_string();
        let mut out = String::new();
        out.push_str(
            "# Body map: the skeleton joint (a name) or the markers (a list: their centroid)\n",
        );
        out.push_str("# giving each body point. Edit and pass back with --map.\n");
        out.push_str(&format!("name = {}\n\n[points]\n", quote(&self.name)));
        for p in &self.points {
            let value = match &p.source {
                PointSource::Joint(j) => quote(j),
                PointSource::Markers(m) => format!(
                    "[{}]",
                    m.iter().map(|s| quote(s)).collect::<Vec<_>>().join(", ")
                ),
            };
            out.push_str(&format!(
                "{} = {value}  # {}\n",
                p.point.name(),
                p.found_by.describe()
            ));
        }
        let absent: Vec<&str> = BodyPoint::ALL
            .iter()
            .filter(|b| self.get(**b).is_none())
            .map(|b| b.name())
            .collect();
        if !absent.is_empty() {
            out.push_str(&format!("# not found: {}\n", absent.join(", ")));
        }
        out
    }
}
