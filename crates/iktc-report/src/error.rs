//! The error type of `iktc-report`.

use std::path::PathBuf;

/// What went wrong while writing a figure, a CSV table or an HTML report.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A file or directory could not be created or written.
    #[error("I/O error on {path}: {source}")]
    Io {
        /// The file or directory that was being written.
        path: PathBuf,
        /// The underlying operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// The plotting library failed while drawing or encoding a figure.
    #[error("plotting failed: {what}")]
    Plot {
        /// What was being drawn and the plotting library's message.
        what: String,
    },
    /// The input handed to the report writer is malformed (what is wrong and what was expected).
    #[error("invalid report input: {what}")]
    Invalid {
        /// What is wrong and what was expected.
        what: String,
    },
}

impl ReportError {
    /// Builds a [`ReportError::Io`] for `path`.
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            path: path.into(),
            source,
        }
    }

    /// Builds a [`ReportError::Plot`] from a context sentence and the plotting library's error.
    pub(crate) fn plot(context: &str, err: impl std::fmt::Display) -> Self {
        Self::Plot {
            what: format!("{context}: {err}"),
        }
    }

    /// Builds a [`ReportError::Invalid`].
    pub(crate) fn invalid(what: impl Into<String>) -> Self {
        Self::Invalid { what: what.into() }
    }
}
