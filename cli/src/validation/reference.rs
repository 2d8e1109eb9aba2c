//! The Martin & Moyce (1952) measurements, compiled in from `data/validation/` (see its README
//! for sources, scalings and confidence).

use projfluid::Error;

/// One measured curve: dimensionless (x, y) points and where they come from.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Short description for tables and legends.
    pub label: &'static str,
    /// The data file under `data/validation/`.
    pub file: &'static str,
    /// (time, value) points in the file's dimensionless units, in file order.
    pub points: Vec<(f64, f64)>,
}

/// Column width a of the experiments used here: 2.25 in (m).
pub const COLUMN_WIDTH: f64 = 0.05715;

macro_rules! data_file {
    ($name:literal) => {
        (
            $name,
            include_str!(concat!("../../data/validation/", $name)),
        )
    };
}

/// Front Z(T), n² = 2 ("Table 2").
const FRONT_N2_2: (&str, &str) = data_file!("mm1952_n2-2_a2.25in_front_table2.csv");
/// Residual height H(τ), n² = 2 ("Table 6").
const HEIGHT_N2_2: (&str, &str) = data_file!("mm1952_n2-2_a2.25in_height_table6.csv");
/// Front Z(T), n² = 2, digitised from Fig. 3 to Z ≈ 14.
const FRONT_N2_2_LATE: (&str, &str) = data_file!("mm1952_n2-2_a2.25in_front_fig3_pysph.csv");
/// Front Z(T), square column.
const FRONT_N2_1: (&str, &str) = data_file!("mm1952_n2-1_a2.25in_front.csv");
/// Residual height H(τ), square column.
const HEIGHT_N2_1: (&str, &str) = data_file!("mm1952_n2-1_a2.25in_height.csv");

/// The measurements for one column shape.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurements {
    /// Front Z = z/a against T = n·t·√(g/a) (tabulated).
    pub front: Curve,
    /// Further front points (digitised from a figure), if any.
    pub front_extra: Option<Curve>,
    /// Residual height H = h/(n²a) against τ = t·√(g/a).
    pub height: Curve,
}

impl Measurements {
    /// The data for height/width ratio `n2` (1 or 2).
    pub fn for_ratio(n2: u32) -> Result<Self, Error> {
        match n2 {
            2 => Ok(Self {
                front: parse("Martin & Moyce Table 2", FRONT_N2_2)?,
                front_extra: Some(parse("Martin & Moyce Fig. 3 (PySPH)", FRONT_N2_2_LATE)?),
                height: parse("Martin & Moyce Table 6", HEIGHT_N2_2)?,
            }),
            1 => Ok(Self {
                front: parse("Martin & Moyce", FRONT_N2_1)?,
                front_extra: None,
                height: parse("Martin & Moyce", HEIGHT_N2_1)?,
            }),
            other => Err(Error::invalid("n2", other, "must be 1 or 2")),
        }
    }
}

/// Parses a data file: `#` comment lines, one header row, then `x,y` rows.
fn parse(label: &'static str, (file, text): (&'static str, &str)) -> Result<Curve, Error> {
    let mut rows = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with('#') && !l.trim().is_empty());
    rows.next(); // the header
    let points = rows
        .map(|(i, line)| {
            let bad = || Error::invalid(format!("{file} line {}", i + 1), line, "must be `x,y`");
            let (x, y) = line.split_once(',').ok_or_else(bad)?;
            let x: f64 = x.trim().parse().map_err(|_| bad())?;
            let y: f64 = y.trim().parse().map_err(|_| bad())?;
            Ok((x, y))
        })
        .collect::<Result<Vec<_>, Error>>()?;
    Ok(Curve {
        label,
        file,
        points,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_files_parse_to_the_tabulated_values() {
        let tall = Measurements::for_ratio(2).unwrap();
        assert_eq!(tall.front.points.len(), 15);
        assert_eq!(tall.front.points[2], (1.19, 1.44));
        assert_eq!(tall.height.points.len(), 17);
        assert_eq!(tall.height.points[16], (7.40, 0.06));
        assert_eq!(tall.front_extra.unwrap().points.len(), 15);
        let square = Measurements::for_ratio(1).unwrap();
        assert_eq!(square.front.points.len(), 20);
        assert_eq!(square.front.points[2], (0.80, 1.44));
        assert_eq!(square.height.points[0], (0.0, 1.0));
        assert!(Measurements::for_ratio(3).is_err());
    }
}
