//! Figures: files are written, SVG has an `<svg` root, PNG decodes and is not blank, bad input
//! gives errors instead of panics.

use std::path::PathBuf;

use iktc_report::{
    write_csv, write_figure, write_report, Figure, Panel, Report, ReportError, Section, Series,
    Table,
};

fn out_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("iktc-report-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Number of distinct RGB colours in a PNG, and its size.
fn png_colours(path: &std::path::Path) -> (usize, u32, u32) {
    let img = image::open(path).expect("PNG decodes").to_rgb8();
    let mut colours: Vec<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    colours.sort_unstable();
    colours.dedup();
    (colours.len(), img.width(), img.height())
}

/// Pixels whose colour is close to `rgb` (within 40 per channel).
fn count_near(path: &std::path::Path, rgb: [u8; 3]) -> usize {
    let img = image::open(path).expect("PNG decodes").to_rgb8();
    img.pixels()
        .filter(|p| {
            p.0.iter()
                .zip(rgb.iter())
                .all(|(a, b)| (i32::from(*a) - i32::from(*b)).abs() < 40)
        })
        .count()
}

fn joint_figure() -> Figure {
    let t = linspace(0.0, 4.0, 400);
    let q1: Vec<f64> = t.iter().map(|t| 1.2 * (1.5 * t).sin()).collect();
    let q2: Vec<f64> = t.iter().map(|t| 0.8 * (0.7 * t).cos()).collect();
    let qd: Vec<f64> = t.iter().map(|t| 1.8 * (1.5 * t).cos()).collect();
    Figure::new("Joint trajectory")
        .panel(
            Panel::new("Joint angles", "time [s]", "q [rad]")
                .with(Series::line("q1", t.clone(), q1.clone()))
                .with(Series::dashed("q1 reference", t.clone(), q2))
                .hline(1.0, "upper limit")
                .hline(-1.0, "lower limit"),
        )
        .panel(
            Panel::new("Joint velocity", "time [s]", "dq [rad/s]").with(Series::line("dq1", t, qd)),
        )
}

#[test]
fn figure_files_are_written_and_readable() {
    let dir = out_dir("joint");
    let files = write_figure(&joint_figure(), &dir, "joint").unwrap();
    assert_eq!(files.svg, dir.join("joint.svg"));
    assert_eq!(files.png, dir.join("joint.png"));
    let svg = std::fs::read_to_string(&files.svg).unwrap();
    assert!(svg.contains("<svg"), "no <svg element");
    assert!(svg.trim_end().ends_with("</svg>"), "SVG not closed");
    for text in [
        "Joint trajectory",
        "time [s]",
        "q [rad]",
        "upper limit",
        "q1 reference",
    ] {
        assert!(svg.contains(text), "SVG lacks text {text:?}");
    }
    assert!(
        svg.contains("sans-serif"),
        "SVG text does not name a font family"
    );
    let (n, w, h) = png_colours(&files.png);
    assert_eq!(
        (w, h),
        (800, 640),
        "one column of two 800x300 panels plus a 40 px title"
    );
    assert!(n > 10, "PNG has only {n} colours");
    // the first series colour and the limit colour are both present
    assert!(count_near(&files.png, [31, 119, 180]) > 300);
    assert!(count_near(&files.png, [200, 30, 30]) > 300);
}

#[test]
fn grid_layout_sets_size() {
    let p = || {
        Panel::new("p", "x [m]", "y [m]").with(Series::points("s", vec![0.0, 1.0], vec![1.0, 0.0]))
    };
    let fig = Figure::new("grid")
        .panel(p())
        .panel(p())
        .panel(p())
        .columns(2);
    let files = write_figure(&fig, &out_dir("grid"), "grid").unwrap();
    let (_, w, h) = png_colours(&files.png);
    assert_eq!((w, h), (1600, 640));
}

#[test]
fn nan_inf_empty_and_constant_series_do_not_panic() {
    let x = vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
    let y = vec![0.0, f64::NAN, 2.0, f64::INFINITY, 1.0, f64::NEG_INFINITY];
    let fig = Figure::new("awkward data")
        .panel(
            Panel::new("NaN and inf", "t [s]", "v [m/s]")
                .with(Series::line("gappy", x.clone(), y.clone()))
                .with(Series::points("gappy points", x.clone(), y)),
        )
        .panel(Panel::new("empty", "t [s]", "v [m/s]").with(Series::line("none", vec![], vec![])))
        .panel(
            Panel::new("constant", "t [s]", "v [m/s]")
                .with(Series::line("flat", x.clone(), vec![3.0; 6]))
                .hline(f64::NAN, "bad limit"),
        )
        .panel(
            Panel::new("all NaN", "t [s]", "v [m/s]").with(Series::dashed(
                "nan",
                x.clone(),
                vec![f64::NAN; 6],
            )),
        )
        .panel(
            Panel::new("single point, log x", "f [Hz]", "gain [dB]")
                .log_x()
                .with(Series::line(
                    "one",
                    vec![-1.0, 0.0, 10.0],
                    vec![1.0, 2.0, 3.0],
                )),
        )
        .panel(
            Panel::new("zero width equal aspect", "x [m]", "y [m]")
                .equal_aspect()
                .with(Series::points("origin", vec![0.0], vec![0.0])),
        );
    let files = write_figure(&fig, &out_dir("awkward"), "awkward").unwrap();
    let (n, _, _) = png_colours(&files.png);
    assert!(n > 10);
}

#[test]
fn bad_figures_are_errors() {
    let dir = out_dir("bad");
    let empty = Figure::new("nothing");
    assert!(matches!(
        write_figure(&empty, &dir, "e"),
        Err(ReportError::Invalid { .. })
    ));
    let mismatch = Figure::new("m").panel(Panel::new("p", "x", "y").with(Series::line(
        "s",
        vec![1.0, 2.0],
        vec![1.0],
    )));
    let e = write_figure(&mismatch, &dir, "m").unwrap_err();
    assert!(matches!(e, ReportError::Invalid { .. }));
    assert!(e.to_string().contains("2 x values but 1 y values"), "{e}");
    let ok = Figure::new("ok").panel(Panel::new("p", "x", "y"));
    assert!(matches!(
        write_figure(&ok, &dir, "a/b"),
        Err(ReportError::Invalid { .. })
    ));
    assert!(matches!(
        write_figure(&ok, &dir, ""),
        Err(ReportError::Invalid { .. })
    ));
    assert!(matches!(
        write_figure(&ok.clone().columns(0), &dir, "c"),
        Err(ReportError::Invalid { .. })
    ));
}

#[test]
fn gallery_for_eyeballing() {
    // Not an assertion-heavy test: writes the kinds of figures the experiments make so a person
    // can look at them in target/tmp/iktc-report-tests/gallery.
    let dir = out_dir("gallery");
    write_figure(&joint_figure(), &dir, "joint").unwrap();
    let f = (0..60)
        .map(|i| 10f64.powf(-1.0 + 4.0 * i as f64 / 59.0))
        .collect::<Vec<_>>();
    let mag: Vec<f64> = f
        .iter()
        .map(|f| -20.0 * (1.0 + (f / 5.0).powi(2)).sqrt().log10())
        .collect();
    let ph: Vec<f64> = f.iter().map(|f| -(f / 5.0).atan().to_degrees()).collect();
    let bode = Figure::new("Bode plot of the tracking loop")
        .panel(
            Panel::new("Magnitude", "frequency [Hz]", "|G| [dB]")
                .log_x()
                .with(Series::line("|G|", f.clone(), mag)),
        )
        .panel(
            Panel::new("Phase", "frequency [Hz]", "arg G [deg]")
                .log_x()
                .with(Series::line("arg G", f, ph))
                .hline(-45.0, "-45 deg"),
        );
    write_figure(&bode, &dir, "bode").unwrap();
    let s = linspace(0.0, std::f64::consts::TAU, 200);
    let xy = Figure::new("Hand path seen from above").panel(
        Panel::new("Hand path", "x [m]", "y [m]")
            .equal_aspect()
            .with(Series::line(
                "hand",
                s.iter().map(|s| 0.3 + 0.1 * s.cos()).collect(),
                s.iter().map(|s| 0.05 * s.sin()).collect(),
            ))
            .with(Series::points(
                "footsteps",
                vec![0.0, 0.1, 0.2, 0.3],
                vec![0.1, -0.1, 0.1, -0.1],
            ))
            .with(Series::dashed("target", vec![0.2, 0.4], vec![0.0, 0.0])),
    );
    write_figure(&xy, &dir, "xy").unwrap();
    let tiny = Figure::new("Small errors")
        .columns(2)
        .panel(Panel::new("error", "time [s]", "e [m]").with(Series::line(
            "e",
            linspace(0.0, 1.0, 50),
            linspace(0.0, 1.0, 50).iter().map(|t| 1e-7 * t).collect(),
        )))
        .panel(
            Panel::new("big", "time [s]", "f [N]").with(Series::line(
                "f",
                linspace(0.0, 1.0, 50),
                linspace(0.0, 1.0, 50)
                    .iter()
                    .map(|t| 1e7 * t + 12345.0)
                    .collect(),
            )),
        );
    let t = linspace(0.0, 1.0, 50);
    let tiny = tiny
        .panel(Panel::new("offset", "time [s]", "z [m]").with(Series::line(
            "z",
            t.clone(),
            t.iter().map(|t| -1000.0 - 1e-3 * t).collect(),
        )))
        .panel(
            Panel::new(
                "long label",
                "time since the start of the experiment [s]",
                "joint torque tau_12 [N m]",
            )
            .with(Series::line(
                "tau",
                t.clone(),
                t.iter().map(|t| -123.456 * t).collect(),
            )),
        );
    write_figure(&tiny, &dir, "scales").unwrap();
    write_csv(
        &dir.join("data/joint.csv"),
        &["t [s]".to_string(), "q1 [rad]".to_string()],
        &[vec![0.0, 0.0], vec![0.01, 0.015]],
    )
    .unwrap();
    let report = Report::new("iktc gallery")
        .intro("<p>Figures of every kind the experiments draw.</p>")
        .section(
            Section::new("Joint limits")
                .intro("<p>Angles stay <b>inside</b> the dashed limits.</p>")
                .figure(
                    "joint.svg",
                    "Joint angle and velocity; dashed red lines are limits",
                )
                .table(
                    Table::new(
                        "Summary",
                        vec!["joint".into(), "max |q| [rad]".into(), "ok".into()],
                    )
                    .row(vec!["q1".into(), "1.2".into(), "no".into()])
                    .row(vec!["q2 <left>".into(), "0.8".into(), "yes".into()]),
                )
                .link("data/joint.csv", "joint angles (CSV)"),
        )
        .section(Section::new("Frequency response").figure("bode.svg", "Bode plot"))
        .section(
            Section::new("Paths")
                .figure("xy.svg", "Hand path, equal aspect")
                .figure("scales.svg", "Very small and very large values"),
        );
    let index = write_report(&report, &dir).unwrap();
    assert!(index.exists());
}

#[test]
fn extreme_magnitudes_do_not_panic() {
    let cases: Vec<(Vec<f64>, Vec<f64>)> = vec![
        (vec![0.0, 1.0], vec![f64::MAX, -f64::MAX]),
        (vec![0.0, 1.0], vec![1e300, -1e300]),
        (vec![0.0, 1e-320], vec![5e-324, 1e-323]),
        (vec![-f64::MAX, f64::MAX], vec![0.0, 1.0]),
        (vec![1.0, 1.0 + 1e-15], vec![1e-9, 1e-9 + 1e-24]),
    ];
    let only: Option<usize> = std::env::var("EXTREME_CASE")
        .ok()
        .and_then(|v| v.parse().ok());
    for (i, (x, y)) in cases.into_iter().enumerate() {
        if only.is_some_and(|o| o != i) {
            continue;
        }
        let fig = Figure::new("extreme")
            .panel(
                Panel::new("lin", "x [m]", "y [m]")
                    .with(Series::line("a", x.clone(), y.clone()))
                    .hline(f64::MAX, "max")
                    .hline(-f64::MAX, "min"),
            )
            .panel(
                Panel::new("eq", "x [m]", "y [m]")
                    .equal_aspect()
                    .with(Series::line("a", x.clone(), y.clone())),
            )
            .panel(
                Panel::new("log", "x [m]", "y [m]")
                    .log_x()
                    .with(Series::points("a", x, y)),
            );
        let r = write_figure(&fig, &out_dir("extreme"), &format!("extreme{i}"));
        assert!(r.is_ok(), "case {i}: {r:?}");
    }
}

/// Small deterministic generator (xorshift64*) so the sweep below needs no extra dependency.
struct Xorshift(u64);
impl Xorshift {
    fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn sweep_of_offsets_and_spans_draws_every_figure() {
    // Offsets from 1e-12 to 1e12 with relative spans down to 1e-14: plotters' tick computation
    // must neither hang nor fail on any of them.
    let mut rng = Xorshift(0x1234_5678_9abc_def1);
    let dir = out_dir("sweep");
    for i in 0..60 {
        let offset =
            10f64.powf(-12.0 + 24.0 * rng.next_f64()) * if i % 2 == 0 { 1.0 } else { -1.0 };
        let rel = 10f64.powf(-14.0 + 14.0 * rng.next_f64());
        let span = offset.abs() * rel;
        let x: Vec<f64> = (0..20)
            .map(|k| offset + span * f64::from(k) / 19.0)
            .collect();
        let y: Vec<f64> = x.iter().map(|v| v * 0.5).collect();
        let fig = Figure::new("")
            .panel_size(300, 150)
            .columns(2)
            .panel(Panel::new("lin", "x", "y").with(Series::line("a", x.clone(), y.clone())))
            .panel(Panel::new("log", "x", "y").log_x().with(Series::line(
                "a",
                x.iter().map(|v| v.abs()).collect(),
                y,
            )));
        let r = write_figure(&fig, &dir, "sweep");
        assert!(r.is_ok(), "offset {offset:e}, span {span:e}: {r:?}");
    }
}
