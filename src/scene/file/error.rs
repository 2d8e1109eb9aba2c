//! Messages for JSON errors in scene files: file, line and column, and the key's path.

use crate::Error;
use std::path::Path;

/// A JSON error as "FILE: line L column C: PATH: MESSAGE".
pub(super) fn json_error(e: serde_json::Error, path: &str, origin: Option<&Path>) -> Error {
    let (line, column) = (e.line(), e.column());
    let mut message = e.to_string();
    let suffix = format!(" at line {line} column {column}");
    if let Some(stripped) = message.strip_suffix(&suffix) {
        message = stripped.to_string();
    }
    let syntax = e.is_syntax() || e.is_eof();
    // An unknown key's path ends with the key itself; name the object that holds it instead.
    let mut path = path;
    if let Some(key) = message
        .strip_prefix("unknown field `")
        .and_then(|rest| rest.split('`').next())
        && let Some(parent) = path.strip_suffix(key)
    {
        path = parent.strip_suffix('.').unwrap_or(".");
        if path.is_empty() {
            path = ".";
        }
    }
    let field = if syntax || path == "." { "scene" } else { path };
    let mut out = String::new();
    if let Some(p) = origin {
        out.push_str(&format!("{}: ", p.display()));
    }
    out.push_str(&format!("line {line} column {column}: "));
    if syntax {
        out.push_str("invalid JSON: ");
    } else if path != "." {
        out.push_str(&format!("{path}: "));
    }
    out.push_str(&message);
    Error::InvalidArgument {
        field: field.to_string(),
        message: out,
    }
}
