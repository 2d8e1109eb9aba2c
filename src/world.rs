//! The world: fluid particles (structure of arrays), static boundary particles, parameters,
//! and the world's own thread pool. The CLI and the C API are thin shells over it.

use crate::boundary::{Aabb, akinci_volumes, sample_box_walls};
use crate::constraint::DensityConstraint;
use crate::kernel::CubicKernel;
use crate::neighbors::{CellTable, PointsByComponent, UniformGrid};
use crate::params::{Params, SolverKind};
use crate::solver::{Chebyshev, GlobalSolver, linear_solver};
use crate::stats::StepStats;
use crate::step::StepBuffers;
use crate::{Error, Vec3, reduce};

/// Fluid particles in their current storage order (Z-order after the first step).
#[derive(Clone, Debug, Default)]
pub(crate) struct Fluid {
    pub positions: Vec<Vec3>,
    pub velocities: Vec<Vec3>,
    pub densities: Vec<f64>,
    /// The order in which each particle was added; outputs are reported in this order.
    pub ids: Vec<u32>,
}

/// Static boundary particles, sorted by the grid's cells, with their Akinci masses.
#[derive(Clone, Debug, Default)]
pub(crate) struct Boundary {
    pub positions: Vec<Vec3>,
    /// ψ_b = ρ0·V_b (kg), valid unless `dirty`.
    pub psi: Vec<f64>,
    pub table: CellTable,
    /// `positions` by component, for the neighbour search (valid unless `dirty`).
    pub by_component: PointsByComponent,
    /// Set when particles were added or the grid changed: sort and volumes must be redone.
    pub dirty: bool,
}

/// A fluid simulation: particles, boundaries, parameters and the state of time stepping.
pub struct World {
    pub(crate) params: Params,
    pub(crate) constraint: DensityConstraint,
    pub(crate) pool: rayon::ThreadPool,
    pub(crate) fluid: Fluid,
    pub(crate) boundary: Boundary,
    /// Container boxes; fluid outside all of them counts as escaped.
    pub(crate) containers: Vec<Aabb>,
    pub(crate) grid: Option<UniformGrid>,
    /// The grid reached its cell limit and no longer grows.
    pub(crate) grid_capped: bool,
    pub(crate) solver: Box<dyn GlobalSolver>,
    pub(crate) chebyshev: Chebyshev,
    pub(crate) buffers: StepBuffers,
    pub(crate) time: f64,
    pub(crate) next_dt: f64,
    pub(crate) steps: u64,
    pub(crate) last: Option<StepStats>,
}

impl World {
    /// An empty world with the given parameters (validated).
    pub fn new(params: Params) -> Result<Self, Error> {
        params.validate()?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(params.threads)
            .build()
            .map_err(|e| {
                Error::invalid("threads", params.threads, &format!("could not start: {e}"))
            })?;
        Self::with_pool(params, pool)
    }

    /// An empty world with the given parameters (validated) that runs on `pool`, which the
    /// caller built (e.g. to join its threads after dropping the world, as the C API does).
    /// `params.threads` is kept as given; the pool's own size decides the parallelism.
    pub fn with_pool(params: Params, pool: rayon::ThreadPool) -> Result<Self, Error> {
        params.validate()?;
        Ok(Self {
            constraint: DensityConstraint {
                kernel: CubicKernel::new(params.support_radius()),
                mass: params.particle_mass(),
                rest_density: params.rest_density,
                weight: params.projection_weight,
                rest_stencil_size: params.rest_stencil_size(),
                materialize_all: false,
                portable: false,
                evaluate_first_step: false,
            },
            pool,
            fluid: Fluid::default(),
            boundary: Boundary::default(),
            containers: Vec::new(),
            grid: None,
            grid_capped: false,
            solver: linear_solver(params.solver),
            chebyshev: Chebyshev::new(params.chebyshev),
            buffers: StepBuffers::default(),
            time: 0.0,
            next_dt: params.dt_initial.clamp(params.dt_min, params.dt_max),
            steps: 0,
            last: None,
            params,
        })
    }

