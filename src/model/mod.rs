//! The contact law as pure functions: geometry in, forces, torques and corrected history out.
//!
//! Each slot (normal, damping, rolling, sliding, twisting, wall) lives in its own file, in the
//! order the force pass evaluates them. The WGSL modules in `shaders/model/` mirror these
//! functions name for name.

pub mod damping;
pub mod normal;
pub mod pointer;
pub mod rolling;
pub mod sliding;
pub mod twisting;
pub mod wall;

pub use damping::Damping;

use crate::material::{ContactConstants, Derived, Material, TwistingStiffness, WallTwisting};
use serde::{Deserialize, Serialize};

/// Model options on top of the material: the paper's modifiers and the damping choice.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ModelOptions {
    /// Rolling modifier m_r: k_r → m_r k_r (paper's calibrated model: 8).
    pub rolling_modifier: f64,
    /// Sliding modifier m_s: k_s → m_s k_s (paper's calibrated model: 2.5).
    pub sliding_modifier: f64,
    /// Twisting modifier m_t: k_t → m_t k_t.
    pub twisting_modifier: f64,
    /// Which expression gives k_t (docs/physics.md, note 2).
    pub twisting_stiffness: TwistingStiffness,
    /// Twisting stiffness against walls: the pair's k_t (paper) or the wall contact's own.
    pub wall_twisting: WallTwisting,
    pub damping: Damping,
}

impl Default for ModelOptions {
    /// Seizinger et al.'s (2012) unmodified model: m_r = m_s = m_t = 1, κ = 1e-6 g/s, k_t as
    /// printed.
    fn default() -> Self {
        ModelOptions {
            rolling_modifier: 1.0,
            sliding_modifier: 1.0,
            twisting_modifier: 1.0,
            twisting_stiffness: TwistingStiffness::Printed,
            wall_twisting: WallTwisting::Pair,
            damping: Damping::Viscous { kappa: 1e-6 },
        }
    }
}

/// Strength factors of one wall's rolling, sliding and twisting stiffness.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallFactors {
    pub rolling: f64,
    pub sliding: f64,
    pub twisting: f64,
}

impl WallFactors {
    pub const FULL: WallFactors = WallFactors {
        rolling: 1.0,
        sliding: 1.0,
        twisting: 1.0,
    };
}

/// The constants the force passes use: material-derived values with the modifiers applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    pub radius: f64,
    pub mass: f64,
    pub moment_of_inertia: f64,
    pub e_star: f64,
    pub poisson: f64,
    pub damping: Damping,
    /// Monomer–monomer constants, modifiers applied.
    pub pair: ContactConstants,
    /// Monomer–wall constants with modifiers applied and wall factors still 1.
    pub wall: ContactConstants,
}

impl ContactLaw {
    pub fn new(material: &Material, options: &ModelOptions) -> Self {
        let derived = Derived::with_wall_twisting(
            material,
            options.twisting_stiffness,
            options.wall_twisting,
        );
        let modify = |mut c: ContactConstants| {
            c.k_r *= options.rolling_modifier;
            c.k_s *= options.sliding_modifier;
            c.k_t *= options.twisting_modifier;
            c
        };
        ContactLaw {
            radius: material.radius,
            mass: derived.mass,
            moment_of_inertia: derived.moment_of_inertia,
            e_star: derived.e_star,
            poisson: material.poisson,
            damping: options.damping,
            pair: modify(derived.pair),
            wall: modify(derived.wall),
        }
    }

    /// Wall constants for a wall with the given strength factors.
    pub fn wall_constants(&self, factors: WallFactors) -> ContactConstants {
        let mut c = self.wall;
        c.k_r *= factors.rolling;
        c.k_s *= factors.sliding;
        c.k_t *= factors.twisting;
        c
    }
}
