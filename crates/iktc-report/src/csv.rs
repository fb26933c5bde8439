//! Numeric CSV tables.

use std::io::{BufWriter, Write};
use std::path::Path;

use crate::error::ReportError;

/// Quotes a CSV header cell when it contains a comma, a quote or a line break (RFC 4180).
fn csv_cell(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes a CSV file: one header line, then one line per row, comma separated.
///
/// Numbers are written in Rust's shortest round-trip form (reading them back with
/// `str::parse::<f64>` gives the same value). Every row must have as many values as `header`
/// has names and every value must be finite (a NaN or an infinity is a run gone wrong, not
/// data), otherwise [`ReportError::Invalid`] names the row and column and nothing is written. The parent directory is created
/// if needed.
pub fn write_csv(path: &Path, header: &[String], rows: &[Vec<f64>]) -> Result<(), ReportError> {
    if header.is_empty() {
        return Err(ReportError::invalid(format!(
            "CSV {} has an empty header; expected at least one column name",
            path.display()
        )));
    }
    if let Some((i, row)) = rows
        .iter()
        .enumerate()
        .find(|(_, r)| r.len() != header.len())
    {
        return Err(ReportError::invalid(format!(
            "CSV {}: row {i} has {} values but the header has {} columns; expected equal counts",
            path.display(),
            row.len(),
            header.len()
        )));
    }
    for (i, row) in rows.iter().enumerate() {
        if let Some(j) = row.iter().position(|v| !v.is_finite()) {
            return Err(ReportError::invalid(format!(
                "CSV {}: row {i}, column `{}` is {}; expected finite numbers only",
                path.display(),
                header[j],
                row[j]
            )));
        }
    }
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| ReportError::io(parent, e))?;
    }
    let file = std::fs::File::create(path).map_err(|e| ReportError::io(path, e))?;
    let mut w = BufWriter::new(file);
    let io = |e| ReportError::io(path, e);
    let head: Vec<String> = header.iter().map(|h| csv_cell(h)).collect();
    writeln!(w, "{}", head.join(",")).map_err(io)?;
    let mut line = String::new();
    for row in rows {
        line.clear();
        for (j, v) in row.iter().enumerate() {
            if j > 0 {
                line.push(',');
            }
            line.push_str(&v.to_string());
        }
        writeln!(w, "{line}").map_err(io)?;
    }
    w.flush().map_err(io)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::csv_cell;

    #[test]
    fn header_cells_are_quoted_when_needed() {
        assert_eq!(csv_cell("t [s]"), "t [s]");
        assert_eq!(csv_cell("a,b"), "\"a,b\"");
        assert_eq!(csv_cell("say \"hi\""), "\"say \"\"hi\"\"\"");
    }
}
