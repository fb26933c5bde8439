//! Drawing a [`Figure`] onto any plotters backend (SVG or bitmap).

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::decimate::decimate;
use crate::error::ReportError;
use crate::figure::{Figure, LineStyle, Panel, Series};
use crate::font::FONT_FAMILY;
use crate::legend::{draw_legend, LegendEntry, Marker};
use crate::range::{
    equalize, finite_bounds, is_usable, linear_formatter, linear_range, log_formatter, log_range,
};

/// Series colours (Tableau-like, red left out: red is reserved for limit lines).
const PALETTE: [RGBColor; 9] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];
/// Colour of horizontal reference (limit) lines.
const LIMIT_COLOR: RGBColor = RGBColor(200, 30, 30);
/// Space around each chart \[px\].
const MARGIN: u32 = 8;
/// Extra space right of each chart so the last tick label fits \[px\].
const MARGIN_RIGHT: u32 = 20;
/// Height reserved for x tick labels and the x-axis label \[px\].
const X_LABEL_AREA: u32 = 42;
/// Width reserved for the y-axis label and tick marks, besides the tick labels \[px\].
const Y_DESC_AREA: u32 = 40;
/// Smallest width reserved for y tick labels and the y-axis label \[px\].
const MIN_Y_LABEL_AREA: u32 = 70;
/// Tick-label text size \[px\].
const TICK_FONT: u32 = 13;
/// Line width of series \[px\].
const LINE_WIDTH: u32 = 2;
/// Marker radius of point series \[px\].
const POINT_RADIUS: u32 = 3;

/// Axis ranges and pixel geometry of one chart.
struct View<'a> {
    /// x-axis range, in the panel's x unit.
    x_range: (f64, f64),
    /// y-axis range, in the panel's y unit.
    y_range: (f64, f64),
    /// Width of the plotting area \[px\].
    columns: usize,
    /// Maps an x value to its pixel column.
    to_col: &'a dyn Fn(f64) -> f64,
    /// Whether any finite point exists.
    has_data: bool,
}

fn err<E: std::fmt::Display>(context: &str) -> impl FnOnce(E) -> ReportError + '_ {
    move |e| ReportError::plot(context, e)
}

/// Draws the whole figure (white background, title row, grid of panels) onto `root`.
pub(crate) fn draw_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
) -> Result<(), ReportError> {
    root.fill(&WHITE).map_err(err("filling the background"))?;
    let title_h = fig.title_height();
    let body = if title_h > 0 {
        let (top, body) = root.split_vertically(title_h);
        let (w, h) = top.dim_in_pixel();
        let style = TextStyle::from((FONT_FAMILY, 22).into_font().style(FontStyle::Bold))
            .pos(Pos::new(HPos::Center, VPos::Center));
        top.draw(&Text::new(
            fig.title.clone(),
            ((w / 2) as i32, (h / 2) as i32 + 2),
            style,
        ))
        .map_err(err("drawing the figure title"))?;
        body
    } else {
        root.clone()
    };
    let cols = fig.columns.max(1).min(fig.panels.len().max(1));
    let areas = body.split_evenly((fig.rows().max(1), cols));
    for (panel, area) in fig.panels.iter().zip(areas.iter()) {
        draw_panel(area, panel)?;
    }
    Ok(())
}

/// Finite points of a series that can be placed on the panel's axes.
fn valid(p: (f64, f64), log_x: bool) -> bool {
    p.0.is_finite() && p.1.is_finite() && (!log_x || p.0 > 0.0)
}

fn series_points(s: &Series) -> impl Iterator<Item = (f64, f64)> + '_ {
    s.x.iter().copied().zip(s.y.iter().copied())
}

