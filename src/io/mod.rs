//! Frame writers.
