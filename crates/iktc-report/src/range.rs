//! Automatic axis ranges and tick-label formatting.

/// Fraction of the data span added on each side of an axis so that curves do not touch the frame.
const MARGIN_FRACTION: f64 = 0.05;
/// Largest magnitude an axis end may have; data beyond is drawn off the chart. Keeps the span
/// finite (plotters' tick computation does not terminate on an infinite span).
pub(crate) const MAX_ABS: f64 = 1e300;
/// Smallest positive axis end of a logarithmic axis.
const MIN_POSITIVE: f64 = 1e-300;

/// Finite minimum and maximum of `values` (`None` when no value is finite).
pub(crate) fn finite_bounds(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// A linear axis range around `bounds` with a margin of [`MARGIN_FRACTION`] on each side.
///
/// No data gives `[0, 1]`; a single value `v` (all values equal) is padded by `|v|/10` (or 1
/// when `v` is about 0) on each side so the range never has zero width. Bounds are clamped to
/// `±MAX_ABS` so the span stays finite.
pub(crate) fn linear_range(bounds: Option<(f64, f64)>) -> (f64, f64) {
    let Some((lo, hi)) = bounds else {
        return (0.0, 1.0);
    };
    let (lo, hi) = (lo.clamp(-MAX_ABS, MAX_ABS), hi.clamp(-MAX_ABS, MAX_ABS));
    let span = hi - lo;
    let scale = lo.abs().max(hi.abs());
    if span <= scale * 1e-12 || span < 1e-290 {
        let pad = if scale > 1e-290 { scale * 0.1 } else { 1.0 };
        return (lo - pad, hi + pad);
    }
    let pad = span * MARGIN_FRACTION;
    (lo - pad, hi + pad)
}

/// A logarithmic axis range around positive `bounds`, padded by a small factor on each side.
///
/// No positive data gives `[1, 10]`; a single value `v` gives `[v/2, 2v]`. Ends are clamped to
/// `[1e-300, MAX_ABS]`.
pub(crate) fn log_range(bounds: Option<(f64, f64)>) -> (f64, f64) {
    let Some((lo, hi)) = bounds else {
        return (1.0, 10.0);
    };
    let (lo, hi) = (
        lo.clamp(MIN_POSITIVE, MAX_ABS),
        hi.clamp(MIN_POSITIVE, MAX_ABS),
    );
    let (l0, l1) = (lo.ln(), hi.ln());
    let pad = if l1 - l0 < 1e-9 {
        std::f64::consts::LN_2
    } else {
        (l1 - l0) * MARGIN_FRACTION
    };
    (
        (l0 - pad).exp().clamp(MIN_POSITIVE, MAX_ABS),
        (l1 + pad).exp().clamp(MIN_POSITIVE, MAX_ABS),
    )
}

/// Widens the smaller of two ranges so that one data unit spans the same number of pixels on
/// both axes (`plot_w` x `plot_h` is the plotting area in pixels).
pub(crate) fn equalize(
    x: (f64, f64),
    y: (f64, f64),
    plot_w: f64,
    plot_h: f64,
) -> ((f64, f64), (f64, f64)) {
    if plot_w <= 0.0 || plot_h <= 0.0 {
        return (x, y);
    }
    let per_px = ((x.1 - x.0) / plot_w).max((y.1 - y.0) / plot_h);
    let widen = |r: (f64, f64), px: f64| {
        let c = 0.5 * r.0 + 0.5 * r.1;
        let half = 0.5 * per_px * px;
        (c - half, c + half)
    };
    let (ex, ey) = (widen(x, plot_w), widen(y, plot_h));
    if is_usable(ex) && is_usable(ey) {
        (ex, ey)
    } else {
        (x, y)
    }
}

/// Whether plotters can draw an axis over `r`: finite ends, a finite positive span.
pub(crate) fn is_usable(r: (f64, f64)) -> bool {
    let span = r.1 - r.0;
    r.0.is_finite() && r.1.is_finite() && span.is_finite() && span > 0.0
}

/// A tick-label formatter for a linear axis spanning `range`: as many decimals as the tick step
/// (about a tenth of the span) needs, scientific notation for very large or very small values.
pub(crate) fn linear_formatter(range: (f64, f64)) -> impl Fn(&f64) -> String {
    let span = (range.1 - range.0).abs();
    let scale = range.0.abs().max(range.1.abs());
    let step = span / 10.0;
    let scientific = !(1e-4..1e6).contains(&scale) || step < 1e-5;
    let decimals = if step > 0.0 && step.is_finite() {
        (-(step.log10().floor()) as i64 + 1).clamp(0, 8) as usize
    } else {
        2
    };
    move |v: &f64| {
        if *v == 0.0 || v.abs() < span * 1e-9 {
            "0".to_string()
        } else if scientific {
            trim_mantissa(format!("{v:.2e}"))
        } else {
            trim_decimals(format!("{v:.decimals$}"))
        }
    }
}

/// A tick-label formatter for a logarithmic axis (decades such as 0.01, 1, 100, 1e6).
pub(crate) fn log_formatter(v: &f64) -> String {
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        trim_decimals(format!("{v:.4}"))
    } else {
        format!("{v:.0e}")
    }
}

