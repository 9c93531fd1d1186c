//! How far a compression has come, once per row: the fraction a progress bar and its ETA use.
//!
//! The top wall moves at a constant speed, so the wall's travel is what grows linearly with
//! the run's time; φ does not (φ ∝ 1/gap: a run that ends at φ 0.5 from 0.15 has gone a
//! quarter of its way in time when φ has risen by a tenth of its range).

use crate::experiment::compression::Row;

/// Progress of a compression, once per row.
pub struct Progress<'a> {
    pub row: &'a Row,
    /// Fraction of the top wall's travel from its start to where φ reaches φ_stop (or of
    /// max_steps, if further); a pressure stop may end the run before it reaches 1.
    pub fraction: f64,
    /// Steps per second of wall-clock time since the job (or resume) started.
    pub steps_per_second: f64,
}

/// The fraction done at `row` of a run whose top wall moves at `wall_speed` [cm/s] from
/// time 0, stopping at `phi_stop` or after `max_steps`, whichever comes first.
///
/// The gap at the start is the gap now plus the wall's travel, so a resumed run gets the
/// same fraction as an uninterrupted one. The gap where φ reaches φ_stop is estimated at the
/// row's cross-section (φ ∝ 1/gap): exact for the omnidirectional box, an estimate where the
/// projected area of a unidirectional run changes.
pub fn fraction_done(row: &Row, wall_speed: f64, phi_stop: f64, max_steps: u64) -> f64 {
    let travelled = wall_speed * row.time;
    let start_gap = row.wall_gap + travelled;
    let stop_gap = row.wall_gap * row.phi / phi_stop;
    let to_travel = start_gap - stop_gap;
    let by_travel = if to_travel > 0.0 {
        travelled / to_travel
    } else {
        1.0
    };
    let by_steps = row.step as f64 / max_steps as f64;
    by_travel.max(by_steps).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::energy::EnergyReport;

    /// A row of an omnidirectional box whose gap started at 100 µm, with φ 0.15 there.
    fn row_at(step: u64, gap_um: f64) -> Row {
        let speed = 1000.0; // 10 m/s in cm/s
        let gap = gap_um * 1e-4;
        Row {
            step,
            time: (100e-4 - gap) / speed,
            wall_gap: gap,
            area: 1e-4,
            phi: 0.15 * 100.0 / gap_um,
            p_top: 0.0,
            p_bottom: 0.0,
            contacts: 0,
            wall_contacts: 0,
            energy: EnergyReport::default(),
        }
    }

    #[test]
    fn fraction_is_the_share_of_the_walls_travel_to_phi_stop() {
        // φ_stop 0.6 is reached at a gap of 25 µm: 75 µm of travel from 100 µm.
        let done = |gap_um: f64| fraction_done(&row_at(10, gap_um), 1000.0, 0.6, u64::MAX);
        assert!(done(100.0).abs() < 1e-12);
        // 30 µm travelled of 75 (φ 0.25, a sixth of the way in φ).
        assert!((done(70.0) - 0.4).abs() < 1e-12, "{}", done(70.0));
        assert!((done(50.0) - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(done(25.0), 1.0);
        assert_eq!(done(20.0), 1.0, "past φ_stop the fraction stays at 1");
    }

    #[test]
    fn max_steps_counts_when_it_comes_first() {
        let row = row_at(750, 70.0);
        assert!((fraction_done(&row, 1000.0, 0.6, 1000) - 0.75).abs() < 1e-12);
        assert!((fraction_done(&row, 1000.0, 0.6, 100_000) - 0.4).abs() < 1e-12);
    }

    #[test]
    fn a_sample_already_past_phi_stop_is_done() {
        let mut row = row_at(0, 100.0);
        row.time = 0.0;
        assert_eq!(fraction_done(&row, 1000.0, 0.1, u64::MAX), 1.0);
    }
}
