//! The duct runs' report: a table as text, the profiles as CSV and a chart.

use super::Report;
use crate::plot::{LineChart, Series, SeriesStyle};
use crate::validation::write_text;
use projfluid::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

impl Report {
    /// A plain-text table: one row per viscosity.
    pub fn text(&self) -> String {
        let s = &self.setup;
        let n = s.count();
        let mut out = String::new();
        let _ = writeln!(
            out,
            "flow down a duct: {} particles ({}x{}x{}, r = {} m), {} s per run, {} solver",
            self.particles,
            n[0],
            n[1],
            n[2],
            s.particle_radius,
            s.duration,
            s.solver.name()
        );
        let _ = writeln!(
            out,
            "{:>12}  {:>8}  {:>12}  {:>12}  {:>10}  {:>6}",
            "nu (m²/s)", "steps", "peak (m/s)", "flux ratio", "RMS error", "count"
        );
        for r in &self.runs {
            let _ = writeln!(
                out,
                "{:>12.1e}  {:>8}  {:>12.4}  {:>12.3}  {:>9.1} %  {:>6}",
                r.viscosity,
                r.steps,
                r.peak,
                r.flux_ratio,
                100.0 * r.error,
                r.compared
            );
        }
        out
    }
}

/// The files [`write_report`] writes.
#[derive(Clone, Debug)]
pub struct ReportFiles {
    /// The profiles across the duct as CSV.
    pub profile_csv: PathBuf,
    /// The profiles, each scaled by its analytic peak, as a chart.
    pub profile_png: PathBuf,
}

/// Writes the profiles (CSV) and their chart (PNG) into `dir` (which must exist).
pub fn write_report(dir: &Path, report: &Report) -> Result<ReportFiles, Error> {
    let files = ReportFiles {
        profile_csv: dir.join("poiseuille_profile.csv"),
        profile_png: dir.join("poiseuille_profile.png"),
    };
    let mut csv = String::from("nu_m2_s,x_m,simulated_m_s,analytic_m_s\n");
    let mut series = Vec::new();
    for r in &report.runs {
        for &(x, sim, exact) in &r.profile {
            let _ = writeln!(csv, "{},{x},{sim},{exact}", r.viscosity);
        }
        series.push(Series {
            label: format!("ν = {:.0e} m²/s", r.viscosity),
            points: r.profile.iter().map(|p| (p.0, p.1 / r.peak)).collect(),
            style: SeriesStyle::Markers,
        });
    }
    if let Some(r) = report.runs.first() {
        series.push(Series {
            label: "analytic".into(),
            points: r.profile.iter().map(|p| (p.0, p.2 / r.peak)).collect(),
            style: SeriesStyle::Line,
        });
    }
    write_text(&files.profile_csv, &csv)?;
    LineChart {
        title: "Flow down a duct: speed across the narrow side at mid-depth".into(),
        x_label: "x from the duct's axis (m)".into(),
        y_label: "speed / analytic peak".into(),
        series,
    }
    .write_png(&files.profile_png)?;
    Ok(files)
}
