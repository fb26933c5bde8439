//! Tasks, linearised to plain data J q̈ = h.
