//! `projfluid run`: one scene, with progress, frames and a summary.
//!
//! The solver options shared with other subcommands, the progress display and the printed
//! summary live in submodules.

mod options;
mod print;
mod progress;

pub(crate) use options::ParamOptions;

use crate::Failure;
use crate::frames::{FrameFormat, Frames};
use crate::probes::ProbeLog;
use crate::solver_parser;
use clap::Args;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use options::validate_naming_options;
use print::print_summary;
use progress::Progress;
use projfluid::checkpoint::{RunEnd, read_checkpoint, write_checkpoint};
use projfluid::scene::{Scene, load_probes};
use projfluid::{Backend, Error, SolverKind};
use projfluid_lab::driver::{self, RunError, RunLength};
use projfluid_lab::validation::hydrostatic::READING_TOLERANCE_PER_RADIUS;
use std::fs::File;
use std::io::Write;
use std::path::PathBuf;

/// Options of `projfluid run`; each given option replaces the scene's setting.
#[derive(Args)]
pub(crate) struct RunArgs {
    /// A built-in scene name (see `projfluid scenes`) or the path of a JSON scene file.
    #[arg(required_unless_present = "resume", conflicts_with = "resume")]
    scene: Option<String>,
    /// Continue the run saved in this checkpoint file, bit for bit, to the end it was going
    /// to (or for --steps/--duration more).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["solver", "rho", "eta", "tau"])]
    resume: Option<PathBuf>,
    /// Write a checkpoint (checkpoint_NNNNNN.pfck, NNNNNN the step count) every N steps.
    #[arg(long, value_name = "N")]
    checkpoint_every: Option<u64>,
    /// Directory for checkpoints, created if missing.
    #[arg(long, value_name = "DIR", default_value = "checkpoints")]
    checkpoint_dir: PathBuf,
    /// Simulated time to run, in seconds [default: the scene's duration].
    #[arg(
        long,
        value_name = "SECONDS",
        conflicts_with = "steps",
        allow_negative_numbers = true
    )]
    duration: Option<f64>,
    /// Number of time steps to run, instead of a duration.
    #[arg(long, value_name = "N")]
    steps: Option<u64>,
    /// Global solver (docs/solvers.md describes each).
    #[arg(long, value_parser = solver_parser())]
    solver: Option<SolverKind>,
    #[command(flatten)]
    params: ParamOptions,
    /// Where the steps run: `cpu`, or `gpu` (Vulkan; in a build with the `gpu` feature:
    /// `cargo run --release --features gpu -- run …`) [default: the scene's `backend`, else
    /// cpu]. There is no fallback: a GPU that cannot be had, or a scene it does not step yet,
    /// is an error naming what is missing.
    #[arg(long, value_name = "cpu|gpu", value_parser = backend_parser())]
    backend: Option<Backend>,
    /// Write data frames (frame_00000.vtp, .vtk or .ply, …) into this directory, created if
    /// missing.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// File format of the data frames: VTK XML with a frames.pvd time series (ParaView,
    /// VisIt), legacy VTK, or binary PLY (Blender, MeshLab).
    #[arg(long, value_enum, default_value_t = FrameFormat::Vtp)]
    format: FrameFormat,
    /// Write PNG pictures (frame_00000.png, …) into this directory, created if missing.
    #[arg(long, value_name = "DIR")]
    png: Option<PathBuf>,
    /// Width of the PNG pictures in pixels (the height is 9/16 of it).
    #[arg(long, value_name = "PIXELS", default_value_t = 640)]
    png_width: usize,
    /// Write a frame (and picture) every N steps, and the initial state as frame 0.
    #[arg(long, value_name = "N", conflicts_with = "fps")]
    every: Option<usize>,
    /// Write a frame (and picture) at every multiple of 1/N seconds of simulated time,
    /// shortening the step before each to land on it, instead of every N steps.
    #[arg(long, value_name = "N")]
    fps: Option<f64>,
    /// Read the probes in this JSON file (the value of a scene's `probes` key, replacing it)
    /// into probes.csv in the output directory.
    #[arg(long, value_name = "FILE")]
    probes: Option<PathBuf>,
    /// Write the run summary as JSON to this file.
    #[arg(long, value_name = "FILE")]
    stats: Option<PathBuf>,
}

