//! `projfluid`: runs a scene (built-in or JSON file) and reports how the solver did.
//!
//! ```text
//! projfluid run SCENE [--duration SECONDS | --steps N] [--solver chebyshev|jacobi1|jacobi|cg|cg1|ldlt]
//!                     [--rho R|auto] [--tau METRES] [--threads N] [--out DIR] [--every N] [--stats FILE]
//!                     [--format vtp|vtk|vtk-ascii|ply] [--png DIR] [--png-width PIXELS] [--probes FILE]
//!                     [--checkpoint-every N] [--checkpoint-dir DIR]
//! projfluid run --resume FILE [--steps N | --duration SECONDS] [output options]
//! projfluid scenes
//! projfluid validate martin-moyce [--n2 2|1] [--resolution N] [--layers N] [--duration TAU]
//!                                 [--coarse-correction on|off] [--solver S] [--threads N]
//!                                 [--out DIR]
//! projfluid validate hydrostatic [--count NX,NY,NZ] [--relax SECONDS] [--damping RATE]
//!                                [--settle SECONDS] [--settings calm|default] [--tau METRES]
//!                                [--reading-tau METRES] [--solver S] [--threads N] [--out DIR]
//! projfluid bench [--scenes A,B,…] [--solvers A,B,…] [--steps N] [--rho R] [--tau METRES]
//!                 [--threads N] [--out DIR]
//! projfluid tune-rho SCENE [--steps T] [--warmup N] [--from R] [--to R] [--step R]
//!                    [--tau METRES] [--threads N] [--out DIR]
//! projfluid probes SCENE --frames DIR [--fps N] [--out FILE] [--threads N]
//! ```
//!
//! Exit codes: 0 success, 1 runtime failure (e.g. output not writable), 2 bad input.
//! Each subcommand lives in its own module.

mod bench;
mod frames;
mod probes;
mod read_probes;
mod run;
mod tune_rho;
mod validate;

use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::{Parser, Subcommand};
use projfluid::SolverKind;
use projfluid::scene::Scene;
use std::io::Write;
use std::process::ExitCode;

/// Command line.
#[derive(Parser)]
#[command(
    name = "projfluid",
    version,
    about = "Projective-fluids SPH solver with Chebyshev acceleration"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Subcommands.
#[derive(Subcommand)]
enum Command {
    /// Run a scene and print a summary of the run.
    Run(Box<run::RunArgs>),
    /// List the built-in scenes.
    Scenes,
    /// Compare the solver with experiment and analytic solutions (writes CSV and PNG files).
    #[command(subcommand)]
    Validate(validate::ValidateCommand),
    /// Run scenes with several solvers and tabulate cost, accuracy and artifacts.
    Bench(bench::BenchArgs),
    /// Choose Chebyshev's ρ for a scene: estimate it, then sweep it.
    TuneRho(tune_rho::TuneRhoArgs),
    /// Read a scene's probes on frames written earlier (VTK XML or legacy VTK, by projfluid or
    /// another solver on the same geometry) and write their readings as CSV.
    Probes(read_probes::ProbesArgs),
}

/// Why the program stops early; decides the exit code.
pub(crate) enum Failure {
    /// Bad scene or option (exit 2).
    Input(String),
    /// The run itself failed, e.g. output could not be written (exit 1).
    Runtime(String),
}

/// `--solver`: one of [`SolverKind::NAMES`], shown as the possible values.
pub(crate) fn solver_parser() -> impl TypedValueParser<Value = SolverKind> {
    PossibleValuesParser::new(SolverKind::NAMES).try_map(|name| {
        SolverKind::from_name(&name).ok_or_else(|| format!("unknown solver `{name}`"))
    })
}

/// An `on|off` switch such as `--coarse-correction`: `on` is true, shown as the possible
/// values.
pub(crate) fn on_off_parser() -> impl TypedValueParser<Value = bool> {
    PossibleValuesParser::new(["on", "off"]).map(|value| value == "on")
}

/// A `--rho` value: a fixed ρ_c or `auto` (estimated online).
#[derive(Clone, Copy, Debug)]
pub(crate) enum RhoArg {
    /// Use this ρ_c throughout.
    Fixed(f64),
    /// Estimate ρ_c online.
    Auto,
}

impl RhoArg {
    /// Applies the choice to Chebyshev settings.
    pub(crate) fn apply(self, c: &mut projfluid::ChebyshevParams) {
        match self {
            RhoArg::Fixed(rho) => {
                c.rho = rho;
                c.auto_rho = false;
            }
            RhoArg::Auto => c.auto_rho = true,
        }
    }
}

/// `--rho`: a number or `auto`.
pub(crate) fn rho_parser(text: &str) -> Result<RhoArg, String> {
    if text == "auto" {
        return Ok(RhoArg::Auto);
    }
    text.parse::<f64>()
        .map(RhoArg::Fixed)
        .map_err(|_| format!("expected a number in [0, 1) or `auto`, got `{text}`"))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => run::run(&args),
        Command::Scenes => list_scenes(),
        Command::Validate(command) => validate::validate(&command),
        Command::Bench(args) => bench::bench(&args),
        Command::TuneRho(args) => tune_rho::tune_rho(&args),
        Command::Probes(args) => read_probes::read_probes(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(msg)) => {
            eprintln!("error: {msg}");
            ExitCode::from(2)
        }
        Err(Failure::Runtime(msg)) => {
            eprintln!("error: {msg}");
            ExitCode::from(1)
        }
    }
}

/// `projfluid scenes`: one line per built-in scene.
fn list_scenes() -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    for name in Scene::builtin_names() {
        if let Some(scene) = Scene::builtin(name) {
            let line = format!(
                "{name:<20} {:>8} particles  {:>5} s simulated\n",
                scene.particle_count(),
                scene.duration
            );
            out.write_all(line.as_bytes())
                .map_err(|e| Failure::Runtime(format!("cannot write to stdout: {e}")))?;
        }
    }
    Ok(())
}
