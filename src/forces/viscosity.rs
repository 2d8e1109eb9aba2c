//! Physical viscosity (docs/method.md §13): the velocities after a step solve the implicit
//! viscous update (I − Δt ν ∇²) v = v* with the SPH Laplacian of Weiler et al. (2018),
//!
//! ∇²v_i ≈ 2(d + 2) Σ_j V_j (x_ij·v_ij) / (|x_ij|² + 0.01 H²) ∇W_ij,
//!
//! which conserves linear and angular momentum. Multiplied by each particle's volume V_i the
//! system is symmetric and positive definite; conjugate gradients with the 3×3 block-diagonal
//! preconditioner solve it without forming the matrix. With no-slip walls, boundary particles
//! of the container, the static obstacles and the static bodies enter the sum at rest. Each
//! particle has its material's ν; a pair takes the harmonic mean of its two (§14).

use super::{Forcing, NonPressureForce};
use crate::material::MaterialId;
use crate::reserve::reserve_total;
use crate::{Vec3, reduce};
use nalgebra::Matrix3;
use rayon::prelude::*;
use std::collections::TryReserveError;

/// 2(d + 2) for d = 3 dimensions.
pub(crate) const LAPLACIAN_FACTOR: f64 = 10.0;

/// The regularisation of |x_ij|² in the Laplacian, in H².
pub(crate) const REGULARISATION: f64 = 0.01;

/// The relative residual ‖r‖ ≤ tolerance·‖b‖ at which a solve stops.
pub(crate) const TOLERANCE: f64 = 1e-4;

/// The largest calibration κ_i: a particle with few neighbours (a splash) is not coupled
/// more strongly than this many times the uncalibrated operator would couple it.
pub(crate) const MOST_CALIBRATION: f64 = 3.0;

/// The most conjugate-gradient iterations of one solve.
pub(crate) const MAX_ITERATIONS: usize = 200;

/// The implicit viscosity solve, each particle of its material's kinematic viscosity, and
/// its buffers.
#[derive(Clone, Debug)]
pub(crate) struct Viscosity {
    /// Whether walls enter the Laplacian at rest (no slip) or not at all (free slip).
    no_slip: bool,
    /// V_i = m/ρ_i (m³).
    volumes: Vec<f64>,
    /// Each particle's calibration κ_i of the Laplacian (dimensionless, [`calibration`]).
    calibration: Vec<f64>,
    /// The inverse of each particle's 3×3 diagonal block.
    preconditioner: Vec<Matrix3<f64>>,
    /// Every pair's coupling ν_ij·g_ij of the step (1/(m²·s), [`Operator::coupled`]),
    /// particle by particle in the order [`Operator::visit`] takes them, so that the
    /// solve's iterations do not evaluate the kernel again; empty where their memory could
    /// not be had, the iterations then evaluating it.
    couplings: Vec<f64>,
    /// Where each particle's couplings start in `couplings` (one past the particles).
    starts: Vec<usize>,
    residual: Vec<Vec3>,
    preconditioned: Vec<Vec3>,
    direction: Vec<Vec3>,
    product: Vec<Vec3>,
}

impl Viscosity {
    /// The solve, with no-slip walls if `no_slip`.
    pub fn new(no_slip: bool) -> Self {
        Self {
            no_slip,
            volumes: Vec::new(),
            calibration: Vec::new(),
            preconditioner: Vec::new(),
            couplings: Vec::new(),
            starts: Vec::new(),
            residual: Vec::new(),
            preconditioned: Vec::new(),
            direction: Vec::new(),
            product: Vec::new(),
        }
    }
}

/// The other particle of a pair: a fluid particle or a boundary particle, by index.
#[derive(Clone, Copy)]
enum Partner {
    Fluid(usize),
    Wall(usize),
}

/// What the operator reads: positions (m), materials, volumes (m³), the calibration, and the
/// coupling c = 2(d+2)·Δt (s), which a pair's viscosity ν_ij multiplies, with the
/// regularisation ε = 0.01 H² (m²).
struct Operator<'a> {
    f: &'a Forcing<'a>,
    x: &'a [Vec3],
    materials: &'a [MaterialId],
    volumes: &'a [f64],
    /// κ_i, or empty while it is being measured (then 1).
    calibration: &'a [f64],
    /// The pairs' couplings and where each particle's start ([`Viscosity::couplings`]),
    /// or empty slices while they are not known.
    couplings: &'a [f64],
    starts: &'a [usize],
    coupling: f64,
    epsilon: f64,
    no_slip: bool,
}

