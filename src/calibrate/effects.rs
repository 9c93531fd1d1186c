//! The effect library: named physical effects, each with ONE parameter, mapped onto the
//! config. Every parameter is a factor on the config's own value, so the factor 1 is the model
//! unchanged; the range is what we consider physically plausible and is searched in log space.

use crate::config::{stable_time_step, Config};
use crate::model::damping::damping_coefficient;
use crate::model::Damping;

/// What kind of physics an effect changes (reports group by it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EffectKind {
    Stiffness,
    Dissipation,
    Material,
    Walls,
}

impl EffectKind {
    pub fn name(self) -> &'static str {
        match self {
            EffectKind::Stiffness => "stiffness modifier",
            EffectKind::Dissipation => "dissipation",
            EffectKind::Material => "material constant",
            EffectKind::Walls => "walls",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Effect {
    RollingStiffness,
    SlidingStiffness,
    TwistingStiffness,
    NormalDamping,
    SurfaceEnergy,
    CriticalRollingLength,
    YoungsModulus,
    SideWallStrength,
}

impl Effect {
    pub const ALL: [Effect; 8] = [
        Effect::RollingStiffness,
        Effect::SlidingStiffness,
        Effect::TwistingStiffness,
        Effect::NormalDamping,
        Effect::SurfaceEnergy,
        Effect::CriticalRollingLength,
        Effect::YoungsModulus,
        Effect::SideWallStrength,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Effect::RollingStiffness => "rolling_stiffness",
            Effect::SlidingStiffness => "sliding_stiffness",
            Effect::TwistingStiffness => "twisting_stiffness",
            Effect::NormalDamping => "normal_damping",
            Effect::SurfaceEnergy => "surface_energy",
            Effect::CriticalRollingLength => "critical_rolling_length",
            Effect::YoungsModulus => "youngs_modulus",
            Effect::SideWallStrength => "side_wall_strength",
        }
    }

    pub fn from_name(name: &str) -> Option<Effect> {
        Effect::ALL.into_iter().find(|e| e.name() == name)
    }

    pub fn kind(self) -> EffectKind {
        match self {
            Effect::RollingStiffness | Effect::SlidingStiffness | Effect::TwistingStiffness => {
                EffectKind::Stiffness
            }
            Effect::NormalDamping => EffectKind::Dissipation,
            Effect::SurfaceEnergy | Effect::CriticalRollingLength | Effect::YoungsModulus => {
                EffectKind::Material
            }
            Effect::SideWallStrength => EffectKind::Walls,
        }
    }

    /// The config key the factor multiplies.
    pub fn key(self) -> &'static str {
        match self {
            Effect::RollingStiffness => "[model] rolling_modifier",
            Effect::SlidingStiffness => "[model] sliding_modifier",
            Effect::TwistingStiffness => "[model] twisting_modifier",
            Effect::NormalDamping => "[model] damping (kappa or t_vis)",
            Effect::SurfaceEnergy => "[material] surface_energy_mj_m2",
            Effect::CriticalRollingLength => "[material] critical_rolling_length_nm",
            Effect::YoungsModulus => "[material] youngs_modulus_gpa",
            Effect::SideWallStrength => "[walls] side (all three factors)",
        }
    }

    /// Plausible factors on the config's value, [lo, hi] with lo < 1 < hi.
    ///
    /// Stiffness modifiers span the paper's calibrated 8 and 2.5 (sliding stops at 4: the
    /// stiffer sliding mode shortens the stable time step as 1/√m_s); surface energy of
    /// silica is quoted from about 10 to 50 mJ/m²; ξ_crit from 0.5 to 32 nm; E within a factor
    /// of a few; damping from 8× weaker to 4× stronger (four times the viscoelastic T_vis
    /// already makes head-on collisions overdamped at any speed); side walls from 100× weaker to full strength.
    pub fn range(self) -> (f64, f64) {
        match self {
            Effect::RollingStiffness => (1.0 / 8.0, 16.0),
            Effect::SlidingStiffness => (1.0 / 8.0, 4.0),
            Effect::TwistingStiffness => (1.0 / 8.0, 8.0),
            Effect::NormalDamping => (1.0 / 8.0, 4.0),
            Effect::SurfaceEnergy => (0.5, 2.5),
            Effect::CriticalRollingLength => (0.25, 16.0),
            Effect::YoungsModulus => (0.25, 2.0),
            Effect::SideWallStrength => (0.1, 1000.0),
        }
    }

    /// Whether the effect can change anything under `config` (damping needs a damping to
    /// scale; side walls exist only in the omnidirectional box).
    pub fn applies(self, config: &Config, has_omni: bool) -> bool {
        match self {
            Effect::NormalDamping => config.model.damping != Damping::None,
            Effect::SideWallStrength => has_omni,
            _ => true,
        }
    }

