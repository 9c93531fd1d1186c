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