impl Operator<'_> {
    /// The weight g_ij ≥ 0 of the pair at offset `r` = x_i − x_j (1/m⁷): with it the pair's
    /// Laplacian term is g_ij·r (r·v_ij).
    #[inline]
    fn weight(&self, r: &Vec3) -> f64 {
        let len2 = r.norm_squared();
        let c = self.f.constraint.kernel.grad_w_coefficient(len2.sqrt());
        -c / (len2 + self.epsilon)
    }

    /// Particle i's kinematic viscosity ν_i (m²/s), its material's.
    #[inline]
    fn nu(&self, i: usize) -> f64 {
        self.f.viscosities[self.materials[i] as usize]
    }

    /// The viscosity ν_ij (m²/s) of the pair of `i` and fluid neighbour `j`, or of `i` and a
    /// wall (`None`): the harmonic mean 2ν_iν_j/(ν_i + ν_j) of two materials, as the flux
    /// between layers of different conductivity is, so that shear stress is continuous across
    /// an interface and a liquid without viscosity drags on none; ν_i towards a wall.
    #[inline]
    fn pair_nu(&self, i: usize, j: Option<usize>) -> f64 {
        let a = self.nu(i);
        let Some(j) = j else { return a };
        let b = self.nu(j);
        if a == b {
            a
        } else if a + b > 0.0 {
            2.0 * a * b / (a + b)
        } else {
            0.0
        }
    }

    /// κ_i, 1 while it is being measured.
    #[inline]
    fn kappa(&self, i: usize) -> f64 {
        self.calibration.get(i).copied().unwrap_or(1.0)
    }

    /// Calls `each(r, Partner)` for every fluid neighbour of `i` and every boundary
    /// neighbour that holds the fluid (no slip), in a fixed order, r = x_i − x_partner (m).
    #[inline]
    fn visit(&self, i: usize, mut each: impl FnMut(Vec3, Partner)) {
        let xi = self.x[i];
        for &j in self.f.nb.fluid.of(i) {
            let j = j as usize;
            each(xi - self.x[j], Partner::Fluid(j));
        }
        if self.no_slip {
            for &b in self.f.nb.boundary.of(i) {
                let b = b as usize;
                if !self.f.boundary.is_moving_particle(b) {
                    let r = xi - self.f.nb.boundary_positions.at(b);
                    each(r, Partner::Wall(b));
                }
            }
        }
    }

    /// Calls `each(g, r, Some(j))` for every fluid neighbour j of `i` and `each(g, r, None)`
    /// for every boundary neighbour that holds the fluid (no slip), g including V_j and the
    /// pair's calibration (κ_i + κ_j)/2, or κ_i towards a wall.
    #[inline]
    fn for_pairs(&self, i: usize, mut each: impl FnMut(f64, Vec3, Option<usize>)) {
        let ki = self.kappa(i);
        let rest = self.f.constraint.rest_density;
        self.visit(i, |r, partner| match partner {
            Partner::Fluid(j) => {
                let kij = 0.5 * (ki + self.kappa(j));
                each(kij * self.weight(&r) * self.volumes[j], r, Some(j));
            }
            Partner::Wall(b) => {
                let g = ki * self.weight(&r) * self.f.nb.boundary_psi[b] / rest;
                each(g, r, None);
            }
        });
    }

    /// [`Operator::for_pairs`] with the pair's viscosity: `each(ν_ij·g, r, partner)`, read
    /// from the step's couplings where they are known.
    #[inline]
    fn coupled(&self, i: usize, mut each: impl FnMut(f64, Vec3, Option<usize>)) {
        if self.starts.is_empty() {
            return self.for_pairs(i, |g, r, j| each(g * self.pair_nu(i, j), r, j));
        }
        let mut k = self.starts[i];
        self.visit(i, |r, partner| {
            let j = match partner {
                Partner::Fluid(j) => Some(j),
                Partner::Wall(_) => None,
            };
            each(self.couplings[k], r, j);
            k += 1;
        });
    }

    /// The number of pairs [`Operator::visit`] takes for particle `i`.
    fn pair_count(&self, i: usize) -> usize {
        let mut count = 0;
        self.visit(i, |_, _| count += 1);
        count
    }

    /// κ_i = 2 / (2(d+2) S_i), S_i = Σ_j V_j g_ij ⟨x_a² x_b²⟩ the mean over the three
    /// coordinate planes: the factor that makes the operator read the shear flows
    /// v_a = x_b² (a ≠ b) as ∇²v_a = 2 on average at particle i, at most [`MOST_CALIBRATION`].
    fn calibration(&self, i: usize) -> f64 {
        let mut moment = 0.0;
        self.for_pairs(i, |g, r, _| {
            let r2 = r.component_mul(&r);
            moment += g * (r2.x * r2.y + r2.y * r2.z + r2.z * r2.x) / 3.0;
        });
        let exact = 2.0 / LAPLACIAN_FACTOR;
        if moment * MOST_CALIBRATION > exact {
            exact / moment
        } else {
            MOST_CALIBRATION
        }
    }

    /// (A v)_i = V_i v_i + c V_i Σ_j ν_ij V_j g_ij r (r·(v_i − v_j)), a wall's v_j being 0.
    fn apply(&self, v: &[Vec3], i: usize) -> Vec3 {
        let mut sum = Vec3::zeros();
        let vi = v[i];
        self.coupled(i, |c, r, j| {
            let relative = j.map_or(vi, |j| vi - v[j]);
            sum += r * (c * r.dot(&relative));
        });
        self.volumes[i] * (vi + sum * self.coupling)
    }

    /// The inverse of particle `i`'s diagonal block V_i (I + c Σ ν_ij g r rᵀ).
    fn block_inverse(&self, i: usize) -> Matrix3<f64> {
        let mut sum = Matrix3::zeros();
        self.coupled(i, |c, r, _| sum += r * r.transpose() * c);
        let block = (Matrix3::identity() + sum * self.coupling) * self.volumes[i];
        block
            .try_inverse()
            .unwrap_or_else(|| Matrix3::identity() / self.volumes[i])
    }
}

