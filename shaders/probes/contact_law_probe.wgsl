// requires: normal damping pointer rolling sliding twisting wall math
//
// Evaluates every contact-law function of shaders/model/ on one input record per invocation,
// for the test that holds each to its Rust twin in src/model/ (tests/gpu_contact_law_probe/). Records are flat f64
// arrays read and written in sequence; the test reads and writes them in the same sequence.
// Each output record starts with the number of values read and written, so a sequence that
// drifts out of step with the host fails loudly instead of comparing the wrong numbers.

struct Params {
    cases: u32,
    in_stride: u32,
    out_stride: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> inputs: array<f64>;
@group(0) @binding(2) var<storage, read_write> outputs: array<f64>;

var<private> in_at: u32;
var<private> out_at: u32;

fn take() -> f64 {
    let v = inputs[in_at];
    in_at += 1u;
    return v;
}

fn take3() -> vec3<f64> {
    let x = take();
    let y = take();
    let z = take();
    return vec3<f64>(x, y, z);
}

fn put(v: f64) {
    outputs[out_at] = v;
    out_at += 1u;
}

fn put3(v: vec3<f64>) {
    put(v.x);
    put(v.y);
    put(v.z);
}

fn put_flag(changed: bool) {
    put(select(0.0lf, 1.0lf, changed));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if index >= params.cases {
        return;
    }
    let in_base = index * params.in_stride;
    let out_base = index * params.out_stride;
    in_at = in_base;
    out_at = out_base + 2u;

    // Normal (JKR).
    let x = take();
    let d = take();
    let f_c = take();
    let delta0 = take();
    put(jkr_overlap_ratio(x));
    put(jkr_contact_radius_ratio(d));
    put(jkr_force(x, f_c));
    put(jkr_potential(x, f_c, delta0));
    put(jkr_potential_at_overlap(d, f_c, delta0));

    // Damping.
    let kind = u32(take());
    let damping = Damping(kind, take());
    let a = take();
    let e_star = take();
    let poisson = take();
    put(damping_coefficient(damping, a, e_star, poisson));

    // Pointer rotation.
    let n = take3();
    let w = take3();
    put3(rotate_pointer(n, w));

    // Rolling.
    let n1 = take3();
    let n2 = take3();
    let reduced_radius = take();
    let k_r = take();
    let xi_crit = take();
    let xi = rolling_displacement(n1, n2, reduced_radius);
    put3(xi);
    put3(rolling_torque(n1, xi, reduced_radius, k_r));
    put(rolling_potential(xi, k_r));
    let rc = rolling_correction(n1, n2, reduced_radius, xi_crit);
    put_flag(rc.changed);
    put3(rc.n1);
    put3(rc.n2);

    // Sliding.
    let nc = take3();
    let s1 = take3();
    let s2 = take3();
    let r1 = take();
    let r2 = take();
    let distance = take();
    let k_s = take();
    let zeta_crit = take();
    let zeta = sliding_displacement(s1, s2, nc, r1, r2);
    put3(zeta);
    put3(sliding_force(zeta, s1, s2, nc, r1, r2, distance, k_s));
    put3(sliding_torque(s1, zeta, r1, k_s, 1.0lf));
    put3(sliding_torque(s2, zeta, r2, k_s, -1.0lf));
    put(sliding_potential(zeta, k_s));
    let sc = sliding_correction(s1, s2, nc, r1, r2, zeta_crit);
    put_flag(sc.changed);
    put3(sc.n1);
    put3(sc.n2);

    // Twisting.
    let twist = take();
    let k_t = take();
    let phi_crit = take();
    let omega_rel = take3();
    let dt = take();
    put3(twisting_torque(twist, nc, k_t));
    put(twisting_potential(twist, k_t));
    put(twist_increment(omega_rel, nc, dt));
    let tc = twisting_correction(twist, phi_crit);
    put_flag(tc.changed);
    put(tc.twist);

    // Wall.
    let position = take3();
    let wall_point = take3();
    let normal = take3();
    let r = take();
    let wn1 = take3();
    let p = take3();
    let wall_k_s = take();
    let wall_xi_crit = take();
    let wall_zeta_crit = take();
    put(wall_overlap(position, wall_point, normal, r));
    put3(wall_rolling_displacement(wn1, normal, r));
    let wrc = wall_rolling_correction(wn1, p, normal, r, wall_xi_crit);
    put_flag(wrc.changed);
    put3(wrc.n1);
    put3(wrc.anchor);
    let wall_zeta = wall_sliding_displacement(position, wn1, r, p, normal);
    put3(wall_zeta);
    put3(wall_sliding_force(wall_zeta, wall_k_s));
    let wsc = wall_sliding_correction(p, wall_zeta, wall_zeta_crit);
    put_flag(wsc.changed);
    put3(wsc.p);

    // glam twins.
    put3(any_orthonormal_vector(take3()));
    put3(vec_normalize(take3()));

    outputs[out_base] = f64(in_at - in_base);
    outputs[out_base + 1u] = f64(out_at - out_base - 2u);
}
