//! Surface tension and adhesion to walls (docs/method.md §17).
//!
//! Surface tension is the continuum surface force of Brackbill, Kothe and Zemach (1992) in
//! its SPH form (Morris 2000; Adami, Hu and Adams 2010): the pressure jump σκ across a
//! surface of curvature κ, spread over the kernel's width as the volume force
//!
//! ```text
//! f = σ κ ∇c / Γ,     c_i = Σ_j V W_ij,     κ = ∇·n̂,  n̂ = −∇c/|∇c|
//! ```
//!
//! c being the colour of the fluid (1 inside, falling to 0 across the surface). The walls
//! are not fluid: where the fluid meets a wall it has a surface too, and the wall's
//! adhesion, not the colour, decides how far it wets. Without particles beyond the surface the
//! particles' gradients sum to a share Γ ≈ ½ of the colour's unit step: Γ is computed from
//! the rest lattice when the world is made ([`captured_step`]), and dividing by it makes the
//! force over the surface the whole σκ per unit area. Each particle has its material's σ;
//! the force acts at free surfaces, not between two liquids. The force is not a pair force,
//! so momentum is conserved only as the surface is closed (a drop does not drift).
//!
//! Adhesion is an energy of the fluid against the walls: −β·Σ_b (ψ_b/ρ0) W_ib per particle,
//! the walls' share of its density, giving the attraction F_i = β Σ_b (ψ_b/ρ0) ∇W(x_i − x_b)
//! (∇W(x_i − x_b) points from i towards b). A wall whose particles stand for the fluid it
//! replaces (as their volumes ψ_b/ρ0 make them do for the density) holds a fluid half-space
//! with Λ·β per unit area ([`lattice_pair_sum`]), so β = W/Λ makes the work of adhesion W
//! (N/m) the energy per unit area of pulling the fluid off the wall.
//!
//! The forces change the velocities at the end of a step, Δv_i = Δt·F_i/m_i. Each
//! particle's force is a gather over the step's neighbour lists in their fixed order, the
//! same for any thread count.

use super::{Forcing, NonPressureForce};
use crate::Vec3;
use crate::fluid::Fluid;
use crate::kernel::CubicKernel;
use crate::material::Materials;
use crate::params::Params;
use rayon::prelude::*;

/// The pair sum Λ (1/m²) of the kernel `kernel` in the cubic lattice of spacing `spacing`
/// (m), the fluid's rest packing: V·Σ W_ij over the pairs that straddle a plane, per unit
/// area, averaged over the plane's orientation, V = d³ being a particle's volume: what the
/// particles on one side of the plane add to the filled volume fractions ρ_i/ρ0 of those on
/// the other.
///
/// A pair at offset o straddles a plane of normal n in (o·n)₊/d³ places per unit area, and
/// (o·n)₊ averages |o|/4 over the directions of n; so Λ = Σ_{o≠0} |o|·W(|o|)/4. A drop's
/// surface meets the lattice at every orientation, hence the average (the (100) plane
/// alone gives 22 % less, a plane of normal (1, 2, 3) 4 % more; tested). It is 13 % below
/// the continuum's (π/d³)∫ r³ W(r) dr, Kirkwood and Buff's integral for a fluid of uniform
/// density, which the lattice's few neighbour shells sample coarsely.
pub(crate) fn lattice_pair_sum(kernel: &CubicKernel, spacing: f64) -> f64 {
    let support = kernel.support_radius();
    let reach = (support / spacing).ceil() as i32;
    let mut sum = 0.0;
    for i in -reach..=reach {
        for j in -reach..=reach {
            for k in -reach..=reach {
                let r = f64::from(i * i + j * j + k * k).sqrt() * spacing;
                if r > 0.0 {
                    sum += r * kernel.w(r);
                }
            }
        }
    }
    sum / 4.0
}

/// Normals are kept where |∇c|·H exceeds this (dimensionless): at the surface |∇c|·H is
/// 0.3–1, inside the fluid it is the packing's noise, whose directions mean nothing.
const NORMAL_THRESHOLD: f64 = 0.1;

