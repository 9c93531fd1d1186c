//! LAMMPS `pair_style granular` / `fix wall/gran granular` coefficients computed from dustdem's
//! contact constants (CGS, as `units cgs` reads them).
//!
//! The nearest model LAMMPS (29 Sep 2021) has: `jkr` normal force (`dmt` at the walls, see
//! [`Normal`]), `damping velocity` (or `viscoelastic`), `tangential mindlin`, `rolling sds`,
//! `twisting marshall`. Where the two models differ in form, the coefficients are chosen so that
//! both agree at the equilibrium contact (a = a₀, elastic force zero); docs/guide/src/benchmarks.md
//! ("LAMMPS beside dustdem") lists what stays different.

use crate::material::{ContactConstants, Material};
use crate::model::{ContactLaw, Damping, WallFactors};

/// LAMMPS's normal model: `jkr` between monomers; `dmt` at the walls.
///
/// JKR is what dustdem uses everywhere, but `fix wall/gran` of LAMMPS 29 Sep 2021 computes a
/// NaN force as soon as a JKR wall contact is stretched below zero overlap (a monomer leaving
/// a wall it touched: found by running the deck; planes and regions alike). DMT is the
/// adhesive model it computes there: Hertz repulsion minus a constant pull-off force 4πγR,
/// ending at zero overlap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normal {
    Jkr,
    Dmt,
}

impl Normal {
    /// Its pull-off force over dustdem's F_c = 3πγR.
    fn pulloff_over_f_c(self) -> f64 {
        match self {
            Normal::Jkr => 1.0,
            Normal::Dmt => 4.0 / 3.0,
        }
    }
}

/// One `granular` model argument list: `jkr|dmt E η ν γ damping D tangential mindlin k_t x_γ
/// μ_s rolling sds k_roll γ_roll μ_roll twisting marshall`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GranularCoeffs {
    pub normal: Normal,
    /// `jkr`/`dmt` E: Young's modulus [dyn/cm²] as LAMMPS reads it ([`GranularCoeffs::wall`]).
    pub youngs_modulus: f64,
    /// `jkr` η_n0: the damping prefactor ([`GranularCoeffs::damping_model`] says its unit).
    pub damping: f64,
    /// `damping` keyword: `velocity` (η_n = η_n0, g/s) or `viscoelastic` (η_n = η_n0 a m_eff).
    pub damping_model: &'static str,
    /// `jkr` ν.
    pub poisson: f64,
    /// `jkr` γ: surface energy [erg/cm²].
    pub surface_energy: f64,
    /// `tangential mindlin` k_t [dyn/cm²]: LAMMPS multiplies it by the contact radius a.
    pub tangential_stiffness: f64,
    /// `tangential mindlin` x_γ,t: tangential damping as a multiple of the normal damping.
    pub tangential_damping: f64,
    /// `tangential mindlin` μ_s: the sliding force is capped at μ_s |F_ne + 2 F_pulloff|
    /// (F_pulloff: 3πγR for jkr, 4πγR for dmt).
    pub sliding_friction: f64,
    /// `rolling sds` k_roll [dyn/cm].
    pub rolling_stiffness: f64,
    /// `rolling sds` γ_roll [g/s].
    pub rolling_damping: f64,
    /// `rolling sds` μ_roll: the rolling pseudo-force is capped at μ_roll |F_ne + 2 F_pulloff|.
    pub rolling_friction: f64,
}

impl GranularCoeffs {
    /// Monomer–monomer contacts (`pair_coeff * *`).
    pub fn pair(material: &Material, law: &ContactLaw) -> Self {
        // LAMMPS mixes E_eff = E/(2(1 − ν²)) for the pair style: the material's own E gives
        // dustdem's E* (tested against a pair at a known overlap).
        Self::from_constants(
            Normal::Jkr,
            material.youngs_modulus,
            material,
            law,
            &law.pair,
            0.5 * law.mass,
        )
    }

