//! The two liquids' report: a table as text, the pressure profile and the mean heights as
//! CSV, and a chart of each.

use super::Report;
use crate::plot::{LineChart, Series, SeriesStyle};
use crate::validation::write_text;
use projfluid::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

impl Report {
    /// A plain-text summary of both runs.
    pub fn text(&self) -> String {
        let (s, rest, over) = (&self.setup, &self.rest, &self.overturn);
        let (a, b) = (s.rest_count(), s.overturn_count());
        let mut out = String::new();
        let _ = writeln!(
            out,
            "two liquids: water (1000 kg/m³) and a lighter liquid ({} kg/m³), r = {} m, {} solver",
            s.light_density,
            s.particle_radius,
            s.solver.name()
        );
        let _ = writeln!(
            out,
            "at rest, lighter over water: {} particles ({}x{}x{}), calm settings, {} s relaxed, {} s free",
            rest.particles, a[0], a[1], a[2], s.relax, s.settle
        );
        let _ = writeln!(
            out,
            "  layers kept: lowest lighter particle {:+.3} m, highest water particle {:+.3} m from the interface",
            rest.lowest_light, rest.highest_water
        );
        let _ = writeln!(
            out,
            "  densities read: water {:.1} kg/m³, lighter {:.1} kg/m³",
            rest.densities.0, rest.densities.1
        );
        let _ = writeln!(
            out,
            "  pressure against the two-slope hydrostatic profile: {:.1} % RMS of the bottom pressure",
            100.0 * rest.profile_error
        );
        let _ = writeln!(
            out,
            "  slopes: {:.3} ρ_w·g in the water, {:.3} ρ_l·g in the lighter liquid",
            rest.slopes.0, rest.slopes.1
        );
        let _ = writeln!(
            out,
            "water over the lighter liquid: {} particles ({}x{}x{}), defaults",
            over.particles, b[0], b[1], b[2]
        );
        let _ = match over.overturned_at {
            Some(t) => writeln!(
                out,
                "  overturned at {t:.2} s (the water's mean height below the lighter liquid's)"
            ),
            None => writeln!(out, "  did not overturn within {} s", s.overturn_duration),
        };
        if let Some(&(t, water, lighter)) = over.heights.last() {
            let _ = writeln!(
                out,
                "  at {t:.2} s: water at {water:.3} m, lighter liquid at {lighter:.3} m (mean heights); {} particles lost",
                over.lost
            );
        }
        out
    }
}

/// The files [`write_report`] writes.
#[derive(Clone, Debug)]
pub struct ReportFiles {
    /// The layers' pressures and the two-slope profile as CSV.
    pub pressure_csv: PathBuf,
    /// Their chart.
    pub pressure_png: PathBuf,
    /// The overturning run's mean heights as CSV.
    pub overturn_csv: PathBuf,
    /// Their chart.
    pub overturn_png: PathBuf,
}

/// Writes the profile and the mean heights (CSV) and their charts (PNG) into `dir` (which
/// must exist).
pub fn write_report(dir: &Path, report: &Report) -> Result<ReportFiles, Error> {
    let files = ReportFiles {
        pressure_csv: dir.join("two_layers_pressure.csv"),
        pressure_png: dir.join("two_layers_pressure.png"),
        overturn_csv: dir.join("two_layers_overturn.csv"),
        overturn_png: dir.join("two_layers_overturn.png"),
    };
    let layers = &report.rest.layers;
    let mut csv = String::from("height_m,pressure_pa,hydrostatic_pa\n");
    for l in layers {
        let _ = writeln!(csv, "{},{},{}", l.height, l.pressure, l.hydrostatic);
    }
    write_text(&files.pressure_csv, &csv)?;
    LineChart {
        title: "Two liquids at rest: pressure against height".into(),
        x_label: "height (m)".into(),
        y_label: "pressure (Pa)".into(),
        series: vec![
            Series {
                label: "constraint pressure, layer means".into(),
                points: layers.iter().map(|l| (l.height, l.pressure)).collect(),
                style: SeriesStyle::Markers,
            },
            Series {
                label: "two-slope hydrostatic".into(),
                points: layers.iter().map(|l| (l.height, l.hydrostatic)).collect(),
                style: SeriesStyle::Line,
            },
        ],
    }
    .write_png(&files.pressure_png)?;

    let heights = &report.overturn.heights;
    let mut csv = String::from("time_s,water_mean_height_m,lighter_mean_height_m\n");
    for (t, water, lighter) in heights {
        let _ = writeln!(csv, "{t},{water},{lighter}");
    }
    write_text(&files.overturn_csv, &csv)?;
    LineChart {
        title: "Water over a lighter liquid: mean heights".into(),
        x_label: "time (s)".into(),
        y_label: "mean height (m)".into(),
        series: vec![
            Series {
                label: "water".into(),
                points: heights.iter().map(|h| (h.0, h.1)).collect(),
                style: SeriesStyle::Line,
            },
            Series {
                label: format!("lighter liquid ({} kg/m³)", report.setup.light_density),
                points: heights.iter().map(|h| (h.0, h.2)).collect(),
                style: SeriesStyle::Line,
            },
        ],
    }
    .write_png(&files.overturn_png)?;
    Ok(files)
}
