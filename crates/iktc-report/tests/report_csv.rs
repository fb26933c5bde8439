//! CSV: round trip of numbers (parsed back independently), header/row mismatch is an error.

use std::path::PathBuf;

use iktc_report::{write_csv, ReportError};

fn out_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("iktc-report-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Minimal CSV reader for the files written here (no quoted numbers).
fn read_back(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn numbers_round_trip_exactly() {
    let path = out_dir("csv").join("sub").join("table.csv");
    let header: Vec<String> = ["t [s]", "q [rad]", "dq [rad/s]"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let rows = vec![
        vec![0.0, 0.1 + 0.2, -1.0 / 3.0],
        vec![1e-300, 6.02214076e23, f64::MIN_POSITIVE],
        vec![-0.0, f64::MAX, 123_456_789.123_456_79],
        vec![-f64::MAX, 5e-324, std::f64::consts::PI],
    ];
    write_csv(&path, &header, &rows).unwrap();
    let (h, back) = read_back(&path);
    assert_eq!(h, header);
    assert_eq!(back.len(), rows.len());
    for (a, b) in rows.iter().zip(&back) {
        for (x, y) in a.iter().zip(b) {
            assert_eq!(x.to_bits(), y.to_bits(), "{x} came back as {y}");
        }
    }
}

#[test]
fn non_finite_values_are_refused_naming_row_and_column() {
    let path = out_dir("csv_nan").join("nan.csv");
    let header = vec!["a".to_string(), "q [rad]".to_string()];
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = write_csv(&path, &header, &[vec![0.0, 1.0], vec![2.0, bad]]).unwrap_err();
        assert!(matches!(e, ReportError::Invalid { .. }));
        let msg = e.to_string();
        assert!(msg.contains("row 1, column `q [rad]`"), "{msg}");
        assert!(!path.exists(), "nothing is written");
    }
}

#[test]
fn header_row_mismatch_is_an_error_and_writes_nothing() {
    let path = out_dir("csv_bad").join("bad.csv");
    let header = vec!["a".to_string(), "b".to_string()];
    let e = write_csv(&path, &header, &[vec![1.0, 2.0], vec![3.0]]).unwrap_err();
    assert!(matches!(e, ReportError::Invalid { .. }));
    assert!(e.to_string().contains("row 1 has 1 values"), "{e}");
    assert!(!path.exists());
    assert!(matches!(
        write_csv(&path, &[], &[]),
        Err(ReportError::Invalid { .. })
    ));
}

#[test]
fn header_with_comma_is_quoted() {
    let path = out_dir("csv_quote").join("q.csv");
    write_csv(&path, &["x, y".to_string(), "z".to_string()], &[]).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text, "\"x, y\",z\n");
}