    /// Monomer–wall contacts of a wall with strength `factors` (`fix wall/gran granular`).
    pub fn wall(material: &Material, law: &ContactLaw, factors: WallFactors) -> Self {
        // fix wall/gran of LAMMPS 29 Sep 2021 forms E_eff = E/(2(1 − ν)), not E/(2(1 − ν²)) as
        // the pair style does (a wall contact at a known overlap gave exactly that force). The
        // E written for the walls, E/(1 + ν), makes its E_eff dustdem's E* = E/(2(1 − ν²)).
        // The wall is the particle's partner of infinite radius and mass: R = r, m_eff = m.
        let e = material.youngs_modulus / (1.0 + material.poisson);
        Self::from_constants(
            Normal::Dmt,
            e,
            material,
            law,
            &law.wall_constants(factors),
            law.mass,
        )
    }

    fn from_constants(
        normal: Normal,
        youngs_modulus: f64,
        material: &Material,
        law: &ContactLaw,
        c: &ContactConstants,
        reduced_mass: f64,
    ) -> Self {
        // LAMMPS caps tangential, rolling and twisting resistance at μ |F_ne + 2 F_pulloff|;
        // dustdem caps the displacement itself. At the equilibrium contact (F_ne = 0) the
        // LAMMPS cap is μ · 2 F_pulloff, so μ = (dustdem's largest force) / (2 F_pulloff)
        // makes the two caps equal there.
        let cap = 2.0 * normal.pulloff_over_f_c() * c.f_c;
        let (damping_model, damping) = match law.damping {
            // dustdem: F = −κ v_n; LAMMPS `velocity`: η_n = η_n0.
            Damping::Viscous { kappa } => ("velocity", kappa),
            // dustdem: c = 2E* T_vis a / ν²; LAMMPS `viscoelastic`: η_n = η_n0 a m_eff.
            Damping::Viscoelastic { t_vis } => (
                "viscoelastic",
                2.0 * law.e_star * t_vis / (law.poisson * law.poisson * reduced_mass),
            ),
            Damping::None => ("velocity", 0.0),
        };
        GranularCoeffs {
            normal,
            youngs_modulus,
            damping,
            damping_model,
            poisson: material.poisson,
            surface_energy: material.surface_energy,
            // dustdem's k_s = 8 a₀ G* (modifiers and wall factor applied); LAMMPS's mindlin
            // stiffness is k_t a, equal to k_s at a = a₀.
            tangential_stiffness: c.k_s / c.a0,
            // dustdem has no tangential damping.
            tangential_damping: 0.0,
            // dustdem's largest sliding force: k_s ζ_crit.
            sliding_friction: c.k_s * c.zeta_crit / cap,
            // dustdem: M = R k_r |ξ| with ξ = R × (relative rotation); LAMMPS: M = R_eff k_roll
            // |ξ_roll| with the same ξ (R = R_eff: r/2 for pairs, r for walls).
            rolling_stiffness: c.k_r,
            rolling_damping: 0.0,
            // dustdem's largest rolling pseudo-force: k_r ξ_crit.
            rolling_friction: c.k_r * c.xi_crit / cap,
        }
    }

    /// The model arguments as `pair_coeff` and `fix wall/gran granular` take them.
    pub fn args(&self) -> String {
        format!(
            "{} {} {} {} {} damping {} tangential mindlin {} {} {} rolling sds {} {} {} \
             twisting marshall",
            match self.normal {
                Normal::Jkr => "jkr",
                Normal::Dmt => "dmt",
            },
            num(self.youngs_modulus),
            num(self.damping),
            num(self.poisson),
            num(self.surface_energy),
            self.damping_model,
            num(self.tangential_stiffness),
            num(self.tangential_damping),
            num(self.sliding_friction),
            num(self.rolling_stiffness),
            num(self.rolling_damping),
            num(self.rolling_friction),
        )
    }
}

/// A number for an input deck: ten significant digits, exponent form (strtod reads `5.4e11`).
pub fn num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.9e}")
    }
}
