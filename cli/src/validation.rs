//! Validation against experiment and analytic solutions: the Martin & Moyce (1952) column
//! collapse ([`martin_moyce`]), the MARIN dam break past a box (Kleefsman et al. 2005,
//! [`kleefsman`]), a tank of water at rest ([`hydrostatic`]), viscous flow down a duct
//! ([`poiseuille`]), two liquids at rest and overturning ([`two_layers`]) and a drop's
//! capillary oscillation ([`droplet`]). The CLI's
//! `projfluid validate` prints and plots what these modules compute; the tests assert on it.

pub mod droplet;
mod fit;
pub mod hydrostatic;
pub mod kleefsman;
pub mod martin_moyce;
pub mod poiseuille;
pub mod reference;
pub mod two_layers;

use projfluid::Error;
use std::path::Path;

/// y at `x` on the polyline through `points` (sorted by x), linearly interpolated; `None`
/// outside [first x, last x].
pub fn interpolate(points: &[(f64, f64)], x: f64) -> Option<f64> {
    let first = points.first()?;
    let last = points.last()?;
    if !(x >= first.0 && x <= last.0) {
        return None;
    }
    let i = points.partition_point(|p| p.0 < x);
    if i == 0 {
        return Some(first.1);
    }
    let (a, b) = (points[i - 1], points[i]);
    if b.0 == a.0 {
        return Some(b.1);
    }
    Some(a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0))
}

/// The first x at which the polyline through `points` (sorted by x) reaches `level` from
/// below, linearly interpolated; `None` if it never does.
pub fn first_crossing(points: &[(f64, f64)], level: f64) -> Option<f64> {
    if points.first()?.1 >= level {
        return Some(points[0].0);
    }
    points.windows(2).find_map(|w| {
        let (a, b) = (w[0], w[1]);
        (a.1 < level && b.1 >= level).then(|| a.0 + (b.0 - a.0) * (level - a.1) / (b.1 - a.1))
    })
}

/// Writes `text` to `path`, naming the path in the error.
pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), Error> {
    std::fs::write(path, text)
        .map_err(|e| Error::Io(format!("cannot write {}: {e}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_and_crossing() {
        let p = [(0.0, 1.0), (1.0, 2.0), (3.0, 2.0), (4.0, 4.0)];
        assert_eq!(interpolate(&p, 0.5), Some(1.5));
        assert_eq!(interpolate(&p, 2.0), Some(2.0));
        assert_eq!(interpolate(&p, 4.0), Some(4.0));
        assert_eq!(interpolate(&p, 4.5), None);
        assert_eq!(interpolate(&p, f64::NAN), None);
        assert_eq!(first_crossing(&p, 1.5), Some(0.5));
        assert_eq!(first_crossing(&p, 3.0), Some(3.5));
        assert_eq!(first_crossing(&p, 0.5), Some(0.0));
        assert_eq!(first_crossing(&p, 5.0), None);
    }
}
