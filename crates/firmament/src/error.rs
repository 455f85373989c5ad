//! The library's error type. Messages name the field, the value and the accepted range.

use thiserror::Error;

/// Everything the library can refuse.
#[derive(Debug, Error)]
pub enum Error {
    /// A parameter outside its accepted range.
    #[error("invalid value for `{field}`: {value} ({expected})")]
    InvalidParameter {
        /// Dotted path of the field, e.g. `constituents[1].phase.g`.
        field: String,
        /// The offending value, as written.
        value: String,
        /// The accepted range, in words.
        expected: String,
    },
    /// A TOML document that does not parse or has unknown fields.
    #[error("{0}")]
    Toml(String),
    /// An unknown preset name.
    #[error("unknown preset `{0}` (known presets: {1})")]
    UnknownPreset(String, String),
    /// A table file that cannot be used.
    #[error("table file {path}: {reason}")]
    TableFile {
        /// The file.
        path: String,
        /// Why it was refused.
        reason: String,
    },
    /// A data or input file that cannot be read.
    #[error("{path}: {reason}")]
    File {
        /// The file.
        path: String,
        /// Why.
        reason: String,
    },
    /// Any I/O failure.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The operation was interrupted (Ctrl-C).
    #[error("interrupted")]
    Interrupted,
}

/// Shorthand.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// A parameter error; `value` is formatted with `{:?}`-free display.
    pub fn invalid(
        field: impl Into<String>,
        value: impl ToString,
        expected: impl Into<String>,
    ) -> Self {
        Error::InvalidParameter {
            field: field.into(),
            value: value.to_string(),
            expected: expected.into(),
        }
    }

    /// The same error with `prefix` before a parameter's field name (a table's name in a
    /// file, e.g. `location.`).
    pub fn prefixed(self, prefix: &str) -> Self {
        match self {
            Error::InvalidParameter {
                field,
                value,
                expected,
            } => Error::InvalidParameter {
                field: format!(
                    "{prefix}{}",
                    field.trim_start_matches("--").replace('-', "_")
                ),
                value,
                expected,
            },
            other => other,
        }
    }
}