/// Maximal runs of consecutive valid points (lines are broken at NaN/inf).
fn segments(s: &Series, log_x: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for p in series_points(s) {
        if valid(p, log_x) {
            cur.push(p);
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Pulls points lying far outside the axis ranges (beyond ten spans; possible only for values
/// beyond `range::MAX_ABS`) to that distance, so that pixel coordinates cannot overflow.
fn clamp_to_view(seg: &[(f64, f64)], view: &View<'_>, log_x: bool) -> Vec<(f64, f64)> {
    let wide = |r: (f64, f64)| {
        let span = r.1 - r.0;
        (r.0 - 10.0 * span, r.1 + 10.0 * span)
    };
    let (x, y) = (view.x_range, view.y_range);
    let xr = if log_x {
        let ratio = (x.1 / x.0).powi(10);
        (x.0 / ratio, x.1 * ratio)
    } else {
        wide(x)
    };
    let yr = wide(y);
    let fit = |v: f64, r: (f64, f64)| {
        if r.0.is_finite() && r.1.is_finite() && r.0 < r.1 {
            v.clamp(r.0, r.1)
        } else {
            v
        }
    };
    seg.iter().map(|&(a, b)| (fit(a, xr), fit(b, yr))).collect()
}

/// Width for the y tick labels and axis label \[px\]: the widest label that the formatter of
/// `y_range` produces, plus room for the rotated axis label.
fn y_label_area<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, y_range: (f64, f64)) -> u32 {
    let fmt = linear_formatter(y_range);
    let style = TextStyle::from((FONT_FAMILY, TICK_FONT).into_font());
    let widest = (0..=20)
        .map(|k| y_range.0 + (y_range.1 - y_range.0) * f64::from(k) / 20.0)
        .map(|v| {
            let label = fmt(&v);
            area.estimate_text_size(&label, &style)
                .map_or(8 * label.len() as u32, |(w, _)| w)
        })
        .max()
        .unwrap_or(0);
    (widest + Y_DESC_AREA).max(MIN_Y_LABEL_AREA)
}

/// The title of `panel` drawn at the top of `area`; the rest of the area, or all of it for a
/// panel without a title.
fn titled_area<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
) -> Result<DrawingArea<DB, Shift>, ReportError> {
    if panel.title.trim().is_empty() {
        Ok(area.clone())
    } else {
        let style = (FONT_FAMILY, 17).into_font().style(FontStyle::Bold);
        area.titled(&panel.title, style)
            .map_err(err("drawing a panel title"))
    }
}

/// The error of a panel whose axis ranges cannot be drawn.
fn unusable(panel: &Panel, x_range: (f64, f64), y_range: (f64, f64)) -> ReportError {
    ReportError::Plot {
        what: format!(
            "panel '{}' has axis ranges x {x_range:?}, y {y_range:?} that cannot be drawn",
            panel.title
        ),
    }
}

/// Draws one panel: its title, its axes sized to its data and limit lines, its series.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
) -> Result<(), ReportError> {
    let area = titled_area(area, panel)?;
    let log_x = panel.log_x;
    let pts = || {
        panel
            .series
            .iter()
            .flat_map(series_points)
            .filter(move |p| valid(*p, log_x))
    };
    let xb = finite_bounds(pts().map(|p| p.0));
    let yb = finite_bounds(pts().map(|p| p.1).chain(panel.hlines.iter().map(|h| h.y)));
    let has_data = xb.is_some();
    let mut y_range = linear_range(yb);
    let y_label_area = y_label_area(&area, y_range);
    let (area_w, area_h) = area.dim_in_pixel();
    let plot_w = f64::from(area_w) - f64::from(2 * MARGIN + MARGIN_RIGHT + y_label_area);
    let plot_h = f64::from(area_h) - f64::from(2 * MARGIN + X_LABEL_AREA);
    let columns = plot_w.max(1.0) as usize;
    let mut builder = ChartBuilder::on(&area);
    builder
        .margin(MARGIN)
        .margin_right(MARGIN_RIGHT)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(y_label_area);
    if log_x {
        let x_range = log_range(xb);
        if !is_usable(x_range) || !is_usable(y_range) {
            return Err(unusable(panel, x_range, y_range));
        }
        let mut chart = builder
            .build_cartesian_2d((x_range.0..x_range.1).log_scale(), y_range.0..y_range.1)
            .map_err(err("building a log-x chart"))?;
        let (l0, l1) = (x_range.0.ln(), x_range.1.ln());
        let to_col = move |x: f64| (x.ln() - l0) / (l1 - l0) * columns as f64;
        let view = View {
            x_range,
            y_range,
            columns,
            to_col: &to_col,
            has_data,
        };
        fill_chart(&mut chart, panel, &view, &log_formatter)
    } else {
        let mut x_range = linear_range(xb);
        if panel.equal_aspect {
            (x_range, y_range) = equalize(x_range, y_range, plot_w, plot_h);
        }
        if !is_usable(x_range) || !is_usable(y_range) {
            return Err(unusable(panel, x_range, y_range));
        }
        let mut chart = builder
            .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
            .map_err(err("building a chart"))?;
        let x_fmt = linear_formatter(x_range);
        let to_col = move |x: f64| (x - x_range.0) / (x_range.1 - x_range.0) * columns as f64;
        let view = View {
            x_range,
            y_range,
            columns,
            to_col: &to_col,
            has_data,
        };
        fill_chart(&mut chart, panel, &view, &x_fmt)
    }
}

/// What the drawn lines leave for the legend: the pixels they cover and the legend entries.
struct Marks {
    /// Pixel of the plotting area's top-left corner in the backend \[px\].
    origin: (i32, i32),
    /// Pixels covered by lines and points, relative to `origin` \[px\].
    occupied: Vec<(i32, i32)>,
    /// Legend entries, in drawing order.
    entries: Vec<LegendEntry>,
}

/// Fills a built chart: grid and axes, limit lines, series, the no-data note and the legend.
fn fill_chart<'a, DB, X>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, RangedCoordf64>>,
    panel: &Panel,
    view: &View<'_>,
    x_fmt: &dyn Fn(&f64) -> String,
) -> Result<(), ReportError>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    draw_mesh(chart, panel, view.y_range, x_fmt)?;
    let origin = {
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        (xr.start, yr.start)
    };
    let mut marks = Marks {
        origin,
        occupied: Vec::new(),
        entries: Vec::new(),
    };
    draw_limit_lines(chart, panel, view, &mut marks)?;
    for (i, s) in panel.series.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        draw_series(chart, s, color, panel.log_x, view, &mut marks)?;
    }

    let plot = chart.plotting_area().strip_coord_spec();
    if !view.has_data {
        draw_no_data_note(&plot)?;
    }

    if marks.entries.len() > 1 {
        draw_legend(&plot, &marks.entries, &marks.occupied)?;
    }
    Ok(())
}

