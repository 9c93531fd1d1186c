// Normal damping along the contact normal: F_damp = −c v_rel n_c. Twin of src/model/damping.rs.

// Damping::kind values; the host encodes its `Damping` enum with the same numbers
// (src/backend/gpu/layout.rs).
const DAMPING_NONE: u32 = 0u;
const DAMPING_VISCOUS: u32 = 1u;
const DAMPING_VISCOELASTIC: u32 = 2u;

// The Rust enum as a tag and its one parameter: κ [g/s] for viscous, T_vis [s] for
// viscoelastic damping, unused for none.
struct Damping {
    kind: u32,
    value: f64,
}

// Damping coefficient c [g/s] for contact radius `a` [cm].
fn damping_coefficient(damping: Damping, a: f64, e_star: f64, poisson: f64) -> f64 {
    switch damping.kind {
        case DAMPING_VISCOUS: {
            return damping.value;
        }
        case DAMPING_VISCOELASTIC: {
            return 2.0lf * e_star * damping.value * a / (poisson * poisson);
        }
        default: {
            return 0.0lf;
        }
    }
}
