//! `projfluid validate`: the Martin & Moyce dam break against the 1952 measurements, the
//! MARIN dam break past a box against Kleefsman et al. (2005), a tank at rest against
//! hydrostatics, viscous flow down a duct against its analytic profile, and two liquids at
//! rest and overturning, and a drop's capillary oscillation against Rayleigh's period.
//! Prints a table and writes CSV and PNG files.

use crate::{Failure, on_off_parser, solver_parser};
use clap::{Args, Subcommand};
use projfluid::scene::ContainerWalls;
use projfluid::{Error, SolverKind};
use projfluid_lab::validation::reference::Measurements;
use projfluid_lab::validation::{
    droplet, hydrostatic, kleefsman, martin_moyce, poiseuille, two_layers,
};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Which validation to run.
#[derive(Subcommand)]
pub(crate) enum ValidateCommand {
    /// Column collapse (Martin & Moyce 1952): surge front and residual height against the
    /// measurements.
    MartinMoyce(MartinMoyceArgs),
    /// Dam break past a box (Kleefsman et al. 2005, SPHERIC Test 2): water heights at the four
    /// gauges against the measurements.
    Kleefsman(KleefsmanArgs),
    /// A tank of water at rest: compression, residual motion, height and pressure profile.
    Hydrostatic(HydrostaticArgs),
    /// Viscous flow down a duct (Poiseuille flow driven by the weight): the speed across the
    /// duct against the analytic profile, at each viscosity.
    Poiseuille(PoiseuilleArgs),
    /// Two liquids: a lighter one over water at rest (the pressure against the two-slope
    /// hydrostatic profile), and water over the lighter one, which overturns.
    TwoLayers(TwoLayersArgs),
    /// A drop without gravity: a cube relaxes into a sphere under its surface tension, is
    /// kicked into its n = 2 mode, and its period is compared with Rayleigh's, at each σ.
    Droplet(DropletArgs),
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
    /// What the tank's walls are: `particles` (one layer r apart) or `field` (smooth, no
    /// particles).
    #[arg(long, value_name = "KIND", default_value = "particles", value_parser = ["particles", "field"])]
    walls: String,
    /// Directory for the CSV and PNG files, created if missing.
    #[arg(long, value_name = "DIR", default_value = "validation")]
    out: PathBuf,
}

impl CommonArgs {
    /// The walls `--walls` names.
    fn walls(&self) -> ContainerWalls {
        match self.walls.as_str() {
            "particles" => ContainerWalls::Particles,
            _ => ContainerWalls::Field,
        }
    }
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
    /// Start every step's outer iteration from the coarse correction (off by default, as in
    /// `projfluid run`).
    #[arg(long, value_name = "on|off", value_parser = on_off_parser())]
    coarse_correction: Option<bool>,
    #[command(flatten)]
    common: CommonArgs,
}

/// Options of `projfluid validate kleefsman`.
#[derive(Args)]
pub(crate) struct KleefsmanArgs {
    /// Particle radius r in metres (0.004–0.05); the lattice spacing is 2r.
    #[arg(
        long,
        value_name = "METRES",
        default_value_t = 0.0125,
        allow_negative_numbers = true
    )]
    radius: f64,
    /// Simulated time in seconds.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 2.0,
        allow_negative_numbers = true
    )]
    duration: f64,
    /// Leave the box out (a check that the comparison sees it).
    #[arg(long)]
    no_obstacle: bool,
    /// Magnitude of gravity in m/s².
    #[arg(
        long,
        value_name = "M/S2",
        default_value_t = 9.81,
        allow_negative_numbers = true
    )]
    gravity: f64,
    /// XSPH viscosity coefficient, in [0, 1] (0 = off).
    #[arg(
        long,
        value_name = "C",
        default_value_t = 0.01,
        allow_negative_numbers = true
    )]
    viscosity: f64,
    /// Outer stopping threshold τ in metres [default: 3e-3·r].
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    tau: Option<f64>,
    /// Start every step's outer iteration from the coarse correction (off by default, as in
    /// `projfluid run`).
    #[arg(long, value_name = "on|off", value_parser = on_off_parser())]
    coarse_correction: Option<bool>,
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

