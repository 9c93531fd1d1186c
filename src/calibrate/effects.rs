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
    MonomerRadius,
    Density,
    DampingForm,
}

impl Effect {
    pub const ALL: [Effect; 11] = [
        Effect::RollingStiffness,
        Effect::SlidingStiffness,
        Effect::TwistingStiffness,
        Effect::NormalDamping,
        Effect::DampingForm,
        Effect::SurfaceEnergy,
        Effect::CriticalRollingLength,
        Effect::YoungsModulus,
        Effect::MonomerRadius,
        Effect::Density,
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
            Effect::MonomerRadius => "monomer_radius",
            Effect::Density => "density",
            Effect::DampingForm => "damping_form",
        }
    }

    /// The effect a decision counts this one as: the damping in the other form is the same
    /// physical effect (more or less loss in the normal direction) as the damping in the
    /// config's form, so the two never tie with each other; the fit picks the form.
    pub fn family(self) -> Effect {
        match self {
            Effect::DampingForm => Effect::NormalDamping,
            e => e,
        }
    }

    /// Whether the factor 1 is the model unchanged. Only the form switch is not: its factor 1
    /// is the other damping form at the same coefficient at the equilibrium contact radius.
    pub fn identity_at_one(self) -> bool {
        self != Effect::DampingForm
    }

    pub fn from_name(name: &str) -> Option<Effect> {
        Effect::ALL.into_iter().find(|e| e.name() == name)
    }

    pub fn kind(self) -> EffectKind {
        match self {
            Effect::RollingStiffness | Effect::SlidingStiffness | Effect::TwistingStiffness => {
                EffectKind::Stiffness
            }
            Effect::NormalDamping | Effect::DampingForm => EffectKind::Dissipation,
            Effect::SurfaceEnergy
            | Effect::CriticalRollingLength
            | Effect::YoungsModulus
            | Effect::MonomerRadius
            | Effect::Density => EffectKind::Material,
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
            Effect::MonomerRadius => "[material] radius_um",
            Effect::Density => "[material] density_g_cm3",
            Effect::DampingForm => "[model] damping (kind switched: viscous <-> viscoelastic)",
        }
    }

    /// The factors first searched, [lo, hi] with lo < 1 < hi: what we consider plausible.
    ///
    /// Stiffness modifiers span the paper's calibrated 8 and 2.5 (sliding stops at 4: the
    /// stiffer sliding mode shortens the stable time step as 1/√m_s); surface energy of
    /// silica is quoted from about 10 to 50 mJ/m²; ξ_crit from 0.5 to 32 nm; E within a factor
    /// of a few; damping from 8× weaker to 4× stronger; side walls from 10× weaker to full
    /// strength (the defaults weaken them 1000×); radius and density are measured, so they
    /// move by tens of percent at most. A fit that lands on an end widens the search towards
    /// [`Effect::limits`].
    pub fn range(self) -> (f64, f64) {
        match self {
            Effect::RollingStiffness => (1.0 / 8.0, 16.0),
            Effect::SlidingStiffness => (1.0 / 8.0, 4.0),
            Effect::TwistingStiffness => (1.0 / 8.0, 8.0),
            Effect::NormalDamping => (1.0 / 8.0, 4.0),
            Effect::DampingForm => (1.0 / 8.0, 8.0),
            Effect::SurfaceEnergy => (0.5, 2.5),
            Effect::CriticalRollingLength => (0.25, 16.0),
            Effect::YoungsModulus => (0.25, 2.0),
            Effect::SideWallStrength => (0.1, 1000.0),
            Effect::MonomerRadius => (0.8, 1.25),
            Effect::Density => (0.8, 1.25),
        }
    }

    /// How far a widened search may go, [lo, hi], and why not further (the same reason
    /// serves both ends unless it says otherwise). Where the searched range already is what
    /// is physically plausible the limits are the range: no widening.
    pub fn limits(self) -> (f64, f64, &'static str) {
        match self {
            Effect::RollingStiffness | Effect::TwistingStiffness => (
                1.0 / 64.0,
                128.0,
                "beyond x128 the mode is stiffer than the normal contact and the time step \
                 falls below a tenth of the base one; below x1/64 the mode is free",
            ),
            Effect::SlidingStiffness => (
                1.0 / 64.0,
                16.0,
                "beyond x16 the sliding mode is stiffer than the normal contact (k_s/k_n > 4) \
                 and the time step falls below a quarter; below x1/64 the mode is free",
            ),
            Effect::NormalDamping | Effect::DampingForm => (
                1.0 / 1024.0,
                4096.0,
                "x4096 of the paper's kappa = 1e-6 g/s already sticks far above any measured \
                 micron-grain speed; below x1/1024 the damping does nothing a test can see",
            ),
            Effect::SurfaceEnergy => (
                0.5,
                2.5,
                "silica surface energies are measured between about 10 and 50 mJ/m2 (the \
                 searched range of the paper's 20 mJ/m2)",
            ),
            Effect::CriticalRollingLength => (
                1.0 / 32.0,
                64.0,
                "xi_crit is measured between about 0.2 and 3 nm for micron silica; a factor 64 \
                 of the paper's 2 nm is over 100 nm, a tenth of the radius",
            ),
            Effect::YoungsModulus => (
                0.25,
                2.0,
                "amorphous silica has E of about 54-72 GPa; the searched range already spans \
                 13.5-108 GPa",
            ),
            Effect::SideWallStrength => (
                1e-3,
                1e4,
                "x1e4 makes the defaults' side walls ten times stickier than a monomer contact",
            ),
            Effect::MonomerRadius => (
                0.8,
                1.25,
                "the monomer radius is measured (0.6 um for the monodisperse silica of Blum's \
                 group, a spread of a few percent); the searched range already allows 20-25%",
            ),
            Effect::Density => (
                0.75,
                1.25,
                "silica densities lie between 2.0 (amorphous) and 2.65 g/cm3 (quartz)",
            ),
        }
    }

    /// Whether the effect can change anything under `config` (damping needs a damping to
    /// scale; side walls exist only in the omnidirectional box).
    pub fn applies(self, config: &Config, has_omni: bool) -> bool {
        match self {
            Effect::NormalDamping | Effect::DampingForm => config.model.damping != Damping::None,
            Effect::SideWallStrength => has_omni,
            _ => true,
        }
    }

    /// The config with this effect at `factor` (1 returns the config unchanged). The time step
    /// is lowered when the stiffer contact law needs it (see [`keep_time_step_stable`]).
    pub fn apply(self, config: &Config, factor: f64) -> Config {
        let mut c = config.clone();
        if factor == 1.0 && self.identity_at_one() {
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
            Effect::MonomerRadius => c.material.radius_um *= factor,
            Effect::Density => c.material.density_g_cm3 *= factor,
            Effect::DampingForm => m.damping = switched_damping(config, factor),
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
            Effect::NormalDamping | Effect::DampingForm => match c.model.damping {
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
            Effect::MonomerRadius => format!("r = {:.4} um", c.material.radius_um),
            Effect::Density => format!("rho = {:.3} g/cm3", c.material.density_g_cm3),
        }
    }
}