    /// The world's parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Switches the global solver (and Chebyshev settings) between steps.
    pub fn set_solver(
        &mut self,
        kind: SolverKind,
        chebyshev: crate::params::ChebyshevParams,
    ) -> Result<(), Error> {
        let mut params = self.params.clone();
        params.solver = kind;
        params.chebyshev = chebyshev;
        params.validate()?;
        self.params = params;
        self.solver = linear_solver(kind);
        self.chebyshev = Chebyshev::new(chebyshev);
        Ok(())
    }

    /// Changes the outer loop's iteration limits between steps: at least `min` and at most
    /// `max` outer iterations per step (min = max forces a fixed count, as ρ estimation
    /// needs). Rejects values that [`Params::validate`] rejects, changing nothing.
    pub fn set_outer_iterations(&mut self, min: usize, max: usize) -> Result<(), Error> {
        let mut params = self.params.clone();
        params.min_outer_iterations = min;
        params.max_outer_iterations = max;
        params.validate()?;
        self.params = params;
        Ok(())
    }

    /// Changes the outer stopping threshold τ (m) between steps. Rejects values that
    /// [`Params::validate`] rejects, changing nothing.
    pub fn set_displacement_tolerance(&mut self, tolerance: f64) -> Result<(), Error> {
        let mut params = self.params.clone();
        params.displacement_tolerance = tolerance;
        params.validate()?;
        self.params = params;
        Ok(())
    }

    /// Adds fluid particles at `positions` (m) with `velocities` (m/s; zero when `None`).
    /// Rejects non-finite values and length mismatches without changing the world.
    pub fn add_fluid_particles(
        &mut self,
        positions: &[Vec3],
        velocities: Option<&[Vec3]>,
    ) -> Result<(), Error> {
        check_finite("positions", positions)?;
        if let Some(v) = velocities {
            if v.len() != positions.len() {
                return Err(Error::invalid(
                    "velocities",
                    v.len(),
                    &format!("must have one entry per position ({})", positions.len()),
                ));
            }
            check_finite("velocities", v)?;
        }
        let first = self.fluid.positions.len();
        if first + positions.len() > u32::MAX as usize / 64 {
            return Err(Error::invalid(
                "positions",
                positions.len(),
                "would exceed the particle limit",
            ));
        }
        self.fluid.positions.extend_from_slice(positions);
        match velocities {
            Some(v) => self.fluid.velocities.extend_from_slice(v),
            None => self
                .fluid
                .velocities
                .resize(first + positions.len(), Vec3::zeros()),
        }
        self.fluid.densities.resize(first + positions.len(), 0.0);
        self.fluid
            .ids
            .extend((first..first + positions.len()).map(|i| i as u32));
        Ok(())
    }

    /// Adds a cubic lattice of fluid particles with spacing 2r: centres at
    /// `start + 2r·(i, j, k)` for i < count[0], j < count[1], k < count[2], all moving with `velocity`.
    pub fn add_fluid_block(
        &mut self,
        start: Vec3,
        count: [usize; 3],
        velocity: Vec3,
    ) -> Result<(), Error> {
        let total = count.iter().try_fold(1usize, |acc, &c| acc.checked_mul(c));
        match total {
            Some(n) if n > 0 && n <= u32::MAX as usize / 64 => {}
            _ => {
                return Err(Error::invalid(
                    "count",
                    format!("{count:?}"),
                    "must be positive and not absurdly large",
                ));
            }
        }
        let d = self.params.spacing();
        let positions: Vec<Vec3> = (0..count[2])
            .flat_map(|k| (0..count[1]).flat_map(move |j| (0..count[0]).map(move |i| (i, j, k))))
            .map(|(i, j, k)| start + Vec3::new(i as f64, j as f64, k as f64) * d)
            .collect();
        check_finite("start", &[start, velocity])?;
        self.add_fluid_particles(&positions, Some(&vec![velocity; positions.len()]))
    }

