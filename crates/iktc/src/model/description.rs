//! A robot description in either format iktc reads, told apart by the document's root
//! element: `<robot>` is URDF, `<mujoco>` is MJCF (feature `mjcf`), whatever the file's
//! extension (`.urdf` or `.xml`).

use std::path::Path;

use super::{BaseKind, ModelOptions, Robot};
use crate::error::{Error, Result};
use crate::resources::ReadLimits;

/// The formats of a robot description.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DescriptionFormat {
    /// URDF (root `<robot>`, or anything not MJCF).
    Urdf,
    /// MuJoCo MJCF (root `<mujoco>`).
    Mjcf,
}

/// The format of the description `text`, from its root element.
pub fn description_format(text: &str) -> DescriptionFormat {
    #[cfg(feature = "mjcf")]
    let root = super::mjcf::root_tag(text);
    #[cfg(not(feature = "mjcf"))]
    let root = text.trim_start().starts_with("<mujoco").then_some("mujoco");
    if root == Some("mujoco") {
        DescriptionFormat::Mjcf
    } else {
        DescriptionFormat::Urdf
    }
}

#[cfg(not(feature = "mjcf"))]
fn no_mjcf() -> Error {
    Error::Urdf {
        message:
            "this is an MJCF model (root <mujoco>), and iktc was built without its feature `mjcf`"
                .into(),
    }
}

/// The base the description itself declares: for MJCF, floating when it has a free joint,
/// else fixed; `None` for URDF, which leaves it to [`ModelOptions::base`].
///
/// Errors: an MJCF model that cannot be read.
pub fn declared_base(text: &str, dir: Option<&Path>) -> Result<Option<BaseKind>> {
    match description_format(text) {
        DescriptionFormat::Urdf => Ok(None),
        #[cfg(feature = "mjcf")]
        DescriptionFormat::Mjcf => {
            let m = super::mjcf::read_mjcf(text, "MJCF text", dir, &ReadLimits::default())?;
            Ok(Some(if m.floats() {
                BaseKind::Floating
            } else {
                BaseKind::Fixed
            }))
        }
        #[cfg(not(feature = "mjcf"))]
        DescriptionFormat::Mjcf => {
            let _ = dir;
            Err(no_mjcf())
        }
    }
}

/// The description `text` (folder `dir` when known) as a URDF tree: the URDF parsed, or the
/// MJCF model's links, joints and geoms. The one place the geometry readers (profile init,
/// viewer meshes, batch records) get a robot's tree from.
pub(crate) fn read_description(
    text: &str,
    dir: Option<&Path>,
    limits: &ReadLimits,
) -> Result<urdf_rs::Robot> {
    match description_format(text) {
        DescriptionFormat::Urdf => Ok(super::read_urdf(text, limits)?.0),
        #[cfg(feature = "mjcf")]
        DescriptionFormat::Mjcf => {
            Ok(super::mjcf::read_mjcf(text, "MJCF text", dir, limits)?.urdf())
        }
        #[cfg(not(feature = "mjcf"))]
        DescriptionFormat::Mjcf => {
            let _ = dir;
            Err(no_mjcf())
        }
    }
}

// The readers behind `RobotFiles` (its docs say what each checks).
pub(crate) fn from_description_str(
    text: &str,
    dir: Option<&Path>,
    options: &ModelOptions,
) -> Result<Robot> {
    match description_format(text) {
        DescriptionFormat::Urdf => super::urdf::from_urdf_str(text, options),
        #[cfg(feature = "mjcf")]
        DescriptionFormat::Mjcf => {
            super::mjcf::from_mjcf_str_with(text, dir, options, &ReadLimits::default())
        }
        #[cfg(not(feature = "mjcf"))]
        DescriptionFormat::Mjcf => {
            let _ = dir;
            Err(no_mjcf())
        }
    }
}

pub(crate) fn from_description_file(path: &Path, options: &ModelOptions) -> Result<Robot> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::Urdf {
        message: format!("cannot read {}: {e}", path.display()),
    })?;
    match description_format(&text) {
        DescriptionFormat::Urdf => super::urdf::from_urdf_str(&text, options),
        #[cfg(feature = "mjcf")]
        DescriptionFormat::Mjcf => super::mjcf::from_mjcf_file(path, options),
        #[cfg(not(feature = "mjcf"))]
        DescriptionFormat::Mjcf => Err(no_mjcf()),
    }
}
