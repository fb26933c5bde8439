//! Figures, CSV tables and HTML reports.
