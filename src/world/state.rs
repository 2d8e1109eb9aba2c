//! The exact state of a world, exported and imported as plain data, so that a saved run
//! (a checkpoint) continues bit for bit as if it had never stopped.
//!
//! Besides positions, velocities and time, a step depends on the storage order of the
//! particles (the counting sort is stable, and the order decides the order of floating-point
//! sums), on the neighbour grid (its origin decides the cells, hence the sort), on the
//! boundary particles in their sorted order and on the online ρ_c estimate. All of these are
//! part of the state, as they are.

use super::World;
use crate::body::BodyState;
use crate::boundary::{Aabb, BoundaryCopy, WALLS};
use crate::emitter::{Emitter, EmitterState};
use crate::neighbors::UniformGrid;
use crate::solver::OnlineRho;
use crate::step::SearchGrid;
use crate::{Error, Vec3};
use serde::{Deserialize, Serialize};

/// A world's complete state apart from its parameters. Per-particle arrays are in the
/// world's storage order; `ids` gives each stored particle's id.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldState {
    /// Simulated time (s).
    pub time: f64,
    /// Steps taken.
    pub steps: u64,
    /// The size of the next CFL-limited step (s).
    pub next_dt: f64,
    /// Fluid positions (m).
    pub positions: Vec<Vec3>,
    /// Fluid velocities (m/s).
    pub velocities: Vec<Vec3>,
    /// Fluid densities after the last step (kg/m³).
    pub densities: Vec<f64>,
    /// The support the constraints gave each fluid particle in the last step, per unit mass
    /// (m/s²), which the next step's warm start reads (docs/method.md §4.1): empty while the
    /// warm start is off.
    pub supports: Vec<Vec3>,
    /// Each fluid particle's material (docs/method.md §14), one of the world's.
    pub materials: Vec<crate::material::MaterialId>,
    /// The pressure (Pa) of each fluid particle that the last step carried through its
    /// iteration (docs/method.md §10.1), which the pressure readings return: empty where
    /// the last step carried none.
    pub pressures: Vec<f64>,
    /// Each stored fluid particle's id (docs/method.md §12.1): unique, below `next_id`.
    pub ids: Vec<u64>,
    /// The id the next added particle gets: the number of particles ever added.
    pub next_id: u64,
    /// Particles removed so far: `next_id` less the number of particles.
    pub removed_count: u64,
    /// Static boundary particle positions (m): walls, obstacles and static bodies (moving
    /// bodies' particles follow from their poses).
    pub boundary_positions: Vec<Vec3>,
    /// The body each static boundary particle belongs to (its [`crate::BodyId`]), or
    /// `u32::MAX` for walls and obstacles.
    pub boundary_owners: Vec<u32>,
    /// The state of every body, in the order they were added.
    pub bodies: Vec<BodyState>,
    /// The boundary is sorted into `grid`'s cells (else it is sorted before the next step).
    pub boundary_sorted: bool,
    /// Container boxes (m).
    pub containers: Vec<Aabb>,
    /// The containers whose walls are fields rather than particles (m), each also one of
    /// `containers` (docs/method.md §7).
    pub field_walls: Vec<Aabb>,
    /// Sink boxes (m).
    pub sinks: Vec<Aabb>,
    /// The domain (m), if one is set.
    pub domain: Option<Aabb>,
    /// Every emitter's spec and progress, in the order they were added.
    pub emitters: Vec<EmitterState>,
    /// The neighbour grid, once a step built one.
    pub grid: Option<GridParts>,
    /// The grid reached its cell limit and no longer grows.
    pub grid_capped: bool,
    /// Chebyshev's online ρ_c estimate.
    pub online_rho: OnlineRho,
}

/// A neighbour grid's defining numbers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridParts {
    /// The corner of cell (0, 0, 0) (m).
    pub origin: [f64; 3],
    /// Cell edge length (m), the kernel support.
    pub cell_size: f64,
    /// Cells along x, y and z.
    pub dims: [usize; 3],
}

