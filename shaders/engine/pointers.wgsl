// requires: pointer
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

fn replaced_second_pointer(old: SecondPointer, n: vec3<f64>) -> SecondPointer {
    return SecondPointer(n);
}

// `p` turned by the rotation vector w, with the twist set to twist.
fn turned_contact_pointer(p: ContactPointer, w: vec3<f64>, twist: f64) -> ContactPointer {
    return ContactPointer(rotate_pointer(p.n, w), twist);
}

fn turned_second_pointer(p: SecondPointer, w: vec3<f64>) -> SecondPointer {
    return SecondPointer(rotate_pointer(p.n, w));
}
