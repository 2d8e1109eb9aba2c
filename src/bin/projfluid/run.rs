//! `projfluid run`: one scene, with progress, frames and a summary.

use crate::{Failure, RhoArg, rho_parser, solver_parser};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use projfluid::driver::{self, RunError, RunLength, StepReport};
use projfluid::io::write_vtk;
use projfluid::scene::Scene;
use projfluid::stats::RunSummary;
use projfluid::{Error, SolverKind, World};
use std::fs::File;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

/// Options of `projfluid run`; each given option replaces the scene's setting.
#[derive(Args)]
pub(crate) struct RunArgs {
    /// A built-in scene name (see `projfluid scenes`) or the path of a JSON scene file.
    scene: String,
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
    /// Global solver (the README's "Command line" section describes each).
    #[arg(long, value_parser = solver_parser())]
    solver: Option<SolverKind>,
    #[command(flatten)]
    params: ParamOptions,
    /// Write VTK frames (frame_00000.vtk, …) into this directory, created if missing.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Write a frame every N steps (and the initial state as frame 0).
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
    let mut scene = Scene::resolve(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
    let target = apply_overrides(&mut scene, args)?;
    let mut world = scene
        .build_world()
        .map_err(|e| Failure::Input(e.to_string()))?;
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
    let mut frames = match &scene.output.dir {
        Some(dir) => Some(Frames::new(dir, scene.output.every)?),
        None => None,
    };
    if let Some(f) = frames.as_mut() {
        f.write(&world)?;
    }
    let goal = match target {
        RunLength::Duration(d) => format!("{d} s simulated"),
        RunLength::Steps(n) => format!("{n} steps"),
    };
    eprintln!(
        "{}: {} particles, {} boundary particles, {} solver, {goal}",
        scene.name,
        world.fluid_count(),
        world.boundary_count(),
        scene.params.solver.name()
    );
    let mut progress = Progress::new(target);
    let acc = driver::run(&mut world, target, |report| {
        if let Some(f) = frames.as_mut() {
            if report.steps % f.every as u64 == 0 {
                f.write(report.world)?;
            }
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

/// Writes numbered VTK frames into a directory.
struct Frames {
    dir: PathBuf,
    every: usize,
    written: usize,
}

impl Frames {
    /// Creates `dir` if needed.
    fn new(dir: &Path, every: usize) -> Result<Self, Failure> {
        std::fs::create_dir_all(dir).map_err(|e| {
            Failure::Runtime(format!(
                "cannot create output directory {}: {e}",
                dir.display()
            ))
        })?;
        Ok(Self {
            dir: dir.to_path_buf(),
            every,
            written: 0,
        })
    }

    /// Writes the world's current state as the next frame.
    fn write(&mut self, world: &World) -> Result<(), Failure> {
        let path = self.dir.join(format!("frame_{:05}.vtk", self.written));
        write_vtk(
            &path,
            &world.positions(),
            &world.velocities(),
            &world.densities(),
        )
        .map_err(|e| Failure::Runtime(e.to_string()))?;
        self.written += 1;
        Ok(())
    }
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