impl World {
    /// The world's exact state (a copy).
    pub fn export_state(&self) -> WorldState {
        let fluid = &self.fluid;
        let (boundary_positions, boundary_owners) = self.boundary.statics();
        WorldState {
            time: self.time,
            steps: self.steps,
            next_dt: self.next_dt,
            positions: fluid.positions.clone(),
            velocities: fluid.velocities.clone(),
            densities: fluid.densities.clone(),
            supports: fluid.supports.clone(),
            materials: fluid.materials.clone(),
            pressures: fluid.pressures.clone(),
            ids: fluid.ids.clone(),
            next_id: fluid.next_id,
            removed_count: fluid.removed,
            boundary_positions,
            boundary_owners,
            bodies: self.bodies.iter().map(|b| b.state()).collect(),
            boundary_sorted: !self.boundary.dirty,
            containers: self.containers.clone(),
            field_walls: self.boundary.walls.iter().map(|w| *w.container()).collect(),
            sinks: self.sinks.clone(),
            domain: self.domain,
            emitters: self.emitters.iter().map(|e| *e.state()).collect(),
            grid: self.grid.grid.as_ref().map(|g| {
                let (origin, cell_size, dims) = g.parts();
                GridParts {
                    origin: origin.into(),
                    cell_size,
                    dims,
                }
            }),
            grid_capped: self.grid.capped,
            online_rho: self.chebyshev.online(),
        }
    }

