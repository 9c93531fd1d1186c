//! The few statistics a noisy shared machine allows: medians and ranges over rounds, and the
//! log-log slope of cost per step against N.

/// Median (the mean of the middle two for an even count); `None` for no values.
pub fn median(values: &[f64]) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mid = sorted.len() / 2;
    match sorted.len() {
        0 => None,
        n if n % 2 == 1 => Some(sorted[mid]),
        _ => Some(0.5 * (sorted[mid - 1] + sorted[mid])),
    }
}

/// (min, max); `None` for no values.
pub fn range(values: &[f64]) -> Option<(f64, f64)> {
    let low = values.iter().copied().reduce(f64::min)?;
    let high = values.iter().copied().reduce(f64::max)?;
    Some((low, high))
}

/// Ratios a[r]/b[r] of the rounds both sides measured. Both sides of a round met the same
/// load, so the ratio is steadier than either rate.
pub fn round_ratios(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x / y).collect()
}

/// Least-squares slope of ln y against ln x; `None` with fewer than two distinct x.
pub fn loglog_slope(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = logs.len() as f64;
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (logs.len() >= 2 && sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_ranges_and_slopes() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        assert_eq!(range(&[2.0, 5.0, 1.0]), Some((1.0, 5.0)));
        assert_eq!(round_ratios(&[2.0, 6.0], &[1.0, 3.0]), [2.0, 2.0]);
        let cost = |n: f64| 3e-7 * n.powf(1.2);
        let points: Vec<(f64, f64)> = [1e3, 1e4, 1e5].iter().map(|&n| (n, cost(n))).collect();
        assert!((loglog_slope(&points).unwrap() - 1.2).abs() < 1e-12);
        assert_eq!(loglog_slope(&points[..1]), None);
    }
}
