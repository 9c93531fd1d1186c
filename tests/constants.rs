//! Every derived constant of docs/physics.md, reproduced from Table 1.
//!
//! docs/physics.md prints six significant figures, so each value is checked to that precision:
//! rounding ours to the printed digits must give the printed value (|Δ| ≤ half a unit in the
//! last printed digit, at most 5e-6 relative, for most entries under 2e-6).

use dustdem::material::*;

fn assert_printed(name: &str, ours: f64, printed: &str) {
    let value: f64 = printed.parse().unwrap();
    let mantissa = printed.trim_start_matches('-').split('e').next().unwrap();
    let decimals = mantissa.split('.').nth(1).map_or(0, str::len) as i32;
    let exponent = printed
        .split('e')
        .nth(1)
        .map_or(0, |e| e.parse::<i32>().unwrap());
    let half_unit = 0.5 * 10f64.powi(exponent - decimals);
    assert!(
        (ours - value).abs() <= half_unit * (1.0 + 1e-9),
        "{name}: computed {ours:.9e}, physics.md prints {printed} (allowed ±{half_unit:e})"
    );
}

#[test]
fn derived_constants_match_physics_md() {
    let m = Material::silicate();
    let d = Derived::new(&m, TwistingStiffness::Printed);
    assert_printed("m", d.mass, "2.39766e-12");
    assert_printed("R", d.pair.reduced_radius, "3.0e-5");
    assert_printed("E*", d.e_star, "2.78035e11");
    assert_printed("G", d.shear_modulus, "2.30769e11");
    assert_printed("G*", d.g_star, "6.30517e10");
    assert_printed("a0", d.pair.a0, "1.22327e-6");
    assert_printed("delta0", d.pair.delta0, "1.66265e-8");
    assert_printed("F_c", d.pair.f_c, "5.65487e-3");
    assert_printed("delta_c", d.pair.delta_c, "1.37249e-8");
    assert_printed(
        "v_stick Chokshi",
        chokshi_sticking_velocity(&m, &d),
        "7.1832",
    );
    assert_printed("k_r", d.pair.k_r, "753.982");
    assert_printed("k_s", d.pair.k_s, "6.17033e5");
    assert_printed("k_t printed", d.pair.k_t, "2.2529e-6");
    assert_printed("zeta_crit", d.pair.zeta_crit, "4.45352e-8");
    assert_printed("phi_crit", d.pair.phi_crit, "0.0198944");
    assert_printed("E_roll", rolling_energy_quarter_turn(&m, &d), "7.10612e-9");
    assert_printed("T_slide", sliding_period(&d, 1.0), "12.39e-9");
    assert_printed("T_slide m_s=2.5", sliding_period(&d, 2.5), "7.833e-9");
    assert_printed("T_normal", normal_period(&d), "10.77e-9");
    assert_printed("a0 wall", d.wall.a0, "1.94182e-6");
    assert_printed("F_c wall", d.wall.f_c, "1.13097e-2");
    let reduced = Derived::new(&m, TwistingStiffness::ReducedShear);
    assert_printed("k_t G/2", reduced.pair.k_t, "1.12645e-6");
    let effective = Derived::new(&m, TwistingStiffness::EffectiveShear);
    assert_printed("k_t G*", effective.pair.k_t, "6.15546e-7");
}

#[test]
fn wall_constants_use_the_monomer_radius() {
    let m = Material::silicate();
    let d = Derived::new(&m, TwistingStiffness::Printed);
    assert_eq!(d.wall.reduced_radius, m.radius);
    // k_r = 4F_c/R = 12πγ is the same against a wall.
    assert!((d.wall.k_r / d.pair.k_r - 1.0).abs() < 1e-14);
    assert!((d.wall.delta_c / d.wall.delta0 - (9.0f64 / 16.0).cbrt()).abs() < 1e-14);
}

#[test]
fn printed_tolerance_check_rejects_a_wrong_value() {
    let wrong = std::panic::catch_unwind(|| assert_printed("x", 2.39767e-12, "2.39766e-12"));
    assert!(wrong.is_err());
}