    /// The config with this effect at `factor` (1 returns the config unchanged). The time step
    /// is lowered when the stiffer contact law needs it (see [`keep_time_step_stable`]).
    pub fn apply(self, config: &Config, factor: f64) -> Config {
        let mut c = config.clone();
        if factor == 1.0 {
            return c;
        }
        let m = &mut c.model;
        match self {
            Effect::RollingStiffness => m.rolling_modifier *= factor,
            Effect::SlidingStiffness => m.sliding_modifier *= factor,
            Effect::TwistingStiffness => m.twisting_modifier *= factor,
            Effect::NormalDamping => {
                m.damping = match m.damping {
                    Damping::None => Damping::None,
                    Damping::Viscous { kappa } => Damping::Viscous {
                        kappa: kappa * factor,
                    },
                    Damping::Viscoelastic { t_vis } => Damping::Viscoelastic {
                        t_vis: t_vis * factor,
                    },
                }
            }
            Effect::SurfaceEnergy => c.material.surface_energy_mj_m2 *= factor,
            Effect::CriticalRollingLength => c.material.critical_rolling_length_nm *= factor,
            Effect::YoungsModulus => c.material.youngs_modulus_gpa *= factor,
            Effect::SideWallStrength => {
                let s = &mut c.walls.side;
                s.rolling *= factor;
                s.sliding *= factor;
                s.twisting *= factor;
            }
        }
        keep_time_step_stable(&mut c);
        c
    }

    /// The physical value the factor gives, for reports ("m_r = 8.1").
    pub fn describe_value(self, config: &Config, factor: f64) -> String {
        let c = self.apply(config, factor);
        match self {
            Effect::RollingStiffness => format!("m_r = {:.3}", c.model.rolling_modifier),
            Effect::SlidingStiffness => format!("m_s = {:.3}", c.model.sliding_modifier),
            Effect::TwistingStiffness => format!("m_t = {:.3}", c.model.twisting_modifier),
            Effect::NormalDamping => match c.model.damping {
                Damping::None => "no damping".into(),
                Damping::Viscous { kappa } => format!("kappa = {kappa:.3e} g/s"),
                Damping::Viscoelastic { t_vis } => format!("T_vis = {t_vis:.3e} s"),
            },
            Effect::SurfaceEnergy => {
                format!("gamma = {:.2} mJ/m2", c.material.surface_energy_mj_m2)
            }
            Effect::CriticalRollingLength => {
                format!("xi_crit = {:.3} nm", c.material.critical_rolling_length_nm)
            }
            Effect::YoungsModulus => format!("E = {:.2} GPa", c.material.youngs_modulus_gpa),
            Effect::SideWallStrength => format!("side walls x{:.3e}", c.walls.side.rolling),
        }
    }
}

/// Lowers `[integration] dt_ns` to 95% of the stability limit when an effect made the contact
/// law stiffer than the step allows, and keeps strong damping explicit-stable: the leap-frog
/// kick of a damped pair is stable for c dt < 2μ = m; we keep a factor 2 (c dt ≤ m/2), with c
/// at twice the equilibrium contact radius. A step that is
/// already small enough is left alone, so the factor 1 changes nothing.
pub fn keep_time_step_stable(c: &mut Config) {
    if c.integration.allow_unstable_dt {
        return;
    }
    let law = c.contact_law();
    let mut limit = stable_time_step(&law, &c.wall_factors());
    let damping = damping_coefficient(&law.damping, 2.0 * law.pair.a0, law.e_star, law.poisson);
    if damping > 0.0 {
        limit = limit.min(0.5 * law.mass / damping);
    }
    if c.dt() > limit {
        c.integration.dt_ns = 0.95 * limit * 1e9;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factor_one_is_the_model_unchanged_and_names_round_trip() {
        let base = Config::default();
        for e in Effect::ALL {
            assert_eq!(e.apply(&base, 1.0), base, "{}", e.name());
            assert_eq!(Effect::from_name(e.name()), Some(e));
            let (lo, hi) = e.range();
            assert!(lo < 1.0 && hi > 1.0);
        }
    }

    #[test]
    fn every_effect_changes_its_key_and_stays_valid() {
        let base = Config::default();
        for e in Effect::ALL {
            let (_, hi) = e.range();
            let changed = e.apply(&base, hi);
            assert_ne!(changed, base, "{}", e.name());
            changed.validate("effect").unwrap();
            assert_ne!(e.describe_value(&base, hi), e.describe_value(&base, 1.0));
        }
    }

    #[test]
    fn stiffer_sliding_lowers_the_time_step_only_when_needed() {
        let mut base = Config::default();
        base.integration.dt_ns = 0.6;
        let soft = Effect::SlidingStiffness.apply(&base, 0.5);
        assert_eq!(soft.integration.dt_ns, 0.6);
        let stiff = Effect::SlidingStiffness.apply(&base, 8.0);
        assert!(stiff.integration.dt_ns < 0.3);
        stiff.validate("stiff").unwrap();
    }
}
