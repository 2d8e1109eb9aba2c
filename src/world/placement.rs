//! Placing fluid where a user puts it (docs/method.md §2.7): particles whose centres lie
//! inside a solid are not created, those nearer a container wall than one particle radius r
//! are moved out to r, and what the new particles still compress, against walls, obstacles,
//! bodies and the fluid already there, is projected away on their positions alone before the
//! first step, so that no velocity comes of it.

use super::World;
use super::snapshot::Snapshot;
use crate::Vec3;
use crate::boundary::Aabb;
use crate::boundary::mesh::TriangleMesh;
use crate::boundary::winding::{is_closed_and_oriented, winding_number};
use crate::neighbors::NeighborLists;
use rayon::prelude::*;
use std::collections::TryReserveError;

/// The placement projection stops once no constraint of the fluid is compressed by more
/// than this fraction of ρ0: what is left turns into velocities of a few mm/s in the first
/// step.
pub(crate) const PLACEMENT_TOLERANCE: f64 = 2e-4;

/// Most passes of the placement projection. Each pass moves compression about one particle
/// spacing through the fluid; a block pressed into a wall needs some ten.
const PLACEMENT_PASSES: usize = 400;

/// Share of the summed corrections a pass applies: the constraints of neighbouring particles
/// overlap, and their full sum overshoots.
const PLACEMENT_RELAXATION: f64 = 0.5;

/// Longest move of a particle in one pass, in particle radii r.
const PLACEMENT_STEP: f64 = 0.25;

/// Most passes of the projection of an emitter's new layers: a layer is one particle deep,
/// and what a wall beside it compresses is gone in a few passes.
const EMISSION_PASSES: usize = 40;

/// The storage indices of the fluid a local projection took, and their positions (m) after it.
type SettledNear = (Vec<u32>, Vec<Vec3>);

/// How [`World::settle_new_fluid`] settles new fluid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Settling {
    /// Moves the new particles out of the solids only (particles given one by one may crowd
    /// arbitrarily, which no projection should chase).
    Clear,
    /// Also projects every compression near the new particles away on their positions, over
    /// the whole world, and evaluates the densities frames report before the first step.
    Block,
}

/// How far [`World::placement_projection`] goes.
#[derive(Clone, Copy, Debug)]
struct Projection {
    /// Most passes.
    passes: usize,
    /// Whether a particle that cannot move counts only the compression the movable ones add
    /// (fluid moving through a step reads compressions of its own, which emitted particles
    /// are not to chase).
    added_only: bool,
}

/// The projection of fluid added between steps.
const BLOCK: Projection = Projection {
    passes: PLACEMENT_PASSES,
    added_only: false,
};

/// The projection of an emitter's new layers.
const EMITTED: Projection = Projection {
    passes: EMISSION_PASSES,
    added_only: true,
};

/// The solids a new fluid particle must not start inside: the container boxes (their
/// outside) and the closed meshes of obstacles and bodies where they stand now.
pub(super) struct Solids {
    containers: Vec<Aabb>,
    closed: Vec<(TriangleMesh, Aabb)>,
}

impl Solids {
    /// Whether a fluid particle centred at `p` (m) would lie inside a solid: outside every
    /// container box (when there are any), or inside a closed obstacle or body mesh.
    pub(super) fn contain(&self, p: &Vec3) -> bool {
        let contained = self.containers.iter().any(|c| c.contains(p, 0.0));
        (!self.containers.is_empty() && !contained)
            || self
                .closed
                .iter()
                .any(|(mesh, bounds)| bounds.contains(p, 0.0) && inside(mesh, p))
    }
}

/// How far (m) a point may lie inside a closed mesh and still count as on its surface.
const SURFACE_TOLERANCE: f64 = 1e-6;

/// Whether `p` (m) lies inside the closed mesh, farther than [`SURFACE_TOLERANCE`] from its
/// surface: fluid may touch a solid. The winding number is 1 inside and 0 outside, and on the
/// surface itself, where it is undefined, one of the six points that tolerance away along the
/// axes reads 0.
fn inside(mesh: &TriangleMesh, p: &Vec3) -> bool {
    let e = SURFACE_TOLERANCE;
    // The winding number is −1 inside a mesh whose triangles face inwards.
    winding_number(mesh, p).abs() > 0.5
        && (0..6).all(|k| {
            let mut q = *p;
            q[k / 2] += if k % 2 == 0 { e } else { -e };
            winding_number(mesh, &q).abs() > 0.5
        })
}

