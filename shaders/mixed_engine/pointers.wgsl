// requires: split_pointer
//
// shaders/engine/pointers.wgsl in the mixed precision: each pointer a double-f32 (n + n_lo),
// turned by an f32 increment added exactly (rotate_split_pointer). A plain f32 pointer turned
// by 10⁻⁶ rad every step falls 1.3 % behind in 10⁵ steps (DESIGN.md, "Precision"). The laws
// read the high part, within 6·10⁻⁸ of the pointer.

struct ContactPointer {
    n: vec3<f32>,
    twist: f32,
    n_lo: vec3<f32>,
}

struct SecondPointer {
    n: vec3<f32>,
    n_lo: vec3<f32>,
}

fn contact_pointer(n: vec3<f32>, twist: f32) -> ContactPointer {
    return ContactPointer(n, twist, vec3<f32>(0.0f));
}

fn second_pointer(n: vec3<f32>) -> SecondPointer {
    return SecondPointer(n, vec3<f32>(0.0f));
}

// A vector a correction left as it was keeps its low part; a new one starts without.
fn replaced_contact_pointer(old: ContactPointer, n: vec3<f32>, twist: f32) -> ContactPointer {
    let kept = all(n == old.n);
    return ContactPointer(n, twist, select(vec3<f32>(0.0f), old.n_lo, kept));
}

fn replaced_second_pointer(old: SecondPointer, n: vec3<f32>) -> SecondPointer {
    let kept = all(n == old.n);
    return SecondPointer(n, select(vec3<f32>(0.0f), old.n_lo, kept));
}

fn turned_contact_pointer(p: ContactPointer, w: vec3<f32>, twist: f32) -> ContactPointer {
    let s = rotate_split_pointer(SplitUnit(p.n, p.n_lo), w);
    return ContactPointer(s.hi, twist, s.lo);
}

fn turned_second_pointer(p: SecondPointer, w: vec3<f32>) -> SecondPointer {
    let s = rotate_split_pointer(SplitUnit(p.n, p.n_lo), w);
    return SecondPointer(s.hi, s.lo);
}
