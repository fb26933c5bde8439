//! Figure description (panels of line, dashed and point series) and [`write_figure`].

use std::path::{Path, PathBuf};

use plotters::prelude::{BitMapBackend, IntoDrawingArea, SVGBackend};

use crate::error::ReportError;
use crate::font::ensure_font;
use crate::render::draw_figure;

/// Default width of one panel [px].
pub const DEFAULT_PANEL_WIDTH: u32 = 800;
/// Default height of one panel [px].
pub const DEFAULT_PANEL_HEIGHT: u32 = 300;

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineStyle {
    /// A solid line through the points (broken where a value is NaN or infinite).
    Solid,
    /// A dashed line through the points (broken where a value is NaN or infinite).
    Dashed,
    /// One marker per point, no line.
    Points,
}

/// One curve of a [`Panel`]: `y[i]` against `x[i]`, in the panel's axis units.
///
/// Points with a NaN or infinite coordinate (or `x <= 0` on a logarithmic x axis) are skipped.
/// `x` and `y` must have the same length.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text (an empty label gives no legend entry).
    pub label: String,
    /// Abscissae, in the panel's x unit.
    pub x: Vec<f64>,
    /// Ordinates, in the panel's y unit.
    pub y: Vec<f64>,
    /// How the series is drawn.
    pub style: LineStyle,
}

impl Series {
    /// A solid line.
    pub fn line(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Self::styled(label, x, y, LineStyle::Solid)
    }

    /// A dashed line (for references, commands or a second method next to a solid one).
    pub fn dashed(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Self::styled(label, x, y, LineStyle::Dashed)
    }

    /// Markers without a line (samples, footsteps, scattered results).
    pub fn points(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Self::styled(label, x, y, LineStyle::Points)
    }

    /// A series with the given style.
    pub fn styled(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>, style: LineStyle) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            style,
        }
    }
}

/// A horizontal reference line across a whole panel (e.g. a joint limit), drawn dashed in red.
#[derive(Debug, Clone, PartialEq)]
pub struct HLine {
    /// Height of the line, in the panel's y unit (a non-finite value is skipped).
    pub y: f64,
    /// Legend text (an empty label gives no legend entry).
    pub label: String,
}

/// One chart: axes with a title, labelled axes, series, reference lines and a legend.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Title drawn above the chart.
    pub title: String,
    /// x-axis label, with its unit, e.g. `"time [s]"`.
    pub x_label: String,
    /// y-axis label, with its unit, e.g. `"q [rad]"`.
    pub y_label: String,
    /// The curves, drawn in order with distinct colours.
    pub series: Vec<Series>,
    /// Horizontal reference lines (limits), drawn dashed.
    pub hlines: Vec<HLine>,
    /// Logarithmic x axis (Bode plots); non-positive x values are skipped.
    pub log_x: bool,
    /// Same scale on both axes (x-y plots: an arm's motion, footsteps seen from above).
    /// Ignored when `log_x` is set.
    pub equal_aspect: bool,
}

impl Panel {
    /// An empty panel with a title and axis labels (put units in the labels: `"q [rad]"`).
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            hlines: Vec::new(),
            log_x: false,
            equal_aspect: false,
        }
    }

    /// Adds a series.
    pub fn with(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }

    /// Adds a horizontal reference line at `y` (panel's y unit), e.g. a joint limit.
    pub fn hline(mut self, y: f64, label: impl Into<String>) -> Self {
        self.hlines.push(HLine {
            y,
            label: label.into(),
        });
        self
    }

    /// Makes the x axis logarithmic (Bode plots).
    pub fn log_x(mut self) -> Self {
        self.log_x = true;
        self
    }

    /// Uses the same scale on both axes (x-y plots).
    pub fn equal_aspect(mut self) -> Self {
        self.equal_aspect = true;
        self
    }
}

/// A figure: a title over panels laid out in a grid, row by row.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title drawn above all panels (empty: no title row).
    pub title: String,
    /// The panels, filled into the grid row by row.
    pub panels: Vec<Panel>,
    /// Number of grid columns (at least 1; default 1).
    pub columns: usize,
    /// Width of one panel [px] (default [`DEFAULT_PANEL_WIDTH`]).
    pub panel_width: u32,
    /// Height of one panel [px] (default [`DEFAULT_PANEL_HEIGHT`]).
    pub panel_height: u32,
}

