//! The dam break's report: the comparison as a table, the gauge history and the comparison as
//! CSV, and one chart per gauge as PNG.

use super::compare::Verdict;
use super::{Comparison, GAUGE_X, GAUGES, Measurements, REFERENCE_LABEL, Reference, Run};
use crate::plot::{LineChart, Series, SeriesStyle};
use crate::validation::write_text;
use projfluid::Error;
use std::fmt::Write;
use std::path::{Path, PathBuf};

fn mark(v: Verdict) -> &'static str {
    match v {
        Verdict::Pass => "ok",
        Verdict::Fail => "FAIL",
        Verdict::NotCovered => "not reached",
    }
}

impl Comparison {
    /// The comparison as a plain-text table.
    pub fn table(&self) -> String {
        let t = self.tolerances;
        let mut out = format!(
            "surge arrival (first height >= {} m): within {} s at H3 and H2, from {} s early to \
             {} s late at H1 (in the box's lee)\n",
            super::ARRIVAL_LEVEL,
            t.arrival,
            t.lee_early,
            t.lee_late
        );
        let _ = writeln!(
            out,
            "{:>5}  {:>7}  {:>9}  {:>9}  {:>8}  {:>7}  {:>9}",
            "gauge", "x (m)", "sim (s)", "meas (s)", "delay", "", "ref (s)"
        );
        for (a, reference) in self.arrivals.iter().zip(&self.reference.arrivals) {
            let sim = a.simulated.map_or("-".into(), |s| format!("{s:.3}"));
            let delay = a.delay().map_or("-".into(), |d| format!("{d:+.3}"));
            let reference = reference.map_or("-".into(), |s| format!("{s:.3}"));
            let _ = writeln!(
                out,
                "{:>5}  {:>7.3}  {sim:>9}  {:>9.3}  {delay:>8}  {:>7}  {reference:>9}",
                GAUGES[a.gauge],
                GAUGE_X[a.gauge],
                a.measured,
                mark(a.verdict(t.arrival_window(a.gauge)))
            );
        }
        let _ = writeln!(
            out,
            "\nreservoir height at H4 (x = 2.638 m), tolerance {} m",
            t.reservoir
        );
        let _ = writeln!(
            out,
            "{:>6}  {:>9}  {:>10}  {:>8}",
            "t (s)", "sim (m)", "meas (m)", "error"
        );
        for l in &self.reservoir {
            let sim = l.simulated.map_or("-".into(), |s| format!("{s:.3}"));
            let err = l
                .simulated
                .map_or("-".into(), |s| format!("{:+.3}", s - l.measured));
            let _ = writeln!(
                out,
                "{:>6.2}  {sim:>9}  {:>10.3}  {err:>8}  {}",
                l.time,
                l.measured,
                mark(l.verdict(t.reservoir))
            );
        }
        let _ = writeln!(
            out,
            "\nRMS difference from the measured height over the run (m): the standing water's \
             surface, the water content of the line (all the water on it), and the surface in \
             the reference run ({REFERENCE_LABEL}) over the same times"
        );
        let _ = writeln!(
            out,
            "{:>5}  {:>7}  {:>8}  {:>8}  {:>9}",
            "gauge", "x (m)", "surface", "content", "reference"
        );
        let rows = self
            .rms
            .iter()
            .zip(&self.content_rms)
            .zip(&self.reference.rms);
        for (g, ((rms, content), reference)) in rows.enumerate() {
            let _ = writeln!(
                out,
                "{:>5}  {:>7.3}  {rms:>8.4}  {content:>8.4}  {reference:>9.4}",
                GAUGES[g], GAUGE_X[g]
            );
        }
        let a = &self.lee_content;
        let sim = a.simulated.map_or("never".into(), |s| format!("{s:.3} s"));
        let delay = a.delay().map_or(String::new(), |d| format!(" ({d:+.3} s)"));
        let _ = writeln!(
            out,
            "\nwater on H1's line, standing or not (content >= {} m): {sim}{delay}, measured \
             height {:.3} s (reported, not judged)",
            super::ARRIVAL_LEVEL,
            a.measured
        );
        out
    }

