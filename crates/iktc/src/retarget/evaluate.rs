//! The fidelity figures ([`super::fidelity`]) of a robot trajectory made by any tool: the
//! captured person against a robot's recorded motion (times, base poses, joint positions by
//! name), with the same definitions and code as a retargeting run's own figures.
//!
//! * **Files** ([`read_trajectory_csv`], [`read_trajectory_npz`]): iktc's own `motion.csv`
//!   and `motion.npz` ([`crate::batch::TrainingTrajectory`]), and a plain CSV with a header:
//!   a time column (`time` or `t`) \[s\], the base pose (`x y z qw qx qy qz`, or iktc's
//!   `base_x base_y base_z base_qw base_qx base_qy base_qz`, in any order; the quaternion
//!   need not be unit, it is normalised) \[m\], then one column per joint named by the robot's
//!   joint names \[rad or m\]. Every robot joint must be there and no other column.
//! * **Times** are the clip's: the person is read at each tick's time.
//! * **Evaluation ticks** are `t_k = t_0 + k Δt` from the first frame's time `t_0` up to
//!   the last frame, `Δt` the evaluation period (by default the control period of a
//!   retargeting run). A trajectory whose frames are those ticks (within 10⁻⁶ s
//!   periods) is used as it is; any other is **resampled**: every joint and base coordinate
//!   by a natural cubic spline through its frames ([`crate::motion::CubicSpline`], C²: q̈
//!   continuous and linear between frames), the base quaternion component-wise after taking
//!   each one on the same side as the previous one, then normalised.
//! * **Smoothness** from positions alone: `q̈_k = (q_{k+1} − 2 q_k + q_{k−1}) / Δt²` at the
//!   interior ticks. For a trajectory that a controller integrated with q̈ held over each
//!   period (iktc's runs) this is the mean of two consecutive commanded q̈, so the run's own
//!   figures (from the commanded q̈) count chatter that alternates tick by tick which the
//!   positions do not show. The figures depend on the evaluation rate; a resampled
//!   trajectory's q̈ changes its slope only at its frames, so its reversal share is at most
//!   its frame rate over the evaluation rate ([`TrajectoryEvaluation::smoothness_note`]).

use std::collections::HashMap;

use nalgebra::{Quaternion, UnitQuaternion, Vector4};
use serde::Serialize;

use super::fidelity::Fidelity;
use crate::error::{Error, Result};
use crate::model::Robot;
use crate::motion::{CubicSpline, Keypoints};
use crate::profile::RobotProfile;

/// A frame time within this many evaluation periods of a tick is that tick \[–\]: a file
/// written at the evaluation rate differs from `t_0 + k Δt` by rounding only, and is then used
/// without resampling.
pub(crate) const TICK_ROUNDING: f64 = 1e-6;

/// A base quaternion whose norm is within this of 1 is used as written, not normalised \[–\]
/// (rounding of a unit quaternion written in full precision).
pub(crate) const UNIT_ROUNDING: f64 = 1e-12;

/// Fewest frames of a trajectory \[–\]: q̈ needs three.
pub(crate) const MIN_TRAJECTORY_FRAMES: usize = 3;

/// Time column names, first preferred.
const TIME_COLUMNS: [&str; 2] = ["time", "t"];
/// Base pose columns (x, y, z, qw, qx, qy, qz): plain names and iktc's.
const BASE_COLUMNS: [[&str; 2]; 7] = [
    ["x", "base_x"],
    ["y", "base_y"],
    ["z", "base_z"],
    ["qw", "base_qw"],
    ["qx", "base_qx"],
    ["qy", "base_qy"],
    ["qz", "base_qz"],
];

/// A robot's recorded motion.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotTrajectory {
    /// Where it came from (a file name), for errors.
    pub source: String,
    /// Clip time of every frame \[s\], strictly increasing.
    pub times: Vec<f64>,
    /// Base pose per frame: position \[m\] and orientation (w, x, y, z; normalised when used);
    /// `None` for a file without base columns (a fixed-base robot).
    pub base: Option<Vec<([f64; 3], [f64; 4])>>,
    /// Joint names (the columns of `joints`).
    pub joint_names: Vec<String>,
    /// Joint positions per frame \[rad or m\], `joint_names` order.
    pub joints: Vec<Vec<f64>>,
}

/// The figures of a trajectory and how they were taken.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrajectoryEvaluation {
    /// Frames of the file.
    pub frames: usize,
    /// The file's mean frame rate \[Hz\].
    pub input_rate_hz: f64,
    /// The evaluation rate 1/Δt \[Hz\].
    pub rate_hz: f64,
    /// Whether the frames were resampled onto the evaluation ticks (module documentation).
    pub resampled: bool,
    /// How the smoothness figures were taken, in words.
    pub smoothness_note: String,
    /// The figures.
    pub fidelity: Fidelity,
}

