//! `projfluid tune-rho`: estimates Chebyshev's ρ for a scene and sweeps it (docs/method.md §5.2).

use crate::Failure;
use crate::bench::{create_dir, print, write_file};
use crate::run::ParamOptions;
use clap::Args;
use projfluid::scene::Scene;
use projfluid::{Error, SolverKind};
use projfluid_lab::tuning::{self, Phase, TuneConfig, TuneReport};
use std::path::{Path, PathBuf};

/// Options of `projfluid tune-rho`.
#[derive(Args)]
pub(crate) struct TuneRhoArgs {
    /// A built-in scene name (see `projfluid scenes`) or the path of a JSON scene file.
    scene: String,
    /// Measured steps T of every run.
    #[arg(long, value_name = "T", default_value_t = TuneConfig::default().steps)]
    steps: u64,
    /// Steps of plain iteration before the snapshot every run starts from.
    #[arg(long, value_name = "N", default_value_t = TuneConfig::default().warmup_steps)]
    warmup: u64,
    /// Smallest ρ of the sweep.
    #[arg(
        long,
        value_name = "R",
        default_value_t = 0.65,
        allow_negative_numbers = true
    )]
    from: f64,
    /// Largest ρ of the sweep (values ≥ 1 are replaced by 0.99).
    #[arg(
        long,
        value_name = "R",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    to: f64,
    /// Spacing of the sweep's grid.
    #[arg(
        long,
        value_name = "R",
        default_value_t = 0.025,
        allow_negative_numbers = true
    )]
    step: f64,
    /// Outer stopping threshold τ, in metres [default: the scene's].
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    tau: Option<f64>,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Directory for tune_rho.md, tune_rho.csv and the plots, created if missing.
    #[arg(long, value_name = "DIR", default_value = "tune_rho_results")]
    out: PathBuf,
}

/// `projfluid tune-rho`.
pub(crate) fn tune_rho(args: &TuneRhoArgs) -> Result<(), Failure> {
    let mut scene = Scene::resolve(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
    let options = ParamOptions {
        rho: None,
        eta: None,
        tau: args.tau,
        warm_start: None,
        coarse_correction: None,
        kinematic_viscosity: None,
        surface_tension: None,
        vorticity_confinement: None,
        no_slip: None,
        threads: args.threads,
    };
    options.apply_checked(&mut scene)?;
    if args.steps == 0 {
        let e = Error::invalid("--steps", 0, "must be at least 1");
        return Err(Failure::Input(e.to_string()));
    }
    let grid = tuning::rho_grid(args.from, args.to, args.step)
        .map_err(|e| Failure::Input(format!("--{e}")))?;
    let config = TuneConfig {
        warmup_steps: args.warmup,
        steps: args.steps,
        grid,
        ..TuneConfig::default()
    };
    create_dir(&args.out)?;
    eprintln!(
        "{}: {} particles; every run starts after {} steps of plain iteration and lasts {} steps",
        scene.name,
        scene.particle_count(),
        config.warmup_steps,
        config.steps
    );
    let report = tuning::tune_rho(&scene, &config, |phase| match phase {
        Phase::Estimate => eprintln!(
            "estimating the contraction: plain iteration, {} outer iterations per step…",
            config.estimate_iterations
        ),
        Phase::Plain => eprintln!("plain iteration ({})…", SolverKind::Jacobi1.name()),
        Phase::Rho(rho) => eprintln!("chebyshev, rho {rho}…"),
        Phase::Auto => eprintln!("chebyshev, rho estimated online…"),
    })
    .map_err(|e| Failure::Runtime(e.to_string()))?;
    let table = tuning::markdown(&report);
    let text = format!("{table}\n{}\n", conclusion(&report));
    print(&text)?;
    write_file(&args.out.join("tune_rho.md"), &text)?;
    write_file(&args.out.join("tune_rho.csv"), &tuning::csv(&report))?;
    write_plots(&args.out, &report)
}

/// The estimate and the choice, in words.
fn conclusion(report: &TuneReport) -> String {
    let estimate = match report.estimate {
        Some(rho) => format!(
            "estimated contraction of the plain iteration: {rho:.3} (median of {} steps)",
            report.step_estimates.len()
        ),
        None => "estimated contraction of the plain iteration: none (no step gave one)".into(),
    };
    let plain = report.plain.outer_iterations_mean;
    let choice = match report.best {
        Some(i) => {
            let t = &report.trials[i];
            let outer = t.summary.outer_iterations_mean;
            format!(
                "best rho: {} ({outer:.2} outer iterations per step against {plain:.2} for plain iteration, {:+.1} %)",
                t.rho,
                (outer / plain - 1.0) * 100.0
            )
        }
        None => "best rho: none (every value was rejected)".into(),
    };
    let auto = report.auto.summary.outer_iterations_mean;
    let online = format!(
        "rho auto: {auto:.2} outer iterations per step (mean online rho {:.3}, {:+.1} % against plain iteration)",
        report.auto.rho,
        (auto / plain - 1.0) * 100.0
    );
    format!("{estimate}\n{choice}\n{online}")
}

/// Writes tune_rho_time.png and tune_rho_iterations.png: time and outer iterations over ρ.
fn write_plots(dir: &Path, report: &TuneReport) -> Result<(), Failure> {
    let [time, iterations] = tuning::charts(report);
    for (chart, file) in [
        (time, "tune_rho_time.png"),
        (iterations, "tune_rho_iterations.png"),
    ] {
        chart
            .write_png(&dir.join(file))
            .map_err(|e| Failure::Runtime(e.to_string()))?;
    }
    Ok(())
}
