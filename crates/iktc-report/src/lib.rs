//! Figures (SVG and PNG), CSV tables and one offline HTML report for iktc experiments.
//!
//! - [`write_figure`] draws a [`Figure`] (a grid of [`Panel`]s holding [`Series`] and limit
//!   lines [`HLine`]) into `stem.svg` and `stem.png`.
//! - [`write_csv`] writes a numeric table with a header row.
//! - [`write_report`] writes `index.html`, a self-contained page (inline CSS, no script, no
//!   network) with a table of contents, figures and summary tables.
#![warn(missing_docs)]

mod csv;
mod decimate;
mod error;
mod figure;
mod font;
mod html;
mod legend;
mod range;
mod render;

pub use crate::csv::write_csv;
pub use crate::error::ReportError;
pub use crate::figure::{
    write_figure, Figure, FigureFiles, HLine, LineStyle, Panel, Series, DEFAULT_PANEL_HEIGHT,
    DEFAULT_PANEL_WIDTH,
};
pub use crate::font::FONT_FAMILY;
pub use crate::html::{escape_html, render_report, write_report, Report, Section, Table};
