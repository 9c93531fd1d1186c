//! Shared builders for the physics tests.
#![allow(dead_code)]

use dustdem::cpu::state::Monomers;
use dustdem::cpu::{CpuEngine, DEFAULT_PAIR_SLOTS, DEFAULT_WALL_SLOTS};
use dustdem::material::Material;
use dustdem::model::{ContactLaw, Damping, ModelOptions};
use glam::DVec3;

pub fn law_with(damping: Damping) -> ContactLaw {
    let options = ModelOptions {
        damping,
        ..ModelOptions::default()
    };
    ContactLaw::new(&Material::silicate(), &options)
}

pub fn undamped() -> ContactLaw {
    law_with(Damping::None)
}

pub fn engine(law: ContactLaw, dt: f64, monomers: Monomers) -> CpuEngine {
    CpuEngine::new(
        law,
        dt,
        monomers,
        Vec::new(),
        DEFAULT_PAIR_SLOTS,
        DEFAULT_WALL_SLOTS,
    )
    .unwrap()
}

/// Two monomers along x at centre distance 2r − overlap.
pub fn pair_at_overlap(law: &ContactLaw, overlap: f64) -> Monomers {
    let h = law.radius - 0.5 * overlap;
    Monomers::new(vec![DVec3::new(-h, 0.0, 0.0), DVec3::new(h, 0.0, 0.0)])
}

/// Times of upward zero crossings of a sampled signal (linear interpolation).
pub fn upward_crossings(t: &[f64], y: &[f64], mean: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for k in 1..y.len() {
        let (a, b) = (y[k - 1] - mean, y[k] - mean);
        if a < 0.0 && b >= 0.0 {
            out.push(t[k - 1] + (t[k] - t[k - 1]) * (-a / (b - a)));
        }
    }
    out
}

pub fn mean_period(crossings: &[f64]) -> f64 {
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}