/// The point of triangle `t` (its corners, m) nearest to `p` (m) (Ericson, *Real-Time
/// Collision Detection*, §5.1.5).
fn nearest_on_triangle(p: &Vec3, [a, b, c]: [Vec3; 3]) -> Vec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denominator = 1.0 / (va + vb + vc);
    a + ab * (vb * denominator) + ac * (vc * denominator)
}

/// The distance (m) from `p` (m) to the nearest point of `mesh`'s surface.
fn distance_to_mesh(p: &Vec3, mesh: &TriangleMesh) -> f64 {
    let vertices = mesh.vertices();
    mesh.triangles()
        .iter()
        .map(|t| (p - nearest_on_triangle(p, t.map(|i| vertices[i as usize]))).norm())
        .fold(f64::INFINITY, f64::min)
}

/// Moves `p` (m), outside the closed `mesh` or on it, to at least `r` (m) from its surface,
/// straight away from the nearest surface point (along the nearest triangle's outward normal
/// where `p` lies on the surface).
fn clear_of_mesh(p: &mut Vec3, mesh: &TriangleMesh, r: f64) {
    let vertices = mesh.vertices();
    let mut nearest: Option<(f64, Vec3, [Vec3; 3])> = None;
    for t in mesh.triangles() {
        let corners = t.map(|i| vertices[i as usize]);
        let q = nearest_on_triangle(p, corners);
        let d = (*p - q).norm_squared();
        if nearest.is_none_or(|(best, _, _)| d < best) {
            nearest = Some((d, q, corners));
        }
    }
    let Some((d, q, [a, b, c])) = nearest else {
        return;
    };
    if d >= r * r {
        return;
    }
    let away = if d > SURFACE_TOLERANCE * SURFACE_TOLERANCE {
        (*p - q).normalize()
    } else {
        let n = (b - a).cross(&(c - a)).normalize();
        let probe = q + n * (2.0 * SURFACE_TOLERANCE);
        if winding_number(mesh, &probe).abs() > 0.5 {
            -n
        } else {
            n
        }
    };
    *p = q + away * r;
}

/// Moves the particles of `positions` (m) marked in `movable` out to `r` (m) from the walls
/// of their holding containers in `holders` and from the closed meshes of `solids`.
fn clear_of_solids(
    positions: &mut [Vec3],
    holders: &[Option<Aabb>],
    movable: &[bool],
    solids: &Solids,
    r: f64,
) {
    clear_of_walls(positions, holders, r);
    for (mesh, bounds) in &solids.closed {
        let reach = Aabb {
            min: bounds.min - Vec3::repeat(r),
            max: bounds.max + Vec3::repeat(r),
        };
        positions
            .par_iter_mut()
            .zip(movable)
            .filter(|(p, free)| **free && reach.contains(p, 0.0))
            .for_each(|(p, _)| clear_of_mesh(p, mesh, r));
    }
}

/// Moves every particle of `positions` (m) that has a holding container in `holders` to at
/// least `r` (m) from each of its walls (where the box is wide enough for that).
fn clear_of_walls(positions: &mut [Vec3], holders: &[Option<Aabb>], r: f64) {
    for (p, holder) in positions.iter_mut().zip(holders) {
        if let Some(c) = holder {
            for a in 0..3 {
                if c.max[a] - c.min[a] > 2.0 * r {
                    p[a] = p[a].clamp(c.min[a] + r, c.max[a] - r);
                }
            }
        }
    }
}

impl World {
    /// The solids of the world as they stand, for [`Solids::contain`].
    pub(super) fn solids(&self) -> Solids {
        let bodies = self
            .bodies
            .iter()
            .filter(|b| is_closed_and_oriented(&b.mesh))
            .map(|b| b.placed_mesh());
        let closed = self
            .obstacles
            .iter()
            .cloned()
            .chain(bodies)
            .map(|mesh| {
                let bounds = mesh.bounds();
                (mesh, bounds)
            })
            .collect();
        Solids {
            containers: self.containers.clone(),
            closed,
        }
    }