    /// CSV of every compared quantity: kind, gauge, time or level, measured, simulated
    /// (empty when not reached), verdict; the reference solver's rows hold its value as
    /// simulated.
    pub fn csv(&self) -> String {
        let t = self.tolerances;
        let mut out = String::from("quantity,gauge,measured,simulated,verdict\n");
        for a in &self.arrivals {
            let sim = a.simulated.map_or(String::new(), |s| format!("{s}"));
            let _ = writeln!(
                out,
                "arrival_s,{},{},{sim},{}",
                GAUGES[a.gauge],
                a.measured,
                mark(a.verdict(t.arrival_window(a.gauge)))
            );
        }
        for l in &self.reservoir {
            let sim = l.simulated.map_or(String::new(), |s| format!("{s}"));
            let _ = writeln!(
                out,
                "height_m_at_{}s,H4,{},{sim},{}",
                l.time,
                l.measured,
                mark(l.verdict(t.reservoir))
            );
        }
        for (g, rms) in self.rms.iter().enumerate() {
            let _ = writeln!(out, "rms_m,{},0,{rms},", GAUGES[g]);
        }
        for (g, rms) in self.content_rms.iter().enumerate() {
            let _ = writeln!(out, "content_rms_m,{},0,{rms},", GAUGES[g]);
        }
        for (a, reference) in self.arrivals.iter().zip(&self.reference.arrivals) {
            let reference = reference.map_or(String::new(), |s| format!("{s}"));
            let _ = writeln!(
                out,
                "reference_arrival_s,{},{},{reference},",
                GAUGES[a.gauge], a.measured
            );
        }
        for (g, rms) in self.reference.rms.iter().enumerate() {
            let _ = writeln!(out, "reference_rms_m,{},0,{rms},", GAUGES[g]);
        }
        let a = &self.lee_content;
        let sim = a.simulated.map_or(String::new(), |s| format!("{s}"));
        let _ = writeln!(out, "content_arrival_s,H1,{},{sim},", a.measured);
        out
    }
}

/// The files [`write_report`] writes.
#[derive(Clone, Debug)]
pub struct ReportFiles {
    /// Gauge history: t, H1..H4, then the contents of their lines, per reading.
    pub series_csv: PathBuf,
    /// The comparison.
    pub comparison_csv: PathBuf,
    /// One chart per gauge, H1..H4.
    pub charts: Vec<PathBuf>,
}

/// Writes the gauge history and the comparison as CSV and a chart per gauge as PNG into
/// `dir` (which must exist), named `kleefsman_*`; the charts show the run, the measurements
/// and the reference solver's run up to the run's end.
pub fn write_report(
    dir: &Path,
    run: &Run,
    data: &Measurements,
    reference: &Reference,
    cmp: &Comparison,
) -> Result<ReportFiles, Error> {
    let files = ReportFiles {
        series_csv: dir.join("kleefsman_series.csv"),
        comparison_csv: dir.join("kleefsman_comparison.csv"),
        charts: GAUGES
            .iter()
            .map(|g| dir.join(format!("kleefsman_{g}.png")))
            .collect(),
    };
    let mut series = String::from(
        "t_s,H1_m,H2_m,H3_m,H4_m,H1_content_m,H2_content_m,H3_content_m,H4_content_m\n",
    );
    for s in &run.samples {
        let [a, b, c, d] = s.heights;
        let [e, f, g, h] = s.contents;
        let _ = writeln!(series, "{},{a},{b},{c},{d},{e},{f},{g},{h}", s.time);
    }
    write_text(&files.series_csv, &series)?;
    write_text(&files.comparison_csv, &cmp.csv())?;
    let end = run.end();
    let what = if run.setup.obstacle {
        String::new()
    } else {
        ", no box".to_string()
    };
    let until_end = |points: &[(f64, f64)]| -> Vec<(f64, f64)> {
        points.iter().copied().filter(|p| p.0 <= end).collect()
    };
    for (g, path) in files.charts.iter().enumerate() {
        let measured = until_end(&data.heights[g]);
        let mut chart_series = vec![Series {
            label: format!("simulation, r = {} m{what}", run.setup.particle_radius),
            points: run.heights(g),
            style: SeriesStyle::Line,
        }];
        if g == super::LEE_GAUGE {
            // In the lee the water first comes through the air (docs/validation.md).
            chart_series.push(Series {
                label: "simulation, water content of the line".into(),
                points: run.contents(g),
                style: SeriesStyle::Line,
            });
        }
        chart_series.push(Series {
            label: format!("reference solver, {REFERENCE_LABEL}"),
            points: until_end(&reference.heights[g]),
            style: SeriesStyle::Line,
        });
        if !measured.is_empty() {
            chart_series.push(Series {
                label: "measured (Kleefsman et al. 2005)".into(),
                points: measured,
                style: SeriesStyle::Line,
            });
        }
        LineChart {
            title: format!("Water height at {} (x = {} m)", GAUGES[g], GAUGE_X[g]),
            x_label: "t (s)".into(),
            y_label: "height (m)".into(),
            series: chart_series,
        }
        .write_png(path)?;
    }
    Ok(files)
}
