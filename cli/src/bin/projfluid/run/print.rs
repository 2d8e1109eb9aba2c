//! The run summary as printed on stdout.

use projfluid_lab::summary::RunSummary;
use std::io::Write;

/// The human-readable summary on stdout.
pub(super) fn print_summary(s: &RunSummary) -> std::io::Result<()> {
    let rows = [
        ("scene", s.scene.clone()),
        ("solver", {
            let rho = if s.rho_auto {
                format!("rho auto, mean {:.3}", s.rho)
            } else {
                format!("rho {}", s.rho)
            };
            let coarse = if s.coarse_correction { "on" } else { "off" };
            format!(
                "{} ({rho}; eta {:.3} %, tau {:.3e} m; coarse correction {coarse})",
                s.solver,
                s.eta * 100.0,
                s.tau
            )
        }),
        ("backend", {
            let precision = if s.backend == "gpu" {
                "single"
            } else {
                "double"
            };
            format!("{} ({precision} precision)", s.backend)
        }),
        ("kinematic viscosity", {
            let walls = if s.no_slip { "no-slip" } else { "free-slip" };
            if s.kinematic_viscosity > 0.0 {
                format!("{:.3e} m²/s, {walls} walls", s.kinematic_viscosity)
            } else {
                format!("off ({walls} walls)")
            }
        }),
        ("vorticity confinement", {
            if s.vorticity_confinement > 0.0 {
                format!("ε = {}", s.vorticity_confinement)
            } else {
                "off".to_string()
            }
        }),
        ("surface tension", {
            if s.surface_tension > 0.0 {
                format!("{} N/m", s.surface_tension)
            } else {
                "off".to_string()
            }
        }),
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
