//! The SPH density constraint C_i = max(ρ_i/ρ0 − 1, 0) and its local projection
//! (docs/method.md §2.3–2.5).
//!
//! [`DensityConstraint`] evaluates densities, weights and memberships (`density`), projects
//! every constraint in the local step (`projection`, ending most projections after their first
//! step by the bound of `first_step`), keeps each stencil's members in arrays padded to whole
//! vectors (`stencil`), and gathers the corrections for the global step (`gather`).

mod density;
mod first_step;
mod gather;
mod projection;
mod stencil;

pub(crate) use density::weigh_by_inertia;
pub use gather::Corrections;
pub use projection::Projection;

use crate::Vec3;
use crate::boundary::{WallContribution, WallField};
use crate::kernel::CubicKernel;
use crate::neighbors::{NeighborLists, PointsByComponent};
use crate::params::ProjectionWeight;
use std::collections::TryReserveError;

/// Reserves, on every thread of `pool`, the buffers of the local step, the gather and the
/// density evaluations for stencils of up to `fluid` fluid and `boundary` boundary members
/// (the most neighbours any particle has in a step's lists), so that those per-thread
/// buffers allocate nothing during the step. Errors when the memory cannot be had.
pub(crate) fn reserve_scratch(
    pool: &rayon::ThreadPool,
    fluid: usize,
    boundary: usize,
) -> Result<(), TryReserveError> {
    pool.broadcast(|_| {
        stencil::SCRATCH.with_borrow_mut(|scratch| scratch.try_reserve(fluid, boundary))?;
        gather::reserve_gather(fluid)
    })
    .into_iter()
    .collect()
}

/// The default [`DensityConstraint::membership_floor`]: particles with fewer than 31 fluid
/// neighbours (spray, thin sheets, the surface) are counted in 32 stencils by the global step,
/// about the size of a resting particle's stencil (33.5). Measured on `dam_break_30k` at the
/// default mass factor (docs/method.md §3.1): the largest density error of its 2 s is 1.55 %,
/// against 3.69 % over its first second with a floor of 16.
pub const MEMBERSHIP_FLOOR: f64 = 32.0;
/// The local projection stops once C_i ≤ this value (Sommer et al. 2020, Weiler et al. 2016).
const CONSTRAINT_GOAL: f64 = 1e-14;
/// At most this many Newton-like steps per projection.
const MAX_PROJECTION_STEPS: usize = 100;
/// The local step and the gather take particles in runs of this many, each run with one
/// borrow of the thread's buffers.
pub(crate) const CHUNK: usize = 64;
/// No Newton step of a projection, its first included, moves a stencil member farther than
/// this fraction of H (= r). The constraint is far from linear over longer distances: where a
/// member presses on a boundary particle the gradient is nearly flat, and an unbounded step
/// threw a member metres away (docs/method.md §2.5).
const NEWTON_STEP_LIMIT: f64 = 0.25;
/// Regularisation ε of λ = −C/(|∇C|² + ε), in m⁻².
const REGULARIZATION: f64 = 1e-6;
/// The bound on ρ_i after a first projection step must stay this far (relative to ρ0) below
/// ρ0 for the step's density to go unevaluated: far more than the round-off of either
/// evaluation (≈ 10⁻¹⁴).
const RELAXATION_MARGIN: f64 = 1e-9;

/// Everything a constraint reads during one time step: the fluid's neighbour lists, the
/// static boundary particles with their Akinci masses ψ_b = ρ0·V_b (kg), and the container
/// walls that are fields rather than particles.
#[derive(Clone, Copy)]
pub struct Neighborhood<'a> {
    /// Fluid neighbours of each fluid particle (j ≠ i).
    pub fluid: &'a NeighborLists,
    /// Boundary neighbours of each fluid particle.
    pub boundary: &'a NeighborLists,
    /// Boundary particle positions (m).
    pub boundary_positions: &'a PointsByComponent,
    /// Boundary particle masses ψ_b (kg).
    pub boundary_psi: &'a [f64],
    /// The weight w_j of every fluid particle in a projection
    /// ([`DensityConstraint::weights`]).
    pub weights: &'a [f64],
    /// Container walls without particles (docs/method.md §7).
    pub walls: &'a [WallField],
}

/// The fluid density constraint with the constants of the local projection.
#[derive(Clone, Copy, Debug)]
pub struct DensityConstraint {
    /// The SPH kernel.
    pub kernel: CubicKernel,
    /// Fluid particle mass m (kg).
    pub mass: f64,
    /// Rest density ρ0 (kg/m³).
    pub rest_density: f64,
    /// Weighting of the projection.
    pub weight: ProjectionWeight,
    /// Stencil size c = ρ0·(4/3)πH³/m of a fluid at rest density (particles per stencil),
    /// the weight of [`ProjectionWeight::Uniform`].
    pub rest_stencil_size: f64,
    /// The fewest stencils the global step counts a particle in (docs/method.md §3.1): a
    /// particle with fewer fluid neighbours (spray) keeps a constraint as stiff, relative to
    /// its mass, as one with this many. 1 or less: the reference behaviour.
    pub membership_floor: f64,
    /// Write every projection's corrections out, as multi-step ones do (the reference path,
    /// for tests of the single-step shortcut).
    pub(crate) materialize_all: bool,
    /// Project and gather with the portable builds even where the processor has AVX2 (for
    /// the test that both builds agree bit for bit).
    pub(crate) portable: bool,
    /// Evaluate ρ_i after every first projection step, also where a bound already shows it
    /// is below ρ0 (for the test that skipping those evaluations changes nothing).
    pub(crate) evaluate_first_step: bool,
}