fn parse_error(source: &str, line: usize, message: String) -> Error {
    Error::Parse {
        source_name: source.into(),
        line,
        message,
    }
}

/// Reads a trajectory CSV (module documentation): a header line, then one line per frame.
///
/// Errors: [`Error::Parse`] naming the line for a missing time column, a partial set of base
/// columns, a repeated column, a row of another length, a number that does not parse or is not
/// finite, fewer than 3 frames or times that do not increase.
pub fn read_trajectory_csv(text: &str, source: &str) -> Result<RobotTrajectory> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(parse_error(
            source,
            1,
            "empty file: expected a header line".into(),
        ));
    };
    let CsvColumns { names, time, base } = csv_columns(header, source)?;
    let used: Vec<usize> = std::iter::once(time)
        .chain(base.iter().flatten().copied())
        .collect();
    let joint_cols: Vec<usize> = (0..names.len()).filter(|i| !used.contains(i)).collect();
    let mut t = RobotTrajectory {
        source: source.into(),
        times: Vec::new(),
        base: base.as_ref().map(|_| Vec::new()),
        joint_names: joint_cols.iter().map(|&i| names[i].clone()).collect(),
        joints: Vec::new(),
    };
    for (ln, line) in lines {
        let v = csv_row(line, ln, &names, source)?;
        t.times.push(v[time]);
        if let (Some(b), Some(cols)) = (t.base.as_mut(), base.as_ref()) {
            b.push((
                [v[cols[0]], v[cols[1]], v[cols[2]]],
                [v[cols[3]], v[cols[4]], v[cols[5]], v[cols[6]]],
            ));
        }
        t.joints.push(joint_cols.iter().map(|&i| v[i]).collect());
    }
    check_times(&t)?;
    Ok(t)
}

/// The columns of a trajectory CSV's header.
struct CsvColumns {
    /// Every column's name, in order.
    names: Vec<String>,
    /// The time column.
    time: usize,
    /// The base's columns (x y z qw qx qy qz), where the file has them.
    base: Option<Vec<usize>>,
}

/// The columns of `header`, the first line of `source`. Errors: a repeated column, no time
/// column, a partial set of base columns.
fn csv_columns(header: &str, source: &str) -> Result<CsvColumns> {
    let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
    let mut seen = HashMap::new();
    for (i, n) in names.iter().enumerate() {
        if let Some(j) = seen.insert(n.as_str(), i) {
            return Err(parse_error(
                source,
                1,
                format!(
                    "column `{n}` appears twice (columns {} and {})",
                    j + 1,
                    i + 1
                ),
            ));
        }
    }
    let find = |cands: &[&str]| cands.iter().find_map(|c| seen.get(c).copied());
    let time = find(&TIME_COLUMNS).ok_or_else(|| {
        parse_error(
            source,
            1,
            format!("no time column: expected one named `time` or `t` (header: {header})"),
        )
    })?;
    let base: Vec<Option<usize>> = BASE_COLUMNS.iter().map(|c| find(c)).collect();
    let base = if base.iter().all(Option::is_none) {
        None
    } else if base.iter().all(Option::is_some) {
        Some(base.into_iter().flatten().collect::<Vec<_>>())
    } else {
        let missing: Vec<&str> = BASE_COLUMNS
            .iter()
            .zip(&base)
            .filter(|(_, b)| b.is_none())
            .map(|(c, _)| c[0])
            .collect();
        return Err(parse_error(
            source,
            1,
            format!(
                "the base pose needs all of x y z qw qx qy qz (or base_x ... base_qz); missing: {}",
                missing.join(" ")
            ),
        ));
    };
    Ok(CsvColumns { names, time, base })
}

/// The values of `line` (index `ln` in `source`) under the columns `names`. Errors: a row of
/// another length, a number that does not parse or is not finite.
fn csv_row(line: &str, ln: usize, names: &[String], source: &str) -> Result<Vec<f64>> {
    let row: Vec<&str> = line.split(',').map(str::trim).collect();
    if row.len() != names.len() {
        return Err(parse_error(
            source,
            ln + 1,
            format!(
                "{} values, expected {} (the header's columns)",
                row.len(),
                names.len()
            ),
        ));
    }
    let mut v = Vec::with_capacity(row.len());
    for (c, s) in row.iter().enumerate() {
        let x: f64 = s.parse().map_err(|_| {
            parse_error(
                source,
                ln + 1,
                format!("column `{}`: `{s}` is not a number", names[c]),
            )
        })?;
        if !x.is_finite() {
            return Err(parse_error(
                source,
                ln + 1,
                format!("column `{}`: {s} is not finite", names[c]),
            ));
        }
        v.push(x);
    }
    Ok(v)
}

