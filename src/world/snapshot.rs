//! The particles as they stand between steps, sorted into a neighbour grid of their own: what
//! the readings taken between steps (the constraint pressures, the probes) search, without
//! touching the step's buffers.

use super::World;
use crate::Vec3;
use crate::boundary::{Aabb, WallField, akinci_volumes};
use crate::constraint::{Neighborhood, weigh_by_inertia};
use crate::neighbors::{CellTable, NeighborLists, PointsByComponent, UniformGrid};
use std::collections::TryReserveError;

/// What a reading between steps panics with when its memory cannot be had: such readings
/// (densities, pressures, probes) serve the Rust API and the tools, not the C API.
const OUT_OF_MEMORY: &str = "out of memory for a reading of the particles between steps";

/// Fluid and boundary particles sorted into one grid of cell size H, the boundary with its
/// Akinci masses.
pub(crate) struct Snapshot {
    /// The grid (cell size: the support radius H).
    pub grid: UniformGrid,
    /// Where each cell's fluid particles lie in `fluid`.
    pub fluid_table: CellTable,
    /// Fluid positions (m), in the order of `fluid_table`.
    pub fluid: Vec<Vec3>,
    /// The storage index in the world of the particle at each of `fluid`.
    pub fluid_order: Vec<u32>,
    /// Where each cell's boundary particles lie in `boundary`.
    pub boundary_table: CellTable,
    /// Boundary positions (m), in the order of `boundary_table`, by component.
    pub boundary: PointsByComponent,
    /// Akinci mass ψ_b = ρ0·V_b (kg) of each of `boundary` (docs/method.md §2.6).
    pub psi: Vec<f64>,
    /// The container walls without particles (docs/method.md §7).
    pub walls: Vec<WallField>,
}

impl Snapshot {
    /// For every query point, the fluid particles within the support radius `h` (m), as
    /// indices into `fluid`, ascending.
    pub fn fluid_near(&self, queries: &[Vec3], h: f64, out: &mut NeighborLists) {
        let (table, points) = (&self.fluid_table, &self.fluid);
        self.grid
            .search(table, points, queries, h, false, out)
            .expect(OUT_OF_MEMORY);
    }

    /// For every query point, the boundary particles within the support radius `h` (m), as
    /// indices into `boundary`, ascending.
    pub fn boundary_near(&self, queries: &[Vec3], h: f64, out: &mut NeighborLists) {
        let (table, points) = (&self.boundary_table, &self.boundary);
        self.grid
            .search_in(table, points, queries, h, false, out)
            .expect(OUT_OF_MEMORY);
    }
}

/// The items of `items` in a vector of exactly their number, or the error when it cannot be
/// had (`items` is walked twice).
fn try_collect<T>(items: impl Iterator<Item = T> + Clone) -> Result<Vec<T>, TryReserveError> {
    let mut out = Vec::new();
    out.try_reserve_exact(items.clone().count())?;
    out.extend(items);
    Ok(out)
}

impl World {
    /// The fluid and boundary particles sorted into a fresh grid, or `None` when there are
    /// none. Runs on the caller's thread pool (call it inside the world's). Before the first
    /// step the boundary has no masses yet; they are then computed here as the step would,
    /// over the boundary particles there are. Panics when the memory cannot be had.
    pub(crate) fn snapshot(&self) -> Option<Snapshot> {
        self.snapshot_with(0.0, false)
    }

    /// [`World::snapshot`] with a grid that reaches `margin` (m) beyond the particles, for
    /// particles that will move that far; with `bodies`, the moving bodies' particles at
    /// their current poses join the boundary with their own masses (before the first step
    /// the boundary does not hold them yet).
    pub(crate) fn snapshot_with(&self, margin: f64, bodies: bool) -> Option<Snapshot> {
        self.snapshot_of(&self.fluid.positions, margin, bodies)
    }

    /// [`World::snapshot_with`] of the fluid positions `fluid` (m) in place of the world's
    /// own, with the world's boundary. `fluid_order` then indexes `fluid`.
    pub(crate) fn snapshot_of(
        &self,
        fluid: &[Vec3],
        margin: f64,
        bodies: bool,
    ) -> Option<Snapshot> {
        let h = self.params.support_radius();
        let boundary = &self.boundary;
        let (mut points, known) = if bodies && boundary.has_moving() {
            let (statics, _) = boundary.statics();
            let psi = (boundary.psi.len() == boundary.len()).then(|| {
                (0..boundary.len())
                    .filter(|&k| !boundary.is_moving_particle(k))
                    .map(|k| boundary.psi[k])
                    .collect::<Vec<f64>>()
            });
            (statics, psi)
        } else {
            let psi = (boundary.psi.len() == boundary.len()).then(|| boundary.psi.clone());
            (boundary.positions.to_vec(), psi)
        };
        let bounds = [
            Aabb::around(fluid),
            Aabb::around(&points),
            Aabb::enclosing(self.moving_body_particles(bodies).map(|(p, _)| p)),
        ]
        .into_iter()
        .flatten()
        .reduce(|a, b| a.union(&b))?;
        let pad = Vec3::repeat(margin);
        let grid =
            UniformGrid::covering(bounds.min - pad, bounds.max + pad, h).expect(OUT_OF_MEMORY);
        let mut psi = match known.filter(|_| !boundary.dirty) {
            Some(psi) => psi,
            None => self.static_masses(&grid, &points).expect(OUT_OF_MEMORY),
        };
        for (p, own) in self.moving_body_particles(bodies) {
            points.push(p);
            psi.push(own);
        }
        Some(
            self.sorted(grid, fluid, &points, &psi)
                .expect(OUT_OF_MEMORY),
        )
    }

