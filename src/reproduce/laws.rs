//! The speed laws of a family (`analysis::law_checks`) from its fixed-φ ensemble fits.

use super::analysis::Family;
use crate::analysis::law_checks::{speed_laws as laws_of, SpeedValue};
pub use crate::analysis::law_checks::{Law, Laws};

/// Eqs. 14–17 from every speed of `family` with a fixed-φ fit, seed errors as weights.
pub fn speed_laws(family: &Family) -> Laws {
    let values: Vec<SpeedValue> = family
        .speeds
        .iter()
        .filter_map(|s| {
            let e = s.fixed.as_ref()?;
            Some([
                s.speed,
                e.mean_fit.params.p_m / 1e3,
                e.err.p_m / 1e3,
                e.mean_fit.params.delta,
                e.err.delta,
            ])
        })
        .collect();
    laws_of(&values)
}
