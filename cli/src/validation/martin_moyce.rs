//! The Martin & Moyce (1952) column collapse: a water column of width a and height n²·a
//! released at t = 0 in a long tank, as a thin 3D slab between two free-slip walls.
//!
//! Tracked quantities (per step):
//! * the surge front z(t): distance from the back wall of the farthest fluid particle near the
//!   floor (centre within 2.5 spacings of the floor plane) that is connected to the back wall
//!   through such particles: sorted by x, no two consecutive ones farther apart than the
//!   kernel support H = 2d. A splash that lands ahead of the front, or a droplet above it,
//!   does not count until the front reaches it;
//! * the residual height h(t): the same rule upwards among particles within 2.5 spacings of
//!   the back wall, from the floor.
//!
//! Distances are measured from the wall planes (the boundary particles) to particle centres.
//! Fluid centres rest one spacing d from a wall plane and each particle stands for a cube of
//! edge d, so the water's surface lies d/2 beyond the outermost centre and its back face d/2
//! in front of the wall plane: centre-to-plane is the water's extent.
//! Scalings are those of the data (`data/validation/README.md`): Z = z/a against
//! T = n·t·√(g/a), H = h/(n²a) against τ = t·√(g/a).

use super::reference::{COLUMN_WIDTH, Curve, Measurements};
use super::{first_crossing, interpolate};
use crate::plot::{LineChart, Series, SeriesStyle};
use projfluid::boundary::Aabb;
use projfluid::{Error, Params, SolverKind, Vec3, World};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The front position Z at which simulation and experiment are aligned in time.
pub const ALIGNMENT_LEVEL: f64 = 1.44;

/// Particles whose centres lie within this many spacings of the floor (back wall) count for the
/// front (the residual height).
const BAND_SPACINGS: f64 = 2.5;

/// How the collapse is set up and how long it runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Setup {
    /// Height/width ratio n² of the column: 2 (height 2a) or 1 (square).
    pub n2: u32,
    /// Particles across the column width a; the spacing is d = a/particles_across.
    pub particles_across: usize,
    /// Slab thickness in particles (between the two side walls).
    pub layers: usize,
    /// Dimensionless duration τ = t·√(g/a).
    pub duration: f64,
    /// Global solver.
    pub solver: SolverKind,
    /// Worker threads (0 = one per core).
    pub threads: usize,
}

impl Setup {
    /// The defaults for ratio `n2`: 20 particles across, 4 layers, and a duration covering
    /// the tabulated front (τ = 3.0 for n² = 2, 3.5 for n² = 1).
    pub fn new(n2: u32) -> Self {
        Self {
            n2,
            particles_across: 20,
            layers: 4,
            duration: if n2 == 1 { 3.5 } else { 3.0 },
            solver: SolverKind::Chebyshev,
            threads: 0,
        }
    }

    /// Checks every field; the error names the bad one.
    pub fn validate(&self) -> Result<(), Error> {
        if !matches!(self.n2, 1 | 2) {
            return Err(Error::invalid("n2", self.n2, "must be 1 or 2"));
        }
        if !(4..=200).contains(&self.particles_across) {
            let n = self.particles_across;
            return Err(Error::invalid(
                "resolution",
                n,
                "must lie between 4 and 200",
            ));
        }
        if !(1..=20).contains(&self.layers) {
            return Err(Error::invalid(
                "layers",
                self.layers,
                "must lie between 1 and 20",
            ));
        }
        if !(self.duration.is_finite() && self.duration > 0.0 && self.duration <= 20.0) {
            return Err(Error::invalid(
                "duration",
                self.duration,
                "must lie in (0, 20]",
            ));
        }
        Ok(())
    }

    /// n = √(n²).
    pub fn n(&self) -> f64 {
        f64::from(self.n2).sqrt()
    }

    /// Lattice spacing d (m).
    pub fn spacing(&self) -> f64 {
        COLUMN_WIDTH / self.particles_across as f64
    }

