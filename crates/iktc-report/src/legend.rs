//! The legend box: one entry per labelled series or limit line, in as many columns as needed to
//! fit the plot's height, in the corner that hides the fewest data points.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::error::ReportError;
use crate::font::FONT_FAMILY;

/// Height of one legend row [px].
const ROW_H: i32 = 17;
/// Padding inside the legend box [px].
const PAD: i32 = 6;
/// Length of the line sample left of each label [px].
const SAMPLE_W: i32 = 24;
/// Gap between the sample and the label [px].
const GAP: i32 = 6;
/// Gap between legend columns [px].
const COL_GAP: i32 = 14;
/// Distance of the legend box from the plot frame [px].
const INSET: i32 = 6;
/// Legend text size [px].
const FONT_SIZE: u32 = 13;

/// How an entry's sample is drawn.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Marker {
    /// Solid line of the given colour.
    Line(RGBColor),
    /// Dashed line of the given colour.
    Dashed(RGBColor),
    /// A filled dot of the given colour.
    Dot(RGBColor),
}

/// One legend row.
#[derive(Debug, Clone)]
pub(crate) struct LegendEntry {
    /// Text of the entry.
    pub label: String,
    /// Sample drawn left of the text.
    pub marker: Marker,
}

fn err<E: std::fmt::Display>(e: E) -> ReportError {
    ReportError::plot("drawing the legend", e)
}

/// Draws `entries` onto the plotting area `area` (pixel coordinates relative to its top-left
/// corner); `occupied` are the pixels of data, used to pick the least crowded corner.
pub(crate) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    occupied: &[(i32, i32)],
) -> Result<(), ReportError> {
    if entries.is_empty() {
        return Ok(());
    }
    let (w, h) = area.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let style = TextStyle::from((FONT_FAMILY, FONT_SIZE).into_font());
    let max_rows = ((h - 2 * PAD - 2 * INSET) / ROW_H).max(1) as usize;
    let ncols = entries.len().div_ceil(max_rows);
    let rows = entries.len().div_ceil(ncols);
    let mut col_w = Vec::with_capacity(ncols);
    for chunk in entries.chunks(rows) {
        let mut widest = 0;
        for e in chunk {
            let tw = area
                .estimate_text_size(&e.label, &style)
                .map(|(tw, _)| tw as i32)
                .unwrap_or(8 * e.label.chars().count() as i32);
            widest = widest.max(tw);
        }
        col_w.push(widest + SAMPLE_W + GAP);
    }
    let box_w = col_w.iter().sum::<i32>() + COL_GAP * (ncols as i32 - 1) + 2 * PAD;
    let box_h = rows as i32 * ROW_H + 2 * PAD;
    let right = (w - box_w - INSET).max(0);
    let bottom = (h - box_h - INSET).max(0);
    // upper-right first: on ties the first corner wins
    let corners = [
        (right, INSET),
        (INSET, INSET),
        (right, bottom),
        (INSET, bottom),
    ];
    let covered = |&(x0, y0): &(i32, i32)| {
        occupied
            .iter()
            .filter(|(x, y)| *x >= x0 && *x < x0 + box_w && *y >= y0 && *y < y0 + box_h)
            .count()
    };
    let (x0, y0) = corners
        .iter()
        .copied()
        .min_by_key(covered)
        .unwrap_or((right, INSET));
    let frame = [(x0, y0), (x0 + box_w, y0 + box_h)];
    area.draw(&Rectangle::new(frame, WHITE.mix(0.88).filled()))
        .map_err(err)?;
    area.draw(&Rectangle::new(
        frame,
        RGBColor(160, 160, 160).stroke_width(1),
    ))
    .map_err(err)?;
    let mut col_x = x0 + PAD;
    for (c, chunk) in entries.chunks(rows).enumerate() {
        for (r, e) in chunk.iter().enumerate() {
            let y = y0 + PAD + r as i32 * ROW_H + ROW_H / 2;
            draw_marker(area, e.marker, col_x, y)?;
            let pos = Pos::new(HPos::Left, VPos::Center);
            area.draw(&Text::new(
                e.label.clone(),
                (col_x + SAMPLE_W + GAP, y),
                style.clone().pos(pos),
            ))
            .map_err(err)?;
        }
        col_x += col_w.get(c).copied().unwrap_or(0) + COL_GAP;
    }
    Ok(())
}

fn draw_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    marker: Marker,
    x: i32,
    y: i32,
) -> Result<(), ReportError> {
    match marker {
        Marker::Line(c) => area.draw(&PathElement::new(
            vec![(x, y), (x + SAMPLE_W, y)],
            c.stroke_width(2),
        )),
        Marker::Dashed(c) => {
            let s = c.stroke_width(2);
            area.draw(&PathElement::new(vec![(x, y), (x + 9, y)], s))
                .and_then(|_| area.draw(&PathElement::new(vec![(x + 15, y), (x + SAMPLE_W, y)], s)))
        }
        Marker::Dot(c) => area.draw(&Circle::new((x + SAMPLE_W / 2, y), 4, c.filled())),
    }
    .map_err(err)
}
