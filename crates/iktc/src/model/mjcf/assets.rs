//! `<asset>`s iktc reads: meshes (their files, for soles and the viewer) and materials
//! (their colours).

use std::collections::HashMap;
use std::path::Path;

use super::defaults::{Attrs, Defaults, MAIN};
use super::geom::MeshAsset;
use super::spec::{numbers, Compiler};
use super::xml::El;
use crate::error::Result;

/// The mesh assets by name (a mesh without `name` is named after its file's stem; its file
/// under `meshdir`, from the folder of the file declaring it: the model `main` in `dir`, or an
/// included file) and the material colours by name.
///
/// Errors: a mesh without `file` or `vertex`, a scale of other than 3 numbers, a bad `rgba`.
#[allow(clippy::type_complexity)]
pub(crate) fn read(
    root: &El,
    c: &Compiler,
    d: &Defaults,
    main: &str,
    dir: Option<&Path>,
) -> Result<(HashMap<String, MeshAsset>, HashMap<String, [f64; 4]>)> {
    let mut meshes = HashMap::new();
    let mut materials = HashMap::new();
    for asset in root.elements("asset") {
        for el in &asset.children {
            let a = Attrs::new(el, MAIN, d)?;
            match el.tag.as_str() {
                "mesh" => {
                    let Some(file) = el.attr("file") else {
                        if el.attr("vertex").is_none() {
                            return Err(el.error("has neither `file` nor `vertex`"));
                        }
                        continue;
                    };
                    let name = match el.attr("name") {
                        Some(n) => n.to_string(),
                        None => Path::new(file)
                            .file_stem()
                            .map(|s| s.to_string_lossy().into_owned())
                            .unwrap_or_else(|| file.to_string()),
                    };
                    let s = numbers(&a, "scale", Some(3))?.unwrap_or_else(|| vec![1.0; 3]);
                    // An included file's folder, relative to the model's.
                    let from = match (dir, Path::new(&*el.file).parent()) {
                        (Some(dir), Some(from)) if &*el.file != main => {
                            from.strip_prefix(dir).unwrap_or(from).to_path_buf()
                        }
                        _ => Default::default(),
                    };
                    meshes.insert(
                        name,
                        MeshAsset {
                            file: from
                                .join(&c.meshdir)
                                .join(file)
                                .to_string_lossy()
                                .into_owned(),
                            scale: [s[0], s[1], s[2]],
                        },
                    );
                }
                "material" => {
                    if let (Some(n), Some(v)) = (el.attr("name"), numbers(&a, "rgba", Some(4))?) {
                        materials.insert(n.to_string(), [v[0], v[1], v[2], v[3]]);
                    }
                }
                _ => {}
            }
        }
    }
    Ok((meshes, materials))
}
