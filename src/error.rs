//! The crate's error type.

use std::fmt;

/// What went wrong, in words a user can act on.
#[derive(Clone, Debug, PartialEq)]
pub enum Error {
    /// An input value is out of range or malformed; `field` names it.
    InvalidArgument {
        /// The offending field or argument, e.g. `particle_radius` or `fluid_blocks[1].count`.
        field: String,
        /// What was wrong with it, including the value.
        message: String,
    },
    /// A file could not be read or written.
    Io(String),
    /// Memory for what the message names could not be allocated; nothing was changed.
    OutOfMemory(String),
}

impl Error {
    /// An invalid-argument error naming `field`, its `value` and the rule it broke.
    pub fn invalid(field: impl Into<String>, value: impl fmt::Display, rule: &str) -> Self {
        let field = field.into();
        Error::InvalidArgument {
            message: format!("{field} {rule}, got {value}"),
            field,
        }
    }

    /// An out-of-memory error for `what` (e.g. `fluid particles`).
    pub fn out_of_memory(what: &str) -> Self {
        Error::OutOfMemory(format!("out of memory while allocating {what}"))
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidArgument { message, .. } => f.write_str(message),
            Error::Io(message) | Error::OutOfMemory(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for Error {}
