//! The three regimes of a dynamic φ–P curve (Sect. 5.2): no compaction up to a critical
//! pressure, a plateau where φ rises at nearly constant pressure, and a steep rise of the
//! pressure once the compacted layer reaches the bottom.
//!
//! Criterion. In time order a dynamic run's log₁₀P rises steeply (regime i), stays nearly
//! flat (ii), and rises steeply again (iii). The curve's log₁₀P is fitted, against the row
//! index, by three straight lines over consecutive rows, each fitted on its own by least
//! squares; the two breakpoints are those with the least total squared residual over all
//! splits (exhaustive, O(n²) with prefix sums). The rows must be equally spaced in time,
//! as a run writes them. Regime (i) is delimited by φ − φ₀ and by its rise: a first piece
//! that rises no faster per row than the plateau is plateau (regime (i) then lies before the
//! first row, as at high wall speed), and the rest is split in two. The split is then checked
//! against the paper's description: φ must stay within `phi_tol` of its first value through
//! regime (i), and the plateau must rise more slowly in log₁₀P per unit φ than both
//! neighbours by `plateau_ratio`.

#[cfg(test)]
mod tests;

use super::average::{spread, Spread};

/// Control of [`find_regimes`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegimeOptions {
    /// Fewest rows of the plateau and of the steep rise (a line with a residual needs three).
    pub min_rows: usize,
    /// Fewest rows of regime (i). Default 0: at high wall speed the wall's first impact
    /// raises the pressure from zero to the plateau's within the first row (100 steps,
    /// 30 ns: at 15 m/s 0.45 µm of wall travel, φ + 0.001), so regime (i) lies before the
    /// first row with a pressure; a regime (i) of fewer than two rows counts as infinitely
    /// steep, and its φ rise is the first row's over the start.
    pub min_first_rows: usize,
    /// Largest rise of φ through regime (i) that still counts as no compaction. Default
    /// 0.01, a fifteenth of the starting φ ≈ 0.15.
    pub phi_tol: f64,
    /// The plateau's d log₁₀P/dφ must be smaller than both neighbours' by this factor.
    pub plateau_ratio: f64,
}

impl Default for RegimeOptions {
    fn default() -> Self {
        Self {
            min_rows: 3,
            min_first_rows: 0,
            phi_tol: 0.01,
            plateau_ratio: 4.0,
        }
    }
}

/// Where the regimes of one curve start. Indices are into the curve as given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Regimes {
    /// First row of regime (ii), the plateau: the critical pressure is reached.
    pub plateau_start: usize,
    /// First row of regime (iii), the steep rise.
    pub steep_start: usize,
    /// Critical pressure [Pa]: the plateau line at its first row (less noisy than that row).
    pub critical_pressure: f64,
    /// Median pressure over the plateau [Pa].
    pub plateau_pressure: f64,
    /// The plateau line at its last row [Pa], where the steep rise takes over.
    pub plateau_end_pressure: f64,
    pub phi_at_plateau_start: f64,
    pub phi_at_steep_start: f64,
    /// Least-squares d log₁₀P / dφ of each regime (infinite where φ does not change).
    pub slopes: [f64; 3],
    /// φ at the plateau's start minus the first φ.
    pub phi_rise_before_critical: f64,
    /// The split matches the paper's description (see the module doc).
    pub three_regimes: bool,
}

/// Prefix sums of 1, x, y, y², x·y with x the position in the curve.
struct Sums {
    y: Vec<f64>,
    yy: Vec<f64>,
    xy: Vec<f64>,
}

impl Sums {
    fn new(y: &[f64]) -> Sums {
        let mut s = Sums {
            y: vec![0.0],
            yy: vec![0.0],
            xy: vec![0.0],
        };
        for (i, &v) in y.iter().enumerate() {
            s.y.push(s.y[i] + v);
            s.yy.push(s.yy[i] + v * v);
            s.xy.push(s.xy[i] + i as f64 * v);
        }
        s
    }

    /// Residual sum of squares of the least-squares line over positions [a, b).
    fn rss(&self, a: usize, b: usize) -> f64 {
        let n = (b - a) as f64;
        let sx = (a + b - 1) as f64 * n / 2.0;
        // Consecutive integers: Σ(x − x̄)² = n(n² − 1)/12 exactly.
        let sxx = n * (n * n - 1.0) / 12.0;
        let sy = self.y[b] - self.y[a];
        let syy = self.yy[b] - self.yy[a] - sy * sy / n;
        let sxy = self.xy[b] - self.xy[a] - sx * sy / n;
        (syy - sxy * sxy / sxx).max(0.0)
    }
}

/// Least-squares line of `y` against `x`: (slope, intercept); slope infinite when x is
/// constant.
fn line(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(x, y)| (x - mx) * (y - my)).sum();
    if sxx > 0.0 {
        (sxy / sxx, my - sxy / sxx * mx)
    } else {
        (f64::INFINITY, f64::NAN)
    }
}

/// Row positions `lo..hi` as abscissae.
fn rows_of(lo: usize, hi: usize) -> Vec<f64> {
    (lo..hi).map(|i| i as f64).collect()
}