    /// Adds static boundary particles at `positions` (m).
    pub fn add_boundary_particles(&mut self, positions: &[Vec3]) -> Result<(), Error> {
        check_finite("positions", positions)?;
        if self.boundary.positions.len() + positions.len() > MAX_PARTICLES {
            return Err(Error::invalid(
                "positions",
                positions.len(),
                "would exceed the boundary particle limit",
            ));
        }
        self.boundary.positions.extend_from_slice(positions);
        self.boundary.dirty = true;
        Ok(())
    }

    /// Adds a closed container box: its six walls sampled with boundary particles of spacing r,
    /// `layers` layers thick (1–3). Fluid outside every container counts as escaped.
    pub fn add_container(&mut self, container: Aabb, layers: usize) -> Result<(), Error> {
        check_finite("container", &[container.min, container.max])?;
        let r = self.params.particle_radius;
        let size = container.max - container.min;
        if (0..3).any(|a| size[a] < 2.0 * self.params.spacing()) {
            return Err(Error::invalid(
                "container",
                format!(
                    "{:?}..{:?}",
                    container.min.as_slice(),
                    container.max.as_slice()
                ),
                "must be at least two particle spacings wide along every axis",
            ));
        }
        if !(1..=3).contains(&layers) {
            return Err(Error::invalid("layers", layers, "must be 1, 2 or 3"));
        }
        if size.iter().any(|&s| s / r > 1e5) {
            return Err(Error::invalid(
                "container",
                format!("{:?}", size.as_slice()),
                "is too large for the particle radius",
            ));
        }
        let expected = box_wall_sample_count(&container, r, layers);
        if expected + self.boundary.positions.len() as f64 > MAX_PARTICLES as f64 {
            return Err(Error::invalid(
                "container",
                format!("{:?}", size.as_slice()),
                &format!("needs about {expected:.3e} boundary particles, more than the limit"),
            ));
        }
        let samples = sample_box_walls(&container, r, layers);
        self.add_boundary_particles(&samples)?;
        self.containers.push(container);
        Ok(())
    }

    /// Number of fluid particles.
    pub fn fluid_count(&self) -> usize {
        self.fluid.positions.len()
    }

    /// Number of boundary particles.
    pub fn boundary_count(&self) -> usize {
        self.boundary.positions.len()
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The time step (s) the next CFL-limited step will use.
    pub fn next_dt(&self) -> f64 {
        self.next_dt
    }

    /// Statistics of the last step, if any step was taken.
    pub fn last_step(&self) -> Option<&StepStats> {
        self.last.as_ref()
    }

    /// δ_k, the largest particle displacement (m) of each outer iteration of the last step.
    pub fn last_displacements(&self) -> &[f64] {
        &self.buffers.displacements
    }

    /// The container boxes added so far.
    pub fn containers(&self) -> &[Aabb] {
        &self.containers
    }

    /// Fluid particle mass m (kg).
    pub fn particle_mass(&self) -> f64 {
        self.constraint.mass
    }

    /// Copies a per-particle quantity into `out` in the order the particles were added.
    fn gather_by_id<T: Copy>(&self, values: &[T], out: &mut [T]) {
        for (v, &id) in values.iter().zip(&self.fluid.ids) {
            out[id as usize] = *v;
        }
    }

    /// Fluid positions (m) in the order they were added.
    pub fn positions(&self) -> Vec<Vec3> {
        let mut out = vec![Vec3::zeros(); self.fluid_count()];
        self.gather_by_id(&self.fluid.positions, &mut out);
        out
    }

    /// Fluid velocities (m/s) in the order the particles were added.
    pub fn velocities(&self) -> Vec<Vec3> {
        let mut out = vec![Vec3::zeros(); self.fluid_count()];
        self.gather_by_id(&self.fluid.velocities, &mut out);
        out
    }

    /// Replaces every fluid velocity (m/s), given in the order the particles were added.
    /// Rejects a length mismatch or a non-finite value without changing the world.
    pub fn set_velocities(&mut self, velocities: &[Vec3]) -> Result<(), Error> {
        if velocities.len() != self.fluid_count() {
            return Err(Error::invalid(
                "velocities",
                velocities.len(),
                &format!(
                    "must have one entry per fluid particle ({})",
                    self.fluid_count()
                ),
            ));
        }
        check_finite("velocities", velocities)?;
        let fluid = &mut self.fluid;
        for (v, &id) in fluid.velocities.iter_mut().zip(&fluid.ids) {
            *v = velocities[id as usize];
        }
        Ok(())
    }

    /// Fluid densities (kg/m³) after the last step, in the order the particles were added
    /// (zero before the first step).
    pub fn densities(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.fluid_count()];
        self.gather_by_id(&self.fluid.densities, &mut out);
        out
    }

