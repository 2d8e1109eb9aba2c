//! Vorticity confinement (docs/method.md §15): an acceleration that turns the flow around its
//! concentrations of vorticity, giving back rotation that the iteration's projections and the
//! XSPH filter damp at the scale of a few particles (Fedkiw et al. 2001, in SPH form as in
//! Macklin and Müller 2013).
//!
//! With the vorticity ω_i = Σ_j V ∇W(x_i − x_j) × (v_j − v_i) (1/s) and the direction
//! N_i = η_i/|η_i| of the gradient η_i = Σ_j V (|ω_j| − |ω_i|) ∇W(x_i − x_j) of its
//! magnitude, particle i is accelerated by
//!
//! ```text
//! a_i = ε · H · |ω_i| · (N_i × ω_i)      (m/s²)
//! ```
//!
//! with ε (dimensionless) the user's coefficient and H the support radius: the acceleration
//! of a rotation of rate |ω| at the kernel's scale, so that one ε means the same at every
//! resolution. Both sums are gathers over the step's neighbour lists, the same for any
//! thread count. The acceleration is applied to the velocities at the end of a step.

use super::{Forcing, NonPressureForce};
use crate::Vec3;
use crate::fluid::Fluid;
use crate::reserve::reserve_total;
use rayon::prelude::*;

/// Vorticity confinement of coefficient ε, with its buffers.
#[derive(Clone, Debug)]
pub(crate) struct VorticityConfinement {
    /// ε (dimensionless).
    epsilon: f64,
    /// Every fluid particle's vorticity ω_i (1/s).
    vorticities: Vec<Vec3>,
    /// Every fluid particle's |ω_i| (1/s).
    magnitudes: Vec<f64>,
}

impl VorticityConfinement {
    /// Confinement of coefficient `epsilon` (> 0).
    pub fn new(epsilon: f64) -> Self {
        Self {
            epsilon,
            vorticities: Vec::new(),
            magnitudes: Vec::new(),
        }
    }
}

impl NonPressureForce for VorticityConfinement {
    fn try_reserve(&mut self, particles: usize) -> Result<(), std::collections::TryReserveError> {
        reserve_total(&mut self.vorticities, particles)?;
        reserve_total(&mut self.magnitudes, particles)
    }

    fn apply(&mut self, f: &Forcing, fluid: &mut Fluid, scratch: &mut Vec<Vec3>) {
        let (kernel, nb) = (&f.constraint.kernel, f.nb);
        let volume = f.constraint.mass / f.constraint.rest_density;
        let (x, v) = (&fluid.positions, &fluid.velocities);
        let neighbors = |i: usize| nb.fluid.of(i).iter().map(|&j| j as usize);
        self.vorticities.clear();
        self.vorticities
            .par_extend((0..x.len()).into_par_iter().map(|i| {
                neighbors(i)
                    .map(|j| kernel.grad_w(&(x[i] - x[j])).cross(&(v[j] - v[i])))
                    .sum::<Vec3>()
                    * volume
            }));
        let omega = &self.vorticities;
        self.magnitudes.clear();
        self.magnitudes
            .par_extend(omega.par_iter().map(|w| w.norm()));
        let norms = &self.magnitudes;
        let scale = self.epsilon * kernel.support_radius() * f.dt;
        scratch.clear();
        scratch.par_extend((0..x.len()).into_par_iter().map(|i| {
            let magnitude = norms[i];
            let eta: Vec3 = neighbors(i)
                .map(|j| kernel.grad_w(&(x[i] - x[j])) * (norms[j] - magnitude))
                .sum();
            let length = eta.norm();
            if length > 0.0 && magnitude > 0.0 {
                v[i] + (eta / length).cross(&omega[i]) * (magnitude * scale)
            } else {
                v[i]
            }
        }));
        std::mem::swap(&mut fluid.velocities, scratch);
    }
}