/// Draws the grid, the axes, their tick labels (tick font \[px\]) and their descriptions.
fn draw_mesh<'a, DB, X>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, RangedCoordf64>>,
    panel: &Panel,
    y_range: (f64, f64),
    x_fmt: &dyn Fn(&f64) -> String,
) -> Result<(), ReportError>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let y_fmt = linear_formatter(y_range);
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .x_label_formatter(x_fmt)
        .y_label_formatter(&y_fmt)
        .x_labels(10)
        .y_labels(7)
        .x_max_light_lines(2)
        .y_max_light_lines(2)
        .label_style((FONT_FAMILY, TICK_FONT))
        .axis_desc_style((FONT_FAMILY, 15))
        .bold_line_style(RGBColor(215, 215, 215))
        .light_line_style(RGBColor(240, 240, 240))
        .axis_style(RGBColor(90, 90, 90))
        .draw()
        .map_err(err("drawing axes"))
}

/// Draws the panel's finite horizontal limit lines (dashed, in the limit colour) across the
/// chart; one legend entry per distinct label.
fn draw_limit_lines<'a, DB, X>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, RangedCoordf64>>,
    panel: &Panel,
    view: &View<'_>,
    marks: &mut Marks,
) -> Result<(), ReportError>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let x_range = view.x_range;
    for h in panel.hlines.iter().filter(|h| h.y.is_finite()) {
        let style = LIMIT_COLOR.stroke_width(LINE_WIDTH);
        let hy = clamp_to_view(&[(x_range.0, h.y)], view, panel.log_x)
            .first()
            .map_or(h.y, |p| p.1);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x_range.0, hy), (x_range.1, hy)],
                10,
                6,
                style,
            ))
            .map_err(err("drawing a limit line"))?;
        let (_, py) = chart.backend_coord(&(x_range.0, hy));
        marks.occupied.extend(
            (0..view.columns as i32)
                .step_by(4)
                .map(|px| (px, py - marks.origin.1)),
        );
        if !h.label.is_empty() && !marks.entries.iter().any(|e| e.label == h.label) {
            marks.entries.push(LegendEntry {
                label: h.label.clone(),
                marker: Marker::Dashed(LIMIT_COLOR),
            });
        }
    }
    Ok(())
}

