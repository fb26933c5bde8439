//! The offline HTML report: one `index.html` with inline CSS, no script and no network access.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::ReportError;

/// A table of text cells (summaries, settings, pass/fail lists).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Table {
    /// Caption shown above the table (plain text, escaped).
    pub caption: String,
    /// Column names (plain text, escaped).
    pub header: Vec<String>,
    /// Rows of cells (plain text, escaped); rows may be shorter or longer than the header.
    pub rows: Vec<Vec<String>>,
}

/// One section of a [`Report`]: a heading, trusted HTML text, figures, tables and links.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Section {
    /// Section heading (plain text, escaped); also its table-of-contents entry.
    pub title: String,
    /// Introductory HTML, inserted as is (trusted: it must come from the program, not from input).
    pub intro_html: String,
    /// Figures as (path relative to the report directory, caption). A `.svg` path is shown as
    /// an image with a link to the `.png` of the same stem next to it.
    pub figures: Vec<(String, String)>,
    /// Summary tables.
    pub tables: Vec<Table>,
    /// Links as (href, text), e.g. to CSV files relative to the report directory.
    pub links: Vec<(String, String)>,
}

/// A whole report: title, trusted introductory HTML and sections.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Report {
    /// Page title and top heading (plain text, escaped).
    pub title: String,
    /// Introductory HTML, inserted as is (trusted).
    pub intro_html: String,
    /// The sections, in order; each gets a table-of-contents entry.
    pub sections: Vec<Section>,
}

impl Table {
    /// A table with a caption and column names and no rows yet.
    pub fn new(caption: impl Into<String>, header: Vec<String>) -> Self {
        Self {
            caption: caption.into(),
            header,
            rows: Vec::new(),
        }
    }

    /// Adds a row.
    pub fn row(mut self, cells: Vec<String>) -> Self {
        self.rows.push(cells);
        self
    }
}

impl Section {
    /// An empty section with a title.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            ..Self::default()
        }
    }

    /// Sets the introductory (trusted) HTML.
    pub fn intro(mut self, html: impl Into<String>) -> Self {
        self.intro_html = html.into();
        self
    }

    /// Adds a figure (path relative to the report directory, caption).
    pub fn figure(mut self, path: impl Into<String>, caption: impl Into<String>) -> Self {
        self.figures.push((path.into(), caption.into()));
        self
    }

    /// Adds a table.
    pub fn table(mut self, t: Table) -> Self {
        self.tables.push(t);
        self
    }

    /// Adds a link (href, text).
    pub fn link(mut self, href: impl Into<String>, text: impl Into<String>) -> Self {
        self.links.push((href.into(), text.into()));
        self
    }
}

impl Report {
    /// An empty report with a title.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            ..Self::default()
        }
    }

    /// Sets the introductory (trusted) HTML.
    pub fn intro(mut self, html: impl Into<String>) -> Self {
        self.intro_html = html.into();
        self
    }

    /// Adds a section.
    pub fn section(mut self, s: Section) -> Self {
        self.sections.push(s);
        self
    }
}

