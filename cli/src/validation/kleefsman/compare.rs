//! Simulation against measurement: the surge's arrival at the gauges H3, H2 and H1, the
//! reservoir's fall at H4, and the RMS difference of every gauge's height; and, reported
//! beside them, the water content's arrival at H1 and its RMS difference at every gauge, and the
//! reference solver's arrivals and RMS differences over the same times.

use super::{GAUGES, Measurements, Reference, Run};
use crate::validation::{first_crossing, interpolate};

/// Water height (m) whose first crossing marks the surge's arrival at a gauge: ten times the
/// measured gauges' offsets before the water comes, and below the thinnest front the
/// simulation resolves (a layer one spacing deep).
pub const ARRIVAL_LEVEL: f64 = 0.02;

/// Gauges whose arrival is compared, in the order the water reaches them: H3 (x = 1.488 m),
/// H2 (0.992 m) and H1 (0.496 m, behind the box).
pub const ARRIVAL_GAUGES: [usize; 3] = [2, 1, 0];

/// The reservoir gauge H4.
pub const RESERVOIR_GAUGE: usize = 3;

/// Times at which the reservoir's height at H4 is compared (s).
pub const RESERVOIR_TIMES: [f64; 8] = [0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0];

/// How far the simulation may lie from the measurements (docs/validation.md says why).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Largest |simulated − measured| arrival time of the surge at H3 and H2 (s).
    pub arrival: f64,
    /// How much earlier than measured the water may reach H1, in the box's lee (s).
    pub lee_early: f64,
    /// How much later than measured the water may reach H1 (s): water stands in the
    /// simulated lee 0.2–0.3 s late at every resolution, viscosity, τ and step size tried,
    /// because it first comes through the air (docs/validation.md).
    pub lee_late: f64,
    /// Largest |simulated − measured| reservoir height at any of [`RESERVOIR_TIMES`] (m).
    pub reservoir: f64,
}

impl Default for Tolerances {
    /// 0.05 s for the surge's arrival, −0.1 s to +0.35 s for the lee's, 0.02 m for the
    /// reservoir height.
    fn default() -> Self {
        Self {
            arrival: 0.05,
            lee_early: 0.1,
            lee_late: 0.35,
            reservoir: 0.02,
        }
    }
}

impl Tolerances {
    /// The window (earliest, latest) of simulated − measured arrival time at gauge `g` (s).
    pub fn arrival_window(&self, g: usize) -> (f64, f64) {
        if g == LEE_GAUGE {
            (-self.lee_early, self.lee_late)
        } else {
            (-self.arrival, self.arrival)
        }
    }
}

/// The gauge in the box's lee, H1.
pub const LEE_GAUGE: usize = 0;

/// Whether a compared quantity lies within its tolerance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Within the tolerance.
    Pass,
    /// Outside it.
    Fail,
    /// The run ended before the quantity could be decided.
    NotCovered,
}

/// The surge's arrival at one gauge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arrival {
    /// Index into [`GAUGES`].
    pub gauge: usize,
    /// Measured time of the first crossing of [`ARRIVAL_LEVEL`] (s).
    pub measured: f64,
    /// Simulated time of the first crossing (s); `None` if the run never reached it.
    pub simulated: Option<f64>,
    /// End of the run (s).
    pub end: f64,
}

impl Arrival {
    /// simulated − measured (s), if the simulated water arrived.
    pub fn delay(&self) -> Option<f64> {
        self.simulated.map(|s| s - self.measured)
    }

    /// The verdict for a delay window (earliest, latest) (s): an arrival still missing when
    /// the run ends after measured + latest is too late.
    pub fn verdict(&self, (earliest, latest): (f64, f64)) -> Verdict {
        match self.delay() {
            Some(delay) if (earliest..=latest).contains(&delay) => Verdict::Pass,
            Some(_) => Verdict::Fail,
            None if self.end > self.measured + latest => Verdict::Fail,
            None => Verdict::NotCovered,
        }
    }
}

/// The reservoir's height at H4 at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReservoirLevel {
    /// Time (s).
    pub time: f64,
    /// Measured height (m).
    pub measured: f64,
    /// Simulated height (m); `None` past the end of the run.
    pub simulated: Option<f64>,
}

impl ReservoirLevel {
    /// The verdict with tolerance `tol` (m).
    pub fn verdict(&self, tol: f64) -> Verdict {
        match self.simulated {
            Some(s) if (s - self.measured).abs() <= tol => Verdict::Pass,
            Some(_) => Verdict::Fail,
            None => Verdict::NotCovered,
        }
    }
}

/// Simulation against measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Arrivals at H3, H2 and H1, in that order.
    pub arrivals: Vec<Arrival>,
    /// H4 at [`RESERVOIR_TIMES`].
    pub reservoir: Vec<ReservoirLevel>,
    /// RMS of simulated − measured height (m) at each gauge of [`GAUGES`], over the measured
    /// times the run covers.
    pub rms: [f64; 4],
    /// The arrival at H1 of water on the gauge's line, standing or not: the first time its
    /// water content reaches [`ARRIVAL_LEVEL`] (reported, not judged).
    pub lee_content: Arrival,
    /// As `rms`, for the water content of each gauge's line against the measured height.
    pub content_rms: [f64; 4],
    /// The reference solver against the same measurements (reported, not judged).
    pub reference: ReferenceComparison,
    /// The tolerances the verdicts use.
    pub tolerances: Tolerances,
}