    /// Static boundary particle positions (m), in the world's storage order.
    pub fn boundary_positions(&self) -> &[Vec3] {
        &self.boundary.positions
    }

    /// Kinetic energy Σ ½m|v|² (J).
    pub fn kinetic_energy(&self) -> f64 {
        let m = self.constraint.mass;
        self.pool
            .install(|| reduce::sum(&self.fluid.velocities, |v| 0.5 * m * v.norm_squared()))
    }

    /// Potential energy −Σ m g·x (J), zero at the origin.
    pub fn potential_energy(&self) -> f64 {
        let m = self.constraint.mass;
        let g = Vec3::from(self.params.gravity);
        self.pool
            .install(|| reduce::sum(&self.fluid.positions, |x| -m * g.dot(x)))
    }

    /// Root-mean-square speed of the fluid (m/s).
    pub fn rms_velocity(&self) -> f64 {
        let n = self.fluid_count().max(1) as f64;
        (self
            .pool
            .install(|| reduce::sum(&self.fluid.velocities, |v| v.norm_squared()))
            / n)
            .sqrt()
    }

    /// Fluid particles farther than r/2 outside every container, or non-finite (0 without containers).
    pub fn escaped_count(&self) -> usize {
        if self.containers.is_empty() {
            return 0;
        }
        let margin = 0.5 * self.params.particle_radius;
        self.fluid
            .positions
            .iter()
            .filter(|p| !self.containers.iter().any(|c| c.contains(p, margin)))
            .count()
    }

    /// Number of fluid particles with a non-finite position or velocity.
    pub fn nan_count(&self) -> usize {
        let bad = |v: &Vec3| !v.iter().all(|c| c.is_finite());
        self.fluid
            .positions
            .iter()
            .zip(&self.fluid.velocities)
            .filter(|(x, v)| bad(x) || bad(v))
            .count()
    }

    /// A hex SHA-256 digest of the positions' bit patterns in the order the particles were
    /// added; equal digests mean bitwise identical positions.
    pub fn positions_hash(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut hasher = Sha256::new();
        // The particles' slots in the order they were added (a quarter of a copy of the
        // positions).
        let mut slots = vec![0u32; self.fluid_count()];
        for (slot, &id) in self.fluid.ids.iter().enumerate() {
            slots[id as usize] = slot as u32;
        }
        for &slot in &slots {
            for c in self.fluid.positions[slot as usize].iter() {
                hasher.update(c.to_bits().to_le_bytes());
            }
        }
        hasher
            .finalize()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }

    /// Makes sure there is a grid and the boundary is sorted with volumes. The grid is
    /// (re)built, with slack around `points` and the boundary, when there is none, when the
    /// boundary changed, or when `outgrown` (some of `points` lie outside it) unless it
    /// already hit its cell limit; then outlying particles are clamped into border cells,
    /// which stays correct.
    pub(crate) fn prepare_grid(&mut self, points: &[Vec3], outgrown: bool) {
        let outgrown = self.grid.is_none() || (outgrown && !self.grid_capped);
        if outgrown || self.boundary.dirty {
            let bounds = [points, &self.boundary.positions]
                .iter()
                .filter_map(|p| Aabb::around(p))
                .reduce(|a, b| a.union(&b));
            let Some(bounds) = bounds else { return };
            let finite = |v: Vec3| {
                v.map(|c| {
                    if c.is_finite() {
                        c.clamp(-1e6, 1e6)
                    } else {
                        0.0
                    }
                })
            };
            // A quarter of the extent as slack, so a splash does not rebuild the grid every step.
            let slack = (bounds.max - bounds.min) * 0.25;
            let h = self.params.support_radius();
            let grid =
                UniformGrid::covering(finite(bounds.min - slack), finite(bounds.max + slack), h);
            self.grid_capped = !self.pool.install(|| grid.covers(points));
            self.grid = Some(grid);
            self.boundary.dirty = true;
        }
        if self.boundary.dirty {
            self.sort_boundary();
        }
    }

