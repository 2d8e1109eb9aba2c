//! Chebyshev semi-iterative acceleration of the outer local/global iteration
//! (ALGORITHM.md §3.7, [SEED] eq. 8, [WANG15]).

use crate::Vec3;
use crate::params::{ChebyshevParams, Omega2Rule};
use rayon::prelude::*;

/// The ω recurrence of one time step.
#[derive(Clone, Debug)]
pub struct Chebyshev {
    params: ChebyshevParams,
    omega: f64,
}

impl Chebyshev {
    /// A recurrence with the given settings, ready for the first outer iteration.
    pub fn new(params: ChebyshevParams) -> Self {
        Self { params, omega: 1.0 }
    }

    /// Restarts the recurrence (at the start of every time step).
    pub fn reset(&mut self) {
        self.omega = 1.0;
    }

    /// ω_{k+1}, the weight that produces X^(k+1) in outer iteration `k` (k = 0, 1, …).
    pub fn next_weight(&mut self, k: usize) -> f64 {
        let ChebyshevParams {
            rho,
            delay,
            omega2_rule,
            ..
        } = self.params;
        self.omega = if k < delay {
            1.0
        } else if k == delay {
            match omega2_rule {
                Omega2Rule::Chebyshev => 2.0 / (2.0 - rho * rho),
                Omega2Rule::SeedLiteral => 4.0 / (4.0 - rho * rho),
            }
        } else {
            4.0 / (4.0 - rho * rho * self.omega)
        };
        self.omega
    }

    /// Turns the plain iterate X̃^(k+1) in `next` into
    /// X^(k+1) = ω(γ(X̃^(k+1) − X^(k)) + X^(k) − X^(k−1)) + X^(k−1).
    /// With ω = γ = 1 it leaves `next` bitwise unchanged.
    pub fn extrapolate(&self, omega: f64, next: &mut [Vec3], current: &[Vec3], previous: &[Vec3]) {
        let gamma = self.params.gamma;
        if omega == 1.0 && gamma == 1.0 {
            return;
        }
        next.par_iter_mut()
            .zip(current.par_iter().zip(previous.par_iter()))
            .for_each(|(n, (c, p))| {
                *n = if gamma == 1.0 {
                    // Momentum form of the same update: X̃ + (ω − 1)(X̃ − X^(k−1)).
                    *n + (*n - p) * (omega - 1.0)
                } else {
                    p + ((*n - c) * gamma + c - p) * omega
                };
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(rho: f64, delay: usize, rule: Omega2Rule) -> ChebyshevParams {
        ChebyshevParams {
            rho,
            delay,
            omega2_rule: rule,
            gamma: 1.0,
        }
    }

    #[test]
    fn weights_follow_the_recurrence() {
        let mut c = Chebyshev::new(params(0.925, 1, Omega2Rule::SeedLiteral));
        let w: Vec<f64> = (0..40).map(|k| c.next_weight(k)).collect();
        assert_eq!(w[0], 1.0);
        assert!((w[1] - 1.272).abs() < 1e-3, "{}", w[1]);
        assert!((w[2] - 1.374).abs() < 1e-3, "{}", w[2]);
        let limit = 2.0 / (1.0 + (1.0 - 0.925f64 * 0.925).sqrt());
        assert!((w[39] - limit).abs() < 1e-9);
        let mut c = Chebyshev::new(params(0.925, 3, Omega2Rule::Chebyshev));
        let w: Vec<f64> = (0..5).map(|k| c.next_weight(k)).collect();
        assert_eq!(&w[..3], &[1.0, 1.0, 1.0]);
        assert!(
            (w[3] - 1.748).abs() < 1e-3 && (w[4] - 1.597).abs() < 1e-3,
            "{w:?}"
        );
    }

    #[test]
    fn accelerates_a_linear_fixed_point_iteration() {
        // x ← G x + c with G = diag(0.9, −0.9, 0.5): plain iteration contracts at 0.9.
        let g = Vec3::new(0.9, -0.9, 0.5);
        let c = Vec3::new(1.0, 2.0, 3.0);
        let fixed = c.component_div(&(Vec3::repeat(1.0) - g));
        let iterations = |rho: f64| {
            let mut cheb = Chebyshev::new(params(rho, 1, Omega2Rule::Chebyshev));
            let (mut prev, mut cur) = (vec![Vec3::zeros()], vec![Vec3::zeros()]);
            for k in 0..1000 {
                let mut next = vec![g.component_mul(&cur[0]) + c];
                let w = cheb.next_weight(k);
                cheb.extrapolate(w, &mut next, &cur, &prev);
                prev = std::mem::replace(&mut cur, next);
                if (cur[0] - fixed).norm() < 1e-10 {
                    return k;
                }
            }
            1000
        };
        let plain = iterations(0.0);
        let accelerated = iterations(0.9);
        assert!(plain > 200, "{plain}");
        assert!(accelerated < plain / 3, "{accelerated} vs {plain}");
    }
}
