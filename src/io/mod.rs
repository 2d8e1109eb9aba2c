//! Frame writers.

pub mod vtk;

pub use vtk::write_vtk;
