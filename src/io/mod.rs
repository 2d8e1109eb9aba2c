//! Readers and writers: VTK frames, OBJ meshes.

pub mod obj;
pub mod vtk;

pub use obj::load_obj;
pub use vtk::write_vtk;
