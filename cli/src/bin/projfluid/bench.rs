//! `projfluid bench`: every scene with every solver, the paper's Table 1 as Markdown and CSV.

use crate::run::ParamOptions;
use crate::{Failure, solver_parser};
use clap::Args;
use projfluid::scene::Scene;
use projfluid::{Error, SolverKind};
use projfluid_lab::bench::{self, BenchEvent, BenchRow};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Options of `projfluid bench`.
#[derive(Args)]
pub(crate) struct BenchArgs {
    /// Scenes (built-in names or JSON files), comma-separated [default: every built-in scene].
    #[arg(long, value_name = "A,B,…", value_delimiter = ',')]
    scenes: Vec<String>,
    /// Solvers, comma-separated [default: all six].
    #[arg(long, value_name = "A,B,…", value_delimiter = ',', value_parser = solver_parser())]
    solvers: Vec<SolverKind>,
    /// Time steps per run; the paper averages over the first 80.
    #[arg(long, value_name = "N", default_value_t = bench::DEFAULT_STEPS)]
    steps: u64,
    /// Steps each solver runs before the next takes its turn, round after round, so that a
    /// drift in the machine's speed slows all solvers alike; 0 runs each solver to the end
    /// before the next starts (one scene's world in memory at a time instead of one per
    /// solver).
    #[arg(long, value_name = "N", default_value_t = bench::DEFAULT_TURN)]
    turn: u64,
    #[command(flatten)]
    params: ParamOptions,
    /// Directory for bench.md, bench.csv, bench.png and bench_iterations.png, created if missing.
    #[arg(long, value_name = "DIR", default_value = "bench_results")]
    out: PathBuf,
}

/// `projfluid bench`.
pub(crate) fn bench(args: &BenchArgs) -> Result<(), Failure> {
    if args.steps == 0 {
        let e = Error::invalid("--steps", 0, "must be at least 1");
        return Err(Failure::Input(e.to_string()));
    }
    let names: Vec<String> = if args.scenes.is_empty() {
        Scene::builtin_names()
            .iter()
            .map(|s| s.to_string())
            .collect()
    } else {
        args.scenes.clone()
    };
    let mut scenes = Vec::with_capacity(names.len());
    for name in &names {
        let mut scene = Scene::resolve(name).map_err(|e| Failure::Input(e.to_string()))?;
        args.params.apply_checked(&mut scene)?;
        scenes.push(scene);
    }
    let solvers = if args.solvers.is_empty() {
        SolverKind::ALL.to_vec()
    } else {
        args.solvers.clone()
    };
    // Create the output directory first, so that an unwritable path fails before the runs.
    create_dir(&args.out)?;
    let rows = bench::run_bench(
        &scenes,
        &solvers,
        args.steps,
        args.turn,
        |event| match event {
            BenchEvent::Start { scene, solver } => {
                eprintln!("{scene} {}: {} steps…", solver.name(), args.steps)
            }
            BenchEvent::Done(row) => eprintln!(
                "  {} {}: {:.2} ms/step, {:.2} outer iterations/step, artifacts: {}",
                row.summary.scene,
                row.summary.solver,
                row.summary.wall_ms_per_step,
                row.summary.outer_iterations_mean,
                row.verdict()
            ),
        },
    )
    .map_err(|e| Failure::Runtime(e.to_string()))?;
    let table = bench::markdown(&rows);
    print(&table)?;
    write_file(&args.out.join("bench.md"), &table)?;
    write_file(&args.out.join("bench.csv"), &bench::csv(&rows))?;
    write_chart(&args.out, &rows)
}

/// Creates the output directory `dir` (and its parents) if missing.
pub(crate) fn create_dir(dir: &Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::Runtime(format!(
            "cannot create output directory {}: {e}",
            dir.display()
        ))
    })
}

/// Writes `text` to stdout.
pub(crate) fn print(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| Failure::Runtime(format!("cannot write to stdout: {e}")))
}

/// Writes `text` to `path`.
pub(crate) fn write_file(path: &Path, text: &str) -> Result<(), Failure> {
    std::fs::write(path, text)
        .map_err(|e| Failure::Runtime(format!("cannot write {}: {e}", path.display())))
}

/// Writes bench.png (wall-clock ms per step) and bench_iterations.png (outer iterations).
fn write_chart(dir: &Path, rows: &[BenchRow]) -> Result<(), Failure> {
    let [time, iterations] = bench::charts(rows);
    for (chart, file) in [(time, "bench.png"), (iterations, "bench_iterations.png")] {
        chart
            .write_png(&dir.join(file))
            .map_err(|e| Failure::Runtime(e.to_string()))?;
    }
    Ok(())
}
