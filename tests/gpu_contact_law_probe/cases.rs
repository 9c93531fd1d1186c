//! The seeded input records: hand-picked edge cases first, then random draws over the physical
//! range of both contact kinds and two parameter sets.

use super::{Case, CASES, SEED};
use crate::common::SplitMix64;
use dustdem::material::{ContactConstants, Material, TwistingStiffness, WallTwisting};
use dustdem::model::normal::{D_MIN, X_AT_ZERO_OVERLAP, X_MIN};
use dustdem::model::{ContactLaw, Damping, ModelOptions};
use glam::{DQuat, DVec3};
use std::f64::consts::PI;

fn random_unit(rng: &mut SplitMix64) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        );
        let l2 = v.length_squared();
        if l2 > 1e-4 && l2 <= 1.0 {
            return v.normalize();
        }
    }
}

/// `v` turned by `angle` about a random axis perpendicular to it.
fn tilt(rng: &mut SplitMix64, v: DVec3, angle: f64) -> DVec3 {
    let axis = v.cross(random_unit(rng)).normalize();
    (DQuat::from_axis_angle(axis, angle) * v).normalize()
}

/// Record `i`'s value of one field: the `i`-th edge case while there are any, else `random`.
fn edge_or<T: Copy>(i: usize, edges: &[T], random: impl FnOnce() -> T) -> T {
    edges.get(i).copied().unwrap_or_else(random)
}

/// Signed zeros and axis-aligned normals: the unit vectors whose any_orthonormal_vector
/// depends on the sign of a zero z.
const AXIS_EDGES: [DVec3; 8] = [
    DVec3::new(1.0, 0.0, -0.0),
    DVec3::new(0.0, 1.0, -0.0),
    DVec3::new(1.0, 0.0, 0.0),
    DVec3::new(0.0, -1.0, 0.0),
    DVec3::new(0.0, 0.0, 1.0),
    DVec3::new(0.0, 0.0, -1.0),
    DVec3::new(0.6, 0.8, -0.0),
    DVec3::new(-0.6, 0.8, 0.0),
];

