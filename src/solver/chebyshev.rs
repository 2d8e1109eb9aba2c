//! Chebyshev semi-iterative acceleration of the outer local/global iteration
//! (ALGORITHM.md §3.7, [SEED] eq. 8, [WANG15]), with a fixed ρ_c or one estimated online from
//! probes of the plain iteration ([`ChebyshevParams::auto_rho`]; README, "Choosing ρ").

use crate::Vec3;
use crate::params::{ChebyshevParams, Omega2Rule};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// With `auto_rho`, every this many steps one step runs the plain iteration (a probe) to
/// measure its contraction.
pub const AUTO_PROBE_INTERVAL: u64 = 40;
/// A probe needs at least this many outer iterations to give an estimate.
pub const AUTO_MIN_PROBE_ITERATIONS: usize = 20;
/// ρ_c = κ·ρ̂ with ρ̂ the smoothed contraction of the probes (README, "Choosing ρ").
pub const AUTO_KAPPA: f64 = 0.9;
/// Weight of a new probe's contraction in the exponential moving average ρ̂.
pub const AUTO_SMOOTHING: f64 = 0.5;
/// Range that the online ρ_c is clamped to.
pub const AUTO_RHO_RANGE: (f64, f64) = (0.5, 0.95);

/// The online ρ_c estimate carried from step to step (saved in checkpoints).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OnlineRho {
    /// ρ_c of the next step.
    pub rho: f64,
    /// Smoothed contraction ρ̂ of the probes so far.
    pub contraction: Option<f64>,
    /// Steps since the last probe.
    pub since_probe: u64,
}

/// The ω recurrence of one time step, and the online ρ_c estimate carried across steps.
#[derive(Clone, Debug)]
pub struct Chebyshev {
    params: ChebyshevParams,
    omega: f64,
    /// ρ_c of the current step.
    rho: f64,
    /// Smoothed plain-iteration contraction ρ̂ (online mode), once measured.
    contraction: Option<f64>,
    /// Steps since the last probe.
    since_probe: u64,
    /// The current step is a probe: plain iteration, no extrapolation.
    probing: bool,
}

impl Chebyshev {
    /// A recurrence with the given settings, ready for the first outer iteration.
    pub fn new(params: ChebyshevParams) -> Self {
        let mut c = Self {
            params,
            omega: 1.0,
            rho: params.rho,
            contraction: None,
            since_probe: AUTO_PROBE_INTERVAL,
            probing: false,
        };
        c.reset();
        c
    }

    /// Restarts the recurrence at the start of every time step and, with `auto_rho`, decides
    /// whether this step is a probe: the first step, then every [`AUTO_PROBE_INTERVAL`] steps.
    pub fn reset(&mut self) {
        self.omega = 1.0;
        self.probing = self.params.auto_rho && self.since_probe >= AUTO_PROBE_INTERVAL;
    }

    /// True when the current step extrapolates (false during a probe).
    pub fn accelerates(&self) -> bool {
        !self.probing
    }

    /// The online estimate's state, to be saved with the world.
    pub fn online(&self) -> OnlineRho {
        OnlineRho {
            rho: self.rho,
            contraction: self.contraction,
            since_probe: self.since_probe,
        }
    }

    /// Restores a state saved by [`Chebyshev::online`].
    pub fn set_online(&mut self, state: OnlineRho) {
        self.rho = state.rho;
        self.contraction = state.contraction;
        self.since_probe = state.since_probe;
        self.reset();
    }

    /// ρ_c that the current step extrapolates with.
    pub fn rho(&self) -> f64 {
        self.rho
    }