/// The config's damping in the other form, with `factor` times the config's damping
/// coefficient at the equilibrium contact radius a₀ (viscoelastic c = 2E* T_vis a/ν², viscous
/// c = κ). The two forms then dissipate alike in small-overlap contacts and differ in how the
/// loss grows with the contact radius, which is what the data must decide.
pub fn switched_damping(config: &Config, factor: f64) -> Damping {
    let law = config.contact_law();
    let a0 = law.pair.a0;
    let c0 = damping_coefficient(&law.damping, a0, law.e_star, law.poisson);
    match config.model.damping {
        Damping::None => Damping::None,
        Damping::Viscous { .. } => Damping::Viscoelastic {
            t_vis: factor * c0 * law.poisson * law.poisson / (2.0 * law.e_star * a0),
        },
        Damping::Viscoelastic { .. } => Damping::Viscous { kappa: factor * c0 },
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
            assert_eq!(
                e.apply(&base, 1.0) == base,
                e.identity_at_one(),
                "{}",
                e.name()
            );
            assert_eq!(Effect::from_name(e.name()), Some(e));
            let (lo, hi) = e.range();
            let (hard_lo, hard_hi, why) = e.limits();
            assert!(hard_lo <= lo && lo < 1.0 && hi > 1.0 && hard_hi >= hi && !why.is_empty());
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
    fn switched_damping_matches_the_coefficient_at_a0_and_switches_back() {
        use crate::model::Damping;
        // The paper's viscous kappa = 1e-6 g/s at a0 of two 0.6-um silica spheres: T_vis =
        // kappa nu^2 / (2 E* a0). By hand from physics.md's E* = 2.78035e11 dyn/cm2 and
        // a0 = 1.22327e-6 cm: 1e-6 * 0.0289 / (2 * 2.78035e11 * 1.22327e-6) = 4.2486e-14 s,
        // about 1/294 of the T_vis = 1.25e-11 s of Seizinger & Kley 2013.
        let mut base = Config::default();
        base.model.damping = Damping::Viscous { kappa: 1e-6 };
        let Damping::Viscoelastic { t_vis } = switched_damping(&base, 1.0) else {
            panic!("viscous switches to viscoelastic")
        };
        assert!((t_vis / 4.2486e-14 - 1.0).abs() < 1e-4, "{t_vis:e}");
        let mut ve = base.clone();
        ve.model.damping = Damping::Viscoelastic { t_vis };
        let Damping::Viscous { kappa } = switched_damping(&ve, 3.0) else {
            panic!("viscoelastic switches to viscous")
        };
        assert!((kappa / 3e-6 - 1.0).abs() < 1e-12, "{kappa:e}");
        assert_eq!(
            Effect::DampingForm.apply(&base, 2.0).model.damping,
            Damping::Viscoelastic { t_vis: 2.0 * t_vis }
        );
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