pub(crate) fn cases() -> Vec<Case> {
    let material = Material::silicate();
    let laws = [
        ContactLaw::new(&material, &ModelOptions::default()),
        // The paper's calibrated modifiers, another k_t (and the wall's own), viscoelastic
        // damping.
        ContactLaw::new(
            &material,
            &ModelOptions {
                rolling_modifier: 8.0,
                sliding_modifier: 2.5,
                twisting_modifier: 1.0,
                twisting_stiffness: TwistingStiffness::ReducedShear,
                wall_twisting: WallTwisting::WallContactRadius,
                damping: Damping::Viscoelastic { t_vis: 5e-12 },
            },
        ),
    ];
    let mut rng = SplitMix64(SEED);
    (0..CASES)
        .map(|i| {
            let law = &laws[i % 2];
            let c: ContactConstants = if (i / 2) % 2 == 0 { law.pair } else { law.wall };
            let rng = &mut rng;

            let x = edge_or(i, &[X_MIN, X_AT_ZERO_OVERLAP, 1.0, 2.5], || {
                rng.uniform(X_MIN, 2.5)
            });
            let d = edge_or(
                i,
                &[
                    D_MIN,
                    D_MIN + 1e-16,
                    D_MIN + 1e-15,
                    D_MIN + 1e-12,
                    D_MIN + 1e-8,
                    D_MIN - 1e-16,
                    -1.0,
                    0.0,
                    -0.0,
                    1.0,
                    6.0,
                ],
                || match rng.unit() {
                    // The branch end, where the quartic's slope vanishes and Newton slows.
                    u if u < 0.2 => D_MIN + rng.log_uniform(1e-15, 1e-1),
                    // Stretched past the break: the linear continuation.
                    u if u < 0.3 => rng.uniform(1.05 * D_MIN, D_MIN),
                    _ => rng.uniform(D_MIN, 6.0),
                },
            );
            let damping = match i % 3 {
                0 => Damping::None,
                1 => Damping::Viscous {
                    kappa: rng.log_uniform(1e-8, 1e-4),
                },
                _ => Damping::Viscoelastic {
                    t_vis: rng.log_uniform(1e-13, 1e-10),
                },
            };

            let n = random_unit(rng);
            let w = edge_or(
                i,
                &[
                    DVec3::ZERO,
                    DVec3::new(1e-9, 0.0, 0.0),
                    DVec3::new(0.0, 0.3, 0.0),
                    DVec3::new(0.0, 0.0, -0.3),
                ],
                || {
                    let magnitude = match rng.unit() {
                        u if u < 0.1 => 0.0,
                        u if u < 0.5 => rng.log_uniform(1e-12, 0.3),
                        _ => rng.uniform(0.0, 0.3),
                    };
                    random_unit(rng) * magnitude
                },
            );

            // Rolling: n₂ = −n₁ turned by θ, |ξ| ≈ Rθ; ξ_crit/R is 3e-3..7e-3.
            let n1 = random_unit(rng);
            let theta = edge_or(i, &[0.0, PI, c.xi_crit / c.reduced_radius], || {
                rng.log_uniform(1e-6, PI)
            });
            let n2 = tilt(rng, -n1, theta);

            // Sliding: pointers tilted off ±n_c; ζ_crit/r is about 1e-2.
            let nc = random_unit(rng);
            let (t1, t2) = edge_or(i, &[(0.0, 0.0), (1e-3, 0.0), (0.0, 0.5)], || {
                (rng.log_uniform(1e-7, 1.0), rng.log_uniform(1e-7, 1.0))
            });
            let s1 = tilt(rng, nc, t1);
            let s2 = tilt(rng, -nc, t2);
            let (r1, r2) = if i % 4 == 3 {
                (
                    material.radius * rng.uniform(0.5, 1.5),
                    material.radius * rng.uniform(0.5, 1.5),
                )
            } else {
                (material.radius, material.radius)
            };
            let distance = r1 + r2 - d * c.delta0;

            // Twisting: φ up to three times φ_crit, ω_rel up to 10⁷ rad/s.
            let twist = edge_or(
                i,
                &[
                    0.0,
                    c.phi_crit,
                    -c.phi_crit,
                    -0.0,
                    c.phi_crit * (1.0 + 1e-15),
                ],
                || c.phi_crit * rng.uniform(-3.0, 3.0),
            );
            let omega_rel = random_unit(rng) * rng.log_uniform(1.0, 1e7);
            let dt = 3e-10 * rng.uniform(0.5, 1.5);

            // Wall: a monomer of radius r at overlap d_w δ₀ from a plane through wall_point.
            let wc = law.wall;
            let normal = edge_or(i, &AXIS_EDGES, || random_unit(rng));
            let r = material.radius;
            let position = DVec3::new(
                rng.uniform(-0.05, 0.05),
                rng.uniform(-0.05, 0.05),
                rng.uniform(-0.05, 0.05),
            );
            let d_w = rng.uniform(1.05 * D_MIN, 5.0);
            let along = random_unit(rng) * rng.uniform(0.0, 1e-3);
            let along = along - normal * along.dot(normal);
            let wall_point = position - normal * (r - d_w * wc.delta0) + along;
            // Edge cases first: pointer exactly onto the wall (no correction), exactly off it
            // (the any_orthonormal_vector branch), then random tilts off −n_w.
            let wn1 = if i < AXIS_EDGES.len() {
                normal
            } else if i < 2 * AXIS_EDGES.len() {
                -normal
            } else {
                let angle = rng.log_uniform(1e-6, PI / 2.0);
                tilt(rng, -normal, angle)
            };
            let p =
                position + wn1 * r - random_unit(rng) * wc.zeta_crit * rng.log_uniform(1e-2, 3.0);

            let unit = edge_or(i, &AXIS_EDGES, || random_unit(rng));
            let any = random_unit(rng) * rng.log_uniform(1e-10, 1e10);

            Case {
                x,
                d,
                f_c: c.f_c,
                delta0: c.delta0,
                damping,
                a: x * c.a0,
                e_star: law.e_star,
                poisson: law.poisson,
                n,
                w,
                n1,
                n2,
                reduced_radius: c.reduced_radius,
                k_r: c.k_r,
                xi_crit: c.xi_crit,
                nc,
                s1,
                s2,
                r1,
                r2,
                distance,
                k_s: c.k_s,
                zeta_crit: c.zeta_crit,
                twist,
                k_t: c.k_t,
                phi_crit: c.phi_crit,
                omega_rel,
                dt,
                position,
                wall_point,
                normal,
                r,
                wn1,
                p,
                wall_k_s: wc.k_s,
                wall_xi_crit: wc.xi_crit,
                wall_zeta_crit: wc.zeta_crit,
                unit,
                any,
            }
        })
        .collect()
}