/// The share Γ of the colour's unit step that the particles' gradients sum to across a flat
/// surface (dimensionless): Σ_k d·|∂c/∂z|(z_k) over the layers k of the rest lattice below
/// a (100) face, c = V Σ_j W(x − x_j) the colour of the particles of volume V = d³.
///
/// The smoothed colour falls from 1 to 0 across the surface over the kernel's width, half
/// of it beyond the last layer where no particle samples it, so Γ is about ½; dividing the
/// surface force by Γ restores the whole jump (docs/method.md §17).
pub(crate) fn captured_step(kernel: &CubicKernel, spacing: f64) -> f64 {
    let reach = (kernel.support_radius() / spacing).ceil() as i32;
    let volume = spacing.powi(3);
    let mut sum = 0.0;
    for layer in 0..=reach {
        // ∂c/∂z at a particle `layer` layers below the face, from every site at or below it.
        let mut slope = 0.0;
        for i in -reach..=reach {
            for j in -reach..=reach {
                for k in (layer - reach).max(0)..=layer + reach {
                    // The site k layers below the face, at offset r = x_i − x_j.
                    let r = Vec3::new(
                        f64::from(i) * spacing,
                        f64::from(j) * spacing,
                        f64::from(k - layer) * spacing,
                    );
                    slope += volume * kernel.grad_w(&r).z;
                }
            }
        }
        sum += spacing * slope;
    }
    sum.abs()
}

/// Surface tension as a force on the surface (Brackbill, Kothe and Zemach 1992, in SPH after
/// Morris 2000 and Adami, Hu and Adams 2010) and adhesion to walls, with their buffers.
#[derive(Clone, Debug)]
pub(crate) struct SurfaceTension {
    /// Every material's surface tension σ over Γ ([`captured_step`]) (N/m), indexed by
    /// material.
    tension: Vec<f64>,
    /// The adhesion coefficient β = W/Λ (J).
    adhesion: f64,
    /// Every material's particle mass m_i (kg), indexed by material.
    masses: Vec<f64>,
    /// Every particle's colour gradient ∇c_i (1/m).
    gradients: Vec<Vec3>,
    /// Every particle's outward unit normal, zero where |∇c| is below the threshold.
    normals: Vec<Vec3>,
}

impl SurfaceTension {
    /// The forces of `params` (the particle size, the wall adhesion) and `materials` (their
    /// surface tensions and masses).
    pub fn new(params: &Params, materials: &Materials) -> Self {
        let kernel = CubicKernel::new(params.support_radius());
        let lambda = lattice_pair_sum(&kernel, params.spacing());
        let captured = captured_step(&kernel, params.spacing());
        let mass = params.particle_mass();
        Self {
            tension: materials.tensions.iter().map(|s| s / captured).collect(),
            adhesion: params.wall_adhesion / lambda,
            masses: materials.mass_ratios.iter().map(|k| k * mass).collect(),
            gradients: Vec::new(),
            normals: Vec::new(),
        }
    }
}

/// The colour gradient ∇c_i = Σ_j V ∇W(x_i − x_j) (1/m) of fluid particle `i`. Walls are
/// not fluid: against a wall the fluid has a surface too, whose tension the wall's
/// adhesion balances (Young and Dupré: without adhesion the fluid does not wet the wall).
#[inline]
fn colour_gradient(f: &Forcing, x: &[Vec3], i: usize) -> Vec3 {
    let (nb, kernel) = (f.nb, &f.constraint.kernel);
    let volume = f.constraint.mass / f.constraint.rest_density;
    let xi = x[i];
    let fluid: Vec3 = nb
        .fluid
        .of(i)
        .iter()
        .map(|&j| kernel.grad_w(&(xi - x[j as usize])))
        .sum();
    fluid * volume
}

/// The curvature κ_i = ∇·n̂ (1/m) at fluid particle `i` with outward normals `normals`:
/// d·Σ_j V (n̂_j − n̂_i)·∇W_ij / Σ_j V |∇W_ij| |r_ij| over the neighbours that have a normal
/// (Adami et al. 2010's normalisation, which rescales the sum for the neighbours without a
/// normal; V cancels); 0 where none has. On a drop it reads on average more than 2/R, its
/// surface being rough at the particles' scale (docs/method.md §17.1).
#[inline]
fn curvature(f: &Forcing, x: &[Vec3], normals: &[Vec3], i: usize) -> f64 {
    let kernel = &f.constraint.kernel;
    let (xi, ni) = (x[i], normals[i]);
    let (mut divergence, mut norm) = (0.0, 0.0);
    for &j in f.nb.fluid.of(i) {
        let j = j as usize;
        let nj = normals[j];
        if nj == Vec3::zeros() {
            continue;
        }
        let r = xi - x[j];
        let c = kernel.grad_w_coefficient(r.norm());
        divergence += c * (nj - ni).dot(&r);
        norm -= c * r.norm_squared();
    }
    if norm > 0.0 {
        3.0 * divergence / norm
    } else {
        0.0
    }
}