    /// Settles the fluid particles whose ids are `first_id` or later, just added between
    /// steps among `solids` (the world's, as [`World::solids`] gave them): moves those nearer
    /// than r to a wall of the container that holds them, or to a closed obstacle or body, out
    /// to r (and keeps them there while it projects); with [`Settling::Block`] it then projects
    /// the density constraints of every particle near them on their positions alone until
    /// none is compressed by more than [`PLACEMENT_TOLERANCE`] beyond what the bulk of a
    /// lattice block reads at the world's mass factor (or [`PLACEMENT_PASSES`] have run), and
    /// evaluates every particle's density where it stands, as frames and reads report it until
    /// the next step. Velocities and the particles added before stay as they are.
    ///
    /// # Panics
    /// When the memory for the neighbour search cannot be had (as the readings between steps).
    pub(super) fn settle_new_fluid(&mut self, first_id: u64, solids: Solids, settling: Settling) {
        let holders: Vec<Option<Aabb>> = self
            .fluid
            .positions
            .iter()
            .zip(&self.fluid.ids)
            .map(|(p, &id)| self.holder(p).filter(|_| id >= first_id))
            .collect();
        let movable: Vec<bool> = self.fluid.ids.iter().map(|&id| id >= first_id).collect();
        self.settle(&movable, &holders, &solids, settling);
    }

    /// Makes room for the closed solid `mesh` (m, where it stands), just added to the world's
    /// solids: removes the fluid particles whose centres lie inside it or nearer than r to its
    /// surface (counted by [`World::removed_count`]) and projects what the solid compresses
    /// away on the positions of the fluid within H of it, as
    /// [`World::settle_new_fluid`] does for a block. Returns how many particles it removed.
    ///
    /// # Panics
    /// When the memory for the neighbour search cannot be had (as the readings between steps).
    pub(super) fn displace_fluid(&mut self, mesh: &TriangleMesh) -> usize {
        let bounds = mesh.bounds();
        let r = self.params.particle_radius;
        // A centre nearer than r to the surface would have to move out to r, crowding the
        // fluid beyond: its particle goes with those inside.
        let removed = self.fluid.remove_where(|p, _| {
            bounds.contains(p, r) && (inside(mesh, p) || distance_to_mesh(p, mesh) < r)
        });
        let h = self.params.support_radius();
        let movable: Vec<bool> = self
            .fluid
            .positions
            .iter()
            .map(|p| bounds.contains(p, h))
            .collect();
        if movable.iter().any(|&m| m) {
            let holders = vec![None; movable.len()];
            let solids = self.solids();
            self.settle(&movable, &holders, &solids, Settling::Block);
        }
        removed
    }

    /// What [`World::settle_new_fluid`] does, for the particles marked in `movable` (in storage
    /// order), kept clear of the walls of their containers in `holders`.
    fn settle(
        &mut self,
        movable: &[bool],
        holders: &[Option<Aabb>],
        solids: &Solids,
        settling: Settling,
    ) {
        let r = self.params.particle_radius;
        let clear =
            |positions: &mut [Vec3]| clear_of_solids(positions, holders, movable, solids, r);
        self.pool.install(|| clear(&mut self.fluid.positions));
        if settling == Settling::Clear {
            return;
        }
        let h = self.params.support_radius();
        let settled = self.pool.install(|| {
            let snapshot = self.snapshot_with(h, true)?;
            let positions = self.fluid.positions.clone();
            self.placement_projection(snapshot, positions, movable, &clear, BLOCK)
                .expect("memory for the placement's neighbour search")
        });
        if let Some(settled) = settled {
            self.fluid.positions = settled;
            self.fluid.pressures.clear();
        }
        self.fluid.densities = self.densities_now();
    }

    /// Settles the particles an emitter inserted at the start of a step, those stored from
    /// index `first` on, among `solids`: moves them out of the walls as
    /// [`World::settle_new_fluid`] does and projects their own compressions, and what they
    /// add to the fluid's, away on their positions, within reach of them and in at most
    /// [`EMISSION_PASSES`] passes. Errors when memory cannot be had, with the new particles
    /// part-way (the caller removes them).
    pub(super) fn settle_emitted(
        &mut self,
        first: usize,
        solids: &Solids,
    ) -> Result<(), TryReserveError> {
        let r = self.params.particle_radius;
        let count = self.fluid.len() - first;
        let mut holders = Vec::new();
        holders.try_reserve_exact(count)?;
        holders.extend(self.fluid.positions[first..].iter().map(|p| self.holder(p)));
        let mut all = Vec::new();
        all.try_reserve_exact(count)?;
        all.resize(count, true);
        self.pool.install(|| {
            clear_of_solids(
                &mut self.fluid.positions[first..],
                &holders,
                &all,
                solids,
                r,
            )
        });
        let world = &*self;
        let settled = world
            .pool
            .install(|| world.emission_projection(first, &holders, solids))?;
        if let Some((taken, settled)) = settled {
            for (&i, p) in taken.iter().zip(settled) {
                if i as usize >= first {
                    self.fluid.positions[i as usize] = p;
                }
            }
        }
        Ok(())
    }

