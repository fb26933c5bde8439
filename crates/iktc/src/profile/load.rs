//! Reading and writing profiles: TOML text, files, the built-in ones.

use std::path::{Component, Path, PathBuf};

use super::schema::{ProfileOrigin, RobotProfile};
use crate::error::{Error, Result};

/// Names accepted by [`RobotProfile::builtin`].
pub const BUILTIN_PROFILES: [&str; 2] = ["jvrc1", "g1"];

const BUILTIN_PROFILE_TEXTS: [&str; 2] = [
    include_str!("../../data/profiles/jvrc1.toml"),
    include_str!("../../data/profiles/g1.toml"),
];

/// The files a built-in profile may name, by path relative to the crate's `data/`.
const EMBEDDED_FILES: [(&str, &str); 2] = [
    ("robots/jvrc1/jvrc1.urdf", crate::model::JVRC1_URDF),
    ("robots/g1/g1_29dof_rev_1_0.urdf", crate::model::G1_URDF),
];

/// The directory of the built-in profiles, relative to the crate's `data/`.
const BUILTIN_PROFILE_DIR: &str = "profiles";

/// The text of a built-in profile (with its comments), as [`RobotProfile::builtin`] reads it.
pub fn builtin_profile_text(name: &str) -> Result<&'static str> {
    BUILTIN_PROFILES
        .iter()
        .position(|n| *n == name)
        .map(|i| BUILTIN_PROFILE_TEXTS[i])
        .ok_or_else(|| Error::UnknownName {
            kind: "built-in robot profile",
            name: name.into(),
            valid: BUILTIN_PROFILES.iter().map(|s| s.to_string()).collect(),
        })
}

/// `dir/rel` with `.` and `..` resolved lexically (for paths inside the embedded data).
fn join_lexically(dir: &str, rel: &str) -> String {
    let mut parts: Vec<String> = Vec::new();
    for c in Path::new(dir).join(rel).components() {
        match c {
            Component::ParentDir => {
                parts.pop();
            }
            Component::Normal(s) => parts.push(s.to_string_lossy().into_owned()),
            _ => {}
        }
    }
    parts.join("/")
}

impl RobotProfile {
    /// Parses a profile from TOML text and checks its numbers ([`RobotProfile::check_values`]).
    /// `source_name` names the text in errors; relative paths are resolved against `origin`.
    ///
    /// Errors: malformed TOML, an unknown or missing key ([`Error::Parse`] with the line), a
    /// bad number ([`Error::Profile`] naming the key).
    pub fn from_toml_str(text: &str, source_name: &str, origin: ProfileOrigin) -> Result<Self> {
        let mut p: RobotProfile = toml::from_str(text).map_err(|e| {
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
        })?;
        p.origin = origin;
        p.check_values()?;
        Ok(p)
    }

    /// Reads a profile file; its `urdf` and map paths are relative to the file's directory.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::Parse {
            source_name: path.display().to_string(),
            line: 0,
            message: format!("cannot read the profile: {e}"),
        })?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_toml_str(
            &text,
            &path.display().to_string(),
            ProfileOrigin::Directory(dir),
        )
    }

    /// A built-in profile by name: `jvrc1` (JVRC-1, AIST) or `g1` (Unitree G1, 29 joints).
    pub fn builtin(name: &str) -> Result<Self> {
        let text = builtin_profile_text(name)?;
        Self::from_toml_str(
            text,
            &format!("built-in profile `{name}`"),
            ProfileOrigin::Builtin,
        )
    }

    /// The profile as TOML text (no comments); [`RobotProfile::from_toml_str`] reads it back
    /// to an equal profile.
    pub fn to_toml_string(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::InvalidSetting {
            name: format!("profile `{}`", self.name),
            value: "(not representable in TOML)".into(),
            expected: format!("a profile TOML can hold: {e}"),
        })
    }

    /// Resolves a path written in the profile (key `key`) and reads the file's text.
    pub(crate) fn read_relative(&self, key: &str, rel: &str) -> Result<String> {
        match &self.origin {
            ProfileOrigin::Builtin => {
                let path = join_lexically(BUILTIN_PROFILE_DIR, rel);
                EMBEDDED_FILES
                    .iter()
                    .find(|(p, _)| *p == path)
                    .map(|(_, text)| text.to_string())
                    .ok_or_else(|| Error::Profile {
                        key: key.into(),
                        value: rel.into(),
                        message: format!(
                            "a built-in profile can only name the embedded files {}",
                            EMBEDDED_FILES
                                .iter()
                                .map(|(p, _)| format!("../{p}"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    })
            }
            ProfileOrigin::Directory(dir) => {
                let path: PathBuf = dir.join(rel);
                std::fs::read_to_string(&path).map_err(|e| Error::Profile {
                    key: key.into(),
                    value: rel.into(),
                    message: format!("cannot read {}: {e}", path.display()),
                })
            }
        }
    }

    /// The robot description's text (URDF or MJCF) the profile names (key `urdf`).
    pub fn urdf_text(&self) -> Result<String> {
        self.read_relative("urdf", &self.urdf)
    }

    /// The folder of the robot description the profile names (key `urdf`), where an MJCF
    /// model's `<include>`s and meshes are found; `None` for a built-in profile.
    pub fn urdf_dir(&self) -> Option<PathBuf> {
        match &self.origin {
            ProfileOrigin::Builtin => None,
            ProfileOrigin::Directory(dir) => Some(
                dir.join(&self.urdf)
                    .parent()
                    .map_or_else(PathBuf::new, Path::to_path_buf),
            ),
        }
    }
}
