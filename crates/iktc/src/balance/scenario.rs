//! The three balance scenarios (identify, design, push) as plain result structs.
