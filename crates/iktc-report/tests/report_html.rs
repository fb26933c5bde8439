//! HTML report: one self-contained index.html, table of contents, figures, escaping.

use std::path::PathBuf;

use iktc_report::{
    escape_html, write_figure, write_report, Figure, Panel, Report, ReportError, Section, Series,
    Table,
};

fn out_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("iktc-report-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn sample_report() -> Report {
    Report {
        title: "IK <control> & limits".into(),
        intro_html: "<p>Trusted <em>intro</em>.</p>".into(),
        sections: vec![
            Section {
                title: "Joint limits \"tight\"".into(),
                intro_html: "<p>Section <b>one</b>.</p>".into(),
                figures: vec![(
                    "figures/joint.svg".into(),
                    "q1 < upper limit & q2 > lower".into(),
                )],
                tables: vec![Table {
                    caption: "Errors <max>".into(),
                    header: vec!["joint".into(), "max |e| [rad]".into()],
                    rows: vec![
                        vec!["q1".into(), "0.001".into()],
                        vec!["<script>alert(1)</script>".into(), "2".into()],
                    ],
                }],
                links: vec![("data/joint.csv".into(), "raw data (CSV)".into())],
            },
            Section::new("Second").intro("<p>two</p>"),
        ],
    }
}

#[test]
fn report_is_written_with_toc_figures_and_tables() {
    let dir = out_dir("html");
    let fig = Figure::new("Joint").panel(Panel::new("q", "t [s]", "q [rad]").with(Series::line(
        "q1",
        vec![0.0, 1.0],
        vec![0.0, 1.0],
    )));
    write_figure(&fig, &dir.join("figures"), "joint").unwrap();
    let path = write_report(&sample_report(), &dir).unwrap();
    assert_eq!(path, dir.join("index.html"));
    let html = std::fs::read_to_string(&path).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.contains("<style>"));
    // table of contents links to both sections, which exist as anchors
    assert!(html.contains("href=\"#sec-1\"") && html.contains("id=\"sec-1\""));
    assert!(html.contains("href=\"#sec-2\"") && html.contains("id=\"sec-2\""));
    // figure embedded as SVG with a PNG link; the files are where the page says
    assert!(html.contains("<img src=\"figures/joint.svg\""));
    assert!(html.contains("href=\"figures/joint.png\""));
    assert!(dir.join("figures/joint.svg").exists() && dir.join("figures/joint.png").exists());
    assert!(html.contains("<td class=\"num\">0.001</td>"));
    assert!(html.contains("href=\"data/joint.csv\""));
    // offline: no scripts, no external resources
    assert!(!html.contains("<script"));
    assert!(!html.contains("http://") && !html.contains("https://"));
    assert!(!html.contains("<link"));
}

#[test]
fn text_is_escaped_but_intro_html_is_not() {
    let html = iktc_report::render_report(&sample_report()).unwrap();
    assert!(html.contains("<title>IK &lt;control&gt; &amp; limits</title>"));
    assert!(html.contains("Joint limits &quot;tight&quot;"));
    assert!(html.contains("q1 &lt; upper limit &amp; q2 &gt; lower"));
    assert!(html.contains("<caption>Errors &lt;max&gt;</caption>"));
    assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(html.contains("<p>Trusted <em>intro</em>.</p>"));
    assert!(html.contains("<p>Section <b>one</b>.</p>"));
    assert_eq!(escape_html("a'b\"c<d>&"), "a&#39;b&quot;c&lt;d&gt;&amp;");
}

#[test]
fn absolute_or_remote_figure_paths_are_rejected() {
    for bad in ["/tmp/x.svg", "https://example.org/x.svg", ""] {
        let r = Report::new("r").section(Section::new("s").figure(bad, "c"));
        assert!(
            matches!(
                write_report(&r, &out_dir("html_bad")),
                Err(ReportError::Invalid { .. })
            ),
            "{bad:?} accepted"
        );
    }
}