/// Reads iktc's `motion.npz` (or any NPZ with its arrays: `time` (n), `joint_names` (m),
/// `joint_pos` (n, m), and optionally `base_pos` (n, 3) with `base_quat_xyzw` (n, 4)).
///
/// Errors: those of [`crate::batch::read_npz`], a missing or misshapen array
/// ([`Error::Parse`]), non-finite values, too few frames, times that do not increase.
pub fn read_trajectory_npz(bytes: &[u8], source: &str) -> Result<RobotTrajectory> {
    use crate::batch::NpyData;
    let arrays = crate::batch::read_npz(bytes, source)?;
    let get = |name: &str| npz_array(&arrays, name, source);
    let floats = |name: &str, shape: &[Option<usize>]| npz_floats(&arrays, name, shape, source);
    let names = match &get("joint_names")?.data {
        NpyData::Str(v) => v.clone(),
        NpyData::F64(_) => {
            return Err(parse_error(
                source,
                0,
                "`joint_names` must hold strings".into(),
            ))
        }
    };
    let times = floats("time", &[None])?;
    let (n, m) = (times.len(), names.len());
    let pos = floats("joint_pos", &[Some(n), Some(m)])?;
    let base = if arrays.iter().any(|a| a.name == "base_pos") {
        let p = floats("base_pos", &[Some(n), Some(3)])?;
        let q = floats("base_quat_xyzw", &[Some(n), Some(4)])?;
        Some(
            (0..n)
                .map(|i| {
                    (
                        [p[3 * i], p[3 * i + 1], p[3 * i + 2]],
                        [q[4 * i + 3], q[4 * i], q[4 * i + 1], q[4 * i + 2]],
                    )
                })
                .collect(),
        )
    } else {
        None
    };
    let t = RobotTrajectory {
        source: source.into(),
        times,
        base,
        joint_names: names,
        joints: pos.chunks(m.max(1)).map(<[f64]>::to_vec).take(n).collect(),
    };
    check_times(&t)?;
    Ok(t)
}

