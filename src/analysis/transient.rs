//! The wall's impact transient on a seed-mean φ–P curve. At high wall speed the pressure
//! peaks as the wall first strikes the sample and then falls for a while before the
//! plateau sets in (at 25 m/s in the paper tier from about 400 to 190 kPa by φ = 0.33).
//! Eq. 13 is monotone in P, so fitted over that fall it widens its transition Δ to span
//! the peak and the plateau both. The rule, stated once: smooth the curve by a running
//! median over [`SMOOTHING`] grid points, find its lowest point; if the highest smoothed
//! pressure before it exceeds that lowest one by more than [`IMPACT_DROP`], the grid points
//! before the lowest one are the transient and are left out of the fit.

use super::ensemble::FixedPhiPoint;

/// Grid points of the running median (five points, ±0.01 in φ on the 0.005 grid).
pub const SMOOTHING: usize = 5;
/// Smallest fall after the impact that counts as a transient. In the paper tier's
/// 40 000-monomer curves the smoothed mean pressure falls by at most 8 % before its lowest
/// point at 1–7.5 m/s (ripples of the mean of three seeds); a fall three times that, 25 %,
/// is no ripple.
pub const IMPACT_DROP: f64 = 1.25;

/// Where a curve's fit starts when its start is an impact transient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transient {
    /// First grid φ of the fit: the smoothed curve's lowest point.
    pub phi_from: f64,
    /// Highest smoothed pressure before that point over the pressure there.
    pub drop: f64,
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    0.5 * (values[(n - 1) / 2] + values[n / 2])
}

/// The running median of the curve's mean pressures, over at most [`SMOOTHING`] points
/// centred on each (fewer at the ends).
fn smoothed(curve: &[FixedPhiPoint]) -> Vec<f64> {
    let half = SMOOTHING / 2;
    (0..curve.len())
        .map(|i| {
            let lo = i.saturating_sub(half);
            let hi = (i + half + 1).min(curve.len());
            let mut window: Vec<f64> = curve[lo..hi].iter().map(|a| a.p_mean).collect();
            median(&mut window)
        })
        .collect()
}

/// The impact transient of `curve` (grid points in ascending φ), if it has one.
pub fn impact_transient(curve: &[FixedPhiPoint]) -> Option<Transient> {
    let s = smoothed(curve);
    let lowest = (0..s.len())
        .filter(|&i| s[i].is_finite() && s[i] > 0.0)
        .min_by(|&i, &j| s[i].total_cmp(&s[j]))?;
    let peak = s[..lowest].iter().copied().fold(f64::NAN, f64::max);
    let drop = peak / s[lowest];
    (drop > IMPACT_DROP).then(|| Transient {
        phi_from: curve[lowest].phi,
        drop,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(p: &[f64]) -> Vec<FixedPhiPoint> {
        p.iter()
            .enumerate()
            .map(|(k, &p_mean)| FixedPhiPoint {
                phi: 0.16 + 0.005 * k as f64,
                p_mean,
                p_sd: f64::NAN,
            })
            .collect()
    }

    #[test]
    fn a_fall_after_the_impact_larger_than_a_quarter_is_cut_at_its_lowest_point() {
        // 400 kPa falling linearly to 200 at point 20, flat, then the steep rise.
        let p: Vec<f64> = (0..60)
            .map(|k| match k {
                0..20 => 400.0 - 10.0 * k as f64,
                20..50 => 200.0,
                _ => 200.0 * 3f64.powi(k - 49),
            })
            .collect();
        let t = impact_transient(&curve(&p)).expect("a transient");
        assert!((t.phi_from - (0.16 + 0.005 * 20.0)).abs() < 1e-12, "{t:?}");
        // The smoothed peak is the median of the first three points, 390.
        assert!((t.drop - 390.0 / 200.0).abs() < 1e-12, "{t:?}");
    }

    #[test]
    fn the_median_of_an_even_window_is_the_mean_of_its_middle_two() {
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [7.0]), 7.0);
        // The second point's window is the first four points: 100, 200, 300, 400 → 250.
        let s = smoothed(&curve(&[400.0, 100.0, 300.0, 200.0, 500.0, 600.0]));
        assert_eq!(s[1], 250.0);
    }

    #[test]
    fn rising_curves_ripples_and_single_spikes_are_no_transient() {
        // Rising throughout (quasi-static): the lowest point is the first.
        let rising: Vec<f64> = (0..40).map(|k| 10.0 * 1.1f64.powi(k)).collect();
        assert_eq!(impact_transient(&curve(&rising)), None);
        // A plateau with ±10 % ripples alternating point to point: the median removes them.
        let ripple: Vec<f64> = (0..40)
            .map(|k| if k % 2 == 0 { 110.0 } else { 90.0 })
            .collect();
        assert_eq!(impact_transient(&curve(&ripple)), None);
        // One spike of twice the plateau at the start: one point, not a fall.
        let mut spike = vec![100.0; 40];
        spike[0] = 200.0;
        assert_eq!(impact_transient(&curve(&spike)), None);
        // A fall of exactly a quarter is not more than a quarter.
        let edge: Vec<f64> = (0..40)
            .map(|k| if k < 10 { 125.0 } else { 100.0 })
            .collect();
        assert_eq!(impact_transient(&curve(&edge)), None);
        let beyond: Vec<f64> = (0..40)
            .map(|k| if k < 10 { 126.0 } else { 100.0 })
            .collect();
        assert!(impact_transient(&curve(&beyond)).is_some());
        assert_eq!(impact_transient(&[]), None);
    }

    #[test]
    fn points_without_a_pressure_are_never_the_lowest() {
        // Three points of zero pressure (the wall not yet in contact), then a fall from 400
        // to 200 kPa: the fall is found, from its own lowest point.
        let p: Vec<f64> = (0..40)
            .map(|k| match k {
                0..3 => 0.0,
                3..13 => 400.0 - 20.0 * (k - 3) as f64,
                _ => 200.0,
            })
            .collect();
        let t = impact_transient(&curve(&p)).expect("a transient");
        assert!((t.phi_from - (0.16 + 0.005 * 13.0)).abs() < 1e-12, "{t:?}");
    }
}
