//! `<compiler>` settings and the attribute values of MJCF: numbers, positions and
//! orientations (`quat`, `axisangle`, `euler`, `xyaxes`, `zaxis`).

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3};

use super::defaults::Attrs;
use super::xml::El;
use crate::error::Result;

/// Below this norm a direction or axis (`axis`, `zaxis`, `xyaxes`, `fromto`) is read as zero
/// \[m or unitless\]: MuJoCo's `mjMINVAL`.
pub(crate) const MIN_NORM: f64 = 1e-15;

/// When `<inertial>` gives way to the geoms' mass (`<compiler inertiafromgeom>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FromGeom {
    /// Never: a body without `<inertial>` is massless.
    Never,
    /// Always: `<inertial>` is ignored.
    Always,
    /// Only for bodies without `<inertial>` (MuJoCo's default, `auto`).
    Auto,
}

/// The `<compiler>` settings iktc reads.
#[derive(Debug, Clone)]
pub(crate) struct Compiler {
    /// Angles in degrees (`angle="degree"`, MuJoCo's default) or radians.
    pub degrees: bool,
    /// `eulerseq`: three of `xyzXYZ`, lower case about the moving axes, upper case about the
    /// fixed ones.
    pub eulerseq: [u8; 3],
    /// `meshdir` (else `assetdir`), relative to the model's folder.
    pub meshdir: String,
    /// `autolimits` (default true): a joint with a `range` is limited unless `limited="false"`.
    pub autolimits: bool,
    /// `inertiafromgeom`.
    pub from_geom: FromGeom,
}

impl Compiler {
    /// The settings of every `<compiler>` under `root`, later ones overriding.
    ///
    /// Errors: an unknown value of `angle`, `eulerseq`, `autolimits`, `inertiafromgeom`, or
    /// `coordinate="global"` (removed from MuJoCo; iktc reads local coordinates only).
    pub fn of(root: &El) -> Result<Compiler> {
        let mut c = Compiler {
            degrees: true,
            eulerseq: *b"xyz",
            meshdir: String::new(),
            autolimits: true,
            from_geom: FromGeom::Auto,
        };
        let mut assetdir = None;
        for el in root.elements("compiler") {
            if let Some(a) = el.attr("angle") {
                c.degrees = match a {
                    "degree" => true,
                    "radian" => false,
                    _ => return Err(bad(el, "angle", a, "`degree` or `radian`")),
                };
            }
            if let Some(s) = el.attr("eulerseq") {
                let b = s.as_bytes();
                if b.len() != 3 || !b.iter().all(|c| b"xyzXYZ".contains(c)) {
                    return Err(bad(el, "eulerseq", s, "three of x, y, z, X, Y, Z"));
                }
                c.eulerseq = [b[0], b[1], b[2]];
            }
            if let Some(d) = el.attr("meshdir") {
                c.meshdir = d.to_string();
            }
            if let Some(d) = el.attr("assetdir") {
                assetdir = Some(d.to_string());
            }
            if let Some(v) = el.attr("autolimits") {
                c.autolimits = boolean(el, "autolimits", v)?;
            }
            if let Some(v) = el.attr("inertiafromgeom") {
                c.from_geom = match v {
                    "false" => FromGeom::Never,
                    "true" => FromGeom::Always,
                    "auto" => FromGeom::Auto,
                    _ => return Err(bad(el, "inertiafromgeom", v, "`false`, `true` or `auto`")),
                };
            }
            if let Some(v) = el.attr("coordinate") {
                if v != "local" {
                    return Err(bad(
                        el,
                        "coordinate",
                        v,
                        "`local` (global coordinates were removed from MuJoCo and are not read)",
                    ));
                }
            }
        }
        if c.meshdir.is_empty() {
            c.meshdir = assetdir.unwrap_or_default();
        }
        Ok(c)
    }

    /// An angle written in the model's unit, in radians.
    pub fn angle(&self, a: f64) -> f64 {
        if self.degrees {
            a.to_radians()
        } else {
            a
        }
    }
}

/// The error for attribute `attr` = `value` of `el`, which should be `expected`.
pub(crate) fn bad(el: &El, attr: &str, value: &str, expected: &str) -> crate::error::Error {
    el.error(format!("{attr}=\"{value}\": expected {expected}"))
}

/// An MJCF boolean: `true` or `false`.
pub(crate) fn boolean(el: &El, attr: &str, v: &str) -> Result<bool> {
    match v {
        "true" => Ok(true),
        "false" => Ok(false),
        _ => Err(bad(el, attr, v, "`true` or `false`")),
    }
}

/// The numbers of attribute `attr` of `a`: `None` when absent; exactly `n` finite numbers
/// when `n` is `Some` (else from 1 to 6 for sizes).
pub(crate) fn numbers(a: &Attrs, attr: &str, n: Option<usize>) -> Result<Option<Vec<f64>>> {
    let Some(text) = a.get(attr) else {
        return Ok(None);
    };
    let v: std::result::Result<Vec<f64>, _> = text.split_whitespace().map(str::parse).collect();
    let expected = match n {
        Some(n) => format!("{n} finite number(s)"),
        None => "finite numbers".to_string(),
    };
    match v {
        Ok(v) if v.iter().all(|x| x.is_finite()) && n.is_none_or(|n| v.len() == n) => Ok(Some(v)),
        _ => Err(bad(a.el, attr, text, &expected)),
    }
}

