//! Min-max decimation of long curves to what the pixels can show.

/// Reduces a run of points with non-decreasing x to at most four per pixel column (the first,
/// lowest, highest and last point of each column, in their original order).
///
/// `to_column` maps an x value to its horizontal pixel position; `columns` is the plot width
/// [px]. Lines drawn through the result cover the same pixels as lines through all points, so
/// the figure looks the same while SVG files stay small. Runs that are short (at most
/// `4 * columns` points) or whose x is not sorted (x-y paths) are returned unchanged.
pub(crate) fn decimate(
    seg: &[(f64, f64)],
    columns: usize,
    to_column: impl Fn(f64) -> f64,
) -> Vec<(f64, f64)> {
    let sorted = seg.windows(2).all(|w| w[0].0 <= w[1].0);
    if seg.len() <= 4 * columns.max(1) || !sorted {
        return seg.to_vec();
    }
    let mut out = Vec::with_capacity(4 * columns + 4);
    let mut start = 0;
    while start < seg.len() {
        let col = to_column(seg[start].0).floor();
        let mut end = start + 1;
        while end < seg.len() && to_column(seg[end].0).floor() == col {
            end += 1;
        }
        let bucket = &seg[start..end];
        let mut lo = 0;
        let mut hi = 0;
        for (i, p) in bucket.iter().enumerate() {
            if p.1 < bucket[lo].1 {
                lo = i;
            }
            if p.1 > bucket[hi].1 {
                hi = i;
            }
        }
        let mut keep = [0, lo, hi, bucket.len() - 1];
        keep.sort_unstable();
        let mut last = None;
        for k in keep {
            if last != Some(k) {
                out.push(bucket[k]);
                last = Some(k);
            }
        }
        start = end;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::decimate;

    #[test]
    fn short_or_unsorted_runs_are_unchanged() {
        let pts: Vec<(f64, f64)> = (0..10).map(|i| (f64::from(i), 0.0)).collect();
        assert_eq!(decimate(&pts, 100, |x| x), pts);
        let unsorted: Vec<(f64, f64)> = (0..1000).map(|i| (f64::from(i % 7), 0.0)).collect();
        assert_eq!(decimate(&unsorted, 10, |x| x), unsorted);
    }

    #[test]
    fn keeps_extremes_of_every_column() {
        // 10 columns of 100 points each; y oscillates with one spike per column
        let pts: Vec<(f64, f64)> = (0..1000)
            .map(|i| {
                let y = if i % 100 == 37 {
                    5.0 + f64::from(i / 100)
                } else {
                    f64::from(i % 3)
                };
                (f64::from(i) / 100.0, y)
            })
            .collect();
        let d = decimate(&pts, 10, |x| x);
        assert!(d.len() <= 40 && d.len() >= 20, "{}", d.len());
        for c in 0..10 {
            let spike = 5.0 + f64::from(c);
            assert!(d.iter().any(|p| p.1 == spike), "column {c} lost its spike");
            // first and last point of each column are kept
            assert!(d.contains(&pts[c as usize * 100]));
            assert!(d.contains(&pts[c as usize * 100 + 99]));
        }
        assert!(d.windows(2).all(|w| w[0].0 <= w[1].0), "order kept");
    }
}