/// `projfluid run`.
pub(crate) fn run(args: &RunArgs) -> Result<(), Failure> {
    let (mut scene, resumed, saved_end) = match (&args.resume, &args.scene) {
        (Some(path), _) => {
            let c = read_checkpoint(path, args.params.threads)
                .map_err(|e| Failure::Input(e.to_string()))?;
            (c.scene, Some(c.world), c.run_end)
        }
        (None, Some(name)) => {
            let scene = Scene::resolve(name).map_err(|e| Failure::Input(e.to_string()))?;
            (scene, None, None)
        }
        (None, None) => return Err(Failure::Input("a scene or --resume FILE is needed".into())),
    };
    // Overrides first: a fresh world is built with them (a resumed one keeps its own).
    let mut target = apply_overrides(&mut scene, args)?;
    let mut world = match resumed {
        Some(world) => world,
        None => scene
            .build_world()
            .map_err(|e| Failure::Input(e.to_string()))?,
    };
    // A fresh world is made on the scene's backend; a resumed one on its checkpoint's,
    // which --backend may change.
    if world.backend() != scene.params.backend {
        world
            .set_backend(scene.params.backend)
            .map_err(|e| Failure::Input(e.to_string()))?;
    }
    if args.resume.is_some() && args.steps.is_none() && args.duration.is_none() {
        target = match saved_end {
            Some(RunEnd::Steps(n)) => RunLength::Steps(n.saturating_sub(world.steps())),
            Some(RunEnd::Time(t)) => RunLength::Duration(t - world.time()),
            None => {
                return Err(Failure::Input(
                    "the checkpoint does not say where its run ends; give --steps or --duration"
                        .into(),
                ));
            }
        };
    }
    // Where this run ends, in absolute terms (saved in checkpoints).
    let (start_time, start_steps) = (world.time(), world.steps());
    let run_end = match target {
        RunLength::Duration(d) => RunEnd::Time(match saved_end {
            Some(RunEnd::Time(t)) if args.duration.is_none() && args.resume.is_some() => t,
            _ => start_time + d,
        }),
        RunLength::Steps(n) => RunEnd::Steps(start_steps + n),
        RunLength::UntilStep(_) | RunLength::UntilTime(_) => {
            unreachable!("apply_overrides gives a relative length")
        }
    };
    if args.checkpoint_every == Some(0) {
        return Err(Failure::Input(
            Error::invalid("--checkpoint-every", 0, "must be at least 1").to_string(),
        ));
    }
    if args.checkpoint_every.is_some() {
        std::fs::create_dir_all(&args.checkpoint_dir).map_err(|e| {
            Failure::Runtime(format!(
                "cannot create checkpoint directory {}: {e}",
                args.checkpoint_dir.display()
            ))
        })?;
    }
    // Open the stats file first, so that an unwritable path fails before a long run.
    let stats_file = match &args.stats {
        Some(path) => Some((
            File::create(path).map_err(|e| {
                Failure::Runtime(format!("cannot write stats file {}: {e}", path.display()))
            })?,
            path,
        )),
        None => None,
    };
    let (every, fps) = (scene.output.every as u64, scene.output.fps);
    let mut frames = Frames::new(
        scene.output.dir.as_deref(),
        args.format,
        args.png.as_deref().map(|dir| (dir, args.png_width)),
        &world,
    )?;
    let mut probes = match (&scene.probes, &scene.output.dir) {
        (Some(probes), Some(dir)) if args.resume.is_some() => {
            Some(ProbeLog::resume(dir, probes.clone(), &world)?)
        }
        (Some(probes), Some(dir)) => {
            let mut log = ProbeLog::create(dir, probes.clone())?;
            log.record(&world)?;
            Some(log)
        }
        _ => None,
    };
    if args.resume.is_some() {
        // Frame k holds step k·every, or time k/fps; the frames up to now were written before.
        let last = match fps {
            Some(fps) => (world.time() * fps + 1e-6).floor() as u64,
            None => world.steps() / every,
        };
        frames.continue_after(last)?;
    } else {
        frames.write(&world)?;
    }
    let goal = match target {
        RunLength::Duration(d) => format!("{d} s simulated"),
        RunLength::Steps(n) => format!("{n} steps"),
        RunLength::UntilStep(_) | RunLength::UntilTime(_) => String::new(),
    };
    // What the fluid blocks held that placement did not create (docs/method.md §2.7).
    let inside = match args.resume {
        Some(_) => 0,
        None => scene.particle_count().saturating_sub(world.fluid_count()),
    };
    let not_created = match inside {
        0 => String::new(),
        n => {
            format!(" ({n} of the fluid blocks' particles lay inside solids and were not created)")
        }
    };
    eprintln!(
        "{}: {} particles{not_created}, {} boundary particles, {} solver on the {}, {goal}",
        scene.name,
        world.fluid_count(),
        world.boundary_count(),
        scene.params.solver.name(),
        world.backend().name().to_uppercase()
    );
    warn_about_loose_pressure_readings(&scene, &world);
    let mut progress = Progress::new(target);
    let length = match run_end {
        RunEnd::Time(end) => RunLength::UntilTime(end),
        RunEnd::Steps(n) => RunLength::UntilStep(n),
    };
    // Steps land on the frame times and on the probes' reading times.
    let rates: Vec<f64> = fps
        .into_iter()
        .chain(scene.probes.as_ref().map(|p| p.rate))
        .collect();
    let acc = driver::run_landing(&mut world, length, &rates, |report| {
        let world = report.world;
        let due = match fps {
            Some(fps) => driver::frame_index(world.time(), fps).is_some(),
            None => world.steps() % every == 0,
        };
        if due {
            frames.write(world)?;
        }
        if let Some(log) = probes.as_mut().filter(|log| log.due(world)) {
            log.record(world)?;
        }
        if let Some(n) = args.checkpoint_every
            && world.steps() % n == 0
        {
            let path = args
                .checkpoint_dir
                .join(format!("checkpoint_{:06}.pfck", world.steps()));
            write_checkpoint(&path, &scene, world, Some(run_end))
                .map_err(|e| Failure::Runtime(e.to_string()))?;
        }
        progress.update(report);
        Ok(())
    })
    .map_err(|e| match e {
        RunError::Step { step, error } => Failure::Runtime(format!("step {step} failed: {error}")),
        RunError::Callback(failure) => failure,
    })?;
    progress.finish();
    let summary = acc.summary(&scene.name, &world);
    print_summary(&summary)
        .map_err(|e| Failure::Runtime(format!("cannot write to stdout: {e}")))?;
    if summary.nan > 0 {
        eprintln!(
            "warning: {} particles have a non-finite position or velocity",
            summary.nan
        );
    }
    if let Some((mut file, path)) = stats_file {
        let json = serde_json::to_string_pretty(&summary)
            .map_err(|e| Failure::Runtime(format!("cannot encode statistics: {e}")))?;
        writeln!(file, "{json}").map_err(|e| {
            Failure::Runtime(format!("cannot write stats file {}: {e}", path.display()))
        })?;
    }
    Ok(())
}

