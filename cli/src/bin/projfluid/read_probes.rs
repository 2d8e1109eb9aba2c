//! `projfluid probes SCENE --frames DIR`: reads the scene's probes on frames written earlier,
//! by projfluid (VTK XML or legacy VTK) or by another solver on the same geometry (legacy
//! VTK), instead of during a run, and writes their readings in the layout of a run's
//! `probes.csv`.

use crate::Failure;
use crate::probes::{header, row};
use clap::Args;
use projfluid::scene::Scene;
use projfluid_lab::frames::{frame_files, read_frame_points};
use std::path::PathBuf;

/// Options of `projfluid probes`.
#[derive(Args)]
pub(crate) struct ProbesArgs {
    /// A built-in scene name (see `projfluid scenes`) or the path of a JSON scene file; its
    /// walls, obstacles and particle size are those of the frames, and its `probes` are read.
    scene: String,
    /// Directory of frames, VTK XML (`*.vtp`) or legacy VTK (`*.vtk`), taken in the order of
    /// the numbers in their names.
    #[arg(long, value_name = "DIR")]
    frames: PathBuf,
    /// Frames per simulated second, for frames without a time of their own: the k-th file
    /// (from 0) is at k/fps seconds. projfluid's frames carry their time.
    #[arg(long, value_name = "N")]
    fps: Option<f64>,
    /// The CSV file to write: `time_s`, then one column per probe, one row per frame.
    #[arg(long, value_name = "FILE", default_value = "probes.csv")]
    out: PathBuf,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N", default_value_t = 0)]
    threads: usize,
}

/// `projfluid probes`.
pub(crate) fn read_probes(args: &ProbesArgs) -> Result<(), Failure> {
    let input = |e: projfluid::Error| Failure::Input(e.to_string());
    let mut scene = Scene::resolve(&args.scene).map_err(input)?;
    let probes = scene
        .probes
        .clone()
        .ok_or_else(|| Failure::Input(format!("scene `{}` has no probes to read", args.scene)))?;
    if let Some(fps) = args.fps.filter(|f| !(f.is_finite() && *f > 0.0)) {
        return Err(Failure::Input(format!(
            "--fps must be a positive number, got {fps}"
        )));
    }
    if !probes.pressure.is_empty() {
        eprintln!(
            "warning: pressure probes need the solver's constraint forces and read NaN on frames"
        );
    }
    scene.params.threads = args.threads;
    let world = scene.build_world().map_err(input)?;
    let files = frame_files(&args.frames).map_err(input)?;
    let mut text = header(&probes);
    for (k, file) in files.iter().enumerate() {
        let frame = read_frame_points(file).map_err(input)?;
        let time = match (frame.time, args.fps) {
            (Some(time), _) => time,
            (None, Some(fps)) => k as f64 / fps,
            (None, None) => {
                return Err(Failure::Input(format!(
                    "{} has no time of its own: give --fps",
                    file.display()
                )));
            }
        };
        let reading = probes
            .read_frame(&world, &frame.positions, time)
            .map_err(|e| Failure::Input(format!("{}: {e}", file.display())))?;
        text += &row(&reading);
    }
    std::fs::write(&args.out, text)
        .map_err(|e| Failure::Runtime(format!("cannot write {}: {e}", args.out.display())))?;
    println!(
        "read {} probes on {} frames of {} into {}",
        probes.columns().len(),
        files.len(),
        args.frames.display(),
        args.out.display()
    );
    Ok(())
}
