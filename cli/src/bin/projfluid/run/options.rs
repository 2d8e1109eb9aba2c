//! Solver options every subcommand that runs scenes accepts, and validation that names the
//! option behind a bad value.

use crate::{Failure, RhoArg, on_off_parser, rho_parser};
use clap::Args;
use projfluid::Error;
use projfluid::scene::Scene;

/// Solver settings that every subcommand running scenes accepts; each given option replaces
/// the scene's setting.
#[derive(Args)]
pub(crate) struct ParamOptions {
    /// Chebyshev spectral radius estimate ρ_c, in [0, 1), or `auto` to estimate it online.
    #[arg(long, value_name = "R|auto", allow_negative_numbers = true, value_parser = rho_parser)]
    pub(crate) rho: Option<RhoArg>,
    /// Outer stopping threshold η on the average density error, a fraction (3e-4 =
    /// 0.03 %; 0 turns the density rule off).
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub(crate) eta: Option<f64>,
    /// Outer stopping threshold τ, in metres (stop when no particle moves farther).
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    pub(crate) tau: Option<f64>,
    /// Share of the last step's support a step starts from, in [0, 1) (0 starts every
    /// step from its inertial prediction).
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub(crate) warm_start: Option<f64>,
    /// Correct the start of every step's outer iteration on a coarse lattice, moving the
    /// whole fluid at once to remove its compression, so that deep water needs far fewer
    /// outer iterations (off by default; not used in worlds with bodies).
    #[arg(long, value_name = "on|off", value_parser = on_off_parser())]
    pub(crate) coarse_correction: Option<bool>,
    /// Kinematic viscosity ν of the implicit physical viscosity solve, in m²/s (0 turns it
    /// off; water 1e-6, honey 1e-2).
    #[arg(long, value_name = "NU", allow_negative_numbers = true)]
    pub(crate) kinematic_viscosity: Option<f64>,
    /// Surface tension σ of the scene's own fluid, in N/m (0 turns it off; water 0.0728).
    #[arg(long, value_name = "SIGMA", allow_negative_numbers = true)]
    pub(crate) surface_tension: Option<f64>,
    /// Vorticity confinement ε in [0, 10], giving back rotation the solver and XSPH damp
    /// (0 turns it off; 0.1–1 is a useful range).
    #[arg(long, value_name = "EPSILON", allow_negative_numbers = true)]
    pub(crate) vorticity_confinement: Option<f64>,
    /// Whether walls, static obstacles and static bodies hold the fluid with no slip under the
    /// physical viscosity (`on`, the default) or let it slide (`off`).
    #[arg(long, value_name = "on|off", value_parser = on_off_parser())]
    pub(crate) no_slip: Option<bool>,
    /// Worker threads (0 = one per core).
    #[arg(long, value_name = "N")]
    pub(crate) threads: Option<usize>,
}

impl ParamOptions {
    /// Sets the given options in `scene.params`.
    pub(super) fn apply(&self, scene: &mut Scene) {
        let p = &mut scene.params;
        if let Some(rho) = self.rho {
            rho.apply(&mut p.chebyshev);
        }
        if let Some(eta) = self.eta {
            p.density_tolerance = eta;
        }
        if let Some(tau) = self.tau {
            p.displacement_tolerance = tau;
        }
        if let Some(share) = self.warm_start {
            p.warm_start = share;
        }
        if let Some(on) = self.coarse_correction {
            p.coarse_correction = on;
        }
        if let Some(nu) = self.kinematic_viscosity {
            p.kinematic_viscosity = nu;
        }
        if let Some(sigma) = self.surface_tension {
            p.surface_tension = sigma;
        }
        if let Some(epsilon) = self.vorticity_confinement {
            p.vorticity_confinement = epsilon;
        }
        if let Some(on) = self.no_slip {
            p.no_slip = on;
        }
        if let Some(threads) = self.threads {
            p.threads = threads;
        }
    }

    /// Which scene key each option sets, and whether it was given.
    pub(super) fn keys(&self) -> [(&'static str, &'static str, bool); 10] {
        [
            ("solver.rho", "--rho", self.rho.is_some()),
            ("solver.eta", "--eta", self.eta.is_some()),
            ("solver.tau", "--tau", self.tau.is_some()),
            (
                "solver.warm_start",
                "--warm-start",
                self.warm_start.is_some(),
            ),
            (
                "solver.coarse_correction",
                "--coarse-correction",
                self.coarse_correction.is_some(),
            ),
            (
                "kinematic_viscosity",
                "--kinematic-viscosity",
                self.kinematic_viscosity.is_some(),
            ),
            (
                "surface_tension",
                "--surface-tension",
                self.surface_tension.is_some(),
            ),
            (
                "vorticity_confinement",
                "--vorticity-confinement",
                self.vorticity_confinement.is_some(),
            ),
            ("no_slip", "--no-slip", self.no_slip.is_some()),
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
pub(super) fn validate_naming_options(
    scene: &Scene,
    options: &[(&str, &str, bool)],
) -> Result<(), Failure> {
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
