//! A SMPL-family body model's joints as linear functions of its shape coefficients, read from
//! the model's `.npz` file (`v_template`, `shapedirs`, `J_regressor`, `kintree_table`; the
//! pose blend shapes, skinning weights and faces are not read: they move the surface, not the
//! joints).
//!
//! The rest joints of a body of shape `β` are `J(β) = 𝒥 (T̄ + S β)` \[m\]: the template
//! vertices `T̄` (V×3) displaced by the shape blend shapes `S` (V×3×B, of which the first
//! `len(β)` are used), regressed by the joint regressor `𝒥` (J×V). The model keeps
//! `𝒥 T̄` (J×3) and `𝒥 S` (J×3×B), so that `J(β) = 𝒥 T̄ + (𝒥 S) β` costs J·3·len(β)
//! products; `S` is read element by element and never held whole.

use std::io::{Read, Seek};
use std::path::Path;

use nalgebra::Vector3;

use super::SmplLayout;
use crate::error::{Error, Result};
use crate::npz::Npz;

/// Most vertices accepted in a body model \[vertices\]: ten times SMPL-X's 10 475, so that a
/// malformed header cannot make the reader allocate without bound.
pub const MAX_MODEL_VERTICES: usize = 104_750;

/// Most shape blend shapes accepted in a body model \[–\]: SMPL-X files hold 300 shape and
/// 100 expression components; ten times more is room for any variant.
pub const MAX_SHAPE_COMPONENTS: usize = 4_000;

/// Most joints accepted in a body model \[joints\]; AMASS's layouts have 52 and 55.
pub const MAX_MODEL_JOINTS: usize = 1_000;

/// The joints of a SMPL-family body model (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct BodyModel {
    source: String,
    parents: Vec<Option<usize>>,
    /// `𝒥 T̄`, one per joint \[m\].
    template_joints: Vec<Vector3<f64>>,
    /// `𝒥 S` as `[(j · 3 + axis) · B + b]` \[m per unit of β\].
    joint_shape_dirs: Vec<f64>,
    shape_count: usize,
}

impl BodyModel {
    /// Reads the model file at `path`.
    ///
    /// Errors: [`Error::Parse`] naming the file when it cannot be read, is not an NPZ
    /// archive, lacks an array or has one of the wrong shape or kind (see
    /// [`BodyModel::from_reader`]).
    pub fn read(path: &Path) -> Result<Self> {
        let source = path.display().to_string();
        let file = std::fs::File::open(path).map_err(|e| Error::Parse {
            source_name: source.clone(),
            line: 0,
            message: format!("cannot read the body model file: {e}"),
        })?;
        Self::from_reader(std::io::BufReader::new(file), &source)
    }