/// Escapes `&`, `<`, `>`, `"` and `'` so that `s` shows as text in HTML content and attributes.
pub fn escape_html(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// Inline style sheet of the report.
const STYLE: &str = "
body { font-family: sans-serif; max-width: 1100px; margin: 1.5em auto; padding: 0 1em;
       color: #222; line-height: 1.45; }
h1 { border-bottom: 2px solid #1f77b4; padding-bottom: .2em; }
h2 { border-bottom: 1px solid #ccc; padding-bottom: .15em; margin-top: 2em; }
nav.toc { background: #f5f7fa; border: 1px solid #dde3ea; padding: .5em 1.2em; }
nav.toc ol { margin: .3em 0; }
figure { margin: 1.2em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #e4e4e4; }
figcaption { font-size: .92em; color: #444; margin-top: .3em; }
table { border-collapse: collapse; margin: 1em 0; font-size: .92em; }
caption { caption-side: top; text-align: left; font-weight: bold; padding-bottom: .3em; }
th, td { border: 1px solid #ccc; padding: .25em .6em; text-align: left; }
th { background: #eef2f6; }
tbody tr:nth-child(even) { background: #fafafa; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
ul.links { padding-left: 1.2em; }
footer { margin-top: 3em; font-size: .85em; color: #777; }
";

/// Whether a figure path is relative to the report directory (no scheme, not absolute).
fn is_relative(path: &str) -> bool {
    !path.is_empty()
        && !path.contains("://")
        && !path.starts_with('/')
        && !path.starts_with('\\')
        && !path.starts_with("data:")
        && !Path::new(path).is_absolute()
}

/// Whether a table cell holds a number (right-aligned).
fn is_numeric(cell: &str) -> bool {
    let t = cell.trim();
    !t.is_empty() && t.parse::<f64>().is_ok()
}

fn write_table(out: &mut String, t: &Table) {
    out.push_str("<table>\n");
    if !t.caption.is_empty() {
        let _ = writeln!(out, "<caption>{}</caption>", escape_html(&t.caption));
    }
    if !t.header.is_empty() {
        out.push_str("<thead><tr>");
        for h in &t.header {
            let _ = write!(out, "<th>{}</th>", escape_html(h));
        }
        out.push_str("</tr></thead>\n");
    }
    out.push_str("<tbody>\n");
    for row in &t.rows {
        out.push_str("<tr>");
        for c in row {
            let class = if is_numeric(c) { " class=\"num\"" } else { "" };
            let _ = write!(out, "<td{class}>{}</td>", escape_html(c));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody>\n</table>\n");
}

fn write_figure_html(out: &mut String, path: &str, caption: &str) {
    let src = escape_html(path);
    let alt = escape_html(caption);
    let _ = write!(
        out,
        "<figure>\n<img src=\"{src}\" alt=\"{alt}\">\n<figcaption>{alt}"
    );
    if let Some(stem) = path.strip_suffix(".svg") {
        let png = escape_html(&format!("{stem}.png"));
        let _ = write!(
            out,
            " (<a href=\"{png}\">PNG</a>, <a href=\"{src}\">SVG</a>)"
        );
    }
    out.push_str("</figcaption>\n</figure>\n");
}

/// Renders the report as one HTML document (see [`write_report`]).
pub fn render_report(report: &Report) -> Result<String, ReportError> {
    for s in &report.sections {
        if let Some((p, _)) = s.figures.iter().find(|(p, _)| !is_relative(p)) {
            return Err(ReportError::invalid(format!(
                "figure path '{p}' in section '{}' is not relative to the report directory; \
                 expected e.g. \"figures/joint_angles.svg\"",
                s.title
            )));
        }
    }
    let title = escape_html(&report.title);
    let mut out = String::new();
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{title}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{title}</h1>\n"
    );
    if !report.intro_html.is_empty() {
        let _ = writeln!(out, "<div class=\"intro\">\n{}\n</div>", report.intro_html);
    }
    if !report.sections.is_empty() {
        out.push_str("<nav class=\"toc\">\n<strong>Contents</strong>\n<ol>\n");
        for (i, s) in report.sections.iter().enumerate() {
            let _ = writeln!(
                out,
                "<li><a href=\"#sec-{}\">{}</a></li>",
                i + 1,
                escape_html(&s.title)
            );
        }
        out.push_str("</ol>\n</nav>\n");
    }
    for (i, s) in report.sections.iter().enumerate() {
        let _ = writeln!(
            out,
            "<section id=\"sec-{}\">\n<h2>{}. {}</h2>",
            i + 1,
            i + 1,
            escape_html(&s.title)
        );
        if !s.intro_html.is_empty() {
            let _ = writeln!(out, "<div class=\"intro\">\n{}\n</div>", s.intro_html);
        }
        for (path, caption) in &s.figures {
            write_figure_html(&mut out, path, caption);
        }
        for t in &s.tables {
            write_table(&mut out, t);
        }
        if !s.links.is_empty() {
            out.push_str("<ul class=\"links\">\n");
            for (href, text) in &s.links {
                let _ = writeln!(
                    out,
                    "<li><a href=\"{}\">{}</a></li>",
                    escape_html(href),
                    escape_html(text)
                );
            }
            out.push_str("</ul>\n");
        }
        out.push_str("</section>\n");
    }
    out.push_str("<footer>Generated by iktc-report.</footer>\n</body>\n</html>\n");
    Ok(out)
}

/// Writes `dir/index.html` (creating `dir` if needed) and returns its path.
///
/// The page is self-contained: inline CSS, no script, no external resource besides the figure
/// files it names (relative paths; an absolute path or URL is [`ReportError::Invalid`]). Titles,
/// captions, table cells and link texts are escaped; `intro_html` fields are inserted as is.
pub fn write_report(report: &Report, dir: &Path) -> Result<PathBuf, ReportError> {
    let html = render_report(report)?;
    std::fs::create_dir_all(dir).map_err(|e| ReportError::io(dir, e))?;
    let path = dir.join("index.html");
    std::fs::write(&path, html).map_err(|e| ReportError::io(&path, e))?;
    Ok(path)
}