/// The array `name` of `arrays` (read from `source`). Errors: no such array.
fn npz_array<'a>(
    arrays: &'a [crate::batch::NpyArray],
    name: &str,
    source: &str,
) -> Result<&'a crate::batch::NpyArray> {
    arrays.iter().find(|a| a.name == name).ok_or_else(|| {
        parse_error(
            source,
            0,
            format!(
                "no array `{name}`; it has: {}",
                arrays
                    .iter()
                    .map(|a| a.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )
    })
}

/// The float64 values of the array `name` of `arrays` (read from `source`), of the `shape`
/// given (`None`: any length). Errors: no such array, another shape or type, a non-finite
/// value.
fn npz_floats(
    arrays: &[crate::batch::NpyArray],
    name: &str,
    shape: &[Option<usize>],
    source: &str,
) -> Result<Vec<f64>> {
    use crate::batch::NpyData;
    let a = npz_array(arrays, name, source)?;
    let ok = a.shape.len() == shape.len()
        && a.shape
            .iter()
            .zip(shape)
            .all(|(d, s)| s.is_none_or(|s| *d == s));
    match (&a.data, ok) {
        (NpyData::F64(v), true) => {
            crate::error::check_all_finite(name, v)?;
            Ok(v.clone())
        }
        _ => Err(parse_error(
            source,
            0,
            format!(
                "array `{name}` has shape {:?}; expected {shape:?} of float64 (None: any)",
                a.shape
            ),
        )),
    }
}

/// At least [`MIN_TRAJECTORY_FRAMES`] frames, times strictly increasing.
fn check_times(t: &RobotTrajectory) -> Result<()> {
    if t.times.len() < MIN_TRAJECTORY_FRAMES {
        return Err(Error::InsufficientData {
            what: format!("the trajectory `{}`", t.source),
            message: format!(
                "it has {} frame(s); at least {MIN_TRAJECTORY_FRAMES} are needed (q̈ by second differences)",
                t.times.len()
            ),
        });
    }
    if let Some(i) = t.times.windows(2).position(|w| w[1] <= w[0]) {
        return Err(Error::InvalidSetting {
            name: format!("time of frame {} of `{}`", i + 1, t.source),
            value: format!("{} after {}", t.times[i + 1], t.times[i]),
            expected: "strictly increasing times [s]".into(),
        });
    }
    Ok(())
}

/// The column of every active joint of `robot` in `t`, in the robot's order. Errors: joints
/// of the robot missing from the file, or columns that are no joint of it, all listed.
fn joint_columns(robot: &Robot, t: &RobotTrajectory) -> Result<Vec<usize>> {
    let names: Vec<String> = robot.dof_names()[robot.base_nv()..].to_vec();
    let missing: Vec<&str> = names
        .iter()
        .filter(|n| !t.joint_names.contains(n))
        .map(String::as_str)
        .collect();
    let extra: Vec<&str> = t
        .joint_names
        .iter()
        .filter(|n| !names.contains(n))
        .map(String::as_str)
        .collect();
    if !missing.is_empty() || !extra.is_empty() {
        let mut msg = Vec::new();
        if !missing.is_empty() {
            msg.push(format!(
                "the robot's joints {} have no column",
                missing.join(", ")
            ));
        }
        if !extra.is_empty() {
            msg.push(format!(
                "the columns {} are no joint of the robot (nor time or base pose)",
                extra.join(", ")
            ));
        }
        return Err(Error::Parse {
            source_name: t.source.clone(),
            line: 1,
            message: format!(
                "{}; expected a column per joint: {}",
                msg.join("; "),
                names.join(", ")
            ),
        });
    }
    Ok(names
        .iter()
        .map(|n| t.joint_names.iter().position(|m| m == n).unwrap_or(0))
        .collect())
}

/// The robot's configurations q (length `nq`) on the evaluation ticks of `t` at period
/// `dt`, the ticks' times, and whether the frames were resampled (module documentation).
///
/// Errors: a robot joint without a column or a column that is no joint (all listed); a
/// floating-base robot and a file without base pose; a zero base quaternion; a rate outside
/// the output rates; more ticks than [`crate::resources::MAX_OUTPUT_FRAMES`].
pub fn trajectory_ticks(
    robot: &Robot,
    t: &RobotTrajectory,
    dt: f64,
) -> Result<(Vec<f64>, Vec<Vec<f64>>, bool)> {
    crate::resources::check_output_rate("evaluation rate (CLI --rate)", 1.0 / dt)?;
    check_times(t)?;
    let cols = joint_columns(robot, t)?;
    let floating = robot.base_nq() == 7;
    let base = match (&t.base, floating) {
        (Some(b), true) => Some(b),
        (None, true) => {
            return Err(Error::Parse {
                source_name: t.source.clone(),
                line: 1,
                message: "the robot has a floating base: columns x y z qw qx qy qz (the base \
                          pose) are needed"
                    .into(),
            })
        }
        (_, false) => None,
    };
    let (t0, t1) = (t.times[0], t.times[t.times.len() - 1]);
    let ticks =
        crate::resources::output_frames("evaluation ticks", t1 - t0, 1.0 / dt, TICK_ROUNDING)?;
    let times: Vec<f64> = (0..ticks).map(|k| t0 + k as f64 * dt).collect();
    let same = ticks == t.times.len()
        && times
            .iter()
            .zip(&t.times)
            .all(|(a, b)| (a - b).abs() <= TICK_ROUNDING * dt);
    // Base quaternions (w, x, y, z), checked; for resampling each on the previous one's side.
    let quats: Vec<Vector4<f64>> = match base {
        Some(b) => base_quaternions(t, b, same)?,
        None => Vec::new(),
    };
    // Channels: joints in the robot's order, then base x y z and quaternion w x y z.
    let mut channels: Vec<Vec<f64>> = cols
        .iter()
        .map(|&c| t.joints.iter().map(|r| r[c]).collect())
        .collect();
    if let Some(b) = base {
        for i in 0..3 {
            channels.push(b.iter().map(|(p, _)| p[i]).collect());
        }
        for i in 0..4 {
            channels.push(quats.iter().map(|q| q[i]).collect());
        }
    }
    let values: Vec<Vec<f64>> = if same {
        channels
    } else {
        channels
            .iter()
            .map(|c| {
                let s = CubicSpline::new(&t.times, c)?;
                let mut out = vec![0.0; ticks];
                s.values_at(&times, &mut out)?;
                Ok(out)
            })
            .collect::<Result<_>>()?
    };
    let qs = (0..ticks)
        .map(|k| tick_configuration(robot, &values, cols.len(), floating, k))
        .collect();
    Ok((times, qs, !same))
}

/// The base quaternions (w, x, y, z) of `t`'s base poses `b`, checked; unless the frames are
/// the ticks (`same`), each on the previous one's side, for resampling. Errors: a zero
/// quaternion.
fn base_quaternions(
    t: &RobotTrajectory,
    b: &[([f64; 3], [f64; 4])],
    same: bool,
) -> Result<Vec<Vector4<f64>>> {
    let mut out: Vec<Vector4<f64>> = Vec::with_capacity(b.len());
    for (i, (_, q)) in b.iter().enumerate() {
        let mut v = Vector4::new(q[0], q[1], q[2], q[3]);
        if v.norm() == 0.0 {
            return Err(Error::InvalidSetting {
                name: format!("base quaternion of frame {i} of `{}`", t.source),
                value: "0 0 0 0".into(),
                expected: "a non-zero quaternion (qw qx qy qz)".into(),
            });
        }
        if !same && out.last().is_some_and(|p| p.dot(&v) < 0.0) {
            v = -v;
        }
        out.push(v);
    }
    Ok(out)
}

/// The configuration q of tick `k` from the channels `values` (the `nj` joints in the robot's
/// order, then with a `floating` base its x y z and quaternion w x y z).
fn tick_configuration(
    robot: &Robot,
    values: &[Vec<f64>],
    nj: usize,
    floating: bool,
    k: usize,
) -> Vec<f64> {
    let mut q = Vec::with_capacity(robot.nq());
    if floating {
        let v = |i: usize| values[nj + i][k];
        let raw = Quaternion::new(v(3), v(4), v(5), v(6));
        // A unit quaternion within rounding is used as written (a file of iktc's own
        // then gives its run's configurations bit for bit).
        let r = if (raw.norm() - 1.0).abs() <= UNIT_ROUNDING {
            UnitQuaternion::new_unchecked(raw)
        } else {
            UnitQuaternion::from_quaternion(raw)
        };
        q.extend([v(0), v(1), v(2)]);
        q.extend_from_slice(r.coords.as_slice());
    }
    q.extend(values[..nj].iter().map(|c| c[k]));
    q
}

/// The fidelity figures of `trajectory` (a motion of the robot of `profile`, `robot` built
/// from it) against the person `kp`, at the evaluation period `dt` \[s\] (module
/// documentation); the same figures and code as a retargeting run's
/// [`super::RetargetQuality::fidelity`], with q̈ from positions.
///
/// Errors: those of [`trajectory_ticks`], a profile without feet, pelvis or hands, a
/// trajectory whose time span does not meet the clip's.
pub fn evaluate_trajectory(
    profile: &RobotProfile,
    robot: &Robot,
    kp: &Keypoints,
    trajectory: &RobotTrajectory,
    dt: f64,
) -> Result<TrajectoryEvaluation> {
    let (times, qs, resampled) = trajectory_ticks(robot, trajectory, dt)?;
    let (c0, c1) = (
        kp.times.first().copied().unwrap_or(0.0),
        kp.times.last().copied().unwrap_or(0.0),
    );
    let (t0, t1) = (times[0], times[times.len() - 1]);
    if t1 < c0 || t0 > c1 {
        return Err(Error::InvalidSetting {
            name: format!("time span of `{}`", trajectory.source),
            value: format!("[{t0}, {t1}] s"),
            expected: format!("times within the clip's [{c0}, {c1}] s (clip time)"),
        });
    }
    let (body, centres, support) = super::measured_body(robot, profile)?;
    let nqb = robot.base_nq();
    let qdd: Vec<Vec<f64>> = qs
        .windows(3)
        .map(|w| {
            (nqb..robot.nq())
                .map(|i| (w[2][i] - 2.0 * w[1][i] + w[0][i]) / (dt * dt))
                .collect()
        })
        .collect();
    let fidelity = super::measure_fidelity(
        robot,
        (&body, &centres),
        &support,
        kp,
        (&times, &qs, &qdd),
        dt,
    )?;
    let frames = trajectory.times.len();
    let input_rate_hz = (frames - 1) as f64 / (trajectory.times[frames - 1] - trajectory.times[0]);
    let rate_hz = 1.0 / dt;
    let mut note = format!(
        "q̈ by second differences of the positions at {rate_hz:.6} Hz (figures depend on the rate)"
    );
    if resampled {
        note.push_str(&format!(
            "; the file's {frames} frames ({input_rate_hz:.6} Hz) resampled by natural cubic \
             splines: q̈ linear between frames, so the reversal share is at most about \
             {:.3}",
            (input_rate_hz / rate_hz).min(1.0)
        ));
    }
    Ok(TrajectoryEvaluation {
        frames,
        input_rate_hz,
        rate_hz,
        resampled,
        smoothness_note: note,
        fidelity,
    })
}

#[cfg(test)]
#[path = "evaluate_tests.rs"]
mod tests;
