//! Fluid materials: several liquids of different rest densities in one world
//! (docs/method.md §14).
//!
//! Every fluid particle carries a material. All materials share the world's particle size,
//! so every particle has the same rest volume V = m/ρ0 (the world's mass over the world's
//! rest density). The density constraint is written on volumes, C_i = V·Σ_j W_ij + … − 1,
//! which is the number-density form of multi-density SPH (Solenthaler and Pajarola 2008):
//! a light particle beside heavy ones sums their volumes, not their masses, so an interface
//! between two liquids is not read as compressed. A material's rest density enters the step
//! through its particles' masses m_i = ρ0_i·V, that is through the inertia of the global step
//! (M in M(x − s)/Δt² = Σ forces): a heavier particle is pushed less by the same constraint
//! force and weighs more.
//!
//! Material 0 is the world's own fluid ([`crate::Params::rest_density`]); others are added
//! with [`crate::World::add_material`].

use crate::Error;

/// The index of a material in its world: 0 is the world's own fluid, then the materials in
/// the order [`crate::World::add_material`] added them.
pub type MaterialId = u16;

/// The most materials a world holds, its own fluid included.
pub const MAX_MATERIALS: usize = 256;

/// The lightest and heaviest rest density a material may have, as multiples of the world's
/// rest density: beyond a factor of ten the global step's inertia differs so much between
/// neighbours that the iteration no longer converges within its limits.
pub const DENSITY_RATIO_RANGE: (f64, f64) = (0.1, 10.0);

/// A liquid's physical properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Rest density ρ0 (kg/m³).
    pub rest_density: f64,
    /// Kinematic viscosity ν (m²/s) of the implicit viscosity solve (docs/method.md §13): 0
    /// leaves the liquid without physical viscosity; water is 1e-6, honey 1e-2 and more.
    pub kinematic_viscosity: f64,
    /// Surface tension coefficient σ (N/m) of the surface force (docs/method.md §17): 0
    /// leaves the liquid without surface tension; water against air is 0.0728.
    pub surface_tension: f64,
}

impl Material {
    /// A liquid of rest density `rest_density` (kg/m³) without physical viscosity or surface
    /// tension.
    pub fn with_density(rest_density: f64) -> Self {
        Self {
            rest_density,
            kinematic_viscosity: 0.0,
            surface_tension: 0.0,
        }
    }
}

impl Material {
    /// Errors, naming the field, where the material cannot be simulated in a world of rest
    /// density `reference` (kg/m³).
    pub(crate) fn check(&self, reference: f64) -> Result<(), Error> {
        let (low, high) = DENSITY_RATIO_RANGE;
        let ratio = self.rest_density / reference;
        if !(ratio.is_finite() && (low..=high).contains(&ratio)) {
            return Err(Error::invalid(
                "rest_density",
                self.rest_density,
                &format!(
                    "must be between {} and {} kg/m³ ({low} to {high} times the world's rest density)",
                    low * reference,
                    high * reference
                ),
            ));
        }
        check_viscosity(self.kinematic_viscosity)?;
        check_surface_tension(self.surface_tension)
    }
}

/// Errors, naming the field, where `nu` (m²/s) is not a kinematic viscosity a material may
/// have: finite and not negative.
pub(crate) fn check_viscosity(nu: f64) -> Result<(), Error> {
    if nu.is_finite() && nu >= 0.0 {
        return Ok(());
    }
    Err(Error::invalid(
        "kinematic_viscosity",
        nu,
        "must be finite and not negative (m²/s; 0 turns it off)",
    ))
}

/// The largest surface tension a material may have (N/m): five times molten iron's. Above
/// it the capillary limit on the step (docs/method.md §8) falls below any useful `dt_min`.
pub const MAX_SURFACE_TENSION: f64 = 10.0;

/// The factor c of the capillary limit Δt ≤ c·√(ρ d³/(2πσ)) on the step (docs/method.md
/// §8), d being the particle spacing: Brackbill et al.'s bound with the particle spacing as
/// the grid's. Its c is measured on a drop 10 particles across (docs/validation.md): at
/// c = 0.2 the drop loses its shape, at c = 0.1 its oscillation period is 9 % longer than
/// at smaller steps, and from c = 0.05 down the period stays within a few per cent.
pub const CAPILLARY_FACTOR: f64 = 0.05;

/// Errors, naming the field, where `sigma` (N/m) is not a surface tension a material may
/// have: finite, not negative and at most [`MAX_SURFACE_TENSION`].
pub(crate) fn check_surface_tension(sigma: f64) -> Result<(), Error> {
    check_coefficient("surface_tension", sigma, MAX_SURFACE_TENSION)
}

/// Errors, naming `field`, where `value` (N/m) is not a coefficient of surface energy:
/// finite, not negative and at most `most`.
pub(crate) fn check_coefficient(field: &str, value: f64, most: f64) -> Result<(), Error> {
    if value.is_finite() && (0.0..=most).contains(&value) {
        return Ok(());
    }
    Err(Error::invalid(
        field,
        value,
        &format!("must be finite and not negative, at most {most} (N/m; 0 turns it off)"),
    ))
}

