//! `projfluid run`: one scene, with progress, frames and a summary.

use crate::frames::{FrameFormat, Frames};
use crate::{Failure, RhoArg, rho_parser, solver_parser};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use projfluid::checkpoint::{RunEnd, read_checkpoint, write_checkpoint};
use projfluid::scene::Scene;
use projfluid::{Error, SolverKind};
use projfluid_lab::driver::{self, RunError, RunLength, StepReport};
use projfluid_lab::summary::RunSummary;
use std::fs::File;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;

/// Options of `projfluid run`; each given option replaces the scene's setting.
#[derive(Args)]
pub(crate) struct RunArgs {
    /// A built-in scene name (see `projfluid scenes`) or the path of a JSON scene file.
    #[arg(required_unless_present = "resume", conflicts_with = "resume")]
    scene: Option<String>,
    /// Continue the run saved in this checkpoint file, bit for bit, to the end it was going
    /// to (or for --steps/--duration more).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["solver", "rho", "tau"])]
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
    /// Write data frames (frame_00000.vtk or .ply, …) into this directory, created if missing.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// File format of the data frames: VTK (ParaView) or binary PLY (Blender, MeshLab).
    #[arg(long, value_enum, default_value_t = FrameFormat::Vtk)]
    format: FrameFormat,
    /// Write PNG pictures (frame_00000.png, …) into this directory, created if missing.
    #[arg(long, value_name = "DIR")]
    png: Option<PathBuf>,
    /// Width of the PNG pictures in pixels (the height is 9/16 of it).
    #[arg(long, value_name = "PIXELS", default_value_t = 640)]
    png_width: usize,
    /// Write a frame (and picture) every N steps, and the initial state as frame 0.
    #[arg(long, value_name = "N")]
    every: Option<usize>,
    /// Write the run summary as JSON to this file.
    #[arg(long, value_name = "FILE")]
    stats: Option<PathBuf>,
}

/// Solver settings that every subcommand running scenes accepts; each given option replaces
/// the scene's setting.
#[derive(Args)]
pub(crate) struct ParamOptions {
    /// Chebyshev spectral radius estimate ρ_c, in [0, 1), or `auto` to estimate it online.
    #[arg(long, value_name = "R|auto", allow_negative_numbers = true, value_parser = rho_parser)]
    pub(crate) rho: Option<RhoArg>,
    /// Outer stopping threshold τ, in metres (stop when no particle moves farther).
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    pub(crate) tau: Option<f64>,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N")]
    pub(crate) threads: Option<usize>,
}

impl ParamOptions {
    /// Sets the given options in `scene.params`.
    fn apply(&self, scene: &mut Scene) {
        let p = &mut scene.params;
        if let Some(rho) = self.rho {
            rho.apply(&mut p.chebyshev);
        }
        if let Some(tau) = self.tau {
            p.displacement_tolerance = tau;
        }
        if let Some(threads) = self.threads {
            p.threads = threads;
        }
    }

    /// Which scene key each option sets, and whether it was given.
    fn keys(&self) -> [(&'static str, &'static str, bool); 3] {
        [
            ("solver.rho", "--rho", self.rho.is_some()),
            ("solver.tau", "--tau", self.tau.is_some()),
            ("threads", "--threads", self.threads.is_some()),
        ]
    }

    /// Applies the options to `scene` and validates it; an error caused by an option names
    /// the option instead of the scene key.
    pub(crate) fn apply_checked(&self, scene: &mut Scene) -> Result<(), Failure> {
        self.apply(scene);
        validate_naming_options(scene, &self.keys())
    }
}

