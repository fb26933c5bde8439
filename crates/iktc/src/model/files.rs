//! Robots read from their description files: URDF, MuJoCo MJCF, or either by its root element.
//!
//! [`RobotFiles`] adds the readers to [`Robot`] (which lives in the format-free core), so that
//! `Robot::from_urdf_file(path, &options)` reads as a constructor once the trait is in scope
//! (it is in [`crate::prelude`]).

use std::path::Path;

use super::{ModelOptions, Robot};
use crate::error::Result;
use crate::resources::ReadLimits;

/// Robot constructors from URDF and MJCF (implemented for [`Robot`]).
pub trait RobotFiles: Sized {
    /// Reads a robot from URDF text (revolute, continuous, prismatic and fixed joints).
    ///
    /// A malformed document, an unsupported joint type, an inconsistent tree or a bad number is
    /// an [`Error`](crate::Error); see [`RobotBuilder::build`](super::RobotBuilder::build).
    ///
    /// Every `<limit>` is checked (see [`RobotFiles::from_urdf_str_with`]), with the default
    /// [`ReadLimits`].
    fn from_urdf_str(text: &str, options: &ModelOptions) -> Result<Self>;

    /// [`RobotFiles::from_urdf_str`] with explicit [`ReadLimits`] (the XML nesting depth).
    ///
    /// What is checked beyond the XML and the tree (each an [`Error`](crate::Error) naming the
    /// joint or link, the attribute, its value and what was expected):
    ///
    /// * the nesting depth (at most [`ReadLimits::max_xml_depth`]), before the document is
    ///   parsed into a tree;
    /// * the elements inside each `<joint>` and `<inertial>` and the attributes of `<limit>`:
    ///   an unknown one is an error, but for an element inside `<joint>` that misspells none
    ///   URDF defines (an exporter's extension such as `<joint_properties>`), which is ignored
    ///   with a warning;
    /// * a revolute or prismatic joint needs a `<limit>` (URDF requires it) with a range
    ///   `lower < upper` (a zero-width range is an error: make the joint fixed or lock it);
    /// * `velocity` must be finite and > 0 (0 or a negative value would mean a joint that
    ///   cannot move); a missing velocity (URDF ≥ 1.2 reads it as unbounded) is accepted with a
    ///   warning;
    /// * `effort` must be finite and ≥ 0; URDF allows 0 (many exporters write it for "unknown"),
    ///   and iktc, being kinematic, does not use efforts: `effort="0"` is accepted with a
    ///   warning ([`Robot::warnings`]);
    /// * `acceleration` (URDF 1.2), when written, must be finite and > 0;
    /// * masses, inertias and origins: see [`RobotBuilder::build`](super::RobotBuilder::build).
    fn from_urdf_str_with(text: &str, options: &ModelOptions, limits: &ReadLimits) -> Result<Self>;

    /// Reads a robot from a URDF file.
    fn from_urdf_file(path: &Path, options: &ModelOptions) -> Result<Self>;

    /// Reads a robot from MJCF text (see the [`mjcf`](super::mjcf) module for what is read).
    /// Without a folder, an `<include>` is an error and mesh files are not looked for: use
    /// [`RobotFiles::from_mjcf_file`] for a model on disk.
    #[cfg(feature = "mjcf")]
    fn from_mjcf_str(text: &str, options: &ModelOptions) -> Result<Self>;

    /// [`RobotFiles::from_mjcf_str`] for a model in the folder `dir` (for `<include>` and mesh
    /// files), with explicit [`ReadLimits`] (the XML nesting depth, included files counted).
    ///
    /// Errors: malformed XML, a root other than `<mujoco>`, an unsupported element or joint
    /// type, a bad number (each naming the element, file and line), then what
    /// [`RobotBuilder::build`](super::RobotBuilder::build) checks.
    #[cfg(feature = "mjcf")]
    fn from_mjcf_str_with(
        text: &str,
        dir: Option<&Path>,
        options: &ModelOptions,
        limits: &ReadLimits,
    ) -> Result<Self>;

    /// Reads a robot from an MJCF file; `<include>` and mesh files are found from its folder.
    #[cfg(feature = "mjcf")]
    fn from_mjcf_file(path: &Path, options: &ModelOptions) -> Result<Self>;

    /// Reads a robot from URDF or MJCF text (by its root element, see
    /// [`description_format`](super::description_format)) in the folder `dir` when known (MJCF
    /// `<include>` and meshes).
    fn from_description_str(text: &str, dir: Option<&Path>, options: &ModelOptions)
        -> Result<Self>;

    /// Reads a robot from a URDF or MJCF file (by its root element, whatever its extension).
    fn from_description_file(path: &Path, options: &ModelOptions) -> Result<Self>;
}

impl RobotFiles for Robot {
    fn from_urdf_str(text: &str, options: &ModelOptions) -> Result<Self> {
        super::urdf::from_urdf_str(text, options)
    }

    fn from_urdf_str_with(text: &str, options: &ModelOptions, limits: &ReadLimits) -> Result<Self> {
        super::urdf::from_urdf_str_with(text, options, limits)
    }

    fn from_urdf_file(path: &Path, options: &ModelOptions) -> Result<Self> {
        super::urdf::from_urdf_file(path, options)
    }

    #[cfg(feature = "mjcf")]
    fn from_mjcf_str(text: &str, options: &ModelOptions) -> Result<Self> {
        super::mjcf::from_mjcf_str(text, options)
    }

    #[cfg(feature = "mjcf")]
    fn from_mjcf_str_with(
        text: &str,
        dir: Option<&Path>,
        options: &ModelOptions,
        limits: &ReadLimits,
    ) -> Result<Self> {
        super::mjcf::from_mjcf_str_with(text, dir, options, limits)
    }

    #[cfg(feature = "mjcf")]
    fn from_mjcf_file(path: &Path, options: &ModelOptions) -> Result<Self> {
        super::mjcf::from_mjcf_file(path, options)
    }

    fn from_description_str(
        text: &str,
        dir: Option<&Path>,
        options: &ModelOptions,
    ) -> Result<Self> {
        super::description::from_description_str(text, dir, options)
    }

    fn from_description_file(path: &Path, options: &ModelOptions) -> Result<Self> {
        super::description::from_description_file(path, options)
    }
}