    /// Replaces the world's particles, containers, sinks, domain, emitters, grid and time
    /// with `state`, as [`World::export_state`] returned it; the world's parameters stay.
    /// Rejects a state whose arrays differ in length, whose values are not finite, whose ids
    /// repeat or reach `next_id`, whose counts disagree, whose boxes or emitters are invalid
    /// or whose grid is invalid, changing nothing; so does ([`Error::OutOfMemory`]) a
    /// shortage of memory for the grid and the boundary's sort.
    pub fn import_state(&mut self, state: WorldState) -> Result<(), Error> {
        let n = state.positions.len();
        for (name, len) in [
            ("velocities", state.velocities.len()),
            ("densities", state.densities.len()),
            ("materials", state.materials.len()),
            ("ids", state.ids.len()),
        ] {
            if len != n {
                return Err(Error::invalid(
                    format!("state.{name}"),
                    len,
                    &format!("must have one entry per position ({n})"),
                ));
            }
        }
        super::check_finite("state.positions", &state.positions)?;
        super::check_finite("state.velocities", &state.velocities)?;
        if !state.supports.is_empty() && state.supports.len() != n {
            return Err(Error::invalid(
                "state.supports",
                state.supports.len(),
                &format!("must be empty or hold one support per particle ({n})"),
            ));
        }
        super::check_finite("state.supports", &state.supports)?;
        if !state.pressures.is_empty() && state.pressures.len() != n {
            return Err(Error::invalid(
                "state.pressures",
                state.pressures.len(),
                &format!("must be empty or hold one pressure per particle ({n})"),
            ));
        }
        if let Some(p) = state.pressures.iter().find(|p| !p.is_finite()) {
            return Err(Error::invalid("state.pressures", p, "must be finite (Pa)"));
        }
        let emitted = state.emitters.iter().map(|e| &e.material);
        for (name, &m) in std::iter::repeat("state.materials")
            .zip(&state.materials)
            .chain(std::iter::repeat("state.emitters.material").zip(emitted))
        {
            self.materials.check_id(name, m)?;
        }
        super::check_finite("state.boundary_positions", &state.boundary_positions)?;
        let ascending = checked_ids(&state)?;
        for (k, sink) in state.sinks.iter().enumerate() {
            super::sinks::check_box(&format!("state.sinks[{k}]"), sink)?;
        }
        if let Some(domain) = &state.domain {
            super::sinks::check_box("state.domain", domain)?;
        }
        let emitters = state
            .emitters
            .iter()
            .enumerate()
            .map(|(k, e)| {
                Emitter::new(*e, self.params.spacing())
                    .map_err(|e| renamed(e, "emitter.", &format!("state.emitters[{k}].")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        if state.boundary_owners.len() != state.boundary_positions.len() {
            return Err(Error::invalid(
                "state.boundary_owners",
                state.boundary_owners.len(),
                &format!(
                    "must have one entry per boundary position ({})",
                    state.boundary_positions.len()
                ),
            ));
        }
        for (k, walls) in state.field_walls.iter().enumerate() {
            self.check_container(walls)
                .map_err(|e| renamed(e, "container", &format!("state.field_walls[{k}]")))?;
        }
        let mut fields = Vec::new();
        fields
            .try_reserve_exact(state.field_walls.len())
            .map_err(|_| Error::out_of_memory("the container walls"))?;
        fields.extend(state.field_walls.iter().map(|&c| self.wall_field(c)));
        let static_body = |o: u32| self.bodies.get(o as usize).is_some_and(|b| !b.moves());
        if let Some(o) = state
            .boundary_owners
            .iter()
            .find(|&&o| o != WALLS && !static_body(o))
        {
            return Err(Error::invalid(
                "state.boundary_owners",
                o,
                "must name a static body of this world or the walls",
            ));
        }
        if state.bodies.len() != self.bodies.len() {
            return Err(Error::invalid(
                "state.bodies",
                state.bodies.len(),
                &format!(
                    "must hold one state per body of the world ({})",
                    self.bodies.len()
                ),
            ));
        }
        for (k, b) in state.bodies.iter().enumerate() {
            let poses = std::iter::once(&b.pose).chain(&b.target);
            for pose in poses {
                crate::body::Pose::from_parts(pose.position, pose.wxyz())
                    .map_err(|e| prefixed_state(e, k))?;
            }
            b.velocity.validate().map_err(|e| prefixed_state(e, k))?;
            super::check_finite("state.bodies.load", &[b.force, b.torque])?;
        }
        if n > super::MAX_PARTICLES || state.boundary_positions.len() > super::MAX_PARTICLES {
            return Err(Error::invalid("state", n, "exceeds the particle limit"));
        }
        let oom = |_| Error::out_of_memory("the neighbour grid and the boundary");
        let grid = match state.grid {
            None => None,
            Some(g) => Some(
                UniformGrid::from_parts_checked(Vec3::from(g.origin), g.cell_size, g.dims)
                    .ok_or_else(|| {
                        Error::invalid("state.grid", format!("{g:?}"), "is not a valid grid")
                    })?
                    .map_err(oom)?,
            ),
        };
        let grid = SearchGrid {
            grid,
            capped: state.grid_capped,
        };
        // A sorted boundary was saved in its sorted order: sorting again keeps that order and
        // recomputes the same volumes. Sorted before anything is replaced, so that a
        // shortage of memory changes nothing.
        let mut boundary = self
            .boundary
            .with_statics(&state.boundary_positions, state.boundary_owners)
            .map_err(oom)?;
        if state.boundary_sorted {
            let (kernel, copy) = (&self.constraint.kernel, &mut BoundaryCopy::default());
            grid.sort_boundary(&self.pool, &self.params, kernel, &mut boundary, copy)
                .map_err(oom)?;
        }
        let fluid = &mut self.fluid;
        fluid.positions = state.positions;
        fluid.velocities = state.velocities;
        fluid.densities = state.densities;
        fluid.supports = state.supports;
        fluid.pressures = state.pressures;
        fluid.materials = state.materials;
        fluid.ids = state.ids;
        fluid.ascending = ascending;
        fluid.next_id = state.next_id;
        fluid.removed = state.removed_count;
        self.boundary = boundary;
        self.boundary.walls = fields;
        for (body, b) in self.bodies.iter_mut().zip(&state.bodies) {
            body.set_state(b);
        }
        self.containers = state.containers;
        self.sinks = state.sinks;
        self.domain = state.domain;
        self.emitters = emitters;
        self.time = state.time;
        self.steps = state.steps;
        self.next_dt = state.next_dt;
        self.chebyshev.set_online(state.online_rho);
        self.grid = grid;
        self.last = None;
        Ok(())
    }
}

/// The state's ids in ascending order, or an error when one repeats or is not below
/// `next_id`, or when `next_id` is not the particle count plus `removed_count`.
fn checked_ids(state: &WorldState) -> Result<Vec<u64>, Error> {
    let mut ascending = state.ids.clone();
    ascending.sort_unstable();
    if let Some(pair) = ascending.windows(2).find(|p| p[0] == p[1]) {
        return Err(Error::invalid("state.ids", pair[0], "must be unique"));
    }
    if let Some(&last) = ascending.last().filter(|&&id| id >= state.next_id) {
        return Err(Error::invalid(
            "state.ids",
            last,
            &format!("must be below state.next_id ({})", state.next_id),
        ));
    }
    let n = state.ids.len() as u64;
    if state.next_id.checked_sub(n) != Some(state.removed_count) {
        return Err(Error::invalid(
            "state.removed_count",
            state.removed_count,
            &format!(
                "must be state.next_id ({}) less the particle count ({n})",
                state.next_id
            ),
        ));
    }
    Ok(ascending)
}

/// `e` with the field's prefix `from` replaced by `to`, in its field and its message.
fn renamed(e: Error, from: &str, to: &str) -> Error {
    match e {
        Error::InvalidArgument { field, message } => Error::InvalidArgument {
            field: field.replacen(from, to, 1),
            message: message.replacen(from, to, 1),
        },
        other => other,
    }
}

/// Names body `k` of a state in an error.
fn prefixed_state(e: Error, k: usize) -> Error {
    match e {
        Error::InvalidArgument { field, message } => Error::InvalidArgument {
            field: format!("state.bodies[{k}].{field}"),
            message,
        },
        other => other,
    }
}