/// The reference solver's run ([`Reference`]) against the measurements, over the times the
/// compared run covers.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceComparison {
    /// The reference's first crossing of [`ARRIVAL_LEVEL`] (s) at each gauge of
    /// [`ARRIVAL_GAUGES`], in that order; `None` if it never reached it within the run's time.
    pub arrivals: Vec<Option<f64>>,
    /// RMS of reference − measured height (m) at each gauge of [`GAUGES`], over the measured
    /// times that both the run and the reference cover.
    pub rms: [f64; 4],
}

/// Compares `run`, and `reference` over the same times, with `data` under `tolerances`.
pub fn compare(
    run: &Run,
    data: &Measurements,
    reference: &Reference,
    tolerances: Tolerances,
) -> Comparison {
    let end = run.end();
    // The arrival at gauge g of the simulated series `sim` (surface or content).
    let arrival = |g: usize, sim: Vec<(f64, f64)>| Arrival {
        gauge: g,
        measured: first_crossing(&data.heights[g], ARRIVAL_LEVEL)
            .expect("the measured water reaches every gauge"),
        simulated: first_crossing(&sim, ARRIVAL_LEVEL),
        end,
    };
    let arrivals = ARRIVAL_GAUGES
        .iter()
        .map(|&g| arrival(g, run.heights(g)))
        .collect();
    let h4 = run.heights(RESERVOIR_GAUGE);
    let reservoir = RESERVOIR_TIMES
        .iter()
        .map(|&time| ReservoirLevel {
            time,
            measured: interpolate(&data.heights[RESERVOIR_GAUGE], time)
                .expect("the measurements cover the compared times"),
            simulated: interpolate(&h4, time),
        })
        .collect();
    let rms_against = |g: usize, sim: &[(f64, f64)]| {
        let squares: Vec<f64> = data.heights[g]
            .iter()
            .filter(|&&(t, _)| t <= end)
            .filter_map(|&(t, h)| interpolate(sim, t).map(|s| (s - h).powi(2)))
            .collect();
        (squares.iter().sum::<f64>() / squares.len().max(1) as f64).sqrt()
    };
    Comparison {
        arrivals,
        reservoir,
        rms: std::array::from_fn(|g| rms_against(g, &run.heights(g))),
        lee_content: arrival(LEE_GAUGE, run.contents(LEE_GAUGE)),
        content_rms: std::array::from_fn(|g| rms_against(g, &run.contents(g))),
        reference: ReferenceComparison {
            arrivals: ARRIVAL_GAUGES
                .iter()
                .map(|&g| {
                    first_crossing(&reference.heights[g], ARRIVAL_LEVEL).filter(|&t| t <= end)
                })
                .collect(),
            rms: std::array::from_fn(|g| rms_against(g, &reference.heights[g])),
        },
        tolerances,
    }
}

impl Comparison {
    /// One line per compared quantity that fails its tolerance, naming it.
    pub fn failures(&self) -> Vec<String> {
        let t = self.tolerances;
        let arrivals = self.arrivals.iter().filter_map(|a| {
            let (early, late) = t.arrival_window(a.gauge);
            (a.verdict((early, late)) == Verdict::Fail).then(|| {
                let sim = a.simulated.map_or("never".into(), |s| format!("{s:.3} s"));
                format!(
                    "arrival at {}: simulated {sim}, measured {:.3} s (allowed {early:+} to \
                     {late:+} s)",
                    GAUGES[a.gauge], a.measured
                )
            })
        });
        let levels = self
            .reservoir
            .iter()
            .filter(|l| l.verdict(t.reservoir) == Verdict::Fail)
            .map(|l| {
                format!(
                    "H4 at {} s: simulated {:.3} m, measured {:.3} m (tolerance {} m)",
                    l.time,
                    l.simulated.unwrap_or(f64::NAN),
                    l.measured,
                    t.reservoir
                )
            });
        arrivals.chain(levels).collect()
    }

    /// Whether every compared quantity was decided (the run covered it).
    pub fn covered(&self) -> bool {
        let t = self.tolerances;
        self.arrivals
            .iter()
            .all(|a| a.verdict(t.arrival_window(a.gauge)) != Verdict::NotCovered)
            && self
                .reservoir
                .iter()
                .all(|l| l.verdict(t.reservoir) != Verdict::NotCovered)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrival_verdicts() {
        let a = |simulated, end| Arrival {
            gauge: 0,
            measured: 0.9,
            simulated,
            end,
        };
        let w = (-0.04, 0.1);
        assert_eq!(a(Some(0.92), 2.0).verdict(w), Verdict::Pass);
        assert_eq!(a(Some(0.99), 2.0).verdict(w), Verdict::Pass);
        assert_eq!(a(Some(0.85), 2.0).verdict(w), Verdict::Fail);
        assert_eq!(a(Some(0.5), 0.6).verdict(w), Verdict::Fail);
        assert_eq!(a(None, 2.0).verdict(w), Verdict::Fail);
        assert_eq!(a(None, 0.95).verdict(w), Verdict::NotCovered);
        let t = Tolerances::default();
        assert_eq!(t.arrival_window(LEE_GAUGE), (-0.1, 0.35));
        assert_eq!(t.arrival_window(1), (-0.05, 0.05));
        let l = |simulated| ReservoirLevel {
            time: 1.0,
            measured: 0.3,
            simulated,
        };
        assert_eq!(l(Some(0.31)).verdict(0.02), Verdict::Pass);
        assert_eq!(l(Some(0.35)).verdict(0.02), Verdict::Fail);
        assert_eq!(l(None).verdict(0.02), Verdict::NotCovered);
    }
}