    /// For [`World::settle_emitted`], on the world's pool: the storage indices of the fluid
    /// within reach of the new particles (stored from index `first` on, held by `holders`),
    /// with their positions after the projection, or `None` where nothing was compressed.
    fn emission_projection(
        &self,
        first: usize,
        holders: &[Option<Aabb>],
        solids: &Solids,
    ) -> Result<Option<SettledNear>, TryReserveError> {
        let r = self.params.particle_radius;
        let step = PLACEMENT_STEP * r;
        let h = self.params.support_radius();
        let Some(around) = Aabb::around(&self.fluid.positions[first..]) else {
            return Ok(None);
        };
        // The new particles, the fluid they can reach in the passes there are, and that
        // fluid's neighbours.
        let reach = Vec3::repeat(2.0 * h + EMISSION_PASSES as f64 * step);
        let region = Aabb {
            min: around.min - reach,
            max: around.max + reach,
        };
        let Some((snapshot, taken)) = self.snapshot_near(&region, h)? else {
            return Ok(None);
        };
        let mut positions = Vec::new();
        positions.try_reserve_exact(taken.len())?;
        positions.extend(taken.iter().map(|&i| self.fluid.positions[i as usize]));
        let mut movable = Vec::new();
        movable.try_reserve_exact(taken.len())?;
        movable.extend(taken.iter().map(|&i| i as usize >= first));
        let mut local_holders = Vec::new();
        local_holders.try_reserve_exact(taken.len())?;
        local_holders.extend(
            taken
                .iter()
                .map(|&i| (i as usize).checked_sub(first).and_then(|k| holders[k])),
        );
        let clear = |positions: &mut [Vec3]| {
            clear_of_solids(positions, &local_holders, &movable, solids, r)
        };
        let settled = self.placement_projection(snapshot, positions, &movable, &clear, EMITTED)?;
        Ok(settled.map(|settled| (taken, settled)))
    }

    /// The container box that holds `p` (m), the first of them, if any.
    fn holder(&self, p: &Vec3) -> Option<Aabb> {
        self.containers.iter().find(|c| c.contains(p, 0.0)).copied()
    }

    /// `positions` (m, indexed as the snapshot's `fluid_order` indexes) after the passes of
    /// the placement projection of the particles marked in `movable` (indexed alike) over
    /// `snapshot`, or `None` where nothing was compressed, as far as `projection` says.
    /// Runs on the caller's pool; errors when memory cannot be had.
    fn placement_projection(
        &self,
        mut snapshot: Snapshot,
        mut positions: Vec<Vec3>,
        movable: &[bool],
        clear: &(dyn Fn(&mut [Vec3]) + Sync),
        Projection { passes, added_only }: Projection,
    ) -> Result<Option<Vec<Vec3>>, TryReserveError> {
        let h = self.params.support_radius();
        let step = PLACEMENT_STEP * self.params.particle_radius;
        // What the lattice itself reads is the mass factor's choice, not placement's to undo.
        let tolerance = PLACEMENT_TOLERANCE + self.lattice_compression();
        let rest = self.constraint.rest_density;
        let (k, m) = (&self.constraint.kernel, self.constraint.mass);
        let (mut fluid_lists, mut boundary_lists) =
            (NeighborLists::default(), NeighborLists::default());
        let n = snapshot.fluid.len();
        let (mut free, mut lambdas, mut moves) = (Vec::new(), Vec::new(), Vec::new());
        free.try_reserve_exact(n)?;
        lambdas.try_reserve_exact(n)?;
        moves.try_reserve_exact(n)?;
        let mut moved = false;
        for _ in 0..passes {
            let x = &snapshot.fluid;
            free.clear();
            free.extend(snapshot.fluid_order.iter().map(|&i| movable[i as usize]));
            snapshot
                .grid
                .search(&snapshot.fluid_table, x, x, h, true, &mut fluid_lists)?;
            snapshot.grid.search_in(
                &snapshot.boundary_table,
                &snapshot.boundary,
                x,
                h,
                false,
                &mut boundary_lists,
            )?;
            let lists = (&fluid_lists, &boundary_lists);
            self.placement_multipliers(&snapshot, lists, &free, added_only, &mut lambdas);
            let worst = lambdas.iter().map(|l| l.1).fold(0.0, f64::max);
            if worst <= tolerance {
                break;
            }
            moved = true;
            (0..x.len())
                .into_par_iter()
                .map(|j| {
                    if !free[j] {
                        return Vec3::zeros();
                    }
                    let xj = x[j];
                    let lj = lambdas[j].0;
                    let mut d = Vec3::zeros();
                    for &i in fluid_lists.of(j) {
                        let i = i as usize;
                        d += (lj + lambdas[i].0) * (m / rest) * k.grad_w(&(xj - x[i]));
                    }
                    if lj != 0.0 {
                        let solid: Vec3 = boundary_lists
                            .of(j)
                            .iter()
                            .map(|&q| {
                                let q = q as usize;
                                snapshot.psi[q] * k.grad_w(&(xj - snapshot.boundary.at(q)))
                            })
                            .sum();
                        let walls = self.constraint.walls_at(xj, &snapshot.walls).gradient;
                        d += lj * (solid + walls) / rest;
                    }
                    let d = PLACEMENT_RELAXATION * d;
                    let len = d.norm();
                    if len > step { d * (step / len) } else { d }
                })
                .collect_into_vec(&mut moves);
            for ((p, d), &i) in x.iter().zip(&moves).zip(&snapshot.fluid_order) {
                positions[i as usize] = p + d;
            }
            clear(&mut positions);
            snapshot.grid.sort(
                &positions,
                &mut snapshot.fluid_order,
                &mut snapshot.fluid_table,
            )?;
            let order = &snapshot.fluid_order;
            snapshot.fluid.clear();
            snapshot
                .fluid
                .extend(order.iter().map(|&i| positions[i as usize]));
        }
        Ok(moved.then_some(positions))
    }

