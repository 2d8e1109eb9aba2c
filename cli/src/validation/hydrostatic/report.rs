//! The settled tank's report: the measured quantities as text, the layer profile as CSV and
//! the pressure chart.

use super::{READING_WINDOW, Report};
use crate::plot::{LineChart, Series, SeriesStyle};
use crate::validation::write_text;
use projfluid::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

impl Report {
    /// A plain-text report of every measured quantity.
    pub fn text(&self) -> String {
        let mut out = String::new();
        let s = &self.setup;
        let _ = writeln!(
            out,
            "tank at rest: {} particles ({}x{}x{}, r = {} m), relaxed {} s at damping {}/s, \
             then {} s free; {} solver, {} settings",
            self.particles,
            s.count[0],
            s.count[1],
            s.count[2],
            s.particle_radius,
            s.relax,
            s.damping,
            s.settle,
            s.solver.name(),
            if s.calm { "calm" } else { "default" }
        );
        let rows = [
            (
                "density error (last step)",
                format!(
                    "avg {:.4} %, max {:.3} % (compression only)",
                    100.0 * self.density_error_avg,
                    100.0 * self.density_error_max
                ),
            ),
            (
                "density error (worst step avg)",
                format!("{:.4} %", 100.0 * self.density_error_avg_worst),
            ),
            (
                "rms velocity after the free run",
                format!("{:.4} m/s", self.rms_velocity),
            ),
            (
                "water height",
                format!(
                    "{:.4} m, N·V/area gives {:.4} m ({:+.2} spacings)",
                    self.height,
                    self.expected_height,
                    (self.height - self.expected_height) / self.spacing
                ),
            ),
            (
                "pressure slope -dp/dy",
                format!(
                    "{:.0} Pa/m, rho0·g = {:.0} Pa/m ({:+.1} %)",
                    self.slope,
                    self.hydrostatic_slope,
                    100.0 * (self.slope / self.hydrostatic_slope - 1.0)
                ),
            ),
            (
                "pressure shape correlation",
                format!(
                    "{:.3} with rho0·g·(H - y) (1 = linear)",
                    self.shape_correlation
                ),
            ),
            (
                "constraint force / weight",
                format!("{:.3} (1 at the fixed point)", self.force_balance),
            ),
            (
                "pressure read at",
                format!(
                    "tau = {:.1e} m over the {READING_WINDOW} s after the free run",
                    self.reading_tolerance
                ),
            ),
            ("escaped or NaN particles", self.escaped.to_string()),
        ];
        for (k, v) in rows {
            let _ = writeln!(out, "{k:<32} {v}");
        }
        let _ = writeln!(
            out,
            "\npressure by layer (particles at least one support radius from the side walls)"
        );
        let _ = writeln!(
            out,
            "{:>8}  {:>10}  {:>16}  {:>6}",
            "y (m)", "p (Pa)", "rho0 g (H-y) (Pa)", "count"
        );
        for l in &self.profile {
            let _ = writeln!(
                out,
                "{:>8.3}  {:>10.1}  {:>16.1}  {:>6}",
                l.height, l.pressure, l.hydrostatic, l.particles
            );
        }
        out
    }
}

/// The files [`write_report`] writes.
#[derive(Clone, Debug)]
pub struct ReportFiles {
    /// Layer profile as CSV.
    pub profile_csv: PathBuf,
    /// Pressure chart.
    pub pressure_png: PathBuf,
}

/// Writes the layer profile (CSV) and the pressure chart (PNG) into `dir` (which must exist).
pub fn write_report(dir: &Path, report: &Report) -> Result<ReportFiles, Error> {
    let files = ReportFiles {
        profile_csv: dir.join("hydrostatic_profile.csv"),
        pressure_png: dir.join("hydrostatic_pressure.png"),
    };
    let mut csv = String::from("height_m,pressure_pa,hydrostatic_pa,particles\n");
    for l in &report.profile {
        let _ = writeln!(
            csv,
            "{},{},{},{}",
            l.height, l.pressure, l.hydrostatic, l.particles
        );
    }
    write_text(&files.profile_csv, &csv)?;
    let series = vec![
        Series {
            label: "every particle".into(),
            points: report.pressures.clone(),
            style: SeriesStyle::Markers,
        },
        Series {
            label: "layer mean, away from side walls".into(),
            points: report
                .profile
                .iter()
                .map(|l| (l.height, l.pressure))
                .collect(),
            style: SeriesStyle::LineMarkers,
        },
        Series {
            label: "ρ0·g·(H − y)".into(),
            points: report
                .profile
                .iter()
                .map(|l| (l.height, l.hydrostatic))
                .collect(),
            style: SeriesStyle::Line,
        },
    ];
    LineChart {
        title: "Tank at rest: constraint pressure against hydrostatics".into(),
        x_label: "height above the floor y (m)".into(),
        y_label: "pressure (Pa)".into(),
        series,
    }
    .write_png(&files.pressure_png)?;
    Ok(files)
}
