//! A plain CSV of named 3D points per frame (what video pose estimators write).
//!
//! ```text
//! # comment lines start with '#'
//! frame,time,pelvis_x,pelvis_y,pelvis_z,left_wrist_x,left_wrist_y,left_wrist_z,...
//! 0,0.000,0.01,0.02,0.95,...
//! ```
//!
//! The header names a `time` column (seconds, strictly increasing; required), optionally a
//! `frame` column (ignored), and for every point three columns `NAME_x`, `NAME_y`, `NAME_z`
//! (also `NAME.x`; case-insensitive suffixes), in that order. Point names are free: the body
//! points are found by name (`pelvis`, `left_wrist`, `LeftHand`, …) or by a body map. An empty
//! cell marks the point missing in that frame (all three must then be empty); missing points
//! are gaps, filled as for markers. `nan`, `inf` and any other non-number are errors naming the
//! line and column.

use nalgebra::Vector3;

use super::markers::MarkerSet;
use crate::error::{Error, Result};

fn axis_suffix(column: &str) -> Option<(&str, usize)> {
    let lower = column.to_ascii_lowercase();
    for (k, s) in ["x", "y", "z"].iter().enumerate() {
        for sep in ['_', '.'] {
            let suffix = format!("{sep}{s}");
            if lower.ends_with(&suffix) && column.len() > suffix.len() {
                return Some((&column[..column.len() - suffix.len()], k));
            }
        }
    }
    None
}

/// Reads a points CSV (see the module documentation); `source` names it in errors
/// ([`Error::Parse`] with the line and column).
pub fn read_points_csv(text: &str, source: &str) -> Result<MarkerSet> {
    let text = super::strip_bom(text);
    let error = |line: usize, message: String| Error::Parse {
        source_name: source.to_string(),
        line,
        message,
    };
    let mut rows = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (header_line, header) = rows
        .next()
        .ok_or_else(|| error(0, "empty file: no header".to_string()))?;
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    let time_col = columns
        .iter()
        .position(|c| c.eq_ignore_ascii_case("time"))
        .ok_or_else(|| {
            error(
                header_line,
                "the header has no `time` column [s]".to_string(),
            )
        })?;
    let mut names: Vec<String> = Vec::new();
    let mut point_cols: Vec<[usize; 3]> = Vec::new();
    let mut c = 0;
    while c < columns.len() {
        let col = columns[c];
        if c == time_col || col.eq_ignore_ascii_case("frame") {
            c += 1;
            continue;
        }
        let triple = (0..3)
            .map(|k| columns.get(c + k).and_then(|x| axis_suffix(x)))
            .collect::<Option<Vec<(&str, usize)>>>();
        match triple.as_deref() {
            Some([(a, 0), (b, 1), (d, 2)]) if a == b && b == d => {
                if names.iter().any(|n| n.as_str() == *a) {
                    return Err(error(header_line, format!("point `{a}` appears twice")));
                }
                names.push(a.to_string());
                point_cols.push([c, c + 1, c + 2]);
                c += 3;
            }
            _ => {
                return Err(error(
                    header_line,
                    format!(
                        "column {} `{col}`: expected `frame`, `time` or three columns NAME_x, NAME_y, NAME_z",
                        c + 1
                    ),
                ))
            }
        }
    }
    if names.is_empty() {
        return Err(error(header_line, "the header names no point".to_string()));
    }
    let mut times: Vec<f64> = Vec::new();
    let mut positions = Vec::new();
    for (line, row) in rows {
        let cells: Vec<&str> = row.split(',').map(str::trim).collect();
        if cells.len() != columns.len() {
            return Err(error(
                line,
                format!(
                    "{} cells; the header has {} columns",
                    cells.len(),
                    columns.len()
                ),
            ));
        }
        let number = |k: usize| -> Result<f64> {
            cells[k]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    error(
                        line,
                        format!(
                            "column {} `{}`: `{}` is not a finite number",
                            k + 1,
                            columns[k],
                            cells[k]
                        ),
                    )
                })
        };
        let t = number(time_col)?;
        if let Some(prev) = times.last() {
            if t <= *prev {
                return Err(error(
                    line,
                    format!("time {t} s is not after the previous {prev} s"),
                ));
            }
        }
        times.push(t);
        for cols in &point_cols {
            let empty = cols.iter().filter(|k| cells[**k].is_empty()).count();
            match empty {
                3 => positions.push(None),
                0 => positions.push(Some(Vector3::new(
                    number(cols[0])?,
                    number(cols[1])?,
                    number(cols[2])?,
                ))),
                _ => {
                    return Err(error(
                        line,
                        format!(
                            "column {}: a point must have all three coordinates or none",
                            cols[0] + 1
                        ),
                    ))
                }
            }
        }
    }
    if times.is_empty() {
        return Err(error(header_line, "no data row".to_string()));
    }
    Ok(MarkerSet {
        source: source.to_string(),
        names,
        times,
        positions,
    })
}
