//! Expectations that do not come from the code under test: the constants docs/physics.md prints
//! (six significant figures, derived by hand from Table 1 of Seizinger et al. 2012), a JKR law
//! written again from Eqs. 1–3 with a bisection inversion, and a one-dimensional head-on
//! collision integrated with RK4. Tests compare the engine against these.
#![allow(dead_code)]

use std::f64::consts::PI;

// Table 1 (silicate) and the printed derived constants, CGS.
pub const RADIUS: f64 = 6.0e-5;
pub const POISSON: f64 = 0.17;
pub const XI_CRIT: f64 = 2.0e-7;
pub const MASS: f64 = 2.39766e-12;
pub const E_STAR: f64 = 2.78035e11;
pub const G_STAR: f64 = 6.30517e10;
pub const A0: f64 = 1.22327e-6;
pub const DELTA0: f64 = 1.66265e-8;
pub const F_C: f64 = 5.65487e-3;
pub const DELTA_C: f64 = 1.37249e-8;
pub const K_R: f64 = 753.982;
pub const K_S: f64 = 6.17033e5;
/// k_t as printed, 16/3 G a₀³.
pub const K_T: f64 = 2.2529e-6;
pub const ZETA_CRIT: f64 = 4.45352e-8;
pub const PHI_CRIT: f64 = 0.0198944;
/// Wall contacts (R = r).
pub const A0_WALL: f64 = 1.94182e-6;
pub const F_C_WALL: f64 = 1.13097e-2;
/// The printed constants carry six significant figures: relative error up to 5e-6 each.
pub const PRINTED_REL: f64 = 5e-6;

pub fn moment_of_inertia() -> f64 {
    0.4 * MASS * RADIUS * RADIUS
}

/// Wall contact constants from the printed a₀,wall and F_c,wall.
pub fn delta0_wall() -> f64 {
    A0_WALL * A0_WALL / (3.0 * RADIUS)
}
pub fn k_r_wall() -> f64 {
    4.0 * F_C_WALL / RADIUS
}
pub fn k_s_wall() -> f64 {
    8.0 * A0_WALL * G_STAR
}
pub fn zeta_crit_wall() -> f64 {
    (2.0 - POISSON) / (16.0 * PI) * A0_WALL
}

/// JKR contact radius ratio x = a/a₀ for an overlap ratio d = δ/δ₀ on the stable branch, by
/// bisection of d = 3x² − 2√x (increasing for x > x_min = 6^(−2/3)).
pub fn contact_radius_ratio(d: f64) -> f64 {
    let x_min = 6f64.powf(-2.0 / 3.0);
    let f = |x: f64| 3.0 * x * x - 2.0 * x.sqrt() - d;
    if f(x_min) >= 0.0 {
        return x_min;
    }
    let (mut lo, mut hi) = (x_min, 1.0);
    while f(hi) < 0.0 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid
        } else {
            hi = mid
        }
        if hi - lo < 1e-16 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// JKR force at overlap δ for contact constants (F_c, δ₀), repulsive positive: 4F_c(x³ − x^{3/2}).
pub fn jkr_force(delta: f64, f_c: f64, delta0: f64) -> f64 {
    let x = contact_radius_ratio(delta / delta0);
    4.0 * f_c * (x * x * x - x.powf(1.5))
}

/// Normal potential ∫₀^δ F dδ' by Gauss–Legendre quadrature in x (δ = δ₀(3x² − 2√x)), zero at
/// δ = 0; δ must lie on the stable branch.
pub fn jkr_potential(delta: f64, f_c: f64, delta0: f64) -> f64 {
    let x0 = (2.0f64 / 3.0).powf(2.0 / 3.0);
    let x1 = contact_radius_ratio(delta / delta0);
    let integrand = |x: f64| {
        let force = 4.0 * f_c * (x * x * x - x.powf(1.5));
        force * delta0 * (6.0 * x - 1.0 / x.sqrt())
    };
    gauss_legendre(integrand, x0, x1, 64)
}

/// Composite 5-point Gauss–Legendre rule over `panels` panels.
pub fn gauss_legendre(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize) -> f64 {
    const NODES: [f64; 5] = [
        0.0,
        0.538_469_310_105_683_1,
        -0.538_469_310_105_683_1,
        0.906_179_845_938_664,
        -0.906_179_845_938_664,
    ];
    const WEIGHTS: [f64; 5] = [
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
        0.236_926_885_056_189_1,
    ];
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        for (node, weight) in NODES.iter().zip(WEIGHTS) {
            sum += weight * f(mid + 0.5 * h * node);
        }
    }
    0.5 * h * sum
}

/// Normal damping of the 1-D reference.
#[derive(Clone, Copy, Debug)]
pub enum Damping1d {
    None,
    /// κ [g/s].
    Viscous(f64),
    /// T_vis [s]: coefficient 2E* T_vis a / ν².
    Viscoelastic(f64),
}

/// Does a head-on collision of two free monomers at relative speed `speed` [cm/s] end with
/// the pair separated? The overlap δ obeys (m/2) δ'' = −F(δ) − c(a) δ' from contact (δ = 0)
/// until the break (δ < −δ_c) or `periods` × 10.77 ns, integrated by RK4 with step `dt`.
pub fn separates(speed: f64, damping: Damping1d, dt: f64, periods: f64) -> bool {
    let mu = 0.5 * MASS;
    let accel = |delta: f64, rate: f64| {
        let c = match damping {
            Damping1d::None => 0.0,
            Damping1d::Viscous(kappa) => kappa,
            Damping1d::Viscoelastic(t_vis) => {
                let a = A0 * contact_radius_ratio(delta / DELTA0);
                2.0 * E_STAR * t_vis * a / (POISSON * POISSON)
            }
        };
        (-jkr_force(delta, F_C, DELTA0) - c * rate) / mu
    };
    let (mut delta, mut rate) = (0.0, speed);
    let steps = (periods * 10.77e-9 / dt) as usize;
    for _ in 0..steps {
        let (k1x, k1v) = (rate, accel(delta, rate));
        let (k2x, k2v) = (
            rate + 0.5 * dt * k1v,
            accel(delta + 0.5 * dt * k1x, rate + 0.5 * dt * k1v),
        );
        let (k3x, k3v) = (
            rate + 0.5 * dt * k2v,
            accel(delta + 0.5 * dt * k2x, rate + 0.5 * dt * k2v),
        );
        let (k4x, k4v) = (rate + dt * k3v, accel(delta + dt * k3x, rate + dt * k3v));
        delta += dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        rate += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if delta < -DELTA_C {
            return true;
        }
    }
    false
}

/// Sticking threshold of the 1-D reference by bisection to a relative width `tolerance`.
pub fn sticking_threshold(
    damping: Damping1d,
    mut sticks: f64,
    mut bounces: f64,
    tolerance: f64,
) -> f64 {
    assert!(!separates(sticks, damping, 2e-12, 5.0) && separates(bounces, damping, 2e-12, 5.0));
    while bounces - sticks > tolerance * sticks {
        let mid = 0.5 * (sticks + bounces);
        if separates(mid, damping, 2e-12, 5.0) {
            bounces = mid
        } else {
            sticks = mid
        }
    }
    0.5 * (sticks + bounces)
}
