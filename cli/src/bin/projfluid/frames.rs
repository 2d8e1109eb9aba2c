//! Numbered outputs of a run: data frames (VTK or PLY) and PNG pictures, written at the
//! start and every N steps.

use crate::Failure;
use projfluid::World;
use projfluid::io::{write_ply, write_vtk};
use projfluid_lab::render::Renderer;
use std::path::{Path, PathBuf};

/// File format of the data frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum FrameFormat {
    /// Legacy VTK polydata (ParaView, VisIt).
    Vtk,
    /// Binary PLY point cloud (Blender, MeshLab).
    Ply,
}

/// Where frames and pictures go, and how many have been written.
pub(crate) struct Frames {
    data: Option<(PathBuf, FrameFormat)>,
    pictures: Option<(PathBuf, Renderer)>,
    written: usize,
}

/// Creates `dir` if needed.
fn create(dir: &Path) -> Result<PathBuf, Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::Runtime(format!(
            "cannot create output directory {}: {e}",
            dir.display()
        ))
    })?;
    Ok(dir.to_path_buf())
}

impl Frames {
    /// Data frames into `data` in `format` and pictures `width` pixels wide into `pictures` (either may
    /// be absent), with the camera framed on `world`'s containers; creates the directories.
    pub(crate) fn new(
        data: Option<&Path>,
        format: FrameFormat,
        pictures: Option<(&Path, usize)>,
        world: &World,
    ) -> Result<Self, Failure> {
        Ok(Self {
            data: data.map(|d| create(d).map(|d| (d, format))).transpose()?,
            pictures: match pictures {
                Some((dir, width)) => Some((
                    create(dir)?,
                    Renderer::for_world(world, width, (width * 9 / 16).max(1)),
                )),
                None => None,
            },
            written: 0,
        })
    }

    /// Numbers the next frame `index + 1`, as when frames 0..=index were written by an
    /// earlier run that this one continues.
    pub(crate) fn continue_after(&mut self, index: u64) {
        self.written = index as usize + 1;
    }

    /// Writes the world's current state as the next frame.
    pub(crate) fn write(&mut self, world: &World) -> Result<(), Failure> {
        let name = format!("frame_{:05}", self.written);
        if let Some((dir, format)) = &self.data {
            let (write, extension): (fn(_, _, _, _) -> _, _) = match format {
                FrameFormat::Vtk => (write_vtk, "vtk"),
                FrameFormat::Ply => (write_ply, "ply"),
            };
            write(
                &dir.join(format!("{name}.{extension}")),
                &world.positions(),
                &world.velocities(),
                &world.densities(),
            )
            .map_err(|e| Failure::Runtime(e.to_string()))?;
        }
        if let Some((dir, renderer)) = &self.pictures {
            renderer
                .render_world(world)
                .write_png(&dir.join(format!("{name}.png")))
                .map_err(|e| Failure::Runtime(e.to_string()))?;
        }
        self.written += 1;
        Ok(())
    }
}
