//! Large figures: many long series are drawn and the SVG stays a reasonable size.

use std::path::PathBuf;

use iktc_report::{write_figure, Figure, Panel, Series};

#[test]
fn long_series_are_decimated_in_files() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("iktc-report-tests/big");
    let n = 20_000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
    let mut p = Panel::new("30 joints at 1 kHz", "time [s]", "q [rad]");
    for j in 0..30 {
        let y = t
            .iter()
            .map(|t| (t * (1.0 + j as f64 * 0.1)).sin() + 0.01 * (t * 500.0).sin())
            .collect();
        p = p.with(Series::line(format!("q{j}"), t.clone(), y));
    }
    let files = write_figure(&Figure::new("big").panel(p), &dir, "big").unwrap();
    let svg_len = std::fs::metadata(&files.svg).unwrap().len();
    // 600k points at ~8 bytes each would be ~4.8 MB; at most 4 points per pixel column of a
    // ~700 px plot per series is ~30 * 2800 points.
    assert!(svg_len < 1_500_000, "SVG is {svg_len} bytes");
    let svg = std::fs::read_to_string(&files.svg).unwrap();
    assert!(svg.contains("q29"), "every series is drawn and named");
}

/// The y pixel coordinates of every point of the long polylines (the decimated curves; axes,
/// ticks and legend samples have a handful of points).
fn curve_points_y(svg: &str) -> Vec<f64> {
    let mut ys = Vec::new();
    for part in svg.split("<polyline").skip(1) {
        let Some(start) = part.find("points=\"") else {
            continue;
        };
        let rest = &part[start + 8..];
        let pts: Vec<f64> = rest[..rest.find('"').unwrap()]
            .split_whitespace()
            .filter_map(|p| p.split_once(',').and_then(|(_, y)| y.parse().ok()))
            .collect();
        if pts.len() > 100 {
            ys.extend(pts);
        }
    }
    ys
}

#[test]
fn a_one_sample_spike_survives_decimation() {
    // 20 000 samples (five times what the plot's pixel columns keep): a flat curve at 0 with a
    // single sample at 1 in the middle of a pixel column, and a flat curve at 0.5. Drawn
    // faithfully, the curves' points sit on three pixel rows, for 0, 0.5 and 1, equally spaced.
    // A decimation that dropped or averaged the spike would leave two rows, or a top row off
    // the equal spacing.
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("iktc-report-tests/spike");
    let n = 20_000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
    let mut spike = vec![0.0; n];
    spike[12_345] = 1.0;
    let p = Panel::new("spike", "time [s]", "y")
        .with(Series::line("spike", t.clone(), spike))
        .with(Series::line("half", t.clone(), vec![0.5; n]));
    let files = write_figure(&Figure::new("spike").panel(p), &dir, "spike").unwrap();
    let svg = std::fs::read_to_string(&files.svg).unwrap();
    let ys = curve_points_y(&svg);
    assert!(
        ys.len() < n / 2,
        "{} points: the curves were not decimated",
        ys.len()
    );
    let mut rows: Vec<f64> = Vec::new();
    for y in ys {
        if !rows.iter().any(|r| (r - y).abs() < 0.5) {
            rows.push(y);
        }
    }
    rows.sort_by(f64::total_cmp);
    assert_eq!(rows.len(), 3, "pixel rows of the curves: {rows:?}");
    // SVG y grows downwards: rows[0] is the spike (1), rows[1] the half line, rows[2] zero.
    let (top, half, zero) = (rows[0], rows[1], rows[2]);
    assert!(
        ((zero - half) - (half - top)).abs() <= 1.0,
        "the spike's row {top} is not at 1 (0 at {zero}, 0.5 at {half})"
    );
}
