//! The comparison's report: a plain-text table, CSV files and the front and height charts.

use super::{ALIGNMENT_LEVEL, Comparison, Row, Run};
use crate::plot::{LineChart, Series, SeriesStyle};
use crate::validation::reference::{Curve, Measurements};
use crate::validation::write_text;
use projfluid::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

impl Comparison {
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
    write_text(&files.series_csv, &series)?;
    write_text(&files.comparison_csv, &cmp.csv())?;
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
