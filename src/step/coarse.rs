//! The coarse correction of the outer iteration (docs/method.md §3.8). The local and global
//! steps carry a correction one support radius per outer iteration, so a deep column needs
//! as many iterations as it is support radii tall to lift its weight off the floor. Before
//! the first global step, the correction moves the whole fluid at once by the displacement
//! u = −∇φ that removes its compression on a lattice of cells a few support radii wide:
//! ∇²φ = −e, e being the fluid's excess volume per cell, with φ = 0 at the free surface and
//! no flux into solids. This is the smallest irrotational displacement that removes the
//! compression the lattice sees; the fine iteration then resolves what is finer than a cell.
//! Each particle moves by u interpolated within its own cell between the gradients across
//! the cell's faces, so that the move's divergence is the one the equation solved for.

mod poisson;

use crate::Vec3;
use crate::boundary::Boundary;
use crate::constraint::Projection;
use crate::reserve::reserve_total;
use poisson::{Cell, Layout, Poisson};
use rayon::prelude::*;
use std::collections::TryReserveError;

/// The edge of a coarse cell, in support radii H.
pub(super) const CELL_SIZE: f64 = 2.0;

/// The largest displacement the correction gives a particle, in multiples of |g|·Δt²:
/// several times what holding a column up against gravity takes, so that the column's weight
/// is carried in one move even where it has just landed; the far larger displacements of a
/// hard impact are local and left to the fine iteration (docs/method.md §3.8).
pub(super) const REACH: f64 = 8.0;

/// The fluid's average compression (dimensionless) above which the correction is made, or
/// above η where that is larger: the default η. Below it what is left is the fine iteration's
/// to resolve, and a run with a tighter η, or with the density rule off, converges without
/// the correction moving it again.
pub(super) const THRESHOLD: f64 = 3e-4;

/// The correction is made before the first global step of a step and again after every
/// this many outer iterations: a compression that the fine iteration's extrapolation carries
/// up a column as a travelling pulse is spread out before it grows (docs/method.md §3.8).
pub(super) const PERIOD: usize = 3;

/// Particles that read below this share of ρ0 lack neighbours (the free surface, splashes)
/// rather than stand in room the fluid could fill; they add nothing to their cell's excess.
const SURFACE_DENSITY: f64 = 0.95;

/// The smallest distance from a cell's centre to the free surface, in cell edges: a cell less
/// than half full has its surface at its centre, nearly.
const THETA_MIN: f64 = 0.05;

/// The most cells a lattice may have per fluid particle (plus a fixed allowance): a fluid so
/// spread out (a particle far from the rest) is not corrected in that step.
const CELLS_PER_PARTICLE: usize = 8;
const CELLS_ALLOWANCE: usize = 4096;

/// A lattice of cubic cells aligned to multiples of its edge, covering the fluid with a
/// margin of one cell on every side.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Lattice {
    /// Integer coordinates of the first cell (cell edges from the origin of space).
    first: [i64; 3],
    dims: [usize; 3],
    /// Cell edge (m).
    edge: f64,
}

