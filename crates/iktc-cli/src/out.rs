//! Standard output through one door: every line the commands print goes through [`write_out`]
//! (the [`outln!`](crate::outln) macro), which returns the I/O error instead of panicking, and
//! [`is_broken_pipe`] lets `main` end quietly with exit 0 when the reader has gone
//! (`iktc model jvrc1 | head -1`).

use std::io::Write;

/// Writes formatted text to standard output; an error (a closed pipe) is returned, not a panic.
pub fn write_out(args: std::fmt::Arguments<'_>) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)?;
    out.flush()
}

/// True when `e` (or what caused it) is a write to a closed pipe.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// `println!` through [`write_out`]: `outln!(...)` evaluates to an `std::io::Result<()>`.
#[macro_export]
macro_rules! outln {
    () => {
        $crate::out::write_out(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::out::write_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}
