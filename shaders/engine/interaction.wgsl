// requires: bindings positions normal damping rolling sliding twisting wall math
//
// One contact's forces, torques, potential and step energy: the twins of pair_interaction,
// pair_contact_potential, pair_step_energy, pair_tangential_step_energy, wall_interaction,
// wall_contact_potential, wall_tangential_step_energy and
// wall_step_energy in src/state/interaction.rs, same operations in the same order. Contact history is passed by value
// (n1, n2 or anchor, twist) because it lives in separate arrays on the device.

// (force on 1, damping part of it, torque on 1, torque on 2).
struct PairInteraction {
    f: vec3<f64>,
    fd: vec3<f64>,
    m1: vec3<f64>,
    m2: vec3<f64>,
}

// (force on the monomer, damping part of it, torque on it).
struct WallInteraction {
    f: vec3<f64>,
    fd: vec3<f64>,
    m: vec3<f64>,
}

fn law_damping() -> Damping {
    return Damping(params.damping_kind, params.damping_value);
}

// The pair as `centres` (engine/positions.wgsl) gives it: x1 − x2 and the overlap, which the
// mixed precision evaluates from split centres (the CPU twin takes x1 and x2).
fn pair_interaction(
    centres: PairCentres,
    v1: vec3<f64>,
    v2: vec3<f64>,
    n1: vec3<f64>,
    n2: vec3<f64>,
    twist: f64,
) -> PairInteraction {
    let k = params.pair;
    let d = centres.x1 - centres.x2;
    let distance = vec_length(d);
    let nc = d / distance;
    let x = jkr_contact_radius_ratio(centres.delta / k.delta0);
    let normal = nc * jkr_force(x, k.f_c);
    let coefficient = damping_coefficient(law_damping(), x * k.a0, params.e_star, params.poisson);
    let damping = nc * (-coefficient * vec_dot(v1 - v2, nc));

    let t = pair_tangential(nc, distance, n1, n2, twist);
    return PairInteraction(normal + damping + t.slide, damping, t.m1, t.m2);
}

// The rolling, sliding and twisting part of a pair contact's interaction, with the
// displacements it was made from: twin of pair_tangential in src/state/interaction.rs.
struct PairTangential {
    slide: vec3<f64>,
    m1: vec3<f64>,
    m2: vec3<f64>,
    xi: vec3<f64>,
    zeta: vec3<f64>,
}

fn pair_tangential(nc: vec3<f64>, distance: f64, n1: vec3<f64>, n2: vec3<f64>, twist: f64) -> PairTangential {
    let k = params.pair;
    let r = params.radius;
    let xi = rolling_displacement(n1, n2, k.reduced_radius);
    let zeta = sliding_displacement(n1, n2, nc, r, r);
    let slide = sliding_force(zeta, n1, n2, nc, r, r, distance, k.k_s);
    let twist_torque = twisting_torque(twist, nc, k.k_t);
    let torque1 = rolling_torque(n1, xi, k.reduced_radius, k.k_r)
        + sliding_torque(n1, zeta, r, k.k_s, 1.0lf)
        + twist_torque;
    let torque2 = rolling_torque(n2, xi, k.reduced_radius, k.k_r)
        + sliding_torque(n2, zeta, r, k.k_s, -1.0lf)
        - twist_torque;
    return PairTangential(slide, torque1, torque2, xi, zeta);
}

fn pair_contact_potential(centres: PairCentres, n1: vec3<f64>, n2: vec3<f64>, twist: f64) -> f64 {
    let k = params.pair;
    let r = params.radius;
    let d = centres.x1 - centres.x2;
    let distance = vec_length(d);
    let nc = d / distance;
    let delta = centres.delta;
    let xi = rolling_displacement(n1, n2, k.reduced_radius);
    let zeta = sliding_displacement(n1, n2, nc, r, r);
    return jkr_potential_at_overlap(delta / k.delta0, k.f_c, k.delta0)
        + rolling_potential(xi, k.k_r)
        + sliding_potential(zeta, k.k_s)
        + twisting_potential(twist, k.k_t);
}

