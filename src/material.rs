//! Material parameters (Table 1 of Seizinger et al. (2012)) and every constant derived from them.
//!
//! All values are CGS (cm, g, s, dyn, erg). The derived constants are computed once on the host
//! from the validated inputs and handed to the contact law; nothing downstream recomputes them.

use std::f64::consts::PI;

/// Bulk properties of the monomer material (all monomers are equal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Monomer radius r [cm].
    pub radius: f64,
    /// Density ρ [g/cm³].
    pub density: f64,
    /// Surface energy γ [erg/cm²] (1 mJ/m² = 1 erg/cm²).
    pub surface_energy: f64,
    /// Young's modulus E [dyn/cm²] (1 GPa = 1e10 dyn/cm²).
    pub youngs_modulus: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Critical rolling length ξ_crit [cm].
    pub xi_crit: f64,
}

impl Material {
    /// Silicate of Table 1: r = 0.6 µm, ρ = 2.65 g/cm³, γ = 20 mJ/m², E = 54 GPa, ν = 0.17,
    /// ξ_crit = 2 nm.
    pub fn silicate() -> Self {
        Material {
            radius: 0.6e-4,
            density: 2.65,
            surface_energy: 20.0,
            youngs_modulus: 54.0e10,
            poisson: 0.17,
            xi_crit: 2.0e-7,
        }
    }

    pub fn mass(&self) -> f64 {
        4.0 / 3.0 * PI * self.radius.powi(3) * self.density
    }

    /// Moment of inertia of a solid sphere, 2/5 m r².
    pub fn moment_of_inertia(&self) -> f64 {
        0.4 * self.mass() * self.radius * self.radius
    }

    pub fn monomer_volume(&self) -> f64 {
        4.0 / 3.0 * PI * self.radius.powi(3)
    }

    /// E* for two bodies of this material.
    pub fn effective_youngs_modulus(&self) -> f64 {
        let one = (1.0 - self.poisson * self.poisson) / self.youngs_modulus;
        1.0 / (one + one)
    }

    /// Shear modulus G = E / (2(1+ν)).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson))
    }

    /// G* with the Mindlin form (2 − ν) (docs/physics.md, note 1; the paper misprints 2 − ν²).
    pub fn effective_shear_modulus(&self) -> f64 {
        let one = (2.0 - self.poisson) / self.shear_modulus();
        1.0 / (one + one)
    }
}

/// Which expression sets the twisting stiffness k_t (docs/physics.md, note 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TwistingStiffness {
    /// k_t = 16/3 G a₀³, as printed in the paper.
    Printed,
    /// k_t = 16/3 (G/2) a₀³, the reduced shear modulus of two equal spheres.
    ReducedShear,
    /// k_t = 16/3 G* a₀³.
    EffectiveShear,
}

/// Which twisting stiffness a monomer–wall contact gets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WallTwisting {
    /// k_t,wall = k_t of two monomers, as Seizinger et al. (2012, Sect. 2.2.4) choose: a monomer
    /// twists elastically through the same angle against a wall as against another monomer.
    #[default]
    Pair,
    /// k_t,wall = 16/3 G a₀,wall³, the pair formula with the wall's contact radius (R = r):
    /// 4 times the pair value, since a₀³ ∝ R².
    WallContactRadius,
}

/// Constants of one kind of contact (monomer–monomer or monomer–wall), before modifiers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactConstants {
    /// Reduced radius R [cm]: r/2 for two equal monomers, r against a wall.
    pub reduced_radius: f64,
    /// Equilibrium contact radius a₀ [cm].
    pub a0: f64,
    /// Equilibrium overlap δ₀ [cm].
    pub delta0: f64,
    /// Pull-off force F_c = 3πγR [dyn].
    pub f_c: f64,
    /// The contact breaks when stretched beyond −δ_c [cm].
    pub delta_c: f64,
    /// Rolling stiffness k_r = 4F_c/R [dyn/cm].
    pub k_r: f64,
    /// Sliding stiffness k_s = 8a₀G* [dyn/cm].
    pub k_s: f64,
    /// Twisting stiffness k_t [erg].
    pub k_t: f64,
    /// Critical rolling displacement [cm].
    pub xi_crit: f64,
    /// Critical sliding displacement (2−ν)/(16π) a₀ [cm].
    pub zeta_crit: f64,
    /// Critical twisting angle 1/(16π) [rad].
    pub phi_crit: f64,
}

