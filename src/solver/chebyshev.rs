//! Chebyshev semi-iterative acceleration of the outer local/global iteration
//! (docs/method.md §3.7, Sommer et al. 2020 eq. 8, Wang 2015), with a fixed ρ_c or one estimated online from
//! the accelerated steps themselves ([`ChebyshevParams::auto_rho`]; docs/solvers.md, "Choosing ρ").

use crate::Vec3;
use crate::params::{ChebyshevParams, Omega2Rule};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::ops::{Add, Mul, Sub};

/// A step needs at least this many outer iterations to give an estimate of the plain
/// iteration's contraction.
pub const AUTO_MIN_ITERATIONS: usize = 5;
/// ρ_c = κ·μ̂ with μ̂ the smoothed estimate of the plain iteration's contraction. κ < 1 is
/// what lets ρ_c come down again: an estimate is never below the ρ_c it was measured with
/// ([`plain_contraction`]), so only the factor κ pulls an over-estimated ρ_c back.
pub const AUTO_KAPPA: f64 = 0.97;
/// Weight of a new step's estimate in the exponential moving average μ̂.
pub const AUTO_SMOOTHING: f64 = 0.5;
/// Range that the online ρ_c is clamped to.
pub const AUTO_RHO_RANGE: (f64, f64) = (0.5, 0.925);

/// The online ρ_c estimate carried from step to step (saved in checkpoints).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OnlineRho {
    /// ρ_c of the next step.
    pub rho: f64,
    /// Smoothed estimate μ̂ of the plain iteration's contraction, once measured.
    pub contraction: Option<f64>,
}

/// The ω recurrence of one time step, and the online ρ_c estimate carried across steps.
#[derive(Clone, Debug)]
pub struct Chebyshev {
    params: ChebyshevParams,
    omega: f64,
    /// ρ_c of the current step.
    rho: f64,
    /// Smoothed estimate μ̂ of the plain iteration's contraction (online mode), once measured.
    contraction: Option<f64>,
}

impl Chebyshev {
    /// A recurrence with the given settings, ready for the first outer iteration.
    pub fn new(params: ChebyshevParams) -> Self {
        Self {
            params,
            omega: 1.0,
            rho: params.rho,
            contraction: None,
        }
    }

    /// Restarts the recurrence at the start of every time step.
    pub fn reset(&mut self) {
        self.omega = 1.0;
    }

    /// The online estimate's state, to be saved with the world.
    pub fn online(&self) -> OnlineRho {
        OnlineRho {
            rho: self.rho,
            contraction: self.contraction,
        }
    }

    /// Restores a state saved by [`Chebyshev::online`].
    pub fn set_online(&mut self, state: OnlineRho) {
        self.rho = state.rho;
        self.contraction = state.contraction;
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
                Omega2Rule::Paper => 4.0 / (4.0 - rho * rho),
            }
        } else {
            4.0 / (4.0 - rho * rho * self.omega)
        };
        self.omega
    }

    /// Online mode only: learns from the displacements δ_0..δ_K of the step just finished,
    /// which extrapolated with the current ρ_c. If the step took at least
    /// [`AUTO_MIN_ITERATIONS`] iterations, their contraction over the last half
    /// ([`late_contraction`]) gives an estimate of the plain iteration's contraction
    /// ([`plain_contraction`]), which enters μ̂ ← (1 − a)μ̂ + a·estimate; then
    /// ρ_c = clamp(κ·μ̂). Until the first estimate ρ_c is the scene's `rho`.
    pub fn finish_step(&mut self, displacements: &[f64]) {
        if !self.params.auto_rho {
            return;
        }
        let Some(rate) = late_contraction(displacements) else {
            return;
        };
        let estimate = plain_contraction(rate, self.rho);
        let smoothed = match self.contraction {
            Some(c) => c + AUTO_SMOOTHING * (estimate - c),
            None => estimate,
        };
        self.contraction = Some(smoothed);
        let (lo, hi) = AUTO_RHO_RANGE;
        self.rho = (AUTO_KAPPA * smoothed).clamp(lo, hi);
    }

    /// Turns the plain iterate X̃^(k+1) in `next` into
    /// X^(k+1) = ω(γ(X̃^(k+1) − X^(k)) + X^(k) − X^(k−1)) + X^(k−1).
    /// With ω = γ = 1 it leaves `next` bitwise unchanged.
    pub fn extrapolate(&self, omega: f64, next: &mut [Vec3], current: &[Vec3], previous: &[Vec3]) {
        if !self.changes(omega) {
            return;
        }
        next.par_iter_mut()
            .zip(current.par_iter().zip(previous.par_iter()))
            .for_each(|(n, (c, p))| *n = self.extrapolated(omega, *n, *c, *p));
    }

    /// Whether extrapolating with weight `omega` changes an iterate (false for ω = γ = 1).
    #[inline]
    pub fn changes(&self, omega: f64) -> bool {
        omega != 1.0 || self.params.gamma != 1.0
    }

    /// One particle of [`Chebyshev::extrapolate`]: X^(k+1) (m) from the plain iterate
    /// `plain` = X̃^(k+1), `current` = X^(k) and `previous` = X^(k−1) (m), with weight `omega`;
    /// the same for any quantity the iteration carries alike (a position, or a carried
    /// multiplier in m²).
    #[inline]
    pub fn extrapolated<T>(&self, omega: f64, plain: T, current: T, previous: T) -> T
    where
        T: Copy + Add<Output = T> + Sub<Output = T> + Mul<f64, Output = T>,
    {
        let gamma = self.params.gamma;
        if gamma == 1.0 {
            // Momentum form of the same update: X̃ + (ω − 1)(X̃ − X^(k−1)).
            plain + (plain - previous) * (omega - 1.0)
        } else {
            previous + ((plain - current) * gamma + current - previous) * omega
        }
    }
}

