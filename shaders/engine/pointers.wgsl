// requires: pointer rolling sliding wall
//
// The contact pointers as each slot stores them. In the exact precision (this file) they are
// the f64 unit vectors of state::PairContact and state::WallContact, turned by
// rotate_pointer. The mixed precision assembles shaders/mixed_engine/pointers.wgsl in its place:
// the same records in the same 32 bytes, each vector a double-f32 (src/mixed/split_pointer.rs).

// A contact's pointer on its owner and the contact's twisting angle: 32 bytes, as a
// vec3<f64> is aligned to 32 and the twist fills its fourth word.
struct ContactPointer {
    n: vec3<f64>,
    twist: f64,
}

// A pair contact's pointer on the partner (32 bytes; the host writes [x, y, z, 0]).
struct SecondPointer {
    n: vec3<f64>,
}

// Where a wall contact formed (state::WallContact's anchor), in the box's frame: 32 bytes (the
// host writes [x, y, z, 0]).
struct WallAnchor {
    p: vec3<f64>,
}

fn contact_pointer(n: vec3<f64>, twist: f64) -> ContactPointer {
    return ContactPointer(n, twist);
}

fn second_pointer(n: vec3<f64>) -> SecondPointer {
    return SecondPointer(n);
}

// `old` with its vector set to n (a correction's result, or n itself) and its twist to twist.
fn replaced_contact_pointer(old: ContactPointer, n: vec3<f64>, twist: f64) -> ContactPointer {
    return ContactPointer(n, twist);
}

// `p` turned by the rotation vector w, its twist advanced by twist_step.
fn turned_contact_pointer(p: ContactPointer, w: vec3<f64>, twist_step: f64) -> ContactPointer {
    return ContactPointer(rotate_pointer(p.n, w), p.twist + twist_step);
}

fn turned_second_pointer(p: SecondPointer, w: vec3<f64>) -> SecondPointer {
    return SecondPointer(rotate_pointer(p.n, w));
}

// A pair contact's two records, and whether a correction changed them.
struct PairPointers {
    changed: bool,
    p1: ContactPointer,
    p2: SecondPointer,
}

// `p` with its twist set to `twist`.
fn with_twist(p: ContactPointer, twist: f64) -> ContactPointer {
    return ContactPointer(p.n, twist);
}

// The inelastic corrections on the stored records (model/rolling.wgsl, model/sliding.wgsl,
// model/wall.wgsl): here on the pointers themselves; the mixed precision's take the low parts
// into the small sums n₁ + n₂ and n₁ + n_w and add the rolling correction as an increment.
fn rolling_correction_of(p1: ContactPointer, p2: SecondPointer, reduced_radius: f64, xi_crit: f64) -> PairPointers {
    let c = rolling_correction(p1.n, p2.n, reduced_radius, xi_crit);
    return PairPointers(c.changed, ContactPointer(c.n1, p1.twist), SecondPointer(c.n2));
}

fn sliding_correction_of(p1: ContactPointer, p2: SecondPointer, nc: vec3<f64>, r: f64, zeta_crit: f64) -> PairPointers {
    let c = sliding_correction(p1.n, p2.n, nc, r, r, zeta_crit);
    return PairPointers(c.changed, ContactPointer(c.n1, p1.twist), SecondPointer(c.n2));
}

fn wall_rolling_correction_of(p: ContactPointer, anchor: vec3<f64>, normal: vec3<f64>, r: f64, xi_crit: f64) -> WallRollingCorrection {
    return wall_rolling_correction(p.n, anchor, normal, r, xi_crit);
}
