//! Normal damping along the contact normal: F_damp = −c v_rel n_c.

use serde::{Deserialize, Serialize};

/// Selectable normal damping (docs/physics.md, Sect. 2.4; Seizinger et al. 2012, Sect. 2.1.4).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Damping {
    /// No normal damping.
    None,
    /// Viscous damping with constant κ [g/s] (Seizinger et al. 2012: κ = 1e-6 g/s).
    Viscous { kappa: f64 },
    /// Viscoelastic damping F = −(2E* T_vis/ν²) a v_rel (Seizinger & Kley 2013, after Krijt et
    /// al. 2013); T_vis [s].
    Viscoelastic { t_vis: f64 },
}

/// Damping coefficient c [g/s] for contact radius `a` [cm].
pub fn damping_coefficient(damping: &Damping, a: f64, e_star: f64, poisson: f64) -> f64 {
    match *damping {
        Damping::None => 0.0,
        Damping::Viscous { kappa } => kappa,
        Damping::Viscoelastic { t_vis } => 2.0 * e_star * t_vis * a / (poisson * poisson),
    }
}
