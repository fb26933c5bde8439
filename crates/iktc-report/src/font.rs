//! The embedded font used for text in PNG figures.
//!
//! PNG text is rasterised by plotters' `ab_glyph` feature, which needs the font bytes at run time;
//! DejaVu Sans (licence in `assets/DejaVuSans-LICENSE.txt`) is embedded so that no system font
//! library is needed. SVG files only name the family [`FONT_FAMILY`], which every browser maps to
//! its own sans-serif font.

use std::sync::OnceLock;

use plotters::style::FontStyle;

use crate::error::ReportError;

/// Font family name used for all text, in SVG (`font-family`) and for the PNG rasteriser.
pub const FONT_FAMILY: &str = "sans-serif";

/// DejaVu Sans, embedded.
static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Outcome of the one-time registration (`true` when the font parsed).
static REGISTERED: OnceLock<bool> = OnceLock::new();

/// Registers the embedded font under [`FONT_FAMILY`] with plotters, once per process.
pub(crate) fn ensure_font() -> Result<(), ReportError> {
    // Other styles (bold titles) fall back to the normal face in plotters' font table.
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT_BYTES).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(ReportError::Plot {
            what: "the embedded DejaVu Sans font could not be parsed by ab_glyph".into(),
        })
    }
}
