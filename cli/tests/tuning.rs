//! Choosing Chebyshev's ρ the paper's way on the small dam break.

use projfluid::scene::Scene;
use projfluid_lab::tuning::{TuneConfig, tune_rho};

/// From the busy phase of the collapse, the sweep finds a ρ that needs fewer outer iterations
/// than the plain iteration, and every run starts from the same state.
#[test]
fn tuned_rho_beats_plain_iteration_on_the_small_dam_break() {
    let mut scene = Scene::builtin("dam_break_small").unwrap();
    scene.params.threads = 2;
    let config = TuneConfig {
        warmup_steps: 40,
        steps: 10,
        estimate_iterations: 40,
        grid: vec![0.8, 0.9],
    };
    let mut phases = Vec::new();
    let report = tune_rho(&scene, &config, |p| phases.push(p)).unwrap();
    assert_eq!(phases.len(), 3 + config.grid.len());
    let plain = &report.plain;
    assert_eq!(plain.solver, "jacobi1");
    assert!(plain.outer_iterations_mean > 5.0, "{plain:?}");
    assert_eq!(report.step_estimates.len(), 10);
    let estimate = report.estimate.unwrap();
    assert!((0.5..1.0).contains(&estimate), "{estimate}");
    let best = &report.trials[report.best.unwrap()];
    assert_eq!(best.rejection, None);
    assert_eq!(best.summary.solver, "chebyshev");
    assert_eq!(best.summary.rho, best.rho);
    assert_eq!(report.best_rho(), Some(best.rho));
    assert!(
        best.summary.outer_iterations_mean < plain.outer_iterations_mean,
        "{} vs {}",
        best.summary.outer_iterations_mean,
        plain.outer_iterations_mean
    );
    // The online estimate runs from the same state and reports its mean ρ.
    let auto = &report.auto;
    assert!(auto.summary.rho_auto && auto.summary.steps == 10);
    assert_eq!(auto.rho, auto.summary.rho);
    for trial in report.trials.iter().chain([auto]) {
        assert_eq!(trial.summary.steps, 10);
        // Deterministic snapshot: every run starts with the same energy.
        assert_eq!(trial.summary.energy_initial, plain.energy_initial);
    }
}

#[test]
fn tuning_rejects_an_unordered_grid_and_zero_steps() {
    let scene = Scene::builtin("dam_break_small").unwrap();
    let unordered = TuneConfig {
        grid: vec![0.9, 0.8],
        ..TuneConfig::default()
    };
    let e = tune_rho(&scene, &unordered, |_| {}).unwrap_err();
    assert!(e.to_string().contains("ascending"), "{e}");
    let no_steps = TuneConfig {
        steps: 0,
        ..TuneConfig::default()
    };
    let e = tune_rho(&scene, &no_steps, |_| {}).unwrap_err();
    assert!(e.to_string().starts_with("steps"), "{e}");
}