/// The runs of series `s` to draw: its finite segments pulled into the view, lines decimated
/// to the chart's pixel columns.
fn series_segments(s: &Series, log_x: bool, view: &View<'_>) -> Vec<Vec<(f64, f64)>> {
    segments(s, log_x)
        .iter()
        .map(|seg| {
            let seg = clamp_to_view(seg, view, log_x);
            match s.style {
                LineStyle::Points => seg,
                _ => decimate(&seg, view.columns, view.to_col),
            }
        })
        .collect()
}

/// Draws series `s` in `color` and records its pixels and its legend entry (when labelled).
fn draw_series<'a, DB, X>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, RangedCoordf64>>,
    s: &Series,
    color: RGBColor,
    log_x: bool,
    view: &View<'_>,
    marks: &mut Marks,
) -> Result<(), ReportError>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let segs = series_segments(s, log_x, view);
    let ctx = format!("drawing series '{}'", s.label);
    let origin = marks.origin;
    for seg in &segs {
        marks.occupied.extend(seg.iter().map(|p| {
            let (px, py) = chart.backend_coord(p);
            (px - origin.0, py - origin.1)
        }));
        draw_segment(chart, seg, s.style, color, &ctx)?;
    }
    if !s.label.is_empty() {
        let marker = match s.style {
            LineStyle::Solid => Marker::Line(color),
            LineStyle::Dashed => Marker::Dashed(color),
            LineStyle::Points => Marker::Dot(color),
        };
        marks.entries.push(LegendEntry {
            label: s.label.clone(),
            marker,
        });
    }
    Ok(())
}

/// Draws one run of a series in `style` (line width and marker radius \[px\]); `ctx` names the
/// series in errors.
fn draw_segment<'a, DB, X>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, RangedCoordf64>>,
    seg: &[(f64, f64)],
    style: LineStyle,
    color: RGBColor,
    ctx: &str,
) -> Result<(), ReportError>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let line = color.stroke_width(LINE_WIDTH);
    if seg.len() == 1 && style != LineStyle::Points {
        // An isolated finite sample of a line has no segment to draw: mark it with a dot.
        chart
            .draw_series(
                seg.iter()
                    .map(|&p| Circle::new(p, LINE_WIDTH + 1, color.filled())),
            )
            .map_err(err(ctx))?;
        return Ok(());
    }
    match style {
        LineStyle::Solid => {
            chart
                .draw_series(LineSeries::new(seg.iter().copied(), line))
                .map_err(err(ctx))?;
        }
        LineStyle::Dashed => {
            chart
                .draw_series(DashedLineSeries::new(seg.iter().copied(), 9, 5, line))
                .map_err(err(ctx))?;
        }
        LineStyle::Points => {
            chart
                .draw_series(
                    seg.iter()
                        .map(|&p| Circle::new(p, POINT_RADIUS, color.filled())),
                )
                .map_err(err(ctx))?;
        }
    }
    Ok(())
}

/// Writes "no finite data" (16 px, grey) at the centre of the plotting area `plot`.
fn draw_no_data_note<DB: DrawingBackend>(plot: &DrawingArea<DB, Shift>) -> Result<(), ReportError> {
    let (w, h) = plot.dim_in_pixel();
    let style = TextStyle::from((FONT_FAMILY, 16).into_font())
        .color(&RGBColor(120, 120, 120))
        .pos(Pos::new(HPos::Center, VPos::Center));
    plot.draw(&Text::new(
        "no finite data",
        ((w / 2) as i32, (h / 2) as i32),
        style,
    ))
    .map_err(err("drawing the no-data note"))
}