/// Removes trailing zeros from the mantissa of a number in scientific notation (`2.50e-8` ->
/// `2.5e-8`).
fn trim_mantissa(s: String) -> String {
    match s.split_once('e') {
        Some((m, e)) => format!("{}e{e}", trim_decimals(m.to_string())),
        None => s,
    }
}

/// Removes trailing zeros (and a trailing decimal point) from a fixed-point number.
fn trim_decimals(s: String) -> String {
    if s.contains('.') {
        let t = s.trim_end_matches('0').trim_end_matches('.');
        if t == "-0" {
            "0".to_string()
        } else {
            t.to_string()
        }
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_skip_non_finite() {
        let b = finite_bounds([f64::NAN, 2.0, f64::INFINITY, -1.0, f64::NEG_INFINITY]);
        assert_eq!(b, Some((-1.0, 2.0)));
        assert_eq!(finite_bounds([f64::NAN]), None);
    }

    #[test]
    fn ranges_have_positive_width() {
        for b in [None, Some((0.0, 0.0)), Some((5.0, 5.0)), Some((-3.0, -3.0))] {
            let (lo, hi) = linear_range(b);
            assert!(hi > lo, "{b:?} -> {lo} {hi}");
        }
        let (lo, hi) = linear_range(Some((0.0, 10.0)));
        assert!((lo + 0.5).abs() < 1e-12 && (hi - 10.5).abs() < 1e-12);
        let (lo, hi) = log_range(Some((3.0, 3.0)));
        assert!((lo - 1.5).abs() < 1e-12 && (hi - 6.0).abs() < 1e-12);
        for b in [
            Some((-f64::MAX, f64::MAX)),
            Some((f64::MAX, f64::MAX)),
            Some((5e-324, 1e-323)),
            Some((0.0, 5e-324)),
        ] {
            assert!(is_usable(linear_range(b)), "{b:?} -> {:?}", linear_range(b));
        }
        for b in [Some((5e-324, f64::MAX)), Some((f64::MAX, f64::MAX))] {
            let r = log_range(b);
            assert!(is_usable(r) && r.0 > 0.0, "{b:?} -> {r:?}");
        }
    }

    #[test]
    fn equal_aspect_gives_same_units_per_pixel() {
        let (x, y) = equalize((0.0, 1.0), (0.0, 4.0), 800.0, 200.0);
        let sx = (x.1 - x.0) / 800.0;
        let sy = (y.1 - y.0) / 200.0;
        assert!((sx - sy).abs() < 1e-12);
        assert!(x.0 <= 0.0 && x.1 >= 1.0 && y.0 <= 0.0 && y.1 >= 4.0);
    }

    #[test]
    fn tick_labels_are_short() {
        let f = linear_formatter((0.0, 1.0));
        assert_eq!(f(&0.30000000000000004), "0.3");
        let f = linear_formatter((0.0, 1e-7));
        assert_eq!(f(&5e-8), "5e-8");
        assert_eq!(f(&2.5e-8), "2.5e-8");
        assert_eq!(log_formatter(&100.0), "100");
        assert_eq!(log_formatter(&1e6), "1e6");
    }
}