/// Validates `scene`; when the error is about a scene key set by a given option (key, option,
/// given), the message names the option.
fn validate_naming_options(scene: &Scene, options: &[(&str, &str, bool)]) -> Result<(), Failure> {
    scene.validate().map_err(|e| {
        let msg = e.to_string();
        if let Error::InvalidArgument { field, .. } = &e {
            for &(key, option, given) in options {
                if given && field == key {
                    return Failure::Input(msg.replacen(key, option, 1));
                }
            }
        }
        Failure::Input(msg)
    })
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
    let every = scene.output.every as u64;
    let mut frames = Frames::new(
        scene.output.dir.as_deref(),
        args.format,
        args.png.as_deref().map(|dir| (dir, args.png_width)),
        &world,
    )?;
    if args.resume.is_some() {
        // Frame k holds step k·every; the frames up to now were written before.
        frames.continue_after(world.steps() / every);
    } else {
        frames.write(&world)?;
    }
    let goal = match target {
        RunLength::Duration(d) => format!("{d} s simulated"),
        RunLength::Steps(n) => format!("{n} steps"),
        RunLength::UntilStep(_) | RunLength::UntilTime(_) => String::new(),
    };
    eprintln!(
        "{}: {} particles, {} boundary particles, {} solver, {goal}",
        scene.name,
        world.fluid_count(),
        world.boundary_count(),
        scene.params.solver.name()
    );
    let mut progress = Progress::new(target);
    let length = match run_end {
        RunEnd::Time(end) => RunLength::UntilTime(end),
        RunEnd::Steps(n) => RunLength::UntilStep(n),
    };
    let acc = driver::run(&mut world, length, |report| {
        let world = report.world;
        if world.steps() % every == 0 {
            frames.write(world)?;
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

/// Applies the command-line overrides to `scene` and checks the result; errors name the option.
fn apply_overrides(scene: &mut Scene, args: &RunArgs) -> Result<RunLength, Failure> {
    if let Some(s) = args.solver {
        scene.params.solver = s;
    }
    args.params.apply(scene);
    if let Some(every) = args.every {
        scene.output.every = every;
    }
    if let Some(dir) = &args.out {
        scene.output.dir = Some(dir.clone());
    }
    if let Some(d) = args.duration {
        scene.duration = d;
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
        ("duration", "--duration", args.duration.is_some()),
    ]);
    validate_naming_options(scene, &options)?;
    Ok(match args.steps {
        Some(n) => RunLength::Steps(n),
        None => RunLength::Duration(scene.duration),
    })
}

/// Progress on stderr: a bar on a terminal, else a line about every 10 % of the run.
struct Progress {
    bar: Option<ProgressBar>,
    next_tenth: u32,
    steps: u64,
    wall: f64,
    outer: u64,
}

impl Progress {
    fn new(target: RunLength) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
            let style = ProgressStyle::with_template(
                "{bar:20.cyan/blue} {percent:>3}% {elapsed:>4} {wide_msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar());
            bar.set_style(style);
            if let RunLength::Steps(n) = target {
                bar.set_message(format!("0/{n} steps"));
            }
            bar
        });
        Self {
            bar,
            next_tenth: 1,
            steps: 0,
            wall: 0.0,
            outer: 0,
        }
    }

    /// Records a finished step.
    fn update(&mut self, report: &StepReport<'_>) {
        self.steps += 1;
        self.wall += report.wall_seconds;
        self.outer += report.stats.outer_iterations as u64;
        let n = self.steps as f64;
        let (t, ms, outer) = (
            report.world.time(),
            self.wall * 1e3 / n,
            self.outer as f64 / n,
        );
        let done = report.done;
        match &self.bar {
            Some(bar) => {
                bar.set_position((done * 1000.0).round() as u64);
                bar.set_message(format!(
                    "t={t:.3}s step {} {ms:.1} ms/step {outer:.1} outer it.",
                    self.steps
                ));
            }
            None if done * 10.0 >= f64::from(self.next_tenth) - 1e-9 => {
                eprintln!(
                    "{:>3.0}%  t = {t:.4} s, step {}, {ms:.1} ms/step, {outer:.1} outer iterations/step",
                    done * 100.0,
                    self.steps
                );
                while f64::from(self.next_tenth) <= done * 10.0 + 1e-9 {
                    self.next_tenth += 1;
                }
            }
            None => {}
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish();
        }
    }
}

/// The human-readable summary on stdout.
fn print_summary(s: &RunSummary) -> std::io::Result<()> {
    let rows = [
        ("scene", s.scene.clone()),
        (
            "solver",
            if s.rho_auto {
                format!(
                    "{} (rho auto, mean {:.3}; tau {:.3e} m)",
                    s.solver, s.rho, s.tau
                )
            } else {
                format!("{} (rho {}, tau {:.3e} m)", s.solver, s.rho, s.tau)
            },
        ),
        ("threads", s.threads.to_string()),
        ("particles", s.particles.to_string()),
        ("boundary particles", s.boundary_particles.to_string()),
        ("steps", s.steps.to_string()),
        ("simulated time", format!("{:.4} s", s.sim_time)),
        (
            "mean time per step",
            format!("{:.2} ms", s.wall_ms_per_step),
        ),
        (
            "mean outer iterations",
            format!("{:.2}", s.outer_iterations_mean),
        ),
        (
            "density error",
            format!(
                "avg {:.3} %, max {:.3} % (compression only)",
                s.density_error_avg_percent, s.density_error_max_percent
            ),
        ),
        ("escaped particles", s.escaped.to_string()),
        ("NaN particles", s.nan.to_string()),
    ];
    let mut out = std::io::stdout().lock();
    for (key, value) in rows {
        writeln!(out, "{key:<22} {value}")?;
    }
    out.flush()
}