    /// Tank length in units of a: the front cannot reach the far wall within the duration
    /// even at the shallow-water (Ritter) speed bound dZ/dT = 2.
    pub fn tank_length(&self) -> f64 {
        (1.0 + 2.0 * self.n() * self.duration).ceil() + 1.0
    }

    /// The world at t = 0 and the tank it stands in. Particle mass factor 1, so that the
    /// column starts at rest density and does not first settle.
    pub fn build(&self) -> Result<(World, Aabb), Error> {
        self.validate()?;
        let a = COLUMN_WIDTH;
        let d = self.spacing();
        let params = Params {
            mass_factor: 1.0,
            solver: self.solver,
            threads: self.threads,
            ..Params::with_radius(0.5 * d)
        };
        let r = params.particle_radius;
        let mut world = World::new(params)?;
        // First centres one spacing (plus r/4, so that no corner starts compressed) from the walls.
        let gap = d + 0.25 * r;
        let count = [
            self.particles_across,
            self.n2 as usize * self.particles_across,
            self.layers,
        ];
        let tank = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(
                self.tank_length() * a,
                (self.n2 as f64 + 1.0) * a,
                2.0 * gap + (self.layers - 1) as f64 * d,
            ),
        };
        world.add_container(tank, 1)?;
        world.add_fluid_block(Vec3::repeat(gap), count, Vec3::zeros())?;
        Ok((world, tank))
    }
}

/// One tracked state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time since release (s).
    pub time: f64,
    /// Front distance z from the back wall (m).
    pub front: f64,
    /// Residual height h at the back wall (m).
    pub height: f64,
    /// Largest compression max(ρ/ρ0 − 1) of the step (dimensionless).
    pub density_error_max: f64,
}

/// A finished collapse: the setup and the tracked history.
#[derive(Clone, Debug)]
pub struct Run {
    /// What was run.
    pub setup: Setup,
    /// One sample at t = 0 and one after every step.
    pub samples: Vec<Sample>,
    /// Fluid particles.
    pub particles: usize,
    /// Boundary particles.
    pub boundary_particles: usize,
    /// Fluid particles that left the tank by the end.
    pub escaped: usize,
    /// Magnitude of gravity g (m/s²).
    pub gravity: f64,
}

/// Distance from `start` to the end of the run of `values` that begins at the smallest value
/// and in which consecutive sorted values lie at most `gap` apart.
fn connected_extent(mut values: Vec<f64>, start: f64, gap: f64) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    let first = *values.first()?;
    let end = values
        .windows(2)
        .find(|w| w[1] - w[0] > gap)
        .map_or(values[values.len() - 1], |w| w[0]);
    Some(end.max(first) - start)
}

/// Front distance z (m) from the back wall plane at x = `back`: see the module docs.
pub fn front_position(positions: &[Vec3], back: f64, floor: f64, spacing: f64) -> Option<f64> {
    let near_floor = positions
        .iter()
        .filter(|p| p.y - floor <= BAND_SPACINGS * spacing)
        .map(|p| p.x)
        .collect();
    connected_extent(near_floor, back, 2.0 * spacing)
}

/// Residual height h (m) above the floor plane at y = `floor` next to the back wall: see the
/// module docs.
pub fn column_height(positions: &[Vec3], back: f64, floor: f64, spacing: f64) -> Option<f64> {
    let near_wall = positions
        .iter()
        .filter(|p| p.x - back <= BAND_SPACINGS * spacing)
        .map(|p| p.y)
        .collect();
    connected_extent(near_wall, floor, 2.0 * spacing)
}

fn sample(world: &World, tank: &Aabb, spacing: f64) -> Result<Sample, Error> {
    let positions = world.positions();
    let lost = || Error::invalid("fluid", "no particles", "left near the floor and back wall");
    let front = front_position(&positions, tank.min.x, tank.min.y, spacing).ok_or_else(lost)?;
    let height = column_height(&positions, tank.min.x, tank.min.y, spacing).ok_or_else(lost)?;
    Ok(Sample {
        time: world.time(),
        front,
        height,
        density_error_max: world.last_step().map_or(0.0, |s| s.density_error_max),
    })
}