impl NonPressureForce for SurfaceTension {
    fn try_reserve(&mut self, particles: usize) -> Result<(), std::collections::TryReserveError> {
        crate::reserve::reserve_total(&mut self.gradients, particles)?;
        crate::reserve::reserve_total(&mut self.normals, particles)
    }

    fn apply(&mut self, f: &Forcing, fluid: &mut Fluid, scratch: &mut Vec<Vec3>) {
        let (x, v, materials) = (&fluid.positions, &fluid.velocities, &fluid.materials);
        let n = x.len();
        let threshold = NORMAL_THRESHOLD / f.constraint.kernel.support_radius();
        self.gradients.clear();
        self.gradients
            .par_extend((0..n).into_par_iter().map(|i| colour_gradient(f, x, i)));
        let gradients = &self.gradients;
        self.normals.clear();
        self.normals.par_extend(gradients.par_iter().map(|g| {
            let length = g.norm();
            if length > threshold {
                -g / length
            } else {
                Vec3::zeros()
            }
        }));
        let normals = &self.normals;
        let volume = f.constraint.mass / f.constraint.rest_density;
        let (dt, tension, masses) = (f.dt, &self.tension, &self.masses);
        let (adhesion, adhesive) = (self.adhesion, self.adhesion > 0.0);
        scratch.clear();
        scratch.par_extend((0..n).into_par_iter().map(|i| {
            let material = materials[i] as usize;
            let sigma = tension[material];
            let mut force = Vec3::zeros();
            if sigma > 0.0 && normals[i] != Vec3::zeros() {
                // f = σκ∇c per unit volume, ∇c pointing into the fluid.
                force += gradients[i] * (sigma * curvature(f, x, normals, i) * volume);
            }
            if adhesive {
                // β Σ_b (ψ_b/ρ0) ∇W(x_i − x_b), the walls built as fields included.
                force += f.constraint.boundary_gradient(x[i], i, f.nb) * adhesion;
            }
            v[i] + force * (dt / masses[material])
        }));
        std::mem::swap(&mut fluid.velocities, scratch);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The orientation average of the lattice's pair sum is the lattice's quadrature of the
    /// continuum's, (π/d³) ∫ r³ W(r) dr (Kirkwood and Buff's integral for a fluid of uniform
    /// density): 13 % below it, and between the sums of the lattice's (100) plane (22 %
    /// below) and of a plane of normal (1, 2, 3) (4 % above).
    #[test]
    fn the_pair_sum_averages_the_planes_of_the_lattice() {
        let spacing = 1.0;
        let kernel = CubicKernel::new(2.0 * spacing);
        let average = lattice_pair_sum(&kernel, spacing);
        let plane = |n: [f64; 3]| {
            let n = Vec3::from(n).normalize();
            let mut sum = 0.0;
            for i in -2i32..=2 {
                for j in -2i32..=2 {
                    for k in -2i32..=2 {
                        let o = Vec3::new(f64::from(i), f64::from(j), f64::from(k));
                        sum += o.dot(&n).max(0.0) * kernel.w(o.norm());
                    }
                }
            }
            sum
        };
        let continuum = {
            const PANELS: usize = 4000;
            let h = kernel.support_radius() / PANELS as f64;
            (0..PANELS)
                .map(|k| ((k as f64 + 0.5) * h).powi(3) * kernel.w((k as f64 + 0.5) * h))
                .sum::<f64>()
                * h
                * std::f64::consts::PI
        };
        assert!(
            (average / continuum - 0.87).abs() < 0.01,
            "{average} {continuum}"
        );
        let (square, oblique) = (plane([0.0, 0.0, 1.0]), plane([1.0, 2.0, 3.0]));
        assert!((square / average - 0.78).abs() < 0.01, "{square} {average}");
        assert!(
            (oblique / average - 1.04).abs() < 0.01,
            "{oblique} {average}"
        );
        // Λ scales as 1/d² at a fixed H/d.
        let half = lattice_pair_sum(&CubicKernel::new(1.0), 0.5);
        assert!((half / average - 4.0).abs() < 1e-12, "{half} {average}");
    }

    /// The particles below a flat surface sum to about half the colour's unit step, the
    /// half inside the fluid; the share does not depend on the particle size.
    #[test]
    fn the_particles_capture_half_the_colour_step() {
        let share = captured_step(&CubicKernel::new(2.0), 1.0);
        assert!((share - 0.5).abs() < 0.1, "{share}");
        let small = captured_step(&CubicKernel::new(0.02), 0.01);
        assert!((small / share - 1.0).abs() < 1e-9, "{small} {share}");
    }
}