impl NonPressureForce for Viscosity {
    fn try_reserve(&mut self, particles: usize) -> Result<(), TryReserveError> {
        reserve_total(&mut self.volumes, particles)?;
        reserve_total(&mut self.calibration, particles)?;
        reserve_total(&mut self.preconditioner, particles)?;
        reserve_total(&mut self.starts, particles + 1)?;
        for v in [
            &mut self.residual,
            &mut self.preconditioned,
            &mut self.direction,
            &mut self.product,
        ] {
            reserve_total(v, particles)?;
        }
        Ok(())
    }

    fn apply(&mut self, f: &Forcing, fluid: &mut crate::fluid::Fluid, _scratch: &mut Vec<Vec3>) {
        let n = fluid.len();
        let mass = f.constraint.mass;
        self.volumes.clear();
        self.volumes
            .par_extend(fluid.densities.par_iter().map(|rho| mass / rho));
        let h = f.constraint.kernel.support_radius();
        let mut op = Operator {
            f,
            x: &fluid.positions,
            materials: &fluid.materials,
            volumes: &self.volumes,
            calibration: &[],
            couplings: &[],
            starts: &[],
            coupling: LAPLACIAN_FACTOR * f.dt,
            epsilon: REGULARISATION * h * h,
            no_slip: self.no_slip,
        };
        self.calibration.clear();
        self.calibration
            .par_extend((0..n).into_par_iter().map(|i| op.calibration(i)));
        op.calibration = &self.calibration;
        // The couplings, where their memory can be had (else the iterations evaluate them).
        self.starts.clear();
        self.couplings.clear();
        let mut total = 0usize;
        self.starts.push(0);
        for i in 0..n {
            total += op.pair_count(i);
            self.starts.push(total);
        }
        if self.couplings.try_reserve(total).is_ok() {
            // In order, within the capacity just reserved.
            for i in 0..n {
                op.coupled(i, |c, _, _| self.couplings.push(c));
            }
        } else {
            self.starts.clear();
        }
        op.couplings = &self.couplings;
        op.starts = &self.starts;
        self.preconditioner.clear();
        self.preconditioner
            .par_extend((0..n).into_par_iter().map(|i| op.block_inverse(i)));
        // The right-hand side V_i v*_i; the solve starts from v*, so r = b − A v*.
        let v = &mut fluid.velocities;
        let volumes = &self.volumes;
        let norm_rhs = reduce::sum_over(n, |i| (v[i] * volumes[i]).norm_squared()).sqrt();
        if norm_rhs == 0.0 {
            return;
        }
        let start: &[Vec3] = v;
        self.residual.clear();
        self.residual.par_extend(
            (0..n)
                .into_par_iter()
                .map(|i| start[i] * volumes[i] - op.apply(start, i)),
        );
        let precondition = |m: &[Matrix3<f64>], r: &[Vec3], z: &mut Vec<Vec3>| {
            z.clear();
            z.par_extend((0..r.len()).into_par_iter().map(|i| m[i] * r[i]));
        };
        precondition(
            &self.preconditioner,
            &self.residual,
            &mut self.preconditioned,
        );
        self.direction.clone_from(&self.preconditioned);
        let dot = |a: &[Vec3], b: &[Vec3]| reduce::sum_over(a.len(), |i| a[i].dot(&b[i]));
        let mut rz = dot(&self.residual, &self.preconditioned);
        for _ in 0..MAX_ITERATIONS {
            let residual_norm = dot(&self.residual, &self.residual).sqrt();
            if residual_norm <= TOLERANCE * norm_rhs {
                break;
            }
            let direction = &self.direction;
            self.product.clear();
            self.product
                .par_extend((0..n).into_par_iter().map(|i| op.apply(direction, i)));
            let curvature = dot(&self.direction, &self.product);
            if curvature <= 0.0 || !curvature.is_finite() {
                break;
            }
            let alpha = rz / curvature;
            v.par_iter_mut()
                .zip(self.residual.par_iter_mut())
                .zip(self.direction.par_iter().zip(self.product.par_iter()))
                .for_each(|((v, r), (p, q))| {
                    *v += p * alpha;
                    *r -= q * alpha;
                });
            precondition(
                &self.preconditioner,
                &self.residual,
                &mut self.preconditioned,
            );
            let next = dot(&self.residual, &self.preconditioned);
            let beta = next / rz;
            rz = next;
            self.direction
                .par_iter_mut()
                .zip(self.preconditioned.par_iter())
                .for_each(|(p, z)| *p = z + *p * beta);
        }
    }
}
