//! Numbered outputs of a run: data frames (VTK or PLY) and PNG pictures, written at the
//! start and then every N steps or at every multiple of 1/fps seconds, each carrying its
//! simulated time; beside them `frames.csv` lists every frame's number, step and time.

use crate::Failure;
use projfluid::World;
use projfluid::io::{VtkEncoding, write_ply, write_vtk_encoded};
use projfluid_lab::render::Renderer;
use std::path::{Path, PathBuf};

/// File format of the data frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum FrameFormat {
    /// Legacy VTK polydata (ParaView, VisIt).
    Vtk,
    /// Legacy VTK polydata as text (larger; readable by any tool).
    VtkAscii,
    /// Binary PLY point cloud (Blender, MeshLab).
    Ply,
}

/// The name of the index written beside the frames.
const INDEX: &str = "frames.csv";

/// One written frame: its number, the world's step count and its simulated time (s).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    frame: usize,
    step: u64,
    time: f64,
}

/// Where frames and pictures go, and what has been written.
pub(crate) struct Frames {
    data: Option<(PathBuf, FrameFormat)>,
    pictures: Option<(PathBuf, Renderer)>,
    written: usize,
    index: Vec<Entry>,
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
            index: Vec::new(),
        })
    }

    /// Numbers the next frame `index + 1`, as when frames 0..=index were written by an
    /// earlier run that this one continues; the earlier run's index rows up to that frame
    /// are kept.
    pub(crate) fn continue_after(&mut self, index: u64) -> Result<(), Failure> {
        self.written = index as usize + 1;
        let dir = self.dirs().next().map(Path::to_path_buf);
        if let Some(dir) = dir {
            self.index = read_index(&dir.join(INDEX))?
                .into_iter()
                .filter(|e| e.frame < self.written)
                .collect();
        }
        Ok(())
    }

    /// The directories that receive frames.
    fn dirs(&self) -> impl Iterator<Item = &Path> {
        let data = self.data.as_ref().map(|(d, _)| d.as_path());
        data.into_iter()
            .chain(self.pictures.as_ref().map(|(d, _)| d.as_path()))
    }

    /// Writes the world's current state as the next frame.
    pub(crate) fn write(&mut self, world: &World) -> Result<(), Failure> {
        let name = format!("frame_{:05}", self.written);
        if let Some((dir, format)) = &self.data {
            let (time, x, v, rho) = (
                world.time(),
                world.positions(),
                world.velocities(),
                world.densities(),
            );
            let vtk = |encoding, path: &Path| write_vtk_encoded(path, encoding, time, &x, &v, &rho);
            match format {
                FrameFormat::Vtk => vtk(VtkEncoding::Binary, &dir.join(format!("{name}.vtk"))),
                FrameFormat::VtkAscii => vtk(VtkEncoding::Ascii, &dir.join(format!("{name}.vtk"))),
                FrameFormat::Ply => write_ply(&dir.join(format!("{name}.ply")), time, &x, &v, &rho),
            }
            .map_err(|e| Failure::Runtime(e.to_string()))?;
        }
        if let Some((dir, renderer)) = &self.pictures {
            renderer
                .render_world(world)
                .write_png(&dir.join(format!("{name}.png")))
                .map_err(|e| Failure::Runtime(e.to_string()))?;
        }
        self.index.push(Entry {
            frame: self.written,
            step: world.steps(),
            time: world.time(),
        });
        let text = index_text(&self.index);
        for dir in self.dirs() {
            let path = dir.join(INDEX);
            std::fs::write(&path, &text)
                .map_err(|e| Failure::Runtime(format!("cannot write {}: {e}", path.display())))?;
        }
        self.written += 1;
        Ok(())
    }
}

/// The index file's text: a header line, then `frame,step,time` per frame, the time (s)
/// printed so that it reads back exactly.
fn index_text(entries: &[Entry]) -> String {
    let mut text = String::from("frame,step,time\n");
    for e in entries {
        text += &format!("{},{},{}\n", e.frame, e.step, e.time);
    }
    text
}

/// The entries of an index file written by [`index_text`]; none if there is no file.
fn read_index(path: &Path) -> Result<Vec<Entry>, Failure> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => {
            return Err(Failure::Runtime(format!(
                "cannot read {}: {e}",
                path.display()
            )));
        }
    };
    let bad =
        |n: usize| Failure::Input(format!("{} line {n}: not frame,step,time", path.display()));
    text.lines()
        .enumerate()
        .skip(1)
        .map(|(n, line)| {
            let mut fields = line.split(',');
            let mut next = || fields.next().ok_or_else(|| bad(n + 1));
            Ok(Entry {
                frame: next()?.parse().map_err(|_| bad(n + 1))?,
                step: next()?.parse().map_err(|_| bad(n + 1))?,
                time: next()?.parse().map_err(|_| bad(n + 1))?,
            })
        })
        .collect()
}
