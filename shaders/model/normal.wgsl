// JKR normal interaction (Eqs. 1–3 of Seizinger et al. (2012)), in the dimensionless contact radius
// x = a/a₀ and overlap d = δ/δ₀. Twin of src/model/normal.rs.

// Smallest contact radius on the stable branch, x_min = 6^(−2/3): δ(x) has its minimum there.
const X_MIN: f64 = 0.30285343213869lf;
// Square root of X_MIN, 6^(−1/3).
const Y_MIN: f64 = 0.5503212081491045lf;
// Overlap ratio at the end of the stable branch: δ(x_min)/δ₀ = −(9/16)^(1/3).
const D_MIN: f64 = -0.8254818122236567lf;
// Contact radius at zero overlap, where a new contact forms: x₀ = (2/3)^(2/3).
const X_AT_ZERO_OVERLAP: f64 = 0.7631428283688879lf;

// δ/δ₀ = 3x² − 2√x.
fn jkr_overlap_ratio(x: f64) -> f64 {
    return 3.0lf * x * x - 2.0lf * sqrt(x);
}

// Inverse of jkr_overlap_ratio on the stable branch x ≥ x_min: Newton on the quartic
// 3y⁴ − 2y = d in y = √x, started right of the root. The iteration bound and both exits are
// those of the Rust twin, so the two stop on the same iterate.
fn jkr_contact_radius_ratio(d: f64) -> f64 {
    if d <= D_MIN {
        return X_MIN;
    }
    var y = newton_start(d);
    for (var i = 0u; i < 100u; i++) {
        let y3 = y * y * y;
        let g = 3.0lf * y3 * y - 2.0lf * y - d;
        let slope = 12.0lf * y3 - 2.0lf;
        let step = g / slope;
        let next = max(y - step, Y_MIN);
        if next >= y {
            break;
        }
        y = next;
        if step <= 1e-15lf * y {
            break;
        }
    }
    return y * y;
}

// A start right of the root of 3y⁴ − 2y = d, close to it near d = 1 (the twin's comment has
// the argument): the smaller of the quartic-root bound and the quadratic (d ≥ 1) or tangent
// (d < 1) expansion about y = 1.
fn newton_start(d: f64) -> f64 {
    let far = max(sqrt(sqrt(d + 2.0lf)), 1.0lf);
    var near: f64;
    if d >= 1.0lf {
        near = 1.0lf + (sqrt(100.0lf + 72.0lf * (d - 1.0lf)) - 10.0lf) / 36.0lf;
    } else {
        near = 1.0lf + (d - 1.0lf) / 10.0lf;
    }
    return min(far, near);
}

// Normal force F = 4F_c (x³ − x^(3/2)), positive when repulsive [dyn].
fn jkr_force(x: f64, f_c: f64) -> f64 {
    return 4.0lf * f_c * (x * x * x - x * sqrt(x));
}

// ∫F dδ from x₀ to x along the branch, in units of F_c δ₀ before scaling.
fn potential_shape(x: f64) -> f64 {
    let x2 = x * x;
    return 4.0lf * (1.2lf * x2 * x2 * x - 2.0lf * x2 * x * sqrt(x) + 0.5lf * x2);
}

// Normal potential energy U(x) = ∫₀^δ F dδ' [erg], zero where a contact forms (δ = 0).
fn jkr_potential(x: f64, f_c: f64, delta0: f64) -> f64 {
    return f_c * delta0 * (potential_shape(x) - potential_shape(X_AT_ZERO_OVERLAP));
}

// Normal potential at any overlap ratio, continued linearly below the branch end with the force
// at x_min: the energy the contact holds at the step it breaks.
fn jkr_potential_at_overlap(d: f64, f_c: f64, delta0: f64) -> f64 {
    return jkr_potential_at_overlap_with(jkr_contact_radius_ratio(d), d, f_c, delta0);
}

// jkr_potential_at_overlap where the contact radius ratio x of d is known.
fn jkr_potential_at_overlap_with(x: f64, d: f64, f_c: f64, delta0: f64) -> f64 {
    let u = jkr_potential(x, f_c, delta0);
    if d < D_MIN {
        return u + jkr_force(X_MIN, f_c) * (d - D_MIN) * delta0;
    }
    return u;
}
