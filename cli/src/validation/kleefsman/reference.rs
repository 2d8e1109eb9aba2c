//! The reference solver's run of the same dam break, compiled in from `data/validation/`:
//! SPlisHSPlasH's DFSPH on the geometry of `scenes/kleefsman_obstacle.json` at r = 12.5 mm,
//! read with projfluid's own gauges (`projfluid probes`; the file's header says how it was
//! made), so that both solvers are compared with the measurements by the same readings.

use super::GAUGES;
use super::measured::parse_columns;
use projfluid::Error;

/// The data file under `data/validation/`.
pub const REFERENCE_FILE: &str = "kleefsman_dfsph_r0.0125.csv";

/// What the reference run was, for tables and legends.
pub const REFERENCE_LABEL: &str = "DFSPH (SPlisHSPlasH 2.16), r = 12.5 mm";

const TEXT: &str = include_str!("../../../data/validation/kleefsman_dfsph_r0.0125.csv");

/// The reference solver's gauge readings.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// (time (s), height (m)) at each gauge of [`GAUGES`], every 20 ms.
    pub heights: [Vec<(f64, f64)>; 4],
    /// (time (s), water content (m)) of each gauge's line.
    pub contents: [Vec<(f64, f64)>; 4],
}

impl Reference {
    /// Parses the compiled-in file; errors name the file, line and column.
    pub fn load() -> Result<Self, Error> {
        parse(TEXT)
    }
}

/// Parses `text` in the layout of [`REFERENCE_FILE`]: the columns `time_s`, `H1_m` … `H4_m`
/// and `H1_content_m` … `H4_content_m`.
fn parse(text: &str) -> Result<Reference, Error> {
    let names: Vec<String> = (GAUGES.iter().map(|g| format!("{g}_m")))
        .chain(GAUGES.iter().map(|g| format!("{g}_content_m")))
        .collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut series = parse_columns(REFERENCE_FILE, text, "time_s", &names)?.into_iter();
    let mut take = || -> [Vec<(f64, f64)>; 4] {
        std::array::from_fn(|_| series.next().expect("eight series"))
    };
    let heights = take();
    let contents = take();
    Ok(Reference { heights, contents })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The file covers 6 s every 20 ms; the reservoir starts full at H4 and every other gauge
    /// dry, and the surge wets H3, H2 and H1 in that order.
    #[test]
    fn reference_file_parses_in_gauge_order() {
        let r = Reference::load().unwrap();
        for series in r.heights.iter().chain(&r.contents) {
            assert_eq!(series.len(), 301);
            assert!(series.windows(2).all(|w| w[1].0 > w[0].0));
            assert_eq!(series.last().unwrap().0, 6.0);
        }
        let first = r.heights.each_ref().map(|s| s[0].1);
        assert!(first[..3].iter().all(|&h| h < 0.005), "{first:?}");
        assert!((first[3] - 0.55).abs() < 0.02, "{first:?}");
        let wet = |s: &[(f64, f64)]| s.iter().find(|p| p.1 >= 0.02).unwrap().0;
        let [h1, h2, h3, _] = r.heights.each_ref().map(|s| wet(s));
        assert!(h3 < h2 && h2 < h1, "{h3} {h2} {h1}");
        let e = parse("time_s,H1_m\n0,1\n").unwrap_err().to_string();
        assert!(e.contains("H2_m") && e.contains(REFERENCE_FILE), "{e}");
    }
}
