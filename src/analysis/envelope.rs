//! φ(P) of one compression read the way the calibration and the sweep analysis read it.

/// Rows of log₁₀P are smoothed by a running median over this many rows before the envelope:
/// single rows of a small sample spike by decades when a contact chain jams.
pub const MEDIAN_ROWS: usize = 9;

/// φ(P) of one compression: filling factors with the running maximum of the median-smoothed
/// log₁₀P, so each pressure is reached once (the first time the sample holds it).
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    pub phi: Vec<f64>,
    pub log10_p: Vec<f64>,
    /// Why the run ended early, if it failed (a run-time guard at high pressure): the envelope
    /// then holds the rows before the failure.
    pub failure: Option<String>,
}

impl Envelope {
    /// From rows of (φ, P [Pa]) in time order.
    pub fn from_rows(rows: &[(f64, f64)]) -> Envelope {
        let log: Vec<f64> = rows
            .iter()
            .map(|&(_, p)| if p > 0.0 { p.log10() } else { -10.0 })
            .collect();
        let half = MEDIAN_ROWS / 2;
        let mut running = f64::NEG_INFINITY;
        let mut log10_p = Vec::with_capacity(rows.len());
        for k in 0..log.len() {
            let mut window: Vec<f64> =
                log[k.saturating_sub(half)..(k + half + 1).min(log.len())].to_vec();
            window.sort_by(f64::total_cmp);
            running = running.max(window[window.len() / 2]);
            log10_p.push(running);
        }
        Envelope {
            phi: rows.iter().map(|r| r.0).collect(),
            log10_p,
            failure: None,
        }
    }

    /// Filling factor when the sample first held pressure `p`; NaN if the run never did.
    /// Below the first row's pressure the sample's starting φ.
    pub fn phi_at(&self, p: f64) -> f64 {
        let x = p.log10();
        match self.log10_p.iter().position(|&e| e >= x) {
            None => f64::NAN,
            Some(0) => self.phi[0],
            Some(i) => {
                let (e0, e1) = (self.log10_p[i - 1], self.log10_p[i]);
                let t = (x - e0) / (e1 - e0);
                self.phi[i - 1] + t * (self.phi[i] - self.phi[i - 1])
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows at φ = 0.1 + 0.01 k with the given pressures.
    fn rows(pressures: &[f64]) -> Vec<(f64, f64)> {
        pressures
            .iter()
            .enumerate()
            .map(|(k, &p)| (0.1 + 0.01 * k as f64, p))
            .collect()
    }

    #[test]
    fn the_median_removes_a_spike_and_keeps_a_step_where_it_is() {
        // 1 Pa for rows 0–19 with a 1 MPa spike at row 10, then 100 Pa for rows 20–39. Row k's
        // window is rows k−4 … k+4 (fewer at the ends): it holds k−15 rows of 100 Pa, a majority
        // from k = 20 on, so the step stays at row 20, and one spike is never a majority.
        let mut p = vec![1.0; 20];
        p[10] = 1e6;
        p.extend([100.0; 20]);
        let e = Envelope::from_rows(&rows(&p));
        let expected: Vec<f64> = (0..40).map(|k| if k < 20 { 0.0 } else { 2.0 }).collect();
        assert_eq!(e.log10_p, expected);
        assert_eq!(e.phi.len(), 40);
        // The first time the sample held 10 Pa: halfway (in log P) from row 19 to row 20.
        assert!((e.phi_at(10.0) - (0.1 + 0.195)).abs() < 1e-12);
    }

    #[test]
    fn the_median_window_is_centred_and_shrinks_at_the_ends() {
        // log P = k on rows 0–19: row k's window is rows max(0, k−4) … min(19, k+4), and its
        // median the value at start + len/2: 2, 3, 3, 4, 4, then k up to row 16, then 16, 17,
        // 17 (the running maximum keeps 16 at row 17).
        let p: Vec<f64> = (0..20).map(|k| 10f64.powi(k)).collect();
        let e = Envelope::from_rows(&rows(&p));
        let mut expected = vec![2.0, 3.0, 3.0, 4.0, 4.0];
        expected.extend((5..=16).map(f64::from));
        expected.extend([16.0, 17.0, 17.0]);
        assert_eq!(e.log10_p.len(), expected.len());
        for (k, (got, want)) in e.log10_p.iter().zip(&expected).enumerate() {
            assert!((got - want).abs() < 1e-12, "row {k}: {got} vs {want}");
        }
    }

    #[test]
    fn rows_without_pressure_sit_at_the_floor() {
        // Zero (and negative) pressures count as 1e-10 Pa, not as log 0 = −∞.
        let e = Envelope::from_rows(&rows(&[0.0; 12]));
        assert_eq!(e.log10_p, vec![-10.0; 12]);
        let e = Envelope::from_rows(&rows(&[-5.0; 3]));
        assert_eq!(e.log10_p, vec![-10.0; 3]);
        // Above the floor nothing was reached; at or below it, the first row's φ.
        let e = Envelope::from_rows(&rows(&[0.0; 12]));
        assert!(e.phi_at(1e-9).is_nan());
        assert_eq!(e.phi_at(1e-11), 0.1);
    }
}