    /// ω_{k+1}, the weight that produces X^(k+1) in outer iteration `k` (k = 0, 1, …).
    pub fn next_weight(&mut self, k: usize) -> f64 {
        let ChebyshevParams {
            delay, omega2_rule, ..
        } = self.params;
        let rho = self.rho;
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

    /// Online mode only: learns from the displacements δ_0..δ_K of the step just finished.
    /// After a probe with at least [`AUTO_MIN_PROBE_ITERATIONS`] iterations, the contraction
    /// (δ_K/δ_h)^(1/(K−h)) over the last half (h = ⌊(K+1)/2⌋) enters ρ̂ ← (1 − a)ρ̂ + a·rate
    /// and ρ_c = clamp(κ·ρ̂); a shorter probe leaves ρ_c as it was (the starting `rho` until
    /// the first estimate).
    pub fn finish_step(&mut self, displacements: &[f64]) {
        if !self.params.auto_rho {
            return;
        }
        if !self.probing {
            self.since_probe += 1;
            return;
        }
        // Whether or not it measured something, the next probe comes an interval later.
        self.since_probe = 0;
        let Some(rate) = late_contraction(displacements) else {
            return;
        };
        let smoothed = match self.contraction {
            Some(c) => c + AUTO_SMOOTHING * (rate - c),
            None => rate,
        };
        self.contraction = Some(smoothed);
        let (lo, hi) = AUTO_RHO_RANGE;
        self.rho = (AUTO_KAPPA * smoothed).clamp(lo, hi);
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

/// Geometric-mean ratio of successive displacements over the last half of `displacements`,
/// or `None` when there are fewer than [`AUTO_MIN_PROBE_ITERATIONS`] or they are not positive.
fn late_contraction(displacements: &[f64]) -> Option<f64> {
    let n = displacements.len();
    if n < AUTO_MIN_PROBE_ITERATIONS {
        return None;
    }
    let (first, last) = (displacements[n / 2], displacements[n - 1]);
    let rate = (last / first).powf(1.0 / (n - 1 - n / 2) as f64);
    (first > 0.0 && last > 0.0 && rate.is_finite()).then(|| rate.min(1.0))
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
            auto_rho: false,
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

    #[test]
    fn online_rho_comes_from_probes_of_the_plain_iteration() {
        let mut c = Chebyshev::new(ChebyshevParams {
            auto_rho: true,
            ..params(0.85, 1, Omega2Rule::SeedLiteral)
        });
        // Probe every AUTO_PROBE_INTERVAL steps, starting with the first.
        let next_probe = |c: &mut Chebyshev| {
            for _ in 0..AUTO_PROBE_INTERVAL {
                c.reset();
                assert!(c.accelerates());
                c.finish_step(&[1.0, 0.1]);
            }
            c.reset();
            assert!(!c.accelerates());
        };
        assert!(!c.accelerates());
        // Too short to measure: the starting ρ_c stays.
        c.finish_step(&[1.0, 0.5, 0.2]);
        assert_eq!(c.rho(), 0.85);
        next_probe(&mut c);
        // Twenty iterations contracting at 0.9.
        let probe: Vec<f64> = (0..20).map(|k| 0.9f64.powi(k)).collect();
        c.finish_step(&probe);
        let first = AUTO_KAPPA * 0.9;
        assert!((c.rho() - first).abs() < 1e-12, "{}", c.rho());
        c.reset();
        assert!(c.accelerates());
        assert_eq!(c.next_weight(0), 1.0);
        assert_eq!(c.next_weight(1), 4.0 / (4.0 - first * first));
        // The next probe is smoothed in.
        next_probe(&mut c);
        let probe: Vec<f64> = (0..22).map(|k| 0.99f64.powi(k)).collect();
        c.finish_step(&probe);
        let smoothed = 0.9 + AUTO_SMOOTHING * (0.99 - 0.9);
        let expected = (AUTO_KAPPA * smoothed).clamp(AUTO_RHO_RANGE.0, AUTO_RHO_RANGE.1);
        assert!((c.rho() - expected).abs() < 1e-12);
        // A fixed ρ_c never probes.
        let mut fixed = Chebyshev::new(params(0.85, 1, Omega2Rule::SeedLiteral));
        assert!(fixed.accelerates());
        fixed.finish_step(&probe);
        assert_eq!(fixed.rho(), 0.85);
    }
}