// Potential plus half the work of the contact's conservative forces over the step just taken
// (see pair_step_energy in src/state/interaction.rs for why).
fn pair_step_energy(i: u32, j: u32, n1: vec3<f64>, n2: vec3<f64>, twist: f64) -> f64 {
    let centres = pair_centres(i, j);
    let v1 = velocity[i].xyz;
    let v2 = velocity[j].xyz;
    let it = pair_interaction(centres, v1, v2, n1, n2, twist);
    let work = vec_dot(it.f - it.fd, v1 - v2)
        + vec_dot(it.m1, angular_velocity[i].xyz)
        + vec_dot(it.m2, angular_velocity[j].xyz);
    return pair_contact_potential(centres, n1, n2, twist) + 0.5lf * params.dt * work;
}

// The part of a pair contact's step energy that an inelastic correction changes: the rolling,
// sliding and twisting potentials plus half the work of their force and torques over the step.
// Twin of pair_tangential_step_energy (and of the pair_frame it takes) in
// src/state/interaction.rs.
fn pair_tangential_step_energy(i: u32, j: u32, n1: vec3<f64>, n2: vec3<f64>, twist: f64) -> f64 {
    let k = params.pair;
    let centres = pair_centres(i, j);
    let d = centres.x1 - centres.x2;
    let distance = vec_length(d);
    let nc = d / distance;
    let v_rel = velocity[i].xyz - velocity[j].xyz;
    let t = pair_tangential(nc, distance, n1, n2, twist);
    let work = vec_dot(t.slide, v_rel)
        + vec_dot(t.m1, angular_velocity[i].xyz)
        + vec_dot(t.m2, angular_velocity[j].xyz);
    return rolling_potential(t.xi, k.k_r) + sliding_potential(t.zeta, k.k_s)
        + twisting_potential(twist, k.k_t) + 0.5lf * params.dt * work;
}

// The monomer in `frame` (engine/positions.wgsl): x, the wall as seen there and the overlap;
// `anchor` in the same frame (the CPU twin takes x and the wall in the box's frame).
fn wall_interaction(frame: WallFrame, v: vec3<f64>, n1: vec3<f64>, anchor: vec3<f64>, twist: f64) -> WallInteraction {
    let x = frame.x;
    let wall = frame.wall;
    let k = wall.k;
    let n = wall.normal.xyz;
    let x_ratio = jkr_contact_radius_ratio(frame.delta / k.delta0);
    let normal = n * jkr_force(x_ratio, k.f_c);
    let coefficient = damping_coefficient(law_damping(), x_ratio * k.a0, params.e_star, params.poisson);
    let damping = n * (-coefficient * vec_dot(v - wall.velocity.xyz, n));
    let t = wall_tangential(x, wall, n1, anchor, twist);
    return WallInteraction(normal + damping + t.slide, damping, t.m);
}

// The rolling, sliding and twisting part of a wall contact's interaction, with the
// displacements it was made from: twin of wall_tangential in src/state/interaction.rs.
struct WallTangential {
    slide: vec3<f64>,
    m: vec3<f64>,
    xi: vec3<f64>,
    zeta: vec3<f64>,
}

fn wall_tangential(x: vec3<f64>, wall: Wall, n1: vec3<f64>, anchor: vec3<f64>, twist: f64) -> WallTangential {
    let k = wall.k;
    let r = params.radius;
    let n = wall.normal.xyz;
    let xi = wall_rolling_displacement(n1, n, r);
    let zeta = wall_sliding_displacement(x, n1, r, anchor, n);
    let torque = rolling_torque(n1, xi, r, k.k_r)
        + sliding_torque(n1, zeta, r, k.k_s, 1.0lf)
        + twisting_torque(twist, n, k.k_t);
    return WallTangential(wall_sliding_force(zeta, k.k_s), torque, xi, zeta);
}