impl Lattice {
    /// The lattice around `points`, or none when it would have more than `limit` cells.
    fn around(points: &[Vec3], edge: f64, limit: usize) -> Option<Self> {
        let (lo, hi) = points
            .par_iter()
            .fold_with(
                (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                |(lo, hi), p| (lo.inf(p), hi.sup(p)),
            )
            .reduce(
                || (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                |a, b| (a.0.inf(&b.0), a.1.sup(&b.1)),
            );
        let mut first = [0; 3];
        let mut dims = [0; 3];
        for a in 0..3 {
            let (l, h) = ((lo[a] / edge).floor(), (hi[a] / edge).floor());
            if !(l.is_finite() && h.is_finite()) || h - l > limit as f64 {
                return None;
            }
            first[a] = l as i64 - 1;
            dims[a] = (h - l) as usize + 3;
        }
        (dims.iter().try_fold(1usize, |n, &d| n.checked_mul(d))? <= limit).then_some(Self {
            first,
            dims,
            edge,
        })
    }

    fn len(&self) -> usize {
        self.dims.iter().product()
    }

    fn strides(&self) -> [usize; 3] {
        [1, self.dims[0], self.dims[0] * self.dims[1]]
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// The cell holding `x` (m), if the lattice does.
    fn cell(&self, x: &Vec3) -> Option<usize> {
        let mut c = [0; 3];
        for a in 0..3 {
            let k = (x[a] / self.edge).floor() - self.first[a] as f64;
            if !(k >= 0.0 && k < self.dims[a] as f64) {
                return None;
            }
            c[a] = k as usize;
        }
        Some(self.index(c))
    }

    /// The coordinates of cell `c` within the lattice.
    fn coordinates(&self, c: usize) -> [usize; 3] {
        [
            c % self.dims[0],
            (c / self.dims[0]) % self.dims[1],
            c / (self.dims[0] * self.dims[1]),
        ]
    }

    /// The centre of cell `c` (m).
    fn centre(&self, c: usize) -> Vec3 {
        let k = self.coordinates(c);
        Vec3::from(std::array::from_fn(|a| {
            (self.first[a] as f64 + k[a] as f64 + 0.5) * self.edge
        }))
    }
}

/// The box around the fluid particles of a cell (m).
#[derive(Clone, Copy, Debug)]
struct Extent {
    min: Vec3,
    max: Vec3,
}

impl Extent {
    const EMPTY: Self = Self {
        min: Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        max: Vec3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
    };

    fn include(&mut self, x: &Vec3) {
        self.min = self.min.inf(x);
        self.max = self.max.sup(x);
    }

    /// The faces (bits as in [`Layout::closed`]) that a boundary particle at `b` lies beyond,
    /// seen from the fluid: past the fluid along one axis and within its extent along the
    /// other two, as a wall through the cell is.
    fn faces_beyond(&self, b: &Vec3) -> u8 {
        let mut faces = 0;
        for a in 0..3 {
            if self.in_front(b, a) {
                if b[a] < self.min[a] {
                    faces |= 1 << (2 * a);
                } else if b[a] > self.max[a] {
                    faces |= 1 << (2 * a + 1);
                }
            }
        }
        faces
    }

    /// Whether `b` (m) lies within the fluid's extent along the two axes other than `a`: in
    /// front of the fluid seen along `a`.
    fn in_front(&self, b: &Vec3, a: usize) -> bool {
        let within = |i: usize| b[i] >= self.min[i] && b[i] <= self.max[i];
        within((a + 1) % 3) && within((a + 2) % 3)
    }
}

/// The coarse correction's lattice and buffers, kept from step to step. Within a step φ of
/// the last solve starts the next one; each step starts from φ = 0, so that a step depends
/// only on the world's state (a checkpoint resumes bit for bit).
#[derive(Clone, Debug, Default)]
pub(crate) struct CoarseCorrection {
    cells: Vec<Cell>,
    /// Fluid volume per cell over the cell's volume.
    fill: Vec<f64>,
    /// The box around each cell's fluid particles.
    extent: Vec<Extent>,
    /// The faces of each fluid cell that a solid closes ([`Layout::closed`]).
    closed: Vec<u8>,
    /// The right-hand side: excess volume over the cell edge (m²).
    excess: Vec<f64>,
    theta: Vec<f64>,
    /// The displacement potential (m²).
    phi: Vec<f64>,
    /// φ of the last solve and its lattice, the start of the next.
    last_phi: Vec<f64>,
    last_lattice: Option<Lattice>,
    /// Each fluid slot's cell.
    slot_cell: Vec<u32>,
    poisson: Poisson,
}

/// What one correction reads.
pub(super) struct Fluid<'a> {
    /// ρ_i at the iterate, from the local step just taken.
    pub projections: &'a [Projection],
    pub boundary: &'a Boundary,
    /// ρ0 (kg/m³).
    pub rest_density: f64,
    /// Each particle's rest volume m/ρ0 (m³).
    pub volume: f64,
    /// The average compression the fine iteration may leave (dimensionless): the correction
    /// removes only what exceeds it.
    pub tolerated: f64,
    /// Support radius H (m).
    pub support_radius: f64,
    /// The most any particle is moved (m).
    pub reach: f64,
}

impl CoarseCorrection {
    /// Forgets the last solve: the next starts from φ = 0.
    pub(super) fn start_step(&mut self) {
        self.last_lattice = None;
    }

    /// Moves the iterate `current` and its predecessor `previous` alike (so that Chebyshev's
    /// extrapolation does not carry the move on) by the coarse correction of the compression
    /// `fluid.projections` read at `current`. Returns whether it moved anything: a fluid
    /// without compression, or spread too thin for a lattice, is left as it is. Errors,
    /// having moved nothing, when memory for the lattice cannot be had.
    pub(super) fn correct(
        &mut self,
        current: &mut [Vec3],
        previous: &mut [Vec3],
        fluid: &Fluid,
    ) -> Result<bool, TryReserveError> {
        let n = current.len();
        if fluid.reach <= 0.0 {
            return Ok(false);
        }
        let edge = CELL_SIZE * fluid.support_radius;
        let limit = CELLS_PER_PARTICLE * n + CELLS_ALLOWANCE;
        let Some(lattice) = Lattice::around(current, edge, limit) else {
            return Ok(false);
        };
        let cells = lattice.len();
        reserve_total(&mut self.slot_cell, n)?;
        reserve_total(&mut self.cells, cells)?;
        reserve_total(&mut self.extent, cells)?;
        reserve_total(&mut self.closed, cells)?;
        for v in [
            &mut self.fill,
            &mut self.excess,
            &mut self.theta,
            &mut self.phi,
        ] {
            reserve_total(v, cells)?;
        }
        if !self.classify(&lattice, current, fluid) || self.excess.iter().all(|&e| e == 0.0) {
            return Ok(false);
        }
        self.start_from_last(&lattice);
        let layout = Layout {
            cells: &self.cells,
            theta: &self.theta,
            closed: &self.closed,
            strides: lattice.strides(),
        };
        self.poisson.solve(&layout, &self.excess, &mut self.phi)?;
        // Only a completed solve starts the next one.
        if reserve_total(&mut self.last_phi, cells).is_ok() {
            self.last_phi.clone_from(&self.phi);
            self.last_lattice = Some(lattice);
        }
        let layout = Layout {
            cells: &self.cells,
            theta: &self.theta,
            closed: &self.closed,
            strides: lattice.strides(),
        };
        let (phi, reach) = (&self.phi, fluid.reach);
        current
            .par_iter_mut()
            .zip(previous.par_iter_mut())
            .zip(self.slot_cell.par_iter())
            .for_each(|((x, previous), &c)| {
                let u = displacement(&layout, &lattice, phi, c as usize, x);
                let length = u.norm();
                let u = if length > reach {
                    u * (reach / length)
                } else {
                    u
                };
                *x += u;
                *previous += u;
            });
        Ok(true)
    }

    /// Marks fluid, solid and air cells, and sums every fluid cell's fill and excess volume
    /// (the excess as the right-hand side, over the cell edge).
    /// Returns false, classifying nothing, where a particle lies outside the lattice (a
    /// position that is not a number).
    fn classify(&mut self, lattice: &Lattice, current: &[Vec3], fluid: &Fluid) -> bool {
        let cells = lattice.len();
        self.slot_cell.clear();
        self.slot_cell.par_extend(
            current
                .par_iter()
                .map(|x| lattice.cell(x).map_or(u32::MAX, |c| c as u32)),
        );
        if self.slot_cell.contains(&u32::MAX) {
            return false;
        }
        self.cells.clear();
        self.cells.resize(cells, Cell::Air);
        self.fill.clear();
        self.fill.resize(cells, 0.0);
        self.excess.clear();
        self.excess.resize(cells, 0.0);
        let cell_volume = lattice.edge.powi(3);
        let rest = fluid.rest_density;
        // In slot order, so that the sums do not depend on the thread count.
        self.extent.clear();
        self.extent.resize(cells, Extent::EMPTY);
        self.closed.clear();
        self.closed.resize(cells, 0);
        for ((&c, p), x) in self.slot_cell.iter().zip(fluid.projections).zip(current) {
            let c = c as usize;
            self.cells[c] = Cell::Fluid;
            self.extent[c].include(x);
            self.fill[c] += fluid.volume / cell_volume;
            if p.density >= SURFACE_DENSITY * rest {
                self.excess[c] += fluid.volume * (p.density / rest - 1.0 - fluid.tolerated);
            }
        }
        for b in fluid.boundary.positions.iter() {
            let Some(c) = lattice.cell(&b) else {
                continue;
            };
            match self.cells[c] {
                Cell::Air => self.close_faces_towards(lattice, c, &b),
                Cell::Fluid => self.closed[c] |= self.extent[c].faces_beyond(&b),
                Cell::Solid => {}
            }
        }
        if !fluid.boundary.walls.is_empty() {
            for c in 0..cells {
                let centre = lattice.centre(c);
                if self.cells[c] == Cell::Air
                    && fluid
                        .boundary
                        .walls
                        .iter()
                        .any(|w| !w.container().contains(&centre, 0.0))
                {
                    self.cells[c] = Cell::Solid;
                }
            }
        }
        // A cell whose fluid expands more than others compress leaves nothing to remove.
        for (e, cell) in self.excess.iter_mut().zip(&self.cells) {
            *e = if *cell == Cell::Fluid {
                e.max(0.0) / lattice.edge
            } else {
                0.0
            };
        }
        self.theta.clear();
        self.theta
            .extend(self.fill.iter().map(|f| (f - 0.5).clamp(THETA_MIN, 1.0)));
        true
    }

    /// Closes the faces towards cell `c` (without fluid) of the fluid cells beside it whose
    /// fluid a boundary particle at `b` (m) in `c` lies in front of: within the fluid's
    /// extent along the face's two axes, as a wall across the face is. A wall that runs past
    /// the fluid, such as a side wall above the water, leaves the face open: the water's
    /// surface below it stays free.
    fn close_faces_towards(&mut self, lattice: &Lattice, c: usize, b: &Vec3) {
        let (k, strides) = (lattice.coordinates(c), lattice.strides());
        for a in 0..3 {
            // The neighbour below c along a sees c across its face towards +a, and so on.
            let below = (k[a] > 0).then(|| (c - strides[a], 2 * a + 1));
            let above = (k[a] + 1 < lattice.dims[a]).then(|| (c + strides[a], 2 * a));
            for (nb, face) in below.into_iter().chain(above) {
                if self.cells[nb] == Cell::Fluid && self.extent[nb].in_front(b, a) {
                    self.closed[nb] |= 1 << face;
                }
            }
        }
    }

    /// Starts φ from the last solve's where the lattices share fluid cells, from 0 elsewhere.
    fn start_from_last(&mut self, lattice: &Lattice) {
        self.phi.clear();
        self.phi.resize(lattice.len(), 0.0);
        let Some(last) = self.last_lattice.filter(|l| l.edge == lattice.edge) else {
            return;
        };
        let (cells, last_phi) = (&self.cells, &self.last_phi);
        self.phi.par_iter_mut().enumerate().for_each(|(c, phi)| {
            if cells[c] != Cell::Fluid {
                return;
            }
            let mut old = [0usize; 3];
            for (a, k) in lattice.coordinates(c).into_iter().enumerate() {
                let global = k as i64 + lattice.first[a];
                let local = global - last.first[a];
                if local < 0 || local >= last.dims[a] as i64 {
                    return;
                }
                old[a] = local as usize;
            }
            *phi = last_phi[last.index(old)];
        });
    }
}

/// The displacement u = −∇φ (m) of a particle at `x` (m) in fluid cell `c`: each component
/// interpolated linearly, along its own axis, between the potential's gradients across the
/// cell's two faces along it, so that u's divergence over the cell is the one the Poisson
/// equation solved for. Across a face that a solid closes, u takes the other face's value
/// (a layer on the floor moves with the column above it); between two closed faces, zero.
fn displacement(layout: &Layout, lattice: &Lattice, phi: &[f64], c: usize, x: &Vec3) -> Vec3 {
    let edge = lattice.edge;
    let low = lattice.centre(c) - Vec3::repeat(0.5 * edge);
    // −∂φ/∂x_a across the face towards +a (`up`) or −a, none across a closed face.
    let across = |a: usize, up: bool| {
        let towards = match layout.neighbour(c, a, up) {
            (nb, Cell::Fluid) => (phi[nb] - phi[c]) / edge,
            (_, Cell::Air) => -phi[c] / (layout.theta[c] * edge),
            (_, Cell::Solid) => return None,
        };
        Some(if up { -towards } else { towards })
    };
    Vec3::from(std::array::from_fn(|a| {
        let t = ((x[a] - low[a]) / edge).clamp(0.0, 1.0);
        match (across(a, false), across(a, true)) {
            (Some(down), Some(up)) => (1.0 - t) * down + t * up,
            (None, Some(up)) => up,
            (Some(down), None) => down,
            (None, None) => 0.0,
        }
    }))
}
