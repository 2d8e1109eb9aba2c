//! `projfluid validate`: the Martin & Moyce dam break against the 1952 measurements, and a
//! tank at rest against hydrostatics. Prints a table and writes CSV and PNG files.

use crate::{Failure, solver_parser};
use clap::{Args, Subcommand};
use projfluid::{Error, SolverKind};
use projfluid_lab::validation::reference::Measurements;
use projfluid_lab::validation::{hydrostatic, martin_moyce};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Which validation to run.
#[derive(Subcommand)]
pub(crate) enum ValidateCommand {
    /// Column collapse (Martin & Moyce 1952): surge front and residual height against the
    /// measurements.
    MartinMoyce(MartinMoyceArgs),
    /// A tank of water at rest: compression, residual motion, height and pressure profile.
    Hydrostatic(HydrostaticArgs),
}

/// Options every validation takes.
#[derive(Args)]
pub(crate) struct CommonArgs {
    /// Global solver.
    #[arg(long, value_parser = solver_parser(), default_value = "chebyshev")]
    solver: SolverKind,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N", default_value_t = 0)]
    threads: usize,
    /// Directory for the CSV and PNG files, created if missing.
    #[arg(long, value_name = "DIR", default_value = "validation")]
    out: PathBuf,
}

/// Options of `projfluid validate martin-moyce`.
#[derive(Args)]
pub(crate) struct MartinMoyceArgs {
    /// Column height/width ratio n²: 2 (height 2a) or 1 (square column).
    #[arg(long, value_name = "N2", default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=2))]
    n2: u32,
    /// Particles across the column width a (4–200).
    #[arg(long, value_name = "N", default_value_t = 20)]
    resolution: usize,
    /// Slab thickness in particles, between the two side walls.
    #[arg(long, value_name = "N", default_value_t = 4)]
    layers: usize,
    /// Dimensionless duration tau = t·√(g/a) [default: 3.0 for n² = 2, 3.5 for n² = 1].
    #[arg(long, value_name = "TAU", allow_negative_numbers = true)]
    duration: Option<f64>,
    #[command(flatten)]
    common: CommonArgs,
}

/// Options of `projfluid validate hydrostatic`.
#[derive(Args)]
pub(crate) struct HydrostaticArgs {
    /// Fluid lattice in particles, x,y,z (y up).
    #[arg(
        long,
        value_name = "NX,NY,NZ",
        default_value = "12,16,12",
        value_delimiter = ','
    )]
    count: Vec<usize>,
    /// Relaxation before the measured run, in seconds: the lattice is stepped with damped
    /// velocities to find its equilibrium packing (0 releases the lattice as built).
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 10.0,
        allow_negative_numbers = true
    )]
    relax: f64,
    /// Velocity damping rate of the relaxation, in 1/s.
    #[arg(
        long,
        value_name = "RATE",
        default_value_t = 4.0,
        allow_negative_numbers = true
    )]
    damping: f64,
    /// Free settling time after the relaxation, in seconds.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 2.0,
        allow_negative_numbers = true
    )]
    settle: f64,
    /// Solver settings: `calm` (uniform weighting, γ = 0.5, ρ = 0.99, τ = 3e-4·r) or the
    /// library's `default` ones.
    #[arg(long, value_name = "NAME", default_value = "calm", value_parser = ["calm", "default"])]
    settings: String,
    /// Outer stopping threshold τ in metres [default: that of --settings].
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    tau: Option<f64>,
    /// τ of the pressure reading after the free run, in metres [default: 1e-5·r].
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    reading_tau: Option<f64>,
    #[command(flatten)]
    common: CommonArgs,
}

/// `projfluid validate …`.
pub(crate) fn validate(command: &ValidateCommand) -> Result<(), Failure> {
    match command {
        ValidateCommand::MartinMoyce(args) => martin_moyce(args),
        ValidateCommand::Hydrostatic(args) => hydrostatic(args),
    }
}

/// An invalid setup is the user's input (exit 2); anything else is a runtime failure (exit 1).
fn input(e: Error) -> Failure {
    Failure::Input(e.to_string())
}