    /// Reads a model from an `.npz` archive; `source` names it in errors.
    ///
    /// Checks: `v_template` is V×3 (V ≤ [`MAX_MODEL_VERTICES`]); `J_regressor` is J×V, dense
    /// (J ≤ [`MAX_MODEL_JOINTS`]); `kintree_table` is 2×J, its first row the parents, the
    /// root's (joint 0) a negative number or one ≥ J (the `uint32` −1 numpy writes), every
    /// other joint's smaller than its own index; `shapedirs` is V×3×B (B ≤
    /// [`MAX_SHAPE_COMPONENTS`]); every value is finite.
    pub fn from_reader<R: Read + Seek>(reader: R, source: &str) -> Result<Self> {
        let mut npz = Npz::new(reader, source)?;
        let bad = |message: String| model_error(source, message);
        let template = npz.array("v_template", 3 * MAX_MODEL_VERTICES)?;
        let v = match template.shape[..] {
            [v, 3] => v,
            _ => {
                return Err(bad(format!(
                    "`v_template` has shape {:?}, expected (vertices, 3)",
                    template.shape
                )))
            }
        };
        let regressor = npz.array("J_regressor", MAX_MODEL_JOINTS * v.max(1))?;
        let j = match regressor.shape[..] {
            [j, vr] if vr == v && j >= 1 => j,
            _ => {
                return Err(bad(format!(
                    "`J_regressor` has shape {:?}, expected (joints, {v}) for the {v} vertices of \
                     `v_template`",
                    regressor.shape
                )))
            }
        };
        let tree = npz.array("kintree_table", 2 * MAX_MODEL_JOINTS)?;
        if tree.shape[..] != [2, j] {
            return Err(bad(format!(
                "`kintree_table` has shape {:?}, expected (2, {j}) for the {j} joints of \
                 `J_regressor`",
                tree.shape
            )));
        }
        let parents = parents(&tree.values[..j]).map_err(bad)?;
        for (name, values) in [
            ("v_template", &template.values),
            ("J_regressor", &regressor.values),
        ] {
            if let Some(k) = values.iter().position(|x| !x.is_finite()) {
                return Err(bad(format!(
                    "`{name}` has a non-finite value at element {k}"
                )));
            }
        }
        let by_vertex = weights_by_vertex(&regressor.values, v);
        let mut template_joints = vec![Vector3::zeros(); j];
        for (vertex, weights) in by_vertex.iter().enumerate() {
            let t = Vector3::from_column_slice(&template.values[3 * vertex..3 * vertex + 3]);
            for (joint, w) in weights {
                template_joints[*joint] += t * *w;
            }
        }
        let (joint_shape_dirs, b) = joint_shape_dirs(&mut npz, &by_vertex, j, source)?;
        Ok(Self {
            source: source.to_string(),
            parents,
            template_joints,
            joint_shape_dirs,
            shape_count: b,
        })
    }

    /// The file the model was read from.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Number of joints J (the root included).
    pub fn joint_count(&self) -> usize {
        self.parents.len()
    }

    /// Number of shape blend shapes B.
    pub fn shape_count(&self) -> usize {
        self.shape_count
    }

    /// The parent of every joint (`None` for the root, joint 0), from `kintree_table`.
    pub fn parents(&self) -> &[Option<usize>] {
        &self.parents
    }

    /// The layout its joint count gives, if AMASS uses it.
    pub fn layout(&self) -> Option<SmplLayout> {
        SmplLayout::from_joint_count(self.joint_count())
    }

    /// The rest joints `J(β) = 𝒥 T̄ + (𝒥 S) β` \[m\] of the body of shape `betas` (see the
    /// module documentation).
    ///
    /// Errors: [`Error::NonFinite`] for a non-finite coefficient; [`Error::InvalidSetting`]
    /// when `betas` has a non-zero coefficient past the model's B shape blend shapes (zeros
    /// there change nothing and are accepted).
    pub fn joints(&self, betas: &[f64]) -> Result<Vec<Vector3<f64>>> {
        for (i, x) in betas.iter().enumerate() {
            crate::error::check_finite(|| format!("shape coefficient betas[{i}]"), *x)?;
        }
        let b = self.shape_count;
        if let Some(k) = betas.iter().skip(b).position(|x| *x != 0.0) {
            return Err(Error::InvalidSetting {
                name: format!(
                    "shape coefficients (betas) for the body model `{}`",
                    self.source
                ),
                value: format!(
                    "{} coefficients, betas[{}] = {} non-zero",
                    betas.len(),
                    b + k,
                    betas[b + k]
                ),
                expected: format!(
                    "at most the model's {b} shape components (`shapedirs`); use a model file \
                     with at least {} (AMASS's archives hold 16)",
                    betas.len()
                ),
            });
        }
        let used = betas.len().min(b);
        Ok(self
            .template_joints
            .iter()
            .enumerate()
            .map(|(j, t)| {
                let mut p = *t;
                for axis in 0..3 {
                    let row = &self.joint_shape_dirs[(j * 3 + axis) * b..][..used];
                    p[axis] += row.iter().zip(betas).map(|(s, x)| s * x).sum::<f64>();
                }
                p
            })
            .collect())
    }
}

