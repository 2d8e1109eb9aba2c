//! Runs one scene with one solver configuration and prints a JSON line of what the defaults
//! are chosen by: outer iterations, density errors, energy rise, time per step. Energies are
//! measured above the lowest fluid particle at the start (`projfluid::driver::energy_datum`).
//!
//! `cargo run --release --example calibrate -- SCENE SECONDS SOLVER RHO DELAY OMEGA2 TAU_PER_R`
//! e.g. `… dam_break_30k 1.0 chebyshev 0.9 3 chebyshev 1e-3`. Environment: `GAMMA` sets
//! Chebyshev's under-relaxation γ, `WEIGHT=neighbor_count|unit|uniform` the projection
//! weighting.
use projfluid::driver::{self, RunLength};
use projfluid::scene::Scene;
use projfluid::{Omega2Rule, ProjectionWeight, SolverKind};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() != 7 {
        eprintln!("usage: calibrate SCENE SECONDS SOLVER RHO DELAY OMEGA2 TAU_PER_R");
        std::process::exit(2);
    }
    let mut scene = Scene::resolve(&a[0]).expect("scene");
    let seconds: f64 = a[1].parse().expect("seconds");
    let p = &mut scene.params;
    p.solver = SolverKind::from_name(&a[2]).expect("solver");
    if a[3] == "auto" {
        p.chebyshev.auto_rho = true;
    } else {
        p.chebyshev.rho = a[3].parse().expect("rho");
        p.chebyshev.auto_rho = false;
    }
    p.chebyshev.delay = a[4].parse().expect("delay");
    p.chebyshev.omega2_rule = Omega2Rule::from_name(&a[5]).expect("omega2");
    if let Ok(v) = std::env::var("GAMMA") {
        p.chebyshev.gamma = v.parse().expect("GAMMA");
    }
    if let Ok(v) = std::env::var("WEIGHT") {
        p.projection_weight = ProjectionWeight::from_name(&v).expect("WEIGHT");
    }
    p.displacement_tolerance = a[6].parse::<f64>().expect("tau") * p.particle_radius;
    let mut world = scene.build_world().expect("world");
    let acc = driver::run_quietly(&mut world, RunLength::Duration(seconds)).expect("run");
    let s = acc.summary(&a[0], &world);
    println!(
        "{{\"scene\":\"{}\",\"solver\":\"{}\",\"rho\":\"{}\",\"rho_mean\":{:.3},\"delay\":{},\"omega2\":\"{}\",\"tau_per_r\":{},\"steps\":{},\"outer_mean\":{:.3},\"ms_per_step\":{:.2},\"err_avg_pct\":{:.5},\"err_max_pct\":{:.3},\"energy_rise_j\":{:.4},\"energy_end_j\":{:.3},\"e0\":{:.3},\"kmax_hits\":{},\"escaped\":{},\"nan\":{}}}",
        a[0],
        a[2],
        a[3],
        s.rho,
        a[4],
        a[5],
        a[6],
        s.steps,
        s.outer_iterations_mean,
        s.wall_ms_per_step,
        s.density_error_avg_percent,
        s.density_error_max_percent,
        s.energy_max - s.energy_initial,
        s.energy_final,
        s.energy_initial,
        s.max_iteration_hits,
        s.escaped,
        s.nan
    );
}
