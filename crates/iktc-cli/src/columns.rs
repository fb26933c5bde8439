//! How the records' enums and options become numbers in CSV columns and on figure axes (the
//! library keeps them as enums and `Option`s).

use iktc::walk::{Phase, Side};

/// A corrected level as a column value: its 1-based number, 0 without correction.
pub fn level_number(level: Option<usize>) -> f64 {
    level.map_or(0.0, |l| (l + 1) as f64)
}

/// A support phase as a column value: 0 double support, 1 left foot in stance, 2 right foot.
pub fn phase_number(phase: Phase) -> f64 {
    match phase {
        Phase::DoubleSupport => 0.0,
        Phase::SingleSupport { stance: Side::Left } => 1.0,
        Phase::SingleSupport {
            stance: Side::Right,
        } => 2.0,
    }
}