/// Geometric-mean ratio of successive displacements over the last half of `displacements`,
/// (δ_K/δ_h)^(1/(K−h)) with h = ⌊(K+1)/2⌋, at most 1; `None` when there are fewer than
/// [`AUTO_MIN_ITERATIONS`] or they are not positive.
fn late_contraction(displacements: &[f64]) -> Option<f64> {
    // Three displacements at least, so that the last half spans one ratio or more.
    const _: () = assert!(AUTO_MIN_ITERATIONS >= 3);
    let n = displacements.len();
    if n < AUTO_MIN_ITERATIONS {
        return None;
    }
    let (first, last) = (displacements[n / 2], displacements[n - 1]);
    let rate = (last / first).powf(1.0 / (n - 1 - n / 2) as f64);
    (first > 0.0 && last > 0.0 && rate.is_finite()).then(|| rate.min(1.0))
}

/// The contraction μ of the plain iteration that makes Chebyshev's iteration with parameter
/// `rho_c` (< μ) contract at `rate` per iteration, in the linear model of docs/method.md §5.4,
/// as in the adaptive Chebyshev procedures of Hageman and Young (Applied Iterative Methods,
/// 1981). Its slowest mode contracts at r = (μ + √(μ² − ρ_c²))/(1 + √(1 − ρ_c²)); with
/// a = r·(1 + √(1 − ρ_c²)) that inverts to μ = (a² + ρ_c²)/(2a). A rate at or below what
/// ρ_c ≥ μ would give (a ≤ ρ_c) says only that μ ≤ ρ_c, and returns ρ_c. With ρ_c = 0
/// (no extrapolation) it returns `rate` itself (up to rounding). Never below ρ_c.
fn plain_contraction(rate: f64, rho_c: f64) -> f64 {
    let a = rate * (1.0 + (1.0 - rho_c * rho_c).sqrt());
    if a > rho_c {
        (a * a + rho_c * rho_c) / (2.0 * a)
    } else {
        rho_c
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
            auto_rho: false,
        }
    }

    #[test]
    fn weights_follow_the_recurrence() {
        let mut c = Chebyshev::new(params(0.925, 1, Omega2Rule::Paper));
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
            iterates(&mut cheb, g, c, 1000)
                .iter()
                .position(|x| (x - fixed).norm() < 1e-10)
                .unwrap_or(1000)
        };
        let plain = iterations(0.0);
        let accelerated = iterations(0.9);
        assert!(plain > 200, "{plain}");
        assert!(accelerated < plain / 3, "{accelerated} vs {plain}");
    }

    /// X^(1)..X^(n) of `n` accelerated iterations of x ← G x + c from X^(0) = 0, with the
    /// weights and ρ_c of `cheb`.
    fn iterates(cheb: &mut Chebyshev, g: Vec3, c: Vec3, n: usize) -> Vec<Vec3> {
        cheb.reset();
        let (mut prev, mut cur) = (vec![Vec3::zeros()], vec![Vec3::zeros()]);
        (0..n)
            .map(|k| {
                let mut next = vec![g.component_mul(&cur[0]) + c];
                let w = cheb.next_weight(k);
                cheb.extrapolate(w, &mut next, &cur, &prev);
                prev = std::mem::replace(&mut cur, next);
                cur[0]
            })
            .collect()
    }

    /// The displacements max_c |X^(k+1) − X^(k)| of [`iterates`].
    fn displacements(cheb: &mut Chebyshev, g: Vec3, c: Vec3, n: usize) -> Vec<f64> {
        let x = iterates(cheb, g, c, n);
        let start = std::iter::once(Vec3::zeros()).chain(x.iter().copied());
        x.iter()
            .zip(start)
            .map(|(next, cur)| (next - cur).abs().max())
            .collect()
    }

    #[test]
    fn plain_contraction_inverts_the_chebyshev_rate() {
        for mu in [0.7f64, 0.9, 0.97] {
            for rho_c in [0.0f64, 0.5, 0.69] {
                let s = (1.0 - rho_c * rho_c).sqrt();
                let rate = (mu + (mu * mu - rho_c * rho_c).sqrt()) / (1.0 + s);
                let estimate = plain_contraction(rate, rho_c);
                assert!((estimate - mu).abs() < 1e-12, "{mu} {rho_c}: {estimate}");
            }
        }
        // Over-estimated: every mode contracts at √(ω∞ − 1) = ρ_c/(1 + √(1 − ρ_c²)) or
        // faster, which says only that μ ≤ ρ_c.
        let ideal = 0.9 / (1.0 + (1.0 - 0.81f64).sqrt());
        assert_eq!(plain_contraction(ideal, 0.9), 0.9);
        assert_eq!(plain_contraction(0.3, 0.9), 0.9);
        assert!((plain_contraction(0.8, 0.0) - 0.8).abs() < 1e-15);
    }

    #[test]
    fn online_rho_finds_the_contraction_of_a_linear_iteration() {
        let online = |rho| {
            Chebyshev::new(ChebyshevParams {
                auto_rho: true,
                ..params(rho, 1, Omega2Rule::Paper)
            })
        };
        // Plain iteration contracts at 0.95 (the other modes faster, one alternating).
        let (g, c) = (Vec3::new(0.95, 0.3, -0.5), Vec3::new(1.0, 2.0, 3.0));
        let mut cheb = online(0.6);
        // Too short to measure: the starting ρ_c stays.
        let short = displacements(&mut cheb, g, c, AUTO_MIN_ITERATIONS - 1);
        cheb.finish_step(&short);
        assert_eq!((cheb.rho(), cheb.online().contraction), (0.6, None));
        let first = displacements(&mut cheb, g, c, 40);
        cheb.finish_step(&first);
        // Measured while extrapolating with ρ_c = 0.6, the step still sees μ ≈ 0.95.
        let estimate = cheb.online().contraction.unwrap();
        assert!((estimate - 0.95).abs() < 0.01, "{estimate}");
        assert_eq!(cheb.rho(), AUTO_KAPPA * estimate);
        for _ in 0..10 {
            let d = displacements(&mut cheb, g, c, 40);
            cheb.finish_step(&d);
        }
        let settled = cheb.rho();
        assert!((settled - AUTO_KAPPA * 0.95).abs() < 0.005, "{settled}");
        // The settled ρ_c needs well under half the iterations of the starting one to
        // bring the displacement below 10⁻⁸ (123 against 287; plain iteration 360).
        let below = |d: Vec<f64>| d.iter().position(|&d| d < 1e-8).unwrap();
        let accelerated = below(displacements(&mut cheb, g, c, 1000));
        let mut start = Chebyshev::new(params(0.6, 1, Omega2Rule::Paper));
        let from_start = below(displacements(&mut start, g, c, 1000));
        assert!(
            accelerated * 2 < from_start,
            "{accelerated} vs {from_start}"
        );

        // An over-estimated ρ_c (plain contraction 0.6) comes down, and not below it by much.
        let g = Vec3::new(0.6, 0.3, -0.5);
        let mut cheb = online(0.92);
        for _ in 0..40 {
            let d = displacements(&mut cheb, g, c, 30);
            cheb.finish_step(&d);
        }
        assert!((0.55..0.65).contains(&cheb.rho()), "{}", cheb.rho());

        // A fixed ρ_c never changes.
        let mut fixed = Chebyshev::new(params(0.85, 1, Omega2Rule::Paper));
        fixed.finish_step(&first);
        assert_eq!(fixed.rho(), 0.85);
    }
}