/// The breaks (a, b) with the least total squared residual of three lines over rows [0, a),
/// [a, b), [b, n), for a in `first_breaks` and pieces two and three of at least `m` rows.
fn best_split(
    sums: &Sums,
    n: usize,
    m: usize,
    first_breaks: std::ops::RangeInclusive<usize>,
) -> (usize, usize) {
    let mut best = (f64::INFINITY, 0, 0);
    for a in first_breaks {
        let first = sums.rss(0, a);
        for b in a + m..=n - m {
            let total = first + sums.rss(a, b) + sums.rss(b, n);
            if total < best.0 {
                best = (total, a, b);
            }
        }
    }
    (best.1, best.2)
}

/// Finds the regimes of `curve`, points (P [Pa], φ) in time order at equal time steps
/// (rows with P ≤ 0 or not finite are left out of the fit). `None` with fewer than
/// `min_first_rows + 2 · min_rows` usable rows.
pub fn find_regimes(curve: &[(f64, f64)], opt: &RegimeOptions) -> Option<Regimes> {
    let keep: Vec<usize> = (0..curve.len())
        .filter(|&i| curve[i].0.is_finite() && curve[i].0 > 0.0 && curve[i].1.is_finite())
        .collect();
    let n = keep.len();
    let m = opt.min_rows.max(2);
    let m1 = opt.min_first_rows;
    if n < m1 + 2 * m {
        return None;
    }
    let y: Vec<f64> = keep.iter().map(|&i| curve[i].0.log10()).collect();
    let phi: Vec<f64> = keep.iter().map(|&i| curve[i].1).collect();
    let sums = Sums::new(&y);
    let (mut a, mut b) = best_split(&sums, n, m, m1..=n - 2 * m);
    // Regime (i) rises faster than the plateau. A first piece that does not (flat, or falling
    // as the wall's impact spike decays) is plateau: the pressure reached the plateau within
    // the first row, so split the rest in two. Without this a curve whose regime (i) is
    // shorter than a row puts its first break at the knee of the steep rise and its second
    // inside the rise.
    let per_row = |lo: usize, hi: usize| line(&rows_of(lo, hi), &y[lo..hi]).0;
    if a >= 2 && per_row(0, a) <= opt.plateau_ratio * per_row(a, b).abs() {
        (a, b) = best_split(&sums, n, m, 0..=0);
    }

    let (plateau_slope, plateau_icpt) = line(&rows_of(a, b), &y[a..b]);
    let at = |i: usize| 10f64.powf(plateau_icpt + plateau_slope * i as f64);
    let mut plateau: Vec<f64> = y[a..b].to_vec();
    plateau.sort_by(f64::total_cmp);
    let median = 0.5 * (plateau[(b - a - 1) / 2] + plateau[(b - a) / 2]);
    let slopes = [(0, a), (a, b), (b, n)].map(|(lo, hi)| line(&phi[lo..hi], &y[lo..hi]).0);
    // From the curve's first row as given (the start, before any pressure was measured).
    let phi_rise = phi[a] - curve[0].1;
    let flat = slopes[1].abs() * opt.plateau_ratio;
    let three_regimes = phi_rise <= opt.phi_tol && flat < slopes[0] && flat < slopes[2];
    Some(Regimes {
        plateau_start: keep[a],
        steep_start: keep[b],
        critical_pressure: at(a),
        plateau_pressure: 10f64.powf(median),
        plateau_end_pressure: at(b - 1),
        phi_at_plateau_start: phi[a],
        phi_at_steep_start: phi[b],
        slopes,
        phi_rise_before_critical: phi_rise,
        three_regimes,
    })
}

/// The regimes of several runs of one case (seeds), each found on its own time-ordered rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegimeSummary {
    pub runs: usize,
    /// Runs whose split matches the paper's description.
    pub three_regimes: usize,
    /// Over those runs: critical pressure, plateau pressure [Pa], φ where the steep rise starts.
    pub critical_pa: Option<Spread>,
    pub plateau_pa: Option<Spread>,
    pub phi_steep: Option<Spread>,
    /// Over those runs: the plateau line's pressure at its end over that at its start.
    pub plateau_rise: Option<Spread>,
}

/// [`find_regimes`] on each run's rows (P [Pa], φ) in time order, then over the runs. A seed
/// average is no input for this: its rows are not equally spaced in time.
pub fn regimes_of_runs(runs: &[&[(f64, f64)]], opt: &RegimeOptions) -> RegimeSummary {
    let found: Vec<Regimes> = runs
        .iter()
        .filter_map(|r| find_regimes(r, opt))
        .filter(|r| r.three_regimes)
        .collect();
    let over = |f: fn(&Regimes) -> f64| spread(&found.iter().map(f).collect::<Vec<_>>());
    RegimeSummary {
        runs: runs.len(),
        three_regimes: found.len(),
        critical_pa: over(|r| r.critical_pressure),
        plateau_pa: over(|r| r.plateau_pressure),
        phi_steep: over(|r| r.phi_at_steep_start),
        plateau_rise: over(|r| r.plateau_end_pressure / r.critical_pressure),
    }
}