/// `--backend`'s values, `cpu` and `gpu`.
fn backend_parser() -> impl TypedValueParser<Value = Backend> {
    PossibleValuesParser::new(Backend::NAMES).try_map(|name| {
        Backend::from_name(&name).ok_or_else(|| format!("unknown backend `{name}`"))
    })
}

/// Applies the command-line overrides to `scene` and checks the result; errors name the option.
fn apply_overrides(scene: &mut Scene, args: &RunArgs) -> Result<RunLength, Failure> {
    if let Some(s) = args.solver {
        scene.params.solver = s;
    }
    if let Some(b) = args.backend {
        scene.params.backend = b;
    }
    args.params.apply(scene);
    if let Some(every) = args.every {
        scene.output.every = every;
        scene.output.fps = None;
    }
    if let Some(fps) = args.fps {
        scene.output.fps = Some(fps);
    }
    if let Some(dir) = &args.out {
        scene.output.dir = Some(dir.clone());
    }
    if let Some(d) = args.duration {
        scene.duration = d;
    }
    if let Some(path) = &args.probes {
        scene.probes = Some(load_probes(path).map_err(|e| Failure::Input(e.to_string()))?);
    }
    if !(16..=8192).contains(&args.png_width) {
        return Err(Failure::Input(
            Error::invalid(
                "--png-width",
                args.png_width,
                "must lie in 16..=8192 pixels",
            )
            .to_string(),
        ));
    }
    if args.steps == Some(0) {
        return Err(Failure::Input(
            Error::invalid("--steps", 0, "must be at least 1").to_string(),
        ));
    }
    let mut options = args.params.keys().to_vec();
    options.extend([
        ("output.every", "--every", args.every.is_some()),
        ("output.fps", "--fps", args.fps.is_some()),
        ("duration", "--duration", args.duration.is_some()),
    ]);
    validate_naming_options(scene, &options)?;
    if scene.probes.is_some() && scene.output.dir.is_none() {
        return Err(Failure::Input(
            "the probes' readings go to probes.csv in the output directory: give output.dir \
             or --out"
                .into(),
        ));
    }
    Ok(match args.steps {
        Some(n) => RunLength::Steps(n),
        None => RunLength::Duration(scene.duration),
    })
}

/// Pressure probes read the constraint forces of each step (docs/method.md §10.3). With the
/// density rule on, a step ends as soon as the compression is small and single readings
/// scatter; where the last step cannot carry its forces (the warm start, the coarse
/// correction) they are read from a local step, which also needs a tight τ. Says so on
/// stderr when a run with pressure probes is solved more loosely than that.
fn warn_about_loose_pressure_readings(scene: &Scene, world: &projfluid::World) {
    if scene.probes.as_ref().is_none_or(|p| p.pressure.is_empty()) {
        return;
    }
    let p = world.params();
    let carried = p.warm_start == 0.0 && !p.coarse_correction;
    let tight = READING_TOLERANCE_PER_RADIUS * p.particle_radius;
    let loose_tau = !carried && p.displacement_tolerance > tight * (1.0 + 1e-9);
    if p.density_tolerance > 0.0 || loose_tau {
        let tau = if carried {
            String::new()
        } else {
            format!(" and solver.tau at most {tight:.2e} m (this run cannot carry them)")
        };
        eprintln!(
            "warning: the pressure probes read the constraint forces, which are accurate only \
             with solver.eta 0{tau} (this run: eta {}, tau {:.2e} m); see docs/method.md §10.3",
            p.density_tolerance, p.displacement_tolerance
        );
    }
}
