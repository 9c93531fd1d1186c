//! The Rust twins of the probe shader's functions on one record, in the shader's write order.

use super::{Case, Record};
use dustdem::model::{damping, normal, pointer, rolling, sliding, twisting, wall};
use glam::DVec3;

/// The Rust twins on one record, in the probe shader's order.
pub(crate) fn expected(c: &Case) -> Record {
    let mut r = Record::default();
    r.put("jkr_overlap_ratio", normal::jkr_overlap_ratio(c.x));
    r.put(
        "jkr_contact_radius_ratio",
        normal::jkr_contact_radius_ratio(c.d),
    );
    r.put("jkr_force", normal::jkr_force(c.x, c.f_c));
    r.put("jkr_potential", normal::jkr_potential(c.x, c.f_c, c.delta0));
    r.put(
        "jkr_potential_at_overlap",
        normal::jkr_potential_at_overlap(c.d, c.f_c, c.delta0),
    );
    r.put(
        "damping_coefficient",
        damping::damping_coefficient(&c.damping, c.a, c.e_star, c.poisson),
    );
    r.put3("rotate_pointer", pointer::rotate_pointer(c.n, c.w));

    let xi = rolling::rolling_displacement(c.n1, c.n2, c.reduced_radius);
    r.put3("rolling_displacement", xi);
    r.put3(
        "rolling_torque",
        rolling::rolling_torque(c.n1, xi, c.reduced_radius, c.k_r),
    );
    r.put("rolling_potential", rolling::rolling_potential(xi, c.k_r));
    let rc = rolling::rolling_correction(c.n1, c.n2, c.reduced_radius, c.xi_crit);
    let pair = |(a, b): (DVec3, DVec3)| [a.x, a.y, a.z, b.x, b.y, b.z];
    r.put_option(
        "rolling_correction",
        "rolling_correction (fired)",
        rc.map(pair).as_ref().map(|v| &v[..]),
        &pair((c.n1, c.n2)),
    );

    let zeta = sliding::sliding_displacement(c.s1, c.s2, c.nc, c.r1, c.r2);
    r.put3("sliding_displacement", zeta);
    r.put3(
        "sliding_force",
        sliding::sliding_force(zeta, c.s1, c.s2, c.nc, c.r1, c.r2, c.distance, c.k_s),
    );
    r.put3(
        "sliding_torque",
        sliding::sliding_torque(c.s1, zeta, c.r1, c.k_s, 1.0),
    );
    r.put3(
        "sliding_torque",
        sliding::sliding_torque(c.s2, zeta, c.r2, c.k_s, -1.0),
    );
    r.put("sliding_potential", sliding::sliding_potential(zeta, c.k_s));
    let sc = sliding::sliding_correction(c.s1, c.s2, c.nc, c.r1, c.r2, c.zeta_crit);
    r.put_option(
        "sliding_correction",
        "sliding_correction (fired)",
        sc.map(pair).as_ref().map(|v| &v[..]),
        &pair((c.s1, c.s2)),
    );

    r.put3(
        "twisting_torque",
        twisting::twisting_torque(c.twist, c.nc, c.k_t),
    );
    r.put(
        "twisting_potential",
        twisting::twisting_potential(c.twist, c.k_t),
    );
    r.put(
        "twist_increment",
        twisting::twist_increment(c.omega_rel, c.nc, c.dt),
    );
    let tc = twisting::twisting_correction(c.twist, c.phi_crit);
    r.put_option(
        "twisting_correction",
        "twisting_correction (fired)",
        tc.map(|t| [t]).as_ref().map(|v| &v[..]),
        &[c.twist],
    );

    r.put(
        "wall_overlap",
        wall::wall_overlap(c.position, c.wall_point, c.normal, c.r),
    );
    r.put3(
        "wall_rolling_displacement",
        wall::wall_rolling_displacement(c.wn1, c.normal, c.r),
    );
    let wrc = wall::wall_rolling_correction(c.wn1, c.p, c.normal, c.r, c.wall_xi_crit);
    r.put_option(
        "wall_rolling_correction",
        "wall_rolling_correction (fired)",
        wrc.map(pair).as_ref().map(|v| &v[..]),
        &pair((c.wn1, c.p)),
    );
    let wall_zeta = wall::wall_sliding_displacement(c.position, c.wn1, c.r, c.p, c.normal);
    r.put3("wall_sliding_displacement", wall_zeta);
    r.put3(
        "wall_sliding_force",
        wall::wall_sliding_force(wall_zeta, c.wall_k_s),
    );
    let wsc = wall::wall_sliding_correction(c.p, wall_zeta, c.wall_zeta_crit);
    r.put_option(
        "wall_sliding_correction",
        "wall_sliding_correction (fired)",
        wsc.map(|v| v.to_array()).as_ref().map(|v| &v[..]),
        &c.p.to_array(),
    );

    r.put3(
        "any_orthonormal_vector (glam)",
        c.unit.any_orthonormal_vector(),
    );
    r.put3("vec_normalize (glam normalize)", c.any.normalize());
    r
}
