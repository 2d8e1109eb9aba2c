//! Readers and writers: VTK frames, OBJ meshes, PNG pictures.

pub mod obj;
pub mod render;
pub mod vtk;

pub use obj::load_obj;
pub use vtk::write_vtk;
