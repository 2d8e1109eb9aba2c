//! Axes: data ranges with a margin, and short tick labels.

use projfluid::Error;

/// An axis tick label on an axis spanning `span`: the value rounded to 9 significant digits
/// (hiding binary round-off such as 0.30000000000000004), in the shortest form that reads
/// back the same; values within 1e-9·span of zero read "0".
pub(super) fn tick(v: f64, span: f64) -> String {
    if v.abs() <= 1e-9 * span || !v.is_finite() {
        return "0".into();
    }
    let rounded: f64 = format!("{v:.8e}").parse().unwrap_or(v);
    let text = format!("{rounded}");
    if text == "-0" { "0".into() } else { text }
}

/// The range of `values` widened by 5 % on each side (or by 1 when all are equal), and
/// stretched to include 0 when `with_zero`. Errors when the span overflows.
pub(super) fn padded_range(
    axis: &str,
    values: impl Iterator<Item = f64>,
    with_zero: bool,
) -> Result<(f64, f64), Error> {
    let init = if with_zero {
        (0.0, 0.0)
    } else {
        (f64::MAX, f64::MIN)
    };
    let (lo, hi) = values.fold(init, |(lo, hi), v| (lo.min(v), hi.max(v)));
    let span = hi - lo;
    let pad = if span > 0.0 {
        0.05 * span
    } else {
        (0.05 * hi.abs()).max(1.0)
    };
    let range = (lo - pad, hi + pad);
    if !(range.1 - range.0).is_finite() {
        return Err(Error::invalid(
            axis,
            format!("{lo:e}..{hi:e}"),
            "must span a finite range",
        ));
    }
    Ok(range)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick(0.1 + 0.2, 1.0), "0.3");
        assert_eq!(tick(90000.0, 1e5), "90000");
        assert_eq!(tick(-0.0, 1.0), "0");
        assert_eq!(tick(-1.25, 1.0), "-1.25");
        assert_eq!(tick(5.5e-17, 1.0), "0");
        assert_eq!(tick(2e-12, 1e-11), "0.000000000002");
    }

    #[test]
    fn padded_range_handles_single_values_and_zero() {
        assert_eq!(
            padded_range("x", [2.0].into_iter(), false).unwrap(),
            (1.0, 3.0)
        );
        let (lo, hi) = padded_range("y", [1.0, 3.0].into_iter(), true).unwrap();
        assert!(lo < 0.0 && hi > 3.0);
        assert!(padded_range("x", [-1e308, 1e308].into_iter(), false).is_err());
    }
}