/// Options of `projfluid validate poiseuille`.
#[derive(Args)]
pub(crate) struct PoiseuilleArgs {
    /// Kinematic viscosities to run, in m²/s, comma-separated.
    #[arg(
        long,
        value_name = "NU,...",
        default_value = "0.01,0.1",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    viscosity: Vec<f64>,
    /// Particles across the duct's narrow side (4–64; the wide side holds 3/2 as many).
    #[arg(long, value_name = "N", default_value_t = 16)]
    resolution: usize,
    /// Simulated time per run, in seconds.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 0.1,
        allow_negative_numbers = true
    )]
    duration: f64,
    #[command(flatten)]
    common: CommonArgs,
}

/// Options of `projfluid validate droplet`.
#[derive(Args)]
pub(crate) struct DropletArgs {
    /// Surface tensions to run, in N/m, comma-separated.
    #[arg(
        long,
        value_name = "SIGMA,...",
        default_value = "0.0182,0.0728",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    surface_tension: Vec<f64>,
    /// Particles along the edge of the cube the drop starts as (6–48).
    #[arg(long, value_name = "N", default_value_t = 16)]
    resolution: usize,
    #[command(flatten)]
    common: CommonArgs,
}

/// Options of `projfluid validate two-layers`.
#[derive(Args)]
pub(crate) struct TwoLayersArgs {
    /// Particles across the tank at rest (6–40; see docs/validation.md for both tanks).
    #[arg(long, value_name = "N", default_value_t = 12)]
    resolution: usize,
    /// Rest density of the lighter liquid, in kg/m³ (the other is water, 1000).
    #[arg(
        long,
        value_name = "KG_M3",
        default_value_t = 800.0,
        allow_negative_numbers = true
    )]
    light_density: f64,
    /// Longest simulated time of the overturning run, in seconds.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 4.0,
        allow_negative_numbers = true
    )]
    duration: f64,
    #[command(flatten)]
    common: CommonArgs,
}

