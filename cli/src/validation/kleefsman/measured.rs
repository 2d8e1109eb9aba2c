//! The MARIN measurements (Kleefsman et al. 2005, SPHERIC Test 2), compiled in from
//! `data/validation/` (see its README for the source, units and caveats): the water heights at
//! the four gauges, every 10 ms.

use super::GAUGES;
use projfluid::Error;

/// The data file under `data/validation/`.
pub const DATA_FILE: &str = "kleefsman_spheric2_exp_every10th.csv";

const TEXT: &str = include_str!("../../../data/validation/kleefsman_spheric2_exp_every10th.csv");

/// The file's column holding each gauge of [`GAUGES`] (H1 at x = 0.496 m … H4 at 2.638 m).
/// The file's `H1` and `H3` are swapped: its `H1` rises first (at about 0.19 s), so it is the
/// gauge at x = 1.488 m, nearest the reservoir; its `H3` stays dry until about 0.91 s, so it is
/// the gauge behind the box at x = 0.496 m (data/validation/README.md).
pub const SOURCE_COLUMNS: [&str; 4] = ["H3_m", "H2_m", "H1_m", "H4_m"];

/// The measured water heights.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurements {
    /// (time (s), height (m)) at each gauge of [`GAUGES`], in file order.
    pub heights: [Vec<(f64, f64)>; 4],
}

impl Measurements {
    /// Parses the compiled-in file: `#` comment lines, a header naming the columns, then
    /// comma-separated rows. Errors name the file, line and column.
    pub fn load() -> Result<Self, Error> {
        parse(TEXT)
    }
}

/// Parses `text` in the layout of [`DATA_FILE`].
fn parse(text: &str) -> Result<Measurements, Error> {
    let series = parse_columns(DATA_FILE, text, "Time_s", &SOURCE_COLUMNS)?;
    let heights = series.try_into().expect("one series per gauge");
    debug_assert_eq!(GAUGES.len(), 4);
    Ok(Measurements { heights })
}

/// The (time, value) series of each of `columns` in the CSV `text` of the data file `file`:
/// `#` comment lines, a header naming the columns (`time` among them), then comma-separated
/// rows of numbers. Errors name the file, and the line and column of a cell that is not a
/// number, or the column the header lacks.
pub(super) fn parse_columns(
    file: &str,
    text: &str,
    time: &str,
    columns: &[&str],
) -> Result<Vec<Vec<(f64, f64)>>, Error> {
    let mut rows = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with('#') && !l.trim().is_empty());
    let (_, header) = rows
        .next()
        .ok_or_else(|| Error::invalid(file, "no rows", "must hold a header and data"))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let column = |name: &str| {
        names.iter().position(|n| *n == name).ok_or_else(|| {
            Error::invalid(
                file,
                format!("header `{header}`"),
                &format!("must have a column `{name}`"),
            )
        })
    };
    let time = column(time)?;
    let columns = columns
        .iter()
        .map(|name| column(name))
        .collect::<Result<Vec<usize>, Error>>()?;
    let mut series = vec![Vec::new(); columns.len()];
    for (i, line) in rows {
        let cells: Vec<&str> = line.split(',').collect();
        let value = |c: usize| -> Result<f64, Error> {
            let bad = || {
                Error::invalid(
                    format!("{file} line {} column {}", i + 1, c + 1),
                    line,
                    "must be a number",
                )
            };
            cells
                .get(c)
                .ok_or_else(bad)?
                .trim()
                .parse()
                .map_err(|_| bad())
        };
        let t = value(time)?;
        for (points, &c) in series.iter_mut().zip(&columns) {
            points.push((t, value(c)?));
        }
    }
    Ok(series)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_file_parses_with_the_height_columns_in_gauge_order() {
        let m = Measurements::load().unwrap();
        for series in &m.heights {
            assert_eq!(series.len(), 604);
            assert!(series.windows(2).all(|w| w[1].0 > w[0].0));
        }
        // The first row: the reservoir gauge H4 stands in 0.547 m of water, the others dry.
        let first = m.heights.each_ref().map(|s| s[0].1);
        assert_eq!(first, [0.0004, 0.0005333333, 0.0002666667, 0.5466666667]);
        // Wetted in order of distance from the reservoir: H3 (1.488 m) first, H1 (behind the
        // box) last.
        let wet = |s: &[(f64, f64)]| s.iter().find(|p| p.1 >= 0.02).unwrap().0;
        let [h1, h2, h3, _] = m.heights.each_ref().map(|s| wet(s));
        assert!(h3 < h2 && h2 < h1, "{h3} {h2} {h1}");
        assert!((0.9..0.95).contains(&h1), "{h1}");
    }

    #[test]
    fn a_bad_file_is_an_error_naming_line_and_column() {
        let text = "# c\nTime_s,H1_m,H2_m,H3_m,H4_m\n0,1,2,3,4\n0.01,1,x,3,4\n";
        let e = parse(text).unwrap_err().to_string();
        assert!(e.contains("line 4 column 3"), "{e}");
        let e = parse("Time_s,H1_m\n").unwrap_err().to_string();
        assert!(e.contains("H3_m"), "{e}");
        assert!(parse("").is_err());
    }
}