/// The 3-vector `attr` of `a`, if written.
pub(crate) fn vec3(a: &Attrs, attr: &str) -> Result<Option<Vector3<f64>>> {
    Ok(numbers(a, attr, Some(3))?.map(|v| Vector3::new(v[0], v[1], v[2])))
}

/// The unit vector `attr` of `a`, if written; a zero vector is an error.
pub(crate) fn unit(a: &Attrs, attr: &str) -> Result<Option<Unit<Vector3<f64>>>> {
    match vec3(a, attr)? {
        None => Ok(None),
        Some(v) => Unit::try_new(v, MIN_NORM)
            .map(Some)
            .ok_or_else(|| bad(a.el, attr, a.get(attr).unwrap_or(""), "a non-zero vector")),
    }
}

/// The rotation taking +z to the unit vector `to` by the smallest angle (a half turn about x
/// when `to` is −z), as MuJoCo turns `zaxis` and `fromto`.
pub(crate) fn z_to(to: &Unit<Vector3<f64>>) -> UnitQuaternion<f64> {
    UnitQuaternion::rotation_between(&Vector3::z(), to).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    })
}

/// The orientation of `a`: from whichever of `quat` (w x y z), `axisangle` (axis, angle),
/// `euler` (after `<compiler eulerseq>`), `xyaxes` or `zaxis` is written (angles in the
/// compiler's unit); identity when none is.
///
/// Errors: more than one of them, a wrong count of numbers, a zero quaternion or axis.
pub(crate) fn orientation(a: &Attrs, c: &Compiler) -> Result<UnitQuaternion<f64>> {
    let given: Vec<&str> = ["quat", "axisangle", "euler", "xyaxes", "zaxis"]
        .into_iter()
        .filter(|k| a.el.attr(k).is_some())
        .collect();
    if given.len() > 1 {
        return Err(a.el.error(format!(
            "gives its orientation twice ({}); expected one of quat, axisangle, euler, xyaxes, zaxis",
            given.join(", ")
        )));
    }
    // An orientation written on the element wins over one from its class.
    let which = given.first().copied().or_else(|| {
        ["quat", "axisangle", "euler", "xyaxes", "zaxis"]
            .into_iter()
            .find(|k| a.get(k).is_some())
    });
    let zero = |attr: &str| bad(a.el, attr, a.get(attr).unwrap_or(""), "a non-zero vector");
    Ok(match which {
        None => UnitQuaternion::identity(),
        Some("quat") => {
            let v = numbers(a, "quat", Some(4))?.unwrap_or_default();
            let q = nalgebra::Quaternion::new(v[0], v[1], v[2], v[3]);
            if q.norm() < MIN_NORM {
                return Err(zero("quat"));
            }
            UnitQuaternion::from_quaternion(q)
        }
        Some("axisangle") => {
            let v = numbers(a, "axisangle", Some(4))?.unwrap_or_default();
            let axis = Unit::try_new(Vector3::new(v[0], v[1], v[2]), MIN_NORM)
                .ok_or_else(|| zero("axisangle"))?;
            UnitQuaternion::from_axis_angle(&axis, c.angle(v[3]))
        }
        Some("euler") => {
            let v = numbers(a, "euler", Some(3))?.unwrap_or_default();
            euler(&c.eulerseq, [c.angle(v[0]), c.angle(v[1]), c.angle(v[2])])
        }
        Some("xyaxes") => {
            let v = numbers(a, "xyaxes", Some(6))?.unwrap_or_default();
            let x = Unit::try_new(Vector3::new(v[0], v[1], v[2]), MIN_NORM)
                .ok_or_else(|| zero("xyaxes"))?;
            let y0 = Vector3::new(v[3], v[4], v[5]);
            let y = Unit::try_new(y0 - x.into_inner() * x.dot(&y0), MIN_NORM)
                .ok_or_else(|| zero("xyaxes"))?;
            let z = x.cross(&y);
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
                Matrix3::from_columns(&[x.into_inner(), y.into_inner(), z]),
            ))
        }
        Some(_) => z_to(&unit(a, "zaxis")?.ok_or_else(|| zero("zaxis"))?),
    })
}

/// The rotation of Euler angles `angles` \[rad\] in the sequence `seq`: each turn about its
/// axis, composed on the right (lower case, moving axes) or on the left (upper case, fixed
/// axes) of the turns before it.
pub(crate) fn euler(seq: &[u8; 3], angles: [f64; 3]) -> UnitQuaternion<f64> {
    let mut q = UnitQuaternion::identity();
    for (c, a) in seq.iter().zip(angles) {
        let axis = match c.to_ascii_lowercase() {
            b'x' => Vector3::x_axis(),
            b'y' => Vector3::y_axis(),
            _ => Vector3::z_axis(),
        };
        let turn = UnitQuaternion::from_axis_angle(&axis, a);
        q = if c.is_ascii_lowercase() {
            q * turn
        } else {
            turn * q
        };
    }
    q
}

/// The pose of `a`: `pos` (default 0) and its orientation.
pub(crate) fn pose(a: &Attrs, c: &Compiler) -> Result<Isometry3<f64>> {
    let p = vec3(a, "pos")?.unwrap_or_default();
    Ok(Isometry3::from_parts(
        Translation3::from(p),
        orientation(a, c)?,
    ))
}