    /// The compression (dimensionless, ≥ 0) of the bulk of a lattice block of spacing 2r:
    /// 0 at the default mass factor, which makes the bulk read ρ0 (docs/method.md §2.2).
    fn lattice_compression(&self) -> f64 {
        let (k, d) = (&self.constraint.kernel, self.params.spacing());
        let mut sum = 0.0;
        for (i, j, l) in (-2i32..=2)
            .flat_map(|i| (-2i32..=2).flat_map(move |j| (-2i32..=2).map(move |l| (i, j, l))))
        {
            sum += k.w(Vec3::new(i as f64, j as f64, l as f64).norm() * d);
        }
        (self.constraint.mass * sum / self.constraint.rest_density - 1.0).max(0.0)
    }

    /// For every fluid particle of `snapshot`, the multiplier λ_i of its density constraint's
    /// projection onto the movable particles (0 where it is not compressed or cannot move
    /// anything) and its compression C_i (dimensionless). With `added_only`, a particle that
    /// cannot move counts only the compression the movable particles add to what it reads
    /// without them. Writes them into `out`, which holds room for them.
    fn placement_multipliers(
        &self,
        snapshot: &Snapshot,
        (fluid_lists, boundary_lists): (&NeighborLists, &NeighborLists),
        movable: &[bool],
        added_only: bool,
        out: &mut Vec<(f64, f64)>,
    ) {
        let k = &self.constraint.kernel;
        let m = self.constraint.mass;
        let rest = self.constraint.rest_density;
        let x = &snapshot.fluid;
        (0..x.len())
            .into_par_iter()
            .map(|i| {
                let xi = x[i];
                let near = fluid_lists.of(i);
                if !movable[i] && !near.iter().any(|&j| movable[j as usize]) {
                    return (0.0, 0.0);
                }
                let mut rho = m * k.w_zero();
                let mut own = Vec3::zeros();
                let mut others = 0.0;
                // What the movable particles add to ρ_i (kg/m³).
                let mut added = 0.0;
                for &j in near {
                    let j = j as usize;
                    let r = xi - x[j];
                    let w = m * k.w(r.norm());
                    rho += w;
                    let g = (m / rest) * k.grad_w(&r);
                    own += g;
                    if movable[j] {
                        others += g.norm_squared();
                        added += w;
                    }
                }
                for &q in boundary_lists.of(i) {
                    let q = q as usize;
                    let r = xi - snapshot.boundary.at(q);
                    rho += snapshot.psi[q] * k.w(r.norm());
                    own += (snapshot.psi[q] / rest) * k.grad_w(&r);
                }
                let walls = self.constraint.walls_at(xi, &snapshot.walls);
                rho += walls.density;
                own += walls.gradient / rest;
                let mut c = (rho / rest - 1.0).max(0.0);
                if added_only && !movable[i] {
                    c -= ((rho - added) / rest - 1.0).max(0.0);
                }
                let own = if movable[i] { own.norm_squared() } else { 0.0 };
                let denominator = own + others;
                if c == 0.0 || denominator <= 0.0 {
                    (0.0, c)
                } else {
                    (-c / (denominator + 1e-6), c)
                }
            })
            .collect_into_vec(out);
    }
}