    /// The fluid within `region` (m) and the boundary within reach of it, sorted into a grid
    /// of their own that reaches `margin` (m) beyond the region, the moving bodies' particles
    /// at their current poses included with their own masses; and the storage index of each
    /// fluid particle taken. `fluid_order` of the snapshot indexes that list, not the storage.
    /// Where the boundary's masses are not known yet, those of the static particles within
    /// reach are computed from their neighbours as a step would. `None` when no fluid lies in
    /// the region; errors, changing nothing, when memory cannot be had.
    pub(crate) fn snapshot_near(
        &self,
        region: &Aabb,
        margin: f64,
    ) -> Result<Option<(Snapshot, Vec<u32>)>, TryReserveError> {
        let h = self.params.support_radius();
        let grow = |b: &Aabb, by: f64| Aabb {
            min: b.min - Vec3::repeat(by),
            max: b.max + Vec3::repeat(by),
        };
        // Boundary particles within h of the region reach its fluid; their masses need their
        // own neighbours, within h of them.
        let (reach, wide) = (grow(region, h), grow(region, 2.0 * h));
        let positions = &self.fluid.positions;
        let taken = try_collect(
            (0..positions.len() as u32).filter(|&i| region.contains(&positions[i as usize], 0.0)),
        )?;
        if taken.is_empty() {
            return Ok(None);
        }
        let fluid = try_collect(taken.iter().map(|&i| positions[i as usize]))?;
        let boundary = &self.boundary;
        let moving = boundary.has_moving();
        let statics = |within: Aabb| {
            (0..boundary.len()).filter(move |&k| {
                !(moving && boundary.is_moving_particle(k))
                    && within.contains(&boundary.positions.at(k), 0.0)
            })
        };
        let grid_box = grow(region, 2.0 * h + margin);
        let grid = UniformGrid::covering(grid_box.min, grid_box.max, h)?;
        let (mut points, mut psi) = if boundary.psi.len() == boundary.len() && !boundary.dirty {
            let points = try_collect(statics(reach).map(|k| boundary.positions.at(k)))?;
            (
                points,
                try_collect(statics(reach).map(|k| boundary.psi[k]))?,
            )
        } else {
            // The static particles near the region, with their neighbours.
            let near = try_collect(statics(wide).map(|k| boundary.positions.at(k)))?;
            let psi = self.static_masses(&grid, &near)?;
            let kept = |k: &usize| reach.contains(&near[*k], 0.0);
            let points = try_collect((0..near.len()).filter(kept).map(|k| near[k]))?;
            (
                points,
                try_collect((0..near.len()).filter(kept).map(|k| psi[k]))?,
            )
        };
        for (p, own) in self.moving_body_particles(true) {
            if reach.contains(&p, 0.0) {
                points.try_reserve(1)?;
                psi.try_reserve(1)?;
                points.push(p);
                psi.push(own);
            }
        }
        Ok(Some((self.sorted(grid, &fluid, &points, &psi)?, taken)))
    }

    /// The Akinci masses ψ_b = ρ0·V_b (kg) of the static boundary particles at `points` (m),
    /// from their neighbours among them (docs/method.md §2.6), sorted into `grid`.
    pub(super) fn static_masses(
        &self,
        grid: &UniformGrid,
        points: &[Vec3],
    ) -> Result<Vec<f64>, TryReserveError> {
        let mut table = CellTable::default();
        let mut order = Vec::new();
        grid.sort(points, &mut order, &mut table)?;
        let mut by_component = PointsByComponent::default();
        by_component.fill(points)?;
        let mut bx = PointsByComponent::default();
        bx.try_permuted_from(&by_component, &order)?;
        let volumes = akinci_volumes(grid, &table, &bx, &self.constraint.kernel)?;
        let mut psi = try_collect(std::iter::repeat_n(0.0, points.len()))?;
        for (&k, v) in order.iter().zip(volumes) {
            psi[k as usize] = v * self.params.rest_density;
        }
        Ok(psi)
    }