impl Figure {
    /// An empty figure with one column of 800 x 300 px panels.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            panels: Vec::new(),
            columns: 1,
            panel_width: DEFAULT_PANEL_WIDTH,
            panel_height: DEFAULT_PANEL_HEIGHT,
        }
    }

    /// Adds a panel.
    pub fn panel(mut self, p: Panel) -> Self {
        self.panels.push(p);
        self
    }

    /// Sets the number of grid columns.
    pub fn columns(mut self, c: usize) -> Self {
        self.columns = c;
        self
    }

    /// Sets the size of one panel [px].
    pub fn panel_size(mut self, width: u32, height: u32) -> Self {
        self.panel_width = width;
        self.panel_height = height;
        self
    }

    /// Number of grid rows needed for the panels.
    pub fn rows(&self) -> usize {
        self.panels.len().div_ceil(self.columns.max(1))
    }

    /// Height of the title row [px] (0 when the title is empty).
    pub(crate) fn title_height(&self) -> u32 {
        if self.title.trim().is_empty() {
            0
        } else {
            40
        }
    }

    /// Total size of the rendered figure [px].
    pub fn size(&self) -> (u32, u32) {
        let cols = self.columns.max(1).min(self.panels.len().max(1));
        let w = self.panel_width.saturating_mul(cols as u32);
        let h = self
            .panel_height
            .saturating_mul(self.rows() as u32)
            .saturating_add(self.title_height());
        (w, h)
    }

    /// Checks the figure can be drawn: at least one panel, `columns >= 1`, panels of at least
    /// 200 x 120 px, matching `x`/`y` lengths in every series.
    pub fn validate(&self) -> Result<(), ReportError> {
        if self.panels.is_empty() {
            return Err(ReportError::invalid(format!(
                "figure '{}' has no panels; add at least one with Figure::panel",
                self.title
            )));
        }
        if self.columns == 0 {
            return Err(ReportError::invalid(format!(
                "figure '{}' has 0 columns; expected at least 1",
                self.title
            )));
        }
        if self.panel_width < 200 || self.panel_height < 120 {
            return Err(ReportError::invalid(format!(
                "figure '{}' has panels of {} x {} px; expected at least 200 x 120 px",
                self.title, self.panel_width, self.panel_height
            )));
        }
        let (w, h) = self.size();
        if w > 20_000 || h > 20_000 {
            return Err(ReportError::invalid(format!(
                "figure '{}' would be {w} x {h} px; expected at most 20000 px per side",
                self.title
            )));
        }
        for p in &self.panels {
            for s in &p.series {
                if s.x.len() != s.y.len() {
                    return Err(ReportError::invalid(format!(
                        "series '{}' in panel '{}' has {} x values but {} y values; expected equal lengths",
                        s.label,
                        p.title,
                        s.x.len(),
                        s.y.len()
                    )));
                }
            }
        }
        Ok(())
    }
}

/// Paths of the files written by [`write_figure`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FigureFiles {
    /// The vector figure, `dir/stem.svg`.
    pub svg: PathBuf,
    /// The raster figure, `dir/stem.png`.
    pub png: PathBuf,
}

/// Draws `fig` into `dir/stem.svg` and `dir/stem.png` (creating `dir` if needed).
///
/// `stem` is a plain file name without extension (no path separators).
pub fn write_figure(fig: &Figure, dir: &Path, stem: &str) -> Result<FigureFiles, ReportError> {
    fig.validate()?;
    if stem.is_empty() || stem.contains(['/', '\\']) || stem == "." || stem == ".." {
        return Err(ReportError::invalid(format!(
            "figure file stem '{stem}' is not a plain file name; expected e.g. \"joint_angles\""
        )));
    }
    ensure_font()?;
    std::fs::create_dir_all(dir).map_err(|e| ReportError::io(dir, e))?;
    let files = FigureFiles {
        svg: dir.join(format!("{stem}.svg")),
        png: dir.join(format!("{stem}.png")),
    };
    let size = fig.size();
    {
        let root = SVGBackend::new(&files.svg, size).into_drawing_area();
        draw_figure(&root, fig)?;
        root.present()
            .map_err(|e| ReportError::plot(&format!("writing {}", files.svg.display()), e))?;
    }
    {
        let root = BitMapBackend::new(&files.png, size).into_drawing_area();
        draw_figure(&root, fig)?;
        root.present()
            .map_err(|e| ReportError::plot(&format!("writing {}", files.png.display()), e))?;
    }
    Ok(files)
}
