//! `iktc.builtin_text`: the text of the data files built into the library (robot models,
//! profiles, retargeting maps, clips), to read or to write a changed copy of.

use pyo3::prelude::*;

use crate::{to_py, IktcError};

/// The kinds `builtin_text` knows, with the names each accepts.
const KINDS: &str = "\"urdf\" (jvrc1, g1), \"mjcf\" (g1), \"profile\" (jvrc1, g1), \"map\" (deepmimic_jvrc1, bvh_jvrc1, deepmimic_g1), \"clip\" (humanoid3d_dance_a, humanoid3d_dance_b, humanoid3d_punch, humanoid3d_walk)";

/// The text of a data file built into iktc: `kind` "urdf" (the robot's URDF: "jvrc1", "g1"),
/// "mjcf" (its MuJoCo model: "g1"), "profile" (a robot profile, TOML: "jvrc1", "g1"), "map"
/// (a retargeting map, TOML) or "clip" (a DeepMimic clip, JSON), and the item's `name`.
#[pyfunction]
pub fn builtin_text(kind: &str, name: &str) -> PyResult<&'static str> {
    let unknown = |what: &str| {
        IktcError::new_err(format!(
            "name = `{name}`: no built-in {what} of that name; kinds and names: {KINDS}"
        ))
    };
    match kind {
        "urdf" => match name {
            "jvrc1" => Ok(iktc::model::JVRC1_URDF),
            "g1" => Ok(iktc::model::G1_URDF),
            _ => Err(unknown("URDF")),
        },
        "mjcf" => match name {
            "g1" => Ok(iktc::model::G1_MJCF),
            _ => Err(unknown("MJCF model")),
        },
        "profile" => iktc::profile::builtin_profile_text(name).map_err(to_py),
        "map" => iktc::motion::builtin_map_text(name).map_err(to_py),
        "clip" => iktc::motion::builtin_clip_text(name).map_err(to_py),
        _ => Err(IktcError::new_err(format!(
            "kind = `{kind}`: expected one of {KINDS}"
        ))),
    }
}