/// An [`Error::Parse`] about the body model `source`.
fn model_error(source: &str, message: String) -> Error {
    Error::Parse {
        source_name: source.to_string(),
        line: 0,
        message: format!("body model: {message}"),
    }
}

/// The joint regressor's (J×V, row-major) non-zero weights, by vertex: (joint, weight).
fn weights_by_vertex(regressor: &[f64], v: usize) -> Vec<Vec<(usize, f64)>> {
    let mut by_vertex: Vec<Vec<(usize, f64)>> = vec![Vec::new(); v];
    for (k, w) in regressor.iter().enumerate() {
        if *w != 0.0 {
            by_vertex[k % v].push((k / v, *w));
        }
    }
    by_vertex
}

/// Reads `shapedirs` (V×3×B) regressed to the `j` joints: (J×3×B row-major, B); a wrong shape
/// or a non-finite value is an error.
fn joint_shape_dirs<R: Read + Seek>(
    npz: &mut Npz<R>,
    by_vertex: &[Vec<(usize, f64)>],
    j: usize,
    source: &str,
) -> Result<(Vec<f64>, usize)> {
    let v = by_vertex.len();
    let dirs_shape = npz.shape("shapedirs")?;
    let b = match dirs_shape[..] {
        [dv, 3, b] if dv == v && b <= MAX_SHAPE_COMPONENTS => b,
        _ => {
            return Err(model_error(
                source,
                format!(
                    "`shapedirs` has shape {dirs_shape:?}, expected ({v}, 3, components ≤ \
                     {MAX_SHAPE_COMPONENTS})"
                ),
            ))
        }
    };
    let mut joint_shape_dirs = vec![0.0; j * 3 * b];
    let mut non_finite = None;
    npz.visit("shapedirs", v * 3 * b, |k, s| {
        if !s.is_finite() {
            non_finite.get_or_insert(k);
            return;
        }
        let (vertex, axis, component) = (k / (3 * b), (k / b) % 3, k % b);
        for (joint, w) in &by_vertex[vertex] {
            joint_shape_dirs[(joint * 3 + axis) * b + component] += w * s;
        }
    })?;
    if let Some(k) = non_finite {
        return Err(model_error(
            source,
            format!("`shapedirs` has a non-finite value at element {k}"),
        ));
    }
    Ok((joint_shape_dirs, b))
}

/// The parents of a `kintree_table`'s first row: the root's a negative number or one at least
/// the joint count (numpy's `uint32` −1), every other joint's a smaller index than its own.
fn parents(row: &[f64]) -> std::result::Result<Vec<Option<usize>>, String> {
    let n = row.len();
    row.iter()
        .enumerate()
        .map(|(i, p)| {
            let valid = p.is_finite() && p.fract() == 0.0;
            match i {
                0 if valid && (*p < 0.0 || *p >= n as f64) => Ok(None),
                0 => Err(format!(
                    "`kintree_table`'s root (joint 0) has parent {p}, expected none (−1 or \
                     4294967295)"
                )),
                _ if valid && *p >= 0.0 && *p < i as f64 => Ok(Some(*p as usize)),
                _ => Err(format!(
                    "`kintree_table` gives joint {i} the parent {p}, expected a joint before it \
                     (0 to {})",
                    i - 1
                )),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::parents;

    #[test]
    fn kintree_parents_are_checked() {
        assert_eq!(
            parents(&[4294967295.0, 0.0, 1.0, 0.0]).unwrap(),
            [None, Some(0), Some(1), Some(0)]
        );
        assert_eq!(parents(&[-1.0, 0.0]).unwrap(), [None, Some(0)]);
        assert!(parents(&[0.0, 0.0]).unwrap_err().contains("root"));
        assert!(parents(&[-1.0, 2.0, 0.0])
            .unwrap_err()
            .contains("joint 1 the parent 2"));
        assert!(parents(&[-1.0, 0.5]).is_err());
    }
}