/// `projfluid validate …`.
pub(crate) fn validate(command: &ValidateCommand) -> Result<(), Failure> {
    match command {
        ValidateCommand::MartinMoyce(args) => martin_moyce(args),
        ValidateCommand::Kleefsman(args) => kleefsman(args),
        ValidateCommand::Hydrostatic(args) => hydrostatic(args),
        ValidateCommand::Poiseuille(args) => poiseuille(args),
        ValidateCommand::TwoLayers(args) => two_layers(args),
        ValidateCommand::Droplet(args) => droplet(args),
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
    setup.walls = args.common.walls();
    setup.coarse_correction = args.coarse_correction.unwrap_or(false);
    if let Some(d) = args.duration {
        setup.duration = d;
    }
    setup.validate().map_err(option_error)?;
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

/// An invalid field of a setup as the option that sets it.
fn option_error(e: Error) -> Failure {
    match e {
        Error::InvalidArgument { field, message } => {
            Failure::Input(message.replacen(&field, &format!("--{field}"), 1))
        }
        other => input(other),
    }
}

fn kleefsman(args: &KleefsmanArgs) -> Result<(), Failure> {
    let setup = kleefsman::Setup {
        particle_radius: args.radius,
        duration: args.duration,
        obstacle: !args.no_obstacle,
        gravity: args.gravity,
        viscosity: args.viscosity,
        tolerance: args.tau,
        solver: args.common.solver,
        threads: args.common.threads,
        walls: args.common.walls(),
        coarse_correction: args.coarse_correction.unwrap_or(false),
    };
    setup.validate().map_err(option_error)?;
    let data = kleefsman::Measurements::load().map_err(runtime)?;
    let reference = kleefsman::Reference::load().map_err(runtime)?;
    create_dir(&args.common.out)?;
    let [nx, ny, nz] = setup.fluid_count();
    eprintln!(
        "kleefsman: r = {} m, {nx} x {ny} x {nz} fluid particles, {}, g = {} m/s², viscosity {}, \
         {} s, {} solver",
        setup.particle_radius,
        if setup.obstacle {
            "with the box"
        } else {
            "no box"
        },
        setup.gravity,
        setup.viscosity,
        setup.duration,
        setup.solver.name()
    );
    let clock = Instant::now();
    let run = kleefsman::simulate(&setup, |_| {}).map_err(runtime)?;
    let tolerances = kleefsman::Tolerances::default();
    let cmp = kleefsman::compare(&run, &data, &reference, tolerances);
    let files = kleefsman::write_report(&args.common.out, &run, &data, &reference, &cmp)
        .map_err(runtime)?;
    let mut text = format!(
        "{} fluid particles, {} boundary particles, {} steps ({:.2} outer iterations per step) \
         in {:.1} s; max compression {:.3} %, {} escaped\n\n",
        run.particles,
        run.boundary_particles,
        run.steps,
        run.outer_iterations as f64 / run.steps.max(1) as f64,
        clock.elapsed().as_secs_f64(),
        100.0 * run.density_error_max,
        run.escaped
    );
    text += &cmp.table();
    let failures = cmp.failures();
    if failures.is_empty() {
        text += "\nevery compared quantity the run covers is within its tolerance\n";
    } else {
        text += &format!("\n{} outside the tolerance:\n", failures.len());
        for f in &failures {
            text += &format!("  {f}\n");
        }
    }
    let charts: Vec<String> = files
        .charts
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    text += &format!(
        "wrote {}, {}, {}\n",
        files.series_csv.display(),
        files.comparison_csv.display(),
        charts.join(", ")
    );
    print(&text)
}

fn hydrostatic(args: &HydrostaticArgs) -> Result<(), Failure> {
    let mut setup = hydrostatic::Setup {
        solver: args.common.solver,
        threads: args.common.threads,
        walls: args.common.walls(),
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
    setup.validate().map_err(option_error)?;
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

fn poiseuille(args: &PoiseuilleArgs) -> Result<(), Failure> {
    if args.common.walls() == ContainerWalls::Field {
        return Err(Failure::Input(
            "--walls field: the duct's walls hold the fluid with no slip, which walls built as \
             fields cannot; use --walls particles"
                .into(),
        ));
    }
    let setup = poiseuille::Setup {
        viscosities: args.viscosity.clone(),
        across: args.resolution,
        duration: args.duration,
        solver: args.common.solver,
        threads: args.common.threads,
        ..poiseuille::Setup::default()
    };
    setup.validate().map_err(option_error)?;
    create_dir(&args.common.out)?;
    let report = poiseuille::simulate(&setup, |_| {}).map_err(runtime)?;
    let files = poiseuille::write_report(&args.common.out, &report).map_err(runtime)?;
    let text = format!(
        "{}\nwrote {}, {}\n",
        report.text(),
        files.profile_csv.display(),
        files.profile_png.display()
    );
    print(&text)
}

fn two_layers(args: &TwoLayersArgs) -> Result<(), Failure> {
    if args.common.walls() == ContainerWalls::Field {
        return Err(Failure::Input(
            "--walls field: the two-liquid tanks are built with particle walls; use --walls \
             particles"
                .into(),
        ));
    }
    let setup = two_layers::Setup {
        across: args.resolution,
        light_density: args.light_density,
        overturn_duration: args.duration,
        solver: args.common.solver,
        threads: args.common.threads,
        ..two_layers::Setup::default()
    };
    setup.validate().map_err(option_error)?;
    create_dir(&args.common.out)?;
    let report = two_layers::simulate(&setup).map_err(runtime)?;
    let files = two_layers::write_report(&args.common.out, &report).map_err(runtime)?;
    let text = format!(
        "{}\nwrote {}, {}, {}, {}\n",
        report.text(),
        files.pressure_csv.display(),
        files.pressure_png.display(),
        files.overturn_csv.display(),
        files.overturn_png.display()
    );
    print(&text)
}

fn droplet(args: &DropletArgs) -> Result<(), Failure> {
    if args.common.walls() == ContainerWalls::Field {
        return Err(Failure::Input(
            "--walls field: the drop floats free, without walls; leave --walls out".into(),
        ));
    }
    if args.common.solver != SolverKind::Chebyshev {
        return Err(Failure::Input(
            "--solver: the drop runs with the default solver, chebyshev".into(),
        ));
    }
    let setup = droplet::Setup {
        tensions: args.surface_tension.clone(),
        across: args.resolution,
        threads: args.common.threads,
        ..droplet::Setup::default()
    };
    setup.validate().map_err(option_error)?;
    create_dir(&args.common.out)?;
    let report = droplet::simulate(&setup, |_| {}).map_err(runtime)?;
    let files = droplet::write_report(&args.common.out, &report).map_err(runtime)?;
    let text = format!(
        "{}\nwrote {}, {}\n",
        report.text(),
        files.response_csv.display(),
        files.response_png.display()
    );
    print(&text)
}
