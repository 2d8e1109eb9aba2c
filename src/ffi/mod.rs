//! The C API (see issue 3).
