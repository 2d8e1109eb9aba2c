//! Simulation against measurement: the time alignment at Z = 1.44 and the rows compared at
//! every measured time.

use super::{ALIGNMENT_LEVEL, Run};
use crate::validation::reference::{Curve, Measurements};
use crate::validation::{first_crossing, interpolate};
use projfluid::Error;

/// The time shift that makes the simulated front reach [`ALIGNMENT_LEVEL`] when the measured
/// one does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alignment {
    /// T at which the measured front reaches Z = 1.44.
    pub measured: f64,
    /// T at which the simulated front first reaches Z = 1.44.
    pub simulated: f64,
    /// measured − simulated: added to simulated T (and, divided by n, to simulated τ).
    pub shift: f64,
}

/// A measured point and the simulation at the same (aligned) time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// Measured time (T for the front, τ for the height).
    pub time: f64,
    /// Measured value (Z or H).
    pub measured: f64,
    /// Simulated value at `time` after alignment; `None` past the end of the run.
    pub simulated: Option<f64>,
}

impl Row {
    /// (simulated − measured)/measured, if simulated.
    pub fn relative_error(&self) -> Option<f64> {
        self.simulated.map(|s| (s - self.measured) / self.measured)
    }
}

/// Simulation against measurement at every measured time.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// The time alignment used.
    pub alignment: Alignment,
    /// Front rows (tabulated data).
    pub front: Vec<Row>,
    /// Front rows of the digitised extension, if any.
    pub front_extra: Vec<Row>,
    /// Residual height rows, unshifted (see [`compare`]).
    pub height: Vec<Row>,
    /// Residual height rows with the front's shift applied (reported, not asserted).
    pub height_shifted: Vec<Row>,
}

/// The simulated value at measured time `time` given the shift; before the simulated release
/// the column stands as at t = 0.
fn at_shifted(curve: &[(f64, f64)], time: f64, shift: f64) -> Option<f64> {
    let t = time - shift;
    if t <= 0.0 {
        curve.first().map(|p| p.1)
    } else {
        interpolate(curve, t)
    }
}

/// Aligns the run with `data` at Z = 1.44 and evaluates it at every measured time. Errors if
/// the simulated front never reaches Z = 1.44.
///
/// The shift compensates the measured front's early lag (the experiment's dam took a finite
/// time to remove). The residual height is compared without it: the measured heights show no
/// such lag (their first points lie on or below the unshifted simulation, not above it), so
/// shifting would compare a delayed simulation with an undelayed measurement. The heights
/// with the shift applied are kept in [`Comparison::height_shifted`] for the record.
pub fn compare(run: &Run, data: &Measurements) -> Result<Comparison, Error> {
    let front = run.front_curve();
    let height = run.height_curve();
    let simulated = first_crossing(&front, ALIGNMENT_LEVEL).ok_or_else(|| {
        Error::invalid(
            "duration",
            run.setup.duration,
            "is too short: the simulated front never reached Z = 1.44",
        )
    })?;
    let swapped: Vec<(f64, f64)> = data.front.points.iter().map(|&(t, z)| (z, t)).collect();
    let measured = interpolate(&swapped, ALIGNMENT_LEVEL)
        .ok_or_else(|| Error::invalid(data.front.file, "its range", "must include Z = 1.44"))?;
    let shift = measured - simulated;
    let rows = |curve: &Curve, sim: &[(f64, f64)], shift: f64| -> Vec<Row> {
        curve
            .points
            .iter()
            .map(|&(time, measured)| Row {
                time,
                measured,
                simulated: at_shifted(sim, time, shift),
            })
            .collect()
    };
    Ok(Comparison {
        alignment: Alignment {
            measured,
            simulated,
            shift,
        },
        front: rows(&data.front, &front, shift),
        front_extra: data
            .front_extra
            .as_ref()
            .map_or(Vec::new(), |c| rows(c, &front, shift)),
        height: rows(&data.height, &height, 0.0),
        height_shifted: rows(&data.height, &height, shift / run.setup.n()),
    })
}

impl Comparison {
    /// Largest |relative error| over the simulated rows of `rows`.
    pub fn worst(rows: &[Row]) -> f64 {
        rows.iter()
            .filter_map(Row::relative_error)
            .map(f64::abs)
            .fold(0.0, f64::max)
    }
}