/// A world's materials beyond its own fluid, and the one that fluid added next is made of.
#[derive(Clone, Debug)]
pub(crate) struct Materials {
    /// Materials 1, 2, … in the order they were added.
    pub added: Vec<Material>,
    /// Every material's mass over the world's particle mass, ρ0_i/ρ0 (dimensionless),
    /// indexed by material: 1 for the world's own fluid.
    pub mass_ratios: Vec<f64>,
    /// Every material's kinematic viscosity ν (m²/s), indexed by material.
    pub viscosities: Vec<f64>,
    /// Every material's surface tension σ (N/m), indexed by material.
    pub tensions: Vec<f64>,
    /// The material of the fluid added next: blocks, particles, and the emitters added next.
    pub current: MaterialId,
}

impl Materials {
    /// The materials of a world whose own fluid has kinematic viscosity `nu` (m²/s) and
    /// surface tension `sigma` (N/m).
    pub fn new(nu: f64, sigma: f64) -> Self {
        Self {
            added: Vec::new(),
            mass_ratios: vec![1.0],
            viscosities: vec![nu],
            tensions: vec![sigma],
            current: 0,
        }
    }

    /// Number of materials, the world's own fluid included.
    pub fn len(&self) -> usize {
        self.added.len() + 1
    }

    /// Whether the world holds only its own fluid.
    #[cfg(feature = "gpu")]
    pub fn single(&self) -> bool {
        self.added.is_empty()
    }

    /// Material `id`, the world's own fluid (of rest density `reference`, kg/m³) for 0.
    pub fn get(&self, id: MaterialId, reference: f64) -> Option<Material> {
        match id {
            0 => Some(Material {
                rest_density: reference,
                kinematic_viscosity: self.viscosities[0],
                surface_tension: self.tensions[0],
            }),
            _ => self.added.get(id as usize - 1).copied(),
        }
    }

    /// Adds `material` to a world of rest density `reference` (kg/m³) and returns its id.
    /// Errors, changing nothing, on a material [`Material::check`] rejects or one too many.
    pub fn add(&mut self, material: Material, reference: f64) -> Result<MaterialId, Error> {
        material.check(reference)?;
        if self.len() >= MAX_MATERIALS {
            return Err(Error::invalid(
                "material",
                self.len(),
                &format!("a world holds at most {MAX_MATERIALS} materials"),
            ));
        }
        self.added.push(material);
        self.mass_ratios.push(material.rest_density / reference);
        self.viscosities.push(material.kinematic_viscosity);
        self.tensions.push(material.surface_tension);
        Ok((self.len() - 1) as MaterialId)
    }

    /// Sets material `id`'s kinematic viscosity to `nu` (m²/s). Errors, changing nothing, on
    /// an id the world has no material for or a viscosity [`check_viscosity`] rejects.
    pub fn set_viscosity(&mut self, id: MaterialId, nu: f64) -> Result<(), Error> {
        self.check_id("material", id)?;
        check_viscosity(nu)?;
        self.viscosities[id as usize] = nu;
        if let Some(m) = (id as usize).checked_sub(1) {
            self.added[m].kinematic_viscosity = nu;
        }
        Ok(())
    }

    /// Sets material `id`'s surface tension to `sigma` (N/m). Errors, changing nothing, on
    /// an id the world has no material for or a surface tension [`check_surface_tension`]
    /// rejects.
    pub fn set_surface_tension(&mut self, id: MaterialId, sigma: f64) -> Result<(), Error> {
        self.check_id("material", id)?;
        check_surface_tension(sigma)?;
        self.tensions[id as usize] = sigma;
        if let Some(m) = (id as usize).checked_sub(1) {
            self.added[m].surface_tension = sigma;
        }
        Ok(())
    }

    /// Whether any material has a surface tension.
    pub fn tense(&self) -> bool {
        self.tensions.iter().any(|&sigma| sigma > 0.0)
    }

    /// The capillary limit on the step size (s; docs/method.md §8): the shortest
    /// [`CAPILLARY_FACTOR`]·√(ρ_i d³/(2π σ_i)) over the materials with a surface tension, ρ_i being the material's
    /// rest density and d the particle spacing, the wall adhesion W counting as a surface
    /// tension of the lightest material; Brackbill, Kothe and Zemach's (1992) bound on an
    /// explicit surface tension, which the fastest capillary wave the particles resolve sets.
    /// At least `dt_min`; infinite without surface tension or adhesion.
    pub fn capillary_step(&self, params: &crate::Params) -> f64 {
        let reference = params.rest_density;
        let volume = params.spacing().powi(3);
        let bound = |density: f64, sigma: f64| {
            if sigma > 0.0 {
                CAPILLARY_FACTOR * (density * volume / (2.0 * std::f64::consts::PI * sigma)).sqrt()
            } else {
                f64::INFINITY
            }
        };
        let lightest = self
            .mass_ratios
            .iter()
            .fold(f64::INFINITY, |a, &b| a.min(b));
        let adhesion = bound(lightest * reference, params.wall_adhesion);
        let step = (self.mass_ratios.iter().zip(&self.tensions))
            .map(|(ratio, &sigma)| bound(ratio * reference, sigma))
            .fold(adhesion, f64::min);
        step.max(params.dt_min)
    }

    /// Whether any material has a physical viscosity.
    pub fn viscous(&self) -> bool {
        self.viscosities.iter().any(|&nu| nu > 0.0)
    }

    /// Errors, naming `field`, where `id` is not one of the materials.
    pub fn check_id(&self, field: &str, id: MaterialId) -> Result<(), Error> {
        if (id as usize) < self.len() {
            return Ok(());
        }
        Err(Error::invalid(
            field,
            id,
            &format!(
                "must name one of the world's {} materials (0 to {})",
                self.len(),
                self.len() - 1
            ),
        ))
    }
}