impl ContactConstants {
    /// Constants for a contact of reduced radius `reduced_radius`; the wall is a sphere of
    /// infinite radius of the same material, so the same E*, G* apply.
    pub fn new(m: &Material, reduced_radius: f64, twisting: TwistingStiffness) -> Self {
        let e_star = m.effective_youngs_modulus();
        let g_star = m.effective_shear_modulus();
        let gamma = m.surface_energy;
        let a0 = (9.0 * PI * gamma * reduced_radius * reduced_radius / e_star).cbrt();
        let delta0 = a0 * a0 / (3.0 * reduced_radius);
        let f_c = 3.0 * PI * gamma * reduced_radius;
        let twist_modulus = match twisting {
            TwistingStiffness::Printed => m.shear_modulus(),
            TwistingStiffness::ReducedShear => 0.5 * m.shear_modulus(),
            TwistingStiffness::EffectiveShear => g_star,
        };
        ContactConstants {
            reduced_radius,
            a0,
            delta0,
            f_c,
            delta_c: (9.0f64 / 16.0).cbrt() * delta0,
            k_r: 4.0 * f_c / reduced_radius,
            k_s: 8.0 * a0 * g_star,
            k_t: 16.0 / 3.0 * twist_modulus * a0.powi(3),
            xi_crit: m.xi_crit,
            zeta_crit: (2.0 - m.poisson) / (16.0 * PI) * a0,
            phi_crit: 1.0 / (16.0 * PI),
        }
    }

    /// Normal stiffness dF/dδ at the equilibrium a = a₀: 6F_c / (5δ₀).
    pub fn normal_stiffness_at_equilibrium(&self) -> f64 {
        6.0 * self.f_c / (5.0 * self.delta0)
    }
}

/// Everything the simulation needs from the material, computed once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Derived {
    pub mass: f64,
    pub moment_of_inertia: f64,
    pub e_star: f64,
    pub shear_modulus: f64,
    pub g_star: f64,
    /// Monomer–monomer contacts.
    pub pair: ContactConstants,
    /// Monomer–wall contacts (R = r; k_t per [`WallTwisting`]).
    pub wall: ContactConstants,
}

impl Derived {
    /// The paper's constants: k_t,wall = k_t ([`WallTwisting::Pair`]).
    pub fn new(m: &Material, twisting: TwistingStiffness) -> Self {
        Self::with_wall_twisting(m, twisting, WallTwisting::Pair)
    }

    pub fn with_wall_twisting(
        m: &Material,
        twisting: TwistingStiffness,
        wall_twisting: WallTwisting,
    ) -> Self {
        let r = m.radius;
        let pair = ContactConstants::new(m, r * r / (r + r), twisting);
        let mut wall = ContactConstants::new(m, r, twisting);
        if wall_twisting == WallTwisting::Pair {
            wall.k_t = pair.k_t;
        }
        Derived {
            mass: m.mass(),
            moment_of_inertia: m.moment_of_inertia(),
            e_star: m.effective_youngs_modulus(),
            shear_modulus: m.shear_modulus(),
            g_star: m.effective_shear_modulus(),
            pair,
            wall,
        }
    }
}

/// Chokshi et al. (1993) sticking velocity, Eq. 5 of the paper (an approximation) [cm/s].
pub fn chokshi_sticking_velocity(m: &Material, d: &Derived) -> f64 {
    let r = d.pair.reduced_radius;
    1.07 * m.surface_energy.powf(5.0 / 6.0)
        / (d.e_star.cbrt() * r.powf(5.0 / 6.0) * m.density.sqrt())
}

/// Energy to roll through a relative pointer rotation of 90°, 6π²γRξ_crit (Dominik &
/// Tielens) [erg].
pub fn rolling_energy_quarter_turn(m: &Material, d: &Derived) -> f64 {
    6.0 * PI * PI * m.surface_energy * d.pair.reduced_radius * m.xi_crit
}

/// Sliding period 2π√(m/(m_s k_s)) of a monomer against a fixed partner, rotation held [s].
pub fn sliding_period(d: &Derived, sliding_modifier: f64) -> f64 {
    2.0 * PI * (d.mass / (sliding_modifier * d.pair.k_s)).sqrt()
}

/// Period of small normal oscillations of a free pair about δ₀, 2π√((m/2)/k_n) [s].
pub fn normal_period(d: &Derived) -> f64 {
    normal_period_of(d.mass, &d.pair)
}

/// Normal period of a free pair of monomers of mass `mass` with contact constants `c` [s].
pub fn normal_period_of(mass: f64, c: &ContactConstants) -> f64 {
    2.0 * PI * (0.5 * mass / c.normal_stiffness_at_equilibrium()).sqrt()
}
