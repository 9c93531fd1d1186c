//! The head-on sticking threshold of two monomers, bisected between the undamped JKR-loop
//! speed (a lower bound: damping only adds loss) and a cap.

use crate::config::Config;
use crate::experiment::collision::{analytic_sticking_speed, head_on_collision, Outcome};
use crate::job::reference_engine;
use crate::material::normal_period_of;

/// Relative width to which sticking thresholds are bisected.
pub const STICKING_TOLERANCE: f64 = 2e-3;
/// Sticking thresholds are searched up to this speed [cm/s] and reported as this speed when the
/// monomers still stick there: with strong viscoelastic damping (c ∝ a, the loss share grows
/// with speed) a collision can be overdamped at every speed, and 30 m/s is far above any
/// measured threshold of micron grains.
pub const STICKING_CAP: f64 = 3000.0;
/// Time steps per normal period in the sticking runs (the bisection resolves 0.2%).
const STICKING_STEPS_PER_PERIOD: f64 = 2000.0;

/// Bisects the head-on sticking threshold [m/s]. The undamped JKR-loop speed is a lower
/// bound (damping only adds loss), so the search starts below it and doubles upwards.
pub(super) fn sticking_threshold_m_s(config: &Config) -> Result<f64, String> {
    let law = config.contact_law();
    let dt = normal_period_of(law.mass, &law.pair) / STICKING_STEPS_PER_PERIOD;
    let sticks = |v: f64| -> Result<bool, String> {
        let r = head_on_collision(&law, v, dt, 5.0, reference_engine).map_err(|e| e.to_string())?;
        Ok(r.outcome == Outcome::Stuck)
    };
    let mut lo = bracket_start(analytic_sticking_speed(&law))?;
    if !sticks(lo)? {
        return Err(format!(
            "two monomers separate at {lo:.3e} cm/s, below the JKR sticking speed"
        ));
    }
    let mut hi = (2.0 * lo).min(STICKING_CAP);
    while sticks(hi)? {
        if hi >= STICKING_CAP {
            return Ok(STICKING_CAP * 1e-2);
        }
        lo = hi;
        hi = (2.0 * hi).min(STICKING_CAP);
    }
    while hi - lo > STICKING_TOLERANCE * lo {
        let mid = 0.5 * (lo + hi);
        if sticks(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(0.5 * (lo + hi) * 1e-2)
}

/// Half the undamped JKR-loop speed [cm/s], where the doubling search starts: it must be
/// finite and positive, or doubling it never leaves it (the search would not end).
fn bracket_start(analytic: f64) -> Result<f64, String> {
    if analytic.is_finite() && analytic > 0.0 {
        Ok(0.5 * analytic)
    } else {
        Err(format!(
            "the JKR sticking speed is {analytic:e} cm/s: no search can start from it"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sticking_search_starts_only_from_a_positive_finite_speed() {
        assert_eq!(bracket_start(8.0), Ok(4.0));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(bracket_start(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn undamped_sticking_threshold_is_the_jkr_speed() {
        let mut c = Config::default();
        c.model.damping = crate::model::Damping::None;
        let v = sticking_threshold_m_s(&c).unwrap();
        let analytic = analytic_sticking_speed(&c.contact_law()) * 1e-2;
        assert!((v / analytic - 1.0).abs() < 0.01, "{v} vs {analytic}");
    }
}
