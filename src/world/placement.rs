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

/// How [`World::settle_new_fluid`] settles new fluid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Settling {
    /// Moves the new particles out of the solids only (particles given one by one may crowd
    /// arbitrarily, which no projection should chase).
    Clear,
    /// Also projects every compression near the new particles away on their positions, over
    /// the whole world, and evaluates the densities frames report before the first step.
    Block,
    /// Also projects the new particles' own compressions away, within reach of them, in at
    /// most [`EMISSION_PASSES`] passes: an emitter's layers, inserted at the start of a step
    /// into fluid that is moving.
    Emitted,
}

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

    /// Settles the fluid particles whose ids are `first_id` or later, just added among
    /// `solids` (the world's, as [`World::solids`] gave them): moves those nearer than r to a
    /// wall of the container that holds them, or to a closed obstacle or body, out to r (and
    /// keeps them there while it projects), then, as `settling` says, projects the density
    /// constraints on the new particles' positions alone until none is compressed by more
    /// than [`PLACEMENT_TOLERANCE`] beyond what the bulk of a lattice block reads at the
    /// world's mass factor (or the passes run out). Velocities and the particles added before
    /// stay as they are.
    ///
    /// # Panics
    /// When the memory for the neighbour search cannot be had (as the readings between steps).
    pub(super) fn settle_new_fluid(&mut self, first_id: u64, solids: Solids, settling: Settling) {
        let r = self.params.particle_radius;
        let holders: Vec<Option<Aabb>> = self
            .fluid
            .positions
            .iter()
            .zip(&self.fluid.ids)
            .map(|(p, &id)| {
                let holder = self.containers.iter().find(|c| c.contains(p, 0.0));
                holder.filter(|_| id >= first_id).copied()
            })
            .collect();
        let closed = solids.closed;
        let movable: Vec<bool> = self.fluid.ids.iter().map(|&id| id >= first_id).collect();
        let clear = |positions: &mut [Vec3]| {
            clear_of_walls(positions, &holders, r);
            for (mesh, bounds) in &closed {
                let reach = Aabb {
                    min: bounds.min - Vec3::repeat(r),
                    max: bounds.max + Vec3::repeat(r),
                };
                positions
                    .par_iter_mut()
                    .zip(&movable)
                    .filter(|(p, free)| **free && reach.contains(p, 0.0))
                    .for_each(|(p, _)| clear_of_mesh(p, mesh, r));
            }
        };
        self.pool.install(|| clear(&mut self.fluid.positions));
        if settling == Settling::Clear {
            return;
        }
        let settled = self
            .pool
            .install(|| self.placement_projection(&movable, &clear, settling));
        if let Some(settled) = settled {
            self.fluid.positions = settled;
        }
        if settling == Settling::Block {
            self.fluid.densities = self.densities_now();
        }
    }

    /// The fluid's positions (m, in storage order) after the passes of
    /// [`World::settle_new_fluid`]'s projection of the particles marked in `movable` (in
    /// storage order), or `None` where nothing was compressed.
    /// Runs on the caller's pool.
    fn placement_projection(
        &self,
        movable: &[bool],
        clear: &(dyn Fn(&mut [Vec3]) + Sync),
        settling: Settling,
    ) -> Option<Vec<Vec3>> {
        let h = self.params.support_radius();
        let step = PLACEMENT_STEP * self.params.particle_radius;
        let (passes, region) = match settling {
            Settling::Emitted => {
                // The new particles, the fluid they can reach in the passes there are, and
                // that fluid's neighbours.
                let new = (0..movable.len())
                    .filter(|&i| movable[i])
                    .map(|i| self.fluid.positions[i]);
                let reach = Vec3::repeat(2.0 * h + EMISSION_PASSES as f64 * step);
                let around = Aabb::enclosing(new)?;
                let region = Aabb {
                    min: around.min - reach,
                    max: around.max + reach,
                };
                (EMISSION_PASSES, Some(region))
            }
            _ => (PLACEMENT_PASSES, None),
        };
        let mut snapshot = self.snapshot_with(h, true, region.as_ref())?;
        // What the lattice itself reads is the mass factor's choice, not placement's to undo.
        let tolerance = PLACEMENT_TOLERANCE + self.lattice_compression();
        let mut positions = self.fluid.positions.clone();
        let rest = self.constraint.rest_density;
        let (k, m) = (&self.constraint.kernel, self.constraint.mass);
        let (mut fluid_lists, mut boundary_lists) =
            (NeighborLists::default(), NeighborLists::default());
        // The storage indices of the fluid the snapshot holds, and their positions.
        let mut taken = snapshot.fluid_order.clone();
        taken.sort_unstable();
        let mut at: Vec<Vec3> = Vec::with_capacity(taken.len());
        let mut order = Vec::new();
        let mut moved = false;
        for _ in 0..passes {
            let x = &snapshot.fluid;
            let free: Vec<bool> = snapshot
                .fluid_order
                .iter()
                .map(|&i| movable[i as usize])
                .collect();
            snapshot
                .grid
                .search(&snapshot.fluid_table, x, x, h, true, &mut fluid_lists)
                .expect("memory for the placement's neighbour search");
            snapshot.boundary_near(x, h, &mut boundary_lists);
            let lists = (&fluid_lists, &boundary_lists);
            // Fluid moving through a step reads compressions of its own, which emitted
            // particles are not to chase: they answer only for what they add.
            let added_only = settling == Settling::Emitted;
            let lambdas = self.placement_multipliers(&snapshot, lists, &free, added_only);
            let worst = lambdas.iter().map(|l| l.1).fold(0.0, f64::max);
            if worst <= tolerance {
                break;
            }
            moved = true;
            let moves: Vec<Vec3> = (0..x.len())
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
                .collect();
            for ((p, d), &i) in x.iter().zip(&moves).zip(&snapshot.fluid_order) {
                positions[i as usize] = p + d;
            }
            clear(&mut positions);
            at.clear();
            at.extend(taken.iter().map(|&i| positions[i as usize]));
            snapshot
                .grid
                .sort(&at, &mut order, &mut snapshot.fluid_table)
                .expect("memory for the placement's sort");
            snapshot.fluid_order = order.iter().map(|&o| taken[o as usize]).collect();
            snapshot.fluid = order.iter().map(|&o| at[o as usize]).collect();
        }
        moved.then_some(positions)
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
    /// without them.
    fn placement_multipliers(
        &self,
        snapshot: &Snapshot,
        (fluid_lists, boundary_lists): (&NeighborLists, &NeighborLists),
        movable: &[bool],
        added_only: bool,
    ) -> Vec<(f64, f64)> {
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
            .collect()
    }
}
