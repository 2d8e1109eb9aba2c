//! The oscillating drop's report: a table as text, the responses as CSV and a chart.

use super::Report;
use crate::plot::{LineChart, Series, SeriesStyle};
use crate::validation::write_text;
use projfluid::Error;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

impl Report {
    /// A plain-text table: one row per surface tension.
    pub fn text(&self) -> String {
        let s = &self.setup;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "oscillating drop (n = 2): {} particles ({n}x{n}x{n}, r = {} m), ν = {} m²/s, kick {} of ω",
            self.particles,
            s.particle_radius(),
            s.kinematic_viscosity,
            s.amplitude,
            n = s.across,
        );
        let _ = writeln!(
            out,
            "{:>10}  {:>8}  {:>8}  {:>12}  {:>12}  {:>8}",
            "σ (N/m)", "R (mm)", "steps", "Rayleigh (s)", "period (s)", "error"
        );
        for r in &self.runs {
            let _ = writeln!(
                out,
                "{:>10.4}  {:>8.3}  {:>8}  {:>12.4}  {:>12.4}  {:>+7.1} %",
                r.surface_tension,
                1e3 * r.radius,
                r.steps,
                r.rayleigh,
                r.period,
                100.0 * r.error
            );
        }
        out
    }
}

/// The files [`write_report`] writes.
#[derive(Clone, Debug)]
pub struct ReportFiles {
    /// The responses over time as CSV.
    pub response_csv: PathBuf,
    /// The responses, each over its largest value against time in Rayleigh periods, with
    /// Rayleigh's sine, as a chart.
    pub response_png: PathBuf,
}

/// Writes the responses (CSV) and their chart (PNG) into `dir` (which must exist).
pub fn write_report(dir: &Path, report: &Report) -> Result<ReportFiles, Error> {
    let files = ReportFiles {
        response_csv: dir.join("droplet_response.csv"),
        response_png: dir.join("droplet_response.png"),
    };
    let mut csv = String::from("sigma_n_m,t_s,response_m2\n");
    let mut series = Vec::new();
    let mut longest: f64 = 0.0;
    for r in &report.runs {
        let peak = r.history.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
        for &(t, q) in &r.history {
            let _ = writeln!(csv, "{},{t},{q}", r.surface_tension);
        }
        let points: Vec<(f64, f64)> = r
            .history
            .iter()
            .map(|&(t, q)| (t / r.rayleigh, q / peak))
            .collect();
        longest = longest.max(points.last().map_or(0.0, |p| p.0));
        series.push(Series {
            label: format!("σ = {} N/m", r.surface_tension),
            points,
            style: SeriesStyle::Line,
        });
    }
    series.push(Series {
        label: "Rayleigh: sin(2πt/T)".into(),
        points: (0..=200)
            .map(|k| {
                let t = longest * k as f64 / 200.0;
                (t, (2.0 * PI * t).sin())
            })
            .collect(),
        style: SeriesStyle::Markers,
    });
    write_text(&files.response_csv, &csv)?;
    LineChart {
        title: "Oscillating drop, n = 2: the response to the kick".into(),
        x_label: "time since the kick / Rayleigh's period".into(),
        y_label: "ΔQ / its largest value".into(),
        series,
    }
    .write_png(&files.response_png)?;
    Ok(files)
}
