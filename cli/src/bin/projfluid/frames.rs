//! Numbered outputs of a run: data frames (VTK XML, legacy VTK or PLY) and PNG pictures,
//! written at the start and then every N steps or at every multiple of 1/fps seconds, each
//! carrying its simulated time; beside them `frames.csv` lists every frame's number, step and
//! time, and with VTK XML frames `frames.pvd` lists the frames at their times for ParaView.

use crate::Failure;
use projfluid::World;
use projfluid::io::{
    Frame, PvdDataSet, VtkEncoding, write_atomically, write_ply, write_pvd, write_vtk_encoded,
    write_vtp,
};
use projfluid_lab::render::Renderer;
use std::path::{Path, PathBuf};

/// File format of the data frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum FrameFormat {
    /// VTK XML polydata with a frames.pvd time series (ParaView, VisIt).
    Vtp,
    /// Legacy VTK polydata (ParaView, VisIt).
    Vtk,
    /// Legacy VTK polydata as text (larger; readable by any tool).
    VtkAscii,
    /// Binary PLY point cloud (Blender, MeshLab).
    Ply,
}

/// The name of the index written beside the frames.
const INDEX: &str = "frames.csv";

/// The name of the collection written beside VTK XML frames.
const COLLECTION: &str = "frames.pvd";

impl FrameFormat {
    /// The extension of its files.
    fn extension(self) -> &'static str {
        match self {
            FrameFormat::Vtp => "vtp",
            FrameFormat::Vtk | FrameFormat::VtkAscii => "vtk",
            FrameFormat::Ply => "ply",
        }
    }
}

/// The name of frame `frame`'s files, without extension.
fn frame_name(frame: usize) -> String {
    format!("frame_{frame:05}")
}

/// The name of frame `frame`'s VTK XML file.
fn vtp_file(frame: usize) -> String {
    format!("{}.{}", frame_name(frame), FrameFormat::Vtp.extension())
}

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
    /// The frames that `frames.pvd` lists: with VTK XML frames, those of `index` whose file
    /// exists (a resumed run may continue one whose frames had another format).
    collection: Vec<Entry>,
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
            collection: Vec::new(),
        })
    }

    /// Numbers the next frame `index + 1`, as when frames 0..=index were written by an
    /// earlier run that this one continues; the earlier run's index rows up to that frame
    /// are kept, and so are the collection's entries of those frames whose VTK XML file
    /// is there.
    pub(crate) fn continue_after(&mut self, index: u64) -> Result<(), Failure> {
        self.written = index as usize + 1;
        let dir = self.dirs().next().map(Path::to_path_buf);
        if let Some(dir) = dir {
            self.index = read_index(&dir.join(INDEX))?
                .into_iter()
                .filter(|e| e.frame < self.written)
                .collect();
        }
        if let Some((dir, FrameFormat::Vtp)) = &self.data {
            let exists = |e: &&Entry| dir.join(vtp_file(e.frame)).is_file();
            self.collection = self.index.iter().filter(exists).copied().collect();
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
        let name = frame_name(self.written);
        if let Some((dir, format)) = &self.data {
            let (x, v, rho) = (world.positions(), world.velocities(), world.densities());
            // Each particle's liquid, where the world has several.
            let materials = if world.material_count() > 1 {
                world.particle_materials()
            } else {
                Vec::new()
            };
            let frame = Frame::new(world.time(), &x, &v, &rho).with_materials(&materials);
            let path = dir.join(format!("{name}.{}", format.extension()));
            match format {
                FrameFormat::Vtp => write_vtp(&path, &frame),
                FrameFormat::Vtk => write_vtk_encoded(&path, VtkEncoding::Binary, &frame),
                FrameFormat::VtkAscii => write_vtk_encoded(&path, VtkEncoding::Ascii, &frame),
                FrameFormat::Ply => write_ply(&path, &frame),
            }
            .map_err(|e| Failure::Runtime(e.to_string()))?;
        }
        if let Some((dir, renderer)) = &self.pictures {
            renderer
                .render_world(world)
                .write_png(&dir.join(format!("{name}.png")))
                .map_err(|e| Failure::Runtime(e.to_string()))?;
        }
        let entry = Entry {
            frame: self.written,
            step: world.steps(),
            time: world.time(),
        };
        self.index.push(entry);
        // Index and collection are replaced whole, so that a run stopped at any point
        // leaves them readable, and a resumed run can continue them.
        let text = index_text(&self.index);
        let runtime = |e: projfluid::Error| Failure::Runtime(e.to_string());
        for dir in self.dirs() {
            write_atomically(&dir.join(INDEX), text.as_bytes()).map_err(runtime)?;
        }
        if let Some((dir, FrameFormat::Vtp)) = &self.data {
            self.collection.push(entry);
            write_pvd(&dir.join(COLLECTION), &collection(&self.collection)).map_err(runtime)?;
        }
        self.written += 1;
        Ok(())
    }
}

/// The collection's entries for VTK XML `frames`: each frame's file, beside the
/// collection, at its simulated time.
fn collection(frames: &[Entry]) -> Vec<PvdDataSet> {
    let dataset = |e: &Entry| PvdDataSet {
        time: e.time,
        file: vtp_file(e.frame),
    };
    frames.iter().map(dataset).collect()
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
