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

/// An [`Error::Parse`] in `source` at `line`.
fn parse_error(source: &str, line: usize, message: String) -> Error {
    Error::Parse {
        source_name: source.to_string(),
        line,
        message,
    }
}

/// The header row: its columns, the time column and the columns of every point.
struct Header<'a> {
    /// The header's 1-based line.
    line: usize,
    /// Column names, trimmed.
    columns: Vec<&'a str>,
    /// Index of the `time` column.
    time_col: usize,
    /// Point names, in column order.
    names: Vec<String>,
    /// The x, y, z column indices per point.
    point_cols: Vec<[usize; 3]>,
}

impl<'a> Header<'a> {
    /// Reads the header row `header` at `line`: a `time` column, optional `frame`, and at least
    /// one point of three columns `NAME_x NAME_y NAME_z`, each name once.
    fn parse(source: &str, line: usize, header: &'a str) -> Result<Self> {
        let error = |message: String| parse_error(source, line, message);
        let columns: Vec<&str> = header.split(',').map(str::trim).collect();
        let time_col = columns
            .iter()
            .position(|c| c.eq_ignore_ascii_case("time"))
            .ok_or_else(|| error("the header has no `time` column [s]".to_string()))?;
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
                        return Err(error(format!("point `{a}` appears twice")));
                    }
                    names.push(a.to_string());
                    point_cols.push([c, c + 1, c + 2]);
                    c += 3;
                }
                _ => {
                    return Err(error(format!(
                        "column {} `{col}`: expected `frame`, `time` or three columns NAME_x, NAME_y, NAME_z",
                        c + 1
                    )))
                }
            }
        }
        if names.is_empty() {
            return Err(error("the header names no point".to_string()));
        }
        Ok(Header {
            line,
            columns,
            time_col,
            names,
            point_cols,
        })
    }

    /// Reads the data row `row` at `line`: its time \[s\], after `previous` if any, and every
    /// point's position (`None` when its three cells are empty).
    fn parse_row(
        &self,
        source: &str,
        line: usize,
        row: &str,
        previous: Option<f64>,
        positions: &mut Vec<Option<Vector3<f64>>>,
    ) -> Result<f64> {
        let error = |message: String| parse_error(source, line, message);
        let columns = &self.columns;
        let cells: Vec<&str> = row.split(',').map(str::trim).collect();
        if cells.len() != columns.len() {
            return Err(error(format!(
                "{} cells; the header has {} columns",
                cells.len(),
                columns.len()
            )));
        }
        let number = |k: usize| -> Result<f64> {
            cells[k]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    error(format!(
                        "column {} `{}`: `{}` is not a finite number",
                        k + 1,
                        columns[k],
                        cells[k]
                    ))
                })
        };
        let t = number(self.time_col)?;
        if let Some(prev) = previous {
            if t <= prev {
                return Err(error(format!(
                    "time {t} s is not after the previous {prev} s"
                )));
            }
        }
        for cols in &self.point_cols {
            let empty = cols.iter().filter(|k| cells[**k].is_empty()).count();
            match empty {
                3 => positions.push(None),
                0 => positions.push(Some(Vector3::new(
                    number(cols[0])?,
                    number(cols[1])?,
                    number(cols[2])?,
                ))),
                _ => {
                    return Err(error(format!(
                        "column {}: a point must have all three coordinates or none",
                        cols[0] + 1
                    )))
                }
            }
        }
        Ok(t)
    }
}

/// Reads a points CSV (see the module documentation); `source` names it in errors
/// ([`Error::Parse`] with the line and column).
pub fn read_points_csv(text: &str, source: &str) -> Result<MarkerSet> {
    let text = super::strip_bom(text);
    let mut rows = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (header_line, header) = rows
        .next()
        .ok_or_else(|| parse_error(source, 0, "empty file: no header".to_string()))?;
    let header = Header::parse(source, header_line, header)?;
    let mut times: Vec<f64> = Vec::new();
    let mut positions = Vec::new();
    for (line, row) in rows {
        let t = header.parse_row(source, line, row, times.last().copied(), &mut positions)?;
        times.push(t);
    }
    if times.is_empty() {
        return Err(parse_error(source, header.line, "no data row".to_string()));
    }
    Ok(MarkerSet {
        source: source.to_string(),
        names: header.names,
        times,
        positions,
    })
}