/// Runs the collapse for `setup.duration`, tracking front and height after every step;
/// `progress` receives the fraction done after each step. Errors on a bad setup, a failed
/// step, or NaN positions.
pub fn simulate(setup: &Setup, mut progress: impl FnMut(f64)) -> Result<Run, Error> {
    let (mut world, tank) = setup.build()?;
    let d = setup.spacing();
    let g = Vec3::from(world.params().gravity).norm();
    let end = setup.duration * (COLUMN_WIDTH / g).sqrt();
    let mut samples = vec![sample(&world, &tank, d)?];
    world.advance_with(end, |world| {
        if world.nan_count() > 0 {
            return Err(Error::invalid(
                "simulation",
                format!("t = {:.4} s", world.time()),
                "produced non-finite particle positions",
            ));
        }
        samples.push(sample(world, &tank, d)?);
        progress(world.time() / end);
        Ok(())
    })?;
    Ok(Run {
        setup: setup.clone(),
        samples,
        particles: world.fluid_count(),
        boundary_particles: world.boundary_count(),
        escaped: world.escaped_count(),
        gravity: g,
    })
}

impl Run {
    /// √(g/a) (1/s): multiplies seconds into τ.
    fn rate(&self) -> f64 {
        (self.gravity / COLUMN_WIDTH).sqrt()
    }

    /// The simulated front as (T, Z) with T = n·t·√(g/a), Z = z/a.
    pub fn front_curve(&self) -> Vec<(f64, f64)> {
        let (n, rate) = (self.setup.n(), self.rate());
        let a = COLUMN_WIDTH;
        self.samples
            .iter()
            .map(|s| (n * s.time * rate, s.front / a))
            .collect()
    }

    /// The simulated residual height as (τ, H) with τ = t·√(g/a), H = h/(n²a).
    pub fn height_curve(&self) -> Vec<(f64, f64)> {
        let column = f64::from(self.setup.n2) * COLUMN_WIDTH;
        let rate = self.rate();
        self.samples
            .iter()
            .map(|s| (s.time * rate, s.height / column))
            .collect()
    }

    /// Largest compression over the run (dimensionless).
    pub fn density_error_max(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.density_error_max)
            .fold(0.0, f64::max)
    }
}

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

    /// A plain-text table of front and height rows, with the alignment stated.
    pub fn table(&self, n2: u32) -> String {
        let a = &self.alignment;
        let mut out = format!(
            "time alignment: the simulated front reaches Z = {ALIGNMENT_LEVEL} at T = {:.3}, the \
             measured one at T = {:.3};\nsimulated front times are shifted by {:+.3} in T. The \
             residual height is compared unshifted\n(the last column applies the same shift, \
             {:+.3} in tau, for comparison).\n",
            a.simulated,
            a.measured,
            a.shift,
            a.shift / f64::from(n2).sqrt()
        );
        let cells = |r: &Row| match (r.simulated, r.relative_error()) {
            (Some(s), Some(e)) => (format!("{s:.3}"), format!("{:+.1} %", 100.0 * e)),
            _ => ("-".into(), "not run".into()),
        };
        let mut front = |title: &str, rows: &[Row]| {
            let _ = writeln!(out, "\n{title}");
            let _ = writeln!(
                out,
                "{:>7}  {:>7}  {:>7}  {:>8}",
                "T", "Z sim", "Z meas", "error"
            );
            for r in rows {
                let (sim, err) = cells(r);
                let _ = writeln!(
                    out,
                    "{:>7.3}  {sim:>7}  {:>7.3}  {err:>8}",
                    r.time, r.measured
                );
            }
        };
        front("surge front (Z = z/a)", &self.front);
        if !self.front_extra.is_empty() {
            front("surge front, digitised Fig. 3", &self.front_extra);
        }
        let _ = writeln!(out, "\nresidual height (H = h/(n^2 a))");
        let _ = writeln!(
            out,
            "{:>7}  {:>7}  {:>7}  {:>8}  {:>15}",
            "tau", "H sim", "H meas", "error", "error (shifted)"
        );
        for (r, shifted) in self.height.iter().zip(&self.height_shifted) {
            let (sim, err) = cells(r);
            let (_, err_shifted) = cells(shifted);
            let _ = writeln!(
                out,
                "{:>7.3}  {sim:>7}  {:>7.3}  {err:>8}  {err_shifted:>15}",
                r.time, r.measured
            );
        }
        out
    }

    /// CSV of every row: quantity, time, measured, simulated, relative error (empty when not
    /// simulated).
    pub fn csv(&self) -> String {
        let mut out = String::from(
            "# front: simulated T shifted to align at Z = 1.44; height: unshifted; \
             height_shifted: with the front's shift; time is T for the front, tau for the height\n\
             quantity,time,measured,simulated,relative_error\n",
        );
        let groups = [
            ("front", &self.front),
            ("front_fig3", &self.front_extra),
            ("height", &self.height),
            ("height_shifted", &self.height_shifted),
        ];
        for (name, rows) in groups {
            for r in rows {
                let sim = r.simulated.map_or(String::new(), |s| format!("{s}"));
                let err = r.relative_error().map_or(String::new(), |e| format!("{e}"));
                let _ = writeln!(out, "{name},{},{},{sim},{err}", r.time, r.measured);
            }
        }
        out
    }
}