fn wall_contact_potential(frame: WallFrame, n1: vec3<f64>, anchor: vec3<f64>, twist: f64) -> f64 {
    let x = frame.x;
    let k = frame.wall.k;
    let r = params.radius;
    let n = frame.wall.normal.xyz;
    let delta = frame.delta;
    let xi = wall_rolling_displacement(n1, n, r);
    let zeta = wall_sliding_displacement(x, n1, r, anchor, n);
    return jkr_potential_at_overlap(delta / k.delta0, k.f_c, k.delta0)
        + rolling_potential(xi, k.k_r)
        + sliding_potential(zeta, k.k_s)
        + twisting_potential(twist, k.k_t);
}

fn wall_step_energy(i: u32, wall: Wall, n1: vec3<f64>, anchor: WallAnchor, twist: f64) -> f64 {
    // In the wall's frame (engine/positions.wgsl): the box's in the exact precision.
    let frame = wall_frame(i, wall);
    let p = anchor_into_frame(anchor, frame);
    let v = velocity[i].xyz;
    let it = wall_interaction(frame, v, n1, p, twist);
    let work = vec_dot(it.f - it.fd, v - wall.velocity.xyz) + vec_dot(it.m, angular_velocity[i].xyz);
    return wall_contact_potential(frame, n1, p, twist) + 0.5lf * params.dt * work;
}

// Wall analogue of pair_tangential_step_energy: twin of wall_tangential_step_energy in
// src/state/interaction.rs (in the wall's frame, as wall_step_energy).
fn wall_tangential_step_energy(i: u32, wall: Wall, n1: vec3<f64>, anchor: WallAnchor, twist: f64) -> f64 {
    let frame = wall_frame(i, wall);
    let p = anchor_into_frame(anchor, frame);
    let v = velocity[i].xyz;
    let k = wall.k;
    let t = wall_tangential(frame.x, wall, n1, p, twist);
    let work = vec_dot(t.slide, v - wall.velocity.xyz) + vec_dot(t.m, angular_velocity[i].xyz);
    return rolling_potential(t.xi, k.k_r) + sliding_potential(t.zeta, k.k_s)
        + twisting_potential(twist, k.k_t) + 0.5lf * params.dt * work;
}

// Whether a contact needs any inelastic correction (apply_inelastic_limits in
// engine/owner.wgsl): the tests that open
// the corrections in rolling_correction, sliding_correction and twisting_correction, on the
// contact as stored. If rolling needs none, sliding is tested on the same pointers as there; if
// it does, the owner is listed anyway. Tested before this step's events, which is the same:
// the events leave surviving contacts as they are, and a new contact starts with ξ = 0,
// twist 0 and |ζ| at rounding level.
fn beyond_limits(x1: vec3<f64>, x2: vec3<f64>, n1: vec3<f64>, n2: vec3<f64>, twist: f64) -> bool {
    let k = params.pair;
    let r = params.radius;
    let nc = vec_normalize(x1 - x2);
    let rolls = !(vec_length(n1 + n2) * k.reduced_radius <= k.xi_crit);
    let slides = !(vec_length(sliding_displacement(n1, n2, nc, r, r)) <= k.zeta_crit);
    let twists = abs(twist) > k.phi_crit;
    return rolls || slides || twists;
}

// The tests contacts_scan needs of one pair contact of owner `i`, on the positions, pointers
// and twist the contact events will see: whether it breaks (δ < −δ_c, as contact_events tests
// it) and whether it is beyond a limit, recorded in the owner's `pair_tests` bits.
fn test_pair_contact(i: u32, x1: vec3<f64>, x2: vec3<f64>, n1: vec3<f64>, n2: vec3<f64>, twist: f64) {
    let delta = 2.0lf * params.radius - vec_length(x1 - x2);
    var bits = select(0u, PAIR_TEST_BREAKS, delta < -params.pair.delta_c);
    bits |= select(0u, PAIR_TEST_BEYOND, beyond_limits(x1, x2, n1, n2, twist));
    if bits != 0u {
        atomicOr(&pair_tests[i], bits);
    }
}