impl DensityConstraint {
    /// What the container walls without particles add at `x` (m), summed over them.
    #[inline(always)]
    pub(crate) fn walls_at(&self, x: Vec3, walls: &[WallField]) -> WallContribution {
        let mut sum = WallContribution::default();
        for field in walls {
            let one = field.at(x, &self.kernel);
            sum.density += one.density;
            sum.gradient += one.gradient;
            sum.curvature += one.curvature;
        }
        sum
    }
}

/// The fixture of the stencil and first-step tests: a jittered cluster of fluid particles
/// over a floor of boundary particles, and the constraint it is tested with.
#[cfg(test)]
mod test_cluster {
    use super::*;
    use crate::Vec3;
    use crate::neighbors::{CellTable, UniformGrid};

    /// Fluid positions (m) with their neighbour lists among the fluid and the boundary, the
    /// boundary positions (m) and masses ψ (kg), and the fluid's projection weights.
    pub(super) struct Cluster {
        pub(super) x: Vec<Vec3>,
        pub(super) fl: NeighborLists,
        pub(super) bl: NeighborLists,
        pub(super) bx: Vec<Vec3>,
        /// `bx` by component, as the constraints read it.
        pub(super) bx_components: PointsByComponent,
        pub(super) psi: Vec<f64>,
        pub(super) weights: Vec<f64>,
    }

    impl Cluster {
        /// What the constraints of the cluster read.
        pub(super) fn nb(&self) -> Neighborhood<'_> {
            Neighborhood {
                fluid: &self.fl,
                boundary: &self.bl,
                boundary_positions: &self.bx_components,
                boundary_psi: &self.psi,
                weights: &self.weights,
                walls: &[],
            }
        }
    }

    /// A jittered cubic lattice of 7³ particles at `spacing` (m) above a floor of boundary
    /// particles, searched with radius H.
    pub(super) fn cluster(constraint: &DensityConstraint, spacing: f64) -> Cluster {
        let h = constraint.kernel.support_radius();
        let mut rng = crate::random::SplitMix64(7);
        let mut jitter = || (rng.next_f64() - 0.5) * 0.02 * spacing;
        let mut fluid = Vec::new();
        for (i, j, k) in
            (0..7).flat_map(|i| (0..7).flat_map(move |j| (0..7).map(move |k| (i, j, k))))
        {
            let p = Vec3::new(i as f64, j as f64 + 1.0, k as f64) * spacing;
            fluid.push(p + Vec3::new(jitter(), jitter(), jitter()));
        }
        let b = 0.5 * spacing;
        let boundary: Vec<Vec3> = (-4..18)
            .flat_map(|i| (-4..18).map(move |k| Vec3::new(i as f64 * b, 0.0, k as f64 * b)))
            .collect();
        let psi = vec![constraint.mass / 8.0; boundary.len()];
        let grid = UniformGrid::covering(Vec3::repeat(-1.0), Vec3::repeat(2.0), h).unwrap();
        let sorted = |points: &[Vec3]| {
            let (mut order, mut table) = (Vec::new(), CellTable::default());
            grid.sort(points, &mut order, &mut table).unwrap();
            let p: Vec<Vec3> = order.iter().map(|&i| points[i as usize]).collect();
            (p, table)
        };
        let (x, fluid_table) = sorted(&fluid);
        let (bx, boundary_table) = sorted(&boundary);
        let (mut fl, mut bl) = (NeighborLists::default(), NeighborLists::default());
        grid.search(&fluid_table, &x, &x, h, true, &mut fl).unwrap();
        grid.search(&boundary_table, &bx, &x, h, false, &mut bl)
            .unwrap();
        let mut weights = Vec::new();
        constraint.weights(&fl, &mut weights);
        let mut bx_components = PointsByComponent::default();
        bx_components.fill(&bx).unwrap();
        Cluster {
            x,
            fl,
            bl,
            bx,
            bx_components,
            psi,
            weights,
        }
    }

    /// The constraint of a fluid with particle radius `r` (m), rest density 1000 kg/m³ and
    /// the default weighting, on the portable path, evaluating every first-step density.
    pub(super) fn test_constraint(r: f64) -> DensityConstraint {
        DensityConstraint {
            kernel: CubicKernel::new(4.0 * r),
            mass: 1000.0 * (2.0 * r).powi(3),
            rest_density: 1000.0,
            weight: ProjectionWeight::NeighborCount,
            rest_stencil_size: 4.0 / 3.0 * std::f64::consts::PI * 8.0,
            membership_floor: 1.0,
            materialize_all: false,
            portable: true,
            evaluate_first_step: true,
        }
    }
}
