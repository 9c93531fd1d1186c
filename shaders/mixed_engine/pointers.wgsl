// requires: split_pointer double_f32 rolling sliding wall math32
//
// shaders/engine/pointers.wgsl in the mixed precision: each pointer a double-f32 (n + n_lo),
// turned by an f32 increment added exactly (rotate_split_pointer). A plain f32 pointer turned
// by 10⁻⁶ rad every step falls 1.3 % behind in 10⁵ steps (DESIGN.md, "Precision"). The laws
// read the high part, within 6·10⁻⁸ of the pointer.

// The twist is a double-f32 too: 10⁻⁶ rad steps on an angle of 10⁻² rad would lose 10⁻³ of
// each step in an f32.
struct ContactPointer {
    n: vec3<f32>,
    twist: f32,
    n_lo: vec3<f32>,
    twist_lo: f32,
}

struct SecondPointer {
    n: vec3<f32>,
    n_lo: vec3<f32>,
}

// The anchor as a double-f32 per axis: the sliding spring is stiff (k_s ζ_crit is F_c/2 at
// ζ_crit = 4.5·10⁻⁸ cm), and an f32 anchor 0.01 cm from the origin is only good to 5·10⁻¹⁰ cm.
struct WallAnchor {
    p: vec3<f32>,
    p_lo: vec3<f32>,
}

fn contact_pointer(n: vec3<f32>, twist: f32) -> ContactPointer {
    return ContactPointer(n, twist, vec3<f32>(0.0f), 0.0f);
}

fn second_pointer(n: vec3<f32>) -> SecondPointer {
    return SecondPointer(n, vec3<f32>(0.0f));
}

// A vector a correction left as it was keeps its low part; a new one starts without.
fn replaced_contact_pointer(old: ContactPointer, n: vec3<f32>, twist: f32) -> ContactPointer {
    let n_lo = select(vec3<f32>(0.0f), old.n_lo, all(n == old.n));
    return ContactPointer(n, twist, n_lo, select(0.0f, old.twist_lo, twist == old.twist));
}

fn turned_contact_pointer(p: ContactPointer, w: vec3<f32>, twist_step: f32) -> ContactPointer {
    let s = rotate_split_pointer(SplitUnit(p.n, p.n_lo), w);
    let twist = double_f32_add_f32(DoubleF32(p.twist, p.twist_lo), twist_step);
    return ContactPointer(s.hi, twist.hi, s.lo, twist.lo);
}

fn turned_second_pointer(p: SecondPointer, w: vec3<f32>) -> SecondPointer {
    let s = rotate_split_pointer(SplitUnit(p.n, p.n_lo), w);
    return SecondPointer(s.hi, s.lo);
}

struct PairPointers {
    changed: bool,
    p1: ContactPointer,
    p2: SecondPointer,
}

fn with_twist(p: ContactPointer, twist: f32) -> ContactPointer {
    return ContactPointer(p.n, twist, p.n_lo, select(0.0f, p.twist_lo, twist == p.twist));
}

// A small change added to a double-f32 vector exactly (per axis).
fn plus_increment(hi: vec3<f32>, lo: vec3<f32>, d: vec3<f32>) -> SplitUnit {
    var out = SplitUnit(hi, lo);
    for (var axis = 0u; axis < 3u; axis++) {
        let sum = double_f32_add_f32(DoubleF32(hi[axis], lo[axis]), d[axis]);
        out.hi[axis] = sum.hi;
        out.lo[axis] = sum.lo;
    }
    return out;
}

// rolling_correction (model/rolling.wgsl) on double-f32 pointers, as increments. s = n₁ + n₂
// is a few thousandths long: the pointers' low parts (6·10⁻⁸) turn its direction by 10⁻⁵ rad,
// and rebuilding the pointers as ½(s ± t) in f32 moves each by 6·10⁻⁸ (the sliding
// displacement by r·6·10⁻⁸) at every correction of a contact rolling at its limit. So s and
// t = n₁ − n₂ take the low parts (the high parts' sums are exact: near-opposite f32
// vectors), and the pointers change by Δs ± Δt, small numbers computed as such: Δs = s(ξ_crit/ξ
// − 1), and t loses its rounding-level part along the new s and grows by k − 1, with
// k² − 1 = (|s|² − |s_new|²)/(4 − |s|²) (|t|² = 4 − |s|² for unit pointers).
fn rolling_correction_of(p1: ContactPointer, p2: SecondPointer, reduced_radius: f32, xi_crit: f32) -> PairPointers {
    let s = (p1.n + p2.n) + (p1.n_lo + p2.n_lo);
    let xi = vec32_length(s) * reduced_radius;
    if xi <= xi_crit {
        return PairPointers(false, p1, p2);
    }
    let ratio = xi_crit / xi;
    let ds = s * (ratio - 1.0f);
    let s_new = s + ds;
    let t = (p1.n - p2.n) + (p1.n_lo - p2.n_lo);
    let along = s_new * (vec32_dot(t, s_new) / vec32_length_squared(s_new));
    let s2 = vec32_length_squared(s);
    let grow_sq = s2 * (1.0f - ratio) * (1.0f + ratio) / (4.0f - s2);
    let grow = grow_sq / (sqrt(1.0f + grow_sq) + 1.0f);
    let dt = (t - along) * grow - along;
    let n1 = plus_increment(p1.n, p1.n_lo, 0.5f * (ds + dt));
    let n2 = plus_increment(p2.n, p2.n_lo, 0.5f * (ds - dt));
    return PairPointers(true, ContactPointer(n1.hi, p1.twist, n1.lo, p1.twist_lo), SecondPointer(n2.hi, n2.lo));
}

// sliding_correction (model/sliding.wgsl) on the high parts; the corrected pointers are new
// (no low parts). It corrects rarely: sliding stays far below ζ_crit in compression.
fn sliding_correction_of(p1: ContactPointer, p2: SecondPointer, nc: vec3<f32>, r: f32, zeta_crit: f32) -> PairPointers {
    let c = sliding_correction(p1.n, p2.n, nc, r, r, zeta_crit);
    if !c.changed {
        return PairPointers(false, p1, p2);
    }
    return PairPointers(true, ContactPointer(c.n1, p1.twist, vec3<f32>(0.0f), p1.twist_lo), second_pointer(c.n2));
}

// wall_rolling_correction (model/wall.wgsl) on a double-f32 pointer, with sin θ as
// q √(1 − q²/4) (q = ξ_crit/r): √(1 − cos²θ) would lose ε/q² of it to cancellation.
fn wall_rolling_correction_of(p: ContactPointer, anchor: vec3<f32>, normal: vec3<f32>, r: f32, xi_crit: f32) -> WallRollingCorrection {
    let s = (p.n + normal) + p.n_lo;
    if vec32_length(s) * r <= xi_crit {
        return WallRollingCorrection(false, p.n, anchor);
    }
    let n1 = p.n + p.n_lo;
    let tangential = s - normal * vec32_dot(s, normal);
    let t_len = vec32_length(tangential);
    let q = xi_crit / r;
    let cos_theta = 1.0f - 0.5f * q * q;
    let sin_theta = q * sqrt(1.0f - 0.25f * q * q);
    var dir: vec3<f32>;
    if t_len > 0.0f {
        dir = tangential / t_len;
    } else {
        dir = any_orthonormal_vector(normal);
    }
    let corrected = -normal * cos_theta + dir * sin_theta;
    return WallRollingCorrection(true, corrected, anchor + ((corrected - p.n) - p.n_lo) * r);
}