fn runtime(e: Error) -> Failure {
    Failure::Runtime(e.to_string())
}

fn create_dir(dir: &Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::Runtime(format!(
            "cannot create output directory {}: {e}",
            dir.display()
        ))
    })
}

fn print(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| Failure::Runtime(format!("cannot write to stdout: {e}")))
}

fn martin_moyce(args: &MartinMoyceArgs) -> Result<(), Failure> {
    let mut setup = martin_moyce::Setup::new(args.n2);
    setup.particles_across = args.resolution;
    setup.layers = args.layers;
    setup.solver = args.common.solver;
    setup.threads = args.common.threads;
    if let Some(d) = args.duration {
        setup.duration = d;
    }
    setup.validate().map_err(|e| match e {
        Error::InvalidArgument { field, message } => {
            Failure::Input(message.replacen(&field, &format!("--{field}"), 1))
        }
        other => input(other),
    })?;
    let data = Measurements::for_ratio(args.n2).map_err(runtime)?;
    create_dir(&args.common.out)?;
    let (a, d) = (
        projfluid_lab::validation::reference::COLUMN_WIDTH,
        setup.spacing(),
    );
    eprintln!(
        "martin-moyce: n² = {}, a = {a} m, {} particles across a (d = {:.2} mm), {} layers, \
         tank {:.1}a long, tau up to {}, {} solver",
        setup.n2,
        setup.particles_across,
        d * 1e3,
        setup.layers,
        setup.tank_length(),
        setup.duration,
        setup.solver.name()
    );
    let clock = Instant::now();
    let run = martin_moyce::simulate(&setup, |_| {}).map_err(runtime)?;
    let cmp = martin_moyce::compare(&run, &data).map_err(input)?;
    let files = martin_moyce::write_report(&args.common.out, &run, &data, &cmp).map_err(runtime)?;
    let mut text = format!(
        "{} fluid particles, {} boundary particles, {} steps in {:.1} s; max compression {:.3} %, \
         {} escaped\n",
        run.particles,
        run.boundary_particles,
        run.samples.len() - 1,
        clock.elapsed().as_secs_f64(),
        100.0 * run.density_error_max(),
        run.escaped
    );
    text += &cmp.table(args.n2);
    text += &format!(
        "\nworst |error|: front {:.1} %, residual height {:.1} %\nwrote {}, {}, {}, {}\n",
        100.0 * martin_moyce::Comparison::worst(&cmp.front),
        100.0 * martin_moyce::Comparison::worst(&cmp.height),
        files.series_csv.display(),
        files.comparison_csv.display(),
        files.front_png.display(),
        files.height_png.display()
    );
    print(&text)
}

fn hydrostatic(args: &HydrostaticArgs) -> Result<(), Failure> {
    let mut setup = hydrostatic::Setup {
        solver: args.common.solver,
        threads: args.common.threads,
        relax: args.relax,
        damping: args.damping,
        settle: args.settle,
        calm: args.settings == "calm",
        tolerance: args.tau,
        reading_tolerance: args.reading_tau,
        ..hydrostatic::Setup::default()
    };
    setup.count = match args.count[..] {
        [x, y, z] => [x, y, z],
        _ => {
            let given = format!("{:?}", args.count);
            return Err(input(Error::invalid(
                "--count",
                given,
                "must be three numbers NX,NY,NZ",
            )));
        }
    };
    setup.validate().map_err(|e| match e {
        Error::InvalidArgument { field, message } => {
            Failure::Input(message.replacen(&field, &format!("--{field}"), 1))
        }
        other => input(other),
    })?;
    create_dir(&args.common.out)?;
    let report = hydrostatic::simulate(&setup, |_| {}).map_err(runtime)?;
    let files = hydrostatic::write_report(&args.common.out, &report).map_err(runtime)?;
    let text = format!(
        "{}\nwrote {}, {}\n",
        report.text(),
        files.profile_csv.display(),
        files.pressure_png.display()
    );
    print(&text)
}