    pub(crate) fn sort_boundary(&mut self) {
        let Some(grid) = &self.grid else { return };
        let b = &mut self.boundary;
        let mut order = Vec::new();
        self.pool.install(|| {
            grid.sort(&b.positions, &mut order, &mut b.table);
            b.table.release_scratch();
            b.positions = order.iter().map(|&i| b.positions[i as usize]).collect();
            b.by_component.fill(&b.positions);
            let kernel = &self.constraint.kernel;
            let volumes = akinci_volumes(grid, &b.table, &b.positions, &b.by_component, kernel);
            b.psi = volumes
                .iter()
                .map(|v| v * self.params.rest_density)
                .collect();
        });
        b.dirty = false;
    }
}

fn check_finite(field: &str, values: &[Vec3]) -> Result<(), Error> {
    match values.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
        Some(i) => Err(Error::invalid(
            format!("{field}[{i}]"),
            format!("{:?}", values[i].as_slice()),
            "must be finite",
        )),
        None => Ok(()),
    }
}

/// Most particles of one kind (fluid or boundary) a world holds; indices must fit in u32 with room.
const MAX_PARTICLES: usize = u32::MAX as usize / 64;

/// The number of samples [`sample_box_walls`] makes for `container` (computed in f64, so that
/// absurd boxes are rejected before anything is allocated).
fn box_wall_sample_count(container: &Aabb, spacing: f64, layers: usize) -> f64 {
    (0..layers)
        .map(|layer| {
            let extent = container.max - container.min + Vec3::repeat(2.0 * layer as f64 * spacing);
            let n = extent.map(|e| (e / spacing).ceil().max(1.0));
            let outer = (n.x + 1.0) * (n.y + 1.0) * (n.z + 1.0);
            let inner = (n.x - 1.0) * (n.y - 1.0) * (n.z - 1.0);
            outer - inner
        })
        .sum()
}

/// Support for embedders such as the C API: fallible reservation and copies into caller buffers.
impl World {
    /// Reserves room for `additional` more fluid particles in every per-particle array, so that
    /// a following add does not fail to allocate. Changes nothing observable.
    /// Errors when the memory cannot be had; the world stays usable.
    pub fn try_reserve_fluid(
        &mut self,
        additional: usize,
    ) -> Result<(), std::collections::TryReserveError> {
        let f = &mut self.fluid;
        f.positions.try_reserve(additional)?;
        f.velocities.try_reserve(additional)?;
        f.densities.try_reserve(additional)?;
        f.ids.try_reserve(additional)
    }

    /// Reserves room for `additional` more boundary particles (see [`World::try_reserve_fluid`]).
    pub fn try_reserve_boundary(
        &mut self,
        additional: usize,
    ) -> Result<(), std::collections::TryReserveError> {
        self.boundary.positions.try_reserve(additional)
    }

    /// Writes fluid positions (m) as x, y, z triples of `f32` into `out[..3·fluid_count()]`, in
    /// the order the particles were added, without allocating. Returns the number of floats
    /// needed as the error, leaving `out` untouched, when `out` is too short.
    pub fn write_positions_f32(&self, out: &mut [f32]) -> Result<(), usize> {
        self.write_vectors_f32(&self.fluid.positions, out)
    }

    /// Writes fluid velocities (m/s) like [`World::write_positions_f32`].
    pub fn write_velocities_f32(&self, out: &mut [f32]) -> Result<(), usize> {
        self.write_vectors_f32(&self.fluid.velocities, out)
    }