    /// The fluid at `fluid` and the boundary at `points` with masses `psi` (kg) sorted into
    /// `grid`.
    fn sorted(
        &self,
        grid: UniformGrid,
        fluid: &[Vec3],
        points: &[Vec3],
        psi: &[f64],
    ) -> Result<Snapshot, TryReserveError> {
        let (mut fluid_table, mut boundary_table) = (CellTable::default(), CellTable::default());
        let (mut fluid_order, mut boundary_order) = (Vec::new(), Vec::new());
        grid.sort(fluid, &mut fluid_order, &mut fluid_table)?;
        grid.sort(points, &mut boundary_order, &mut boundary_table)?;
        let sorted_fluid = try_collect(fluid_order.iter().map(|&i| fluid[i as usize]))?;
        let mut by_component = PointsByComponent::default();
        by_component.fill(points)?;
        let mut bx = PointsByComponent::default();
        bx.try_permuted_from(&by_component, &boundary_order)?;
        let psi = try_collect(boundary_order.iter().map(|&i| psi[i as usize]))?;
        let mut walls = Vec::new();
        walls.try_reserve_exact(self.boundary.walls.len())?;
        walls.extend(self.boundary.walls.iter().cloned());
        Ok(Snapshot {
            grid,
            fluid_table,
            fluid: sorted_fluid,
            fluid_order,
            boundary_table,
            boundary: bx,
            psi,
            walls,
        })
    }

    /// With `bodies`, the moving bodies' particles at their current poses (m) with their masses
    /// ψ (kg); none otherwise.
    fn moving_body_particles(&self, bodies: bool) -> impl Iterator<Item = (Vec3, f64)> + '_ {
        self.bodies
            .iter()
            .filter(move |b| bodies && b.moves())
            .flat_map(|b| {
                b.samples
                    .iter()
                    .zip(&b.psi)
                    .map(move |(s, &psi)| (b.pose.apply(s), psi))
            })
    }

    /// Runs `read` with the neighbourhood of every fluid particle of `snapshot` (its fluid and
    /// boundary neighbours within the support radius, with the projection weights), indexed
    /// in the snapshot's order. Runs on the caller's thread pool.
    pub(crate) fn with_neighborhood<R>(
        &self,
        snapshot: &Snapshot,
        read: impl FnOnce(&Neighborhood) -> R,
    ) -> R {
        let h = self.params.support_radius();
        let x = &snapshot.fluid;
        let (mut fluid_lists, mut boundary_lists) =
            (NeighborLists::default(), NeighborLists::default());
        snapshot
            .grid
            .search(&snapshot.fluid_table, x, x, h, true, &mut fluid_lists)
            .expect(OUT_OF_MEMORY);
        snapshot.boundary_near(x, h, &mut boundary_lists);
        let mut weights = Vec::new();
        self.constraint.weights(&fluid_lists, &mut weights);
        // The weights of the step's projections (docs/method.md §14).
        let ratios = &self.materials.mass_ratios;
        if ratios.iter().any(|&r| r != 1.0) {
            let (order, materials) = (&snapshot.fluid_order, &self.fluid.materials);
            let mass = self.constraint.mass;
            weigh_by_inertia(&mut weights, mass, |k| {
                mass * ratios[materials[order[k] as usize] as usize]
            });
        }
        read(&Neighborhood {
            fluid: &fluid_lists,
            boundary: &boundary_lists,
            boundary_positions: &snapshot.boundary,
            boundary_psi: &snapshot.psi,
            weights: &weights,
            walls: &snapshot.walls,
        })
    }

    /// The SPH density ρ_i (kg/m³) of every fluid particle at its current position, in
    /// ascending id order (see [`World::ids`]). Unlike [`World::densities`], which reports
    /// the densities the last step ended with, this evaluates them now: before the first step
    /// it shows whether the fluid starts at rest density, against walls and obstacles too.
    ///
    /// # Panics
    /// When the memory for the neighbour search cannot be had.
    pub fn current_densities(&self) -> Vec<f64> {
        let in_storage_order = self.densities_now();
        let mut out = vec![0.0; self.fluid_count()];
        self.gather_by_id(&in_storage_order, &mut out);
        out
    }

    /// The SPH density ρ_i (kg/m³) of every fluid particle at its current position, in
    /// storage order.
    ///
    /// # Panics
    /// When the memory for the neighbour search cannot be had.
    pub(crate) fn densities_now(&self) -> Vec<f64> {
        self.pool.install(|| {
            let Some(snapshot) = self.snapshot() else {
                return Vec::new();
            };
            let mut rho = Vec::new();
            self.with_neighborhood(&snapshot, |nb| {
                self.constraint.densities(&snapshot.fluid, nb, &mut rho)
            });
            let mut out = vec![0.0; rho.len()];
            for (&k, value) in snapshot.fluid_order.iter().zip(rho) {
                out[k as usize] = value;
            }
            out
        })
    }
}