/// The files [`write_report`] writes.
#[derive(Clone, Debug)]
pub struct ReportFiles {
    /// Tracked history: t, T, tau, z, h, Z, H per step.
    pub series_csv: PathBuf,
    /// The comparison rows.
    pub comparison_csv: PathBuf,
    /// Front chart.
    pub front_png: PathBuf,
    /// Height chart.
    pub height_png: PathBuf,
}

/// Writes the history and comparison as CSV and the front and height charts as PNG into
/// `dir` (which must exist), named `martin_moyce_n2-<n²>_*`.
pub fn write_report(
    dir: &Path,
    run: &Run,
    data: &Measurements,
    cmp: &Comparison,
) -> Result<ReportFiles, Error> {
    let stem = format!("martin_moyce_n2-{}", run.setup.n2);
    let files = ReportFiles {
        series_csv: dir.join(format!("{stem}_series.csv")),
        comparison_csv: dir.join(format!("{stem}_comparison.csv")),
        front_png: dir.join(format!("{stem}_front.png")),
        height_png: dir.join(format!("{stem}_height.png")),
    };
    let mut series = String::from("t_s,T,tau,z_m,h_m,Z,H\n");
    for ((s, f), h) in run
        .samples
        .iter()
        .zip(run.front_curve())
        .zip(run.height_curve())
    {
        let _ = writeln!(
            series,
            "{},{},{},{},{},{},{}",
            s.time, f.0, h.0, s.front, s.height, f.1, h.1
        );
    }
    super::write_text(&files.series_csv, &series)?;
    super::write_text(&files.comparison_csv, &cmp.csv())?;
    let shift = cmp.alignment.shift;
    let title = |what: &str| {
        format!(
            "{what}, n² = {}, {} particles across a",
            run.setup.n2, run.setup.particles_across
        )
    };
    let shifted = |curve: Vec<(f64, f64)>, shift: f64| -> Vec<(f64, f64)> {
        curve.into_iter().map(|(t, v)| (t + shift, v)).collect()
    };
    let measured = |c: &Curve| Series {
        label: c.label.to_string(),
        points: c.points.clone(),
        style: SeriesStyle::Markers,
    };
    let mut front_series = vec![
        Series {
            label: format!("simulation, shifted {shift:+.2} in T (compared)"),
            points: shifted(run.front_curve(), shift),
            style: SeriesStyle::Line,
        },
        Series {
            label: "simulation, unshifted".into(),
            points: run.front_curve(),
            style: SeriesStyle::Line,
        },
        measured(&data.front),
    ];
    if let Some(extra) = &data.front_extra {
        let end = run.front_curve().last().map_or(0.0, |p| p.0) + shift;
        let mut c = extra.clone();
        c.points.retain(|p| p.0 <= end);
        if !c.points.is_empty() {
            front_series.push(measured(&c));
        }
    }
    LineChart {
        title: title("Surge front"),
        x_label: "T = n·t·√(g/a)".into(),
        y_label: "Z = z/a".into(),
        series: front_series,
    }
    .write_png(&files.front_png)?;
    let tau_shift = shift / run.setup.n();
    let end = run.height_curve().last().map_or(0.0, |p| p.0) + tau_shift.max(0.0);
    let mut height_data = data.height.clone();
    height_data.points.retain(|p| p.0 <= end);
    let mut height_series = vec![
        Series {
            label: "simulation (compared)".into(),
            points: run.height_curve(),
            style: SeriesStyle::Line,
        },
        Series {
            label: format!("simulation, front's shift {tau_shift:+.2} in τ"),
            points: shifted(run.height_curve(), tau_shift),
            style: SeriesStyle::Line,
        },
    ];
    if !height_data.points.is_empty() {
        height_series.push(measured(&height_data));
    }
    LineChart {
        title: title("Residual column height"),
        x_label: "τ = t·√(g/a)".into(),
        y_label: "H = h/(n²a)".into(),
        series: height_series,
    }
    .write_png(&files.height_png)?;
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn front_ignores_detached_splashes_and_high_droplets() {
        let d = 0.01;
        let mut p: Vec<Vec3> = (0..10)
            .map(|i| Vec3::new(0.01 + i as f64 * d, 0.01, 0.0))
            .collect();
        // A droplet above the front, and a splash on the floor beyond the kernel support.
        p.push(Vec3::new(0.5, 0.2, 0.0));
        p.push(Vec3::new(0.10 + 2.5 * d, 0.01, 0.0));
        assert!((front_position(&p, 0.0, 0.0, d).unwrap() - 0.10).abs() < 1e-12);
        // Once the front reaches the splash (within 2d), it counts.
        p.push(Vec3::new(0.11, 0.02, 0.0));
        let z = front_position(&p, 0.0, 0.0, d).unwrap();
        assert!((z - (0.10 + 2.5 * d)).abs() < 1e-12, "{z}");
        assert_eq!(front_position(&[], 0.0, 0.0, d), None);
    }

    #[test]
    fn height_is_the_connected_top_next_to_the_back_wall() {
        let d = 0.01;
        let mut p: Vec<Vec3> = (0..8)
            .map(|j| Vec3::new(0.01, 0.01 + j as f64 * d, 0.0))
            .collect();
        p.push(Vec3::new(0.01, 0.5, 0.0)); // a droplet far above
        p.push(Vec3::new(0.2, 0.3, 0.0)); // far from the wall
        assert!((column_height(&p, 0.0, 0.0, d).unwrap() - 0.08).abs() < 1e-12);
    }

    #[test]
    fn setup_is_validated_and_builds_the_column() {
        let mut s = Setup::new(2);
        s.particles_across = 6;
        let (world, tank) = s.build().unwrap();
        assert_eq!(world.fluid_count(), 6 * 12 * 4);
        assert!(tank.max.x >= s.tank_length() * COLUMN_WIDTH * 0.999);
        let positions = world.positions();
        let (a, d) = (COLUMN_WIDTH, s.spacing());
        let z = front_position(&positions, 0.0, 0.0, d).unwrap();
        let h = column_height(&positions, 0.0, 0.0, d).unwrap();
        // Centres start one spacing plus r/4 from the walls: extents a + r/4 and 2a + r/4.
        assert!((z - (a + 0.125 * d)).abs() < 1e-9, "z = {z}");
        assert!((h - (2.0 * a + 0.125 * d)).abs() < 1e-9, "h = {h}");
        for bad in [
            Setup {
                n2: 3,
                ..Setup::new(2)
            },
            Setup {
                particles_across: 2,
                ..Setup::new(2)
            },
            Setup {
                layers: 0,
                ..Setup::new(2)
            },
            Setup {
                duration: f64::NAN,
                ..Setup::new(2)
            },
        ] {
            assert!(bad.build().is_err());
        }
    }
}