    /// Writes fluid densities (kg/m³, zero before the first step) into
    /// `out[..fluid_count()]` in the order the particles were added; errs with the number of
    /// floats needed, leaving `out` untouched, when `out` is too short.
    pub fn write_densities_f32(&self, out: &mut [f32]) -> Result<(), usize> {
        let n = self.fluid_count();
        let out = out.get_mut(..n).ok_or(n)?;
        for (&rho, &id) in self.fluid.densities.iter().zip(&self.fluid.ids) {
            out[id as usize] = rho as f32;
        }
        Ok(())
    }

    fn write_vectors_f32(&self, values: &[Vec3], out: &mut [f32]) -> Result<(), usize> {
        let n = 3 * self.fluid_count();
        let out = out.get_mut(..n).ok_or(n)?;
        for (v, &id) in values.iter().zip(&self.fluid.ids) {
            let i = 3 * id as usize;
            out[i..i + 3].copy_from_slice(&[v.x as f32, v.y as f32, v.z as f32]);
        }
        Ok(())
    }
}

use crate::boundary::mesh::{TriangleMesh, sample_count_bound, sample_poisson_disk};

/// Most boundary particles one triangle mesh may need (by [`sample_count_bound`]), which also
/// bounds the sampler's time and memory.
const MAX_MESH_SAMPLES: f64 = 50e6;

/// Static triangle meshes as obstacles.
impl World {
    /// Adds a static obstacle: the surface of `mesh` (m) sampled by Poisson disk with a
    /// minimum distance of one particle radius r (see [`sample_poisson_disk`]), the samples
    /// added as boundary particles. Their Akinci volumes are computed before the next step.
    /// Winding does not matter and the mesh need not be closed; only the surface is sampled,
    /// one layer thick. Errors, leaving the world unchanged, when the mesh is far larger than r
    /// (an extent above 10⁶·r or more than about 5·10⁷ samples) or the boundary particle
    /// limit would be exceeded.
    pub fn add_boundary_mesh(&mut self, mesh: &TriangleMesh) -> Result<(), Error> {
        let r = self.params.particle_radius;
        let bounds = mesh.bounds();
        let size = bounds.max - bounds.min;
        if size.iter().any(|&s| s / r > 1e6) {
            return Err(Error::invalid(
                "mesh",
                format!("extent {:?} m", size.as_slice()),
                &format!("is too large for the particle radius {r} m (at most 1e6·r per axis)"),
            ));
        }
        let bound = sample_count_bound(mesh, r);
        if !(bound <= MAX_MESH_SAMPLES
            && bound + self.boundary.positions.len() as f64 <= MAX_PARTICLES as f64)
        {
            return Err(Error::invalid(
                "mesh",
                format!("area {:.3e} m² needing up to {bound:.3e}", mesh.area()),
                &format!(
                    "is too large for the particle radius {r} m (at most {MAX_MESH_SAMPLES:.0e} \
                     boundary particles, {MAX_PARTICLES} in all)"
                ),
            ));
        }
        let samples = sample_poisson_disk(mesh, r);
        self.add_boundary_particles(&samples)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::Aabb;

    /// Velocities set in insertion order come back in insertion order after the particles
    /// were re-sorted by a step; bad input changes nothing.
    #[test]
    fn set_velocities_uses_insertion_order_and_rejects_bad_input() {
        let mut world = World::new(Params::default()).unwrap();
        let container = Aabb {
            min: Vec3::zeros(),
            max: Vec3::repeat(0.5),
        };
        world.add_container(container, 1).unwrap();
        world
            .add_fluid_block(Vec3::repeat(0.1), [3, 2, 2], Vec3::zeros())
            .unwrap();
        world.step().unwrap();
        let wanted: Vec<Vec3> = (0..12).map(|i| Vec3::new(i as f64, 0.5, -1.0)).collect();
        world.set_velocities(&wanted).unwrap();
        assert_eq!(world.velocities(), wanted);
        assert!(world.set_velocities(&wanted[..11]).is_err());
        let mut bad = wanted.clone();
        bad[3].y = f64::NAN;
        assert!(world.set_velocities(&bad).is_err());
        assert_eq!(world.velocities(), wanted);
    }
}
