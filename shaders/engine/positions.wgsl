// requires: bindings wall
//
// Where the monomers and the walls are, as the passes read and move them. In the exact
// precision (this file) centres and wall points are f64 and every function is the CPU
// reference's arithmetic, unchanged. The mixed precision assembles
// shaders/mixed_engine/positions.wgsl in its place: the same functions on split centres and
// double-f32 wall points (DESIGN.md, "Precision").

// Centre of monomer i (cells, candidate lists, rows).
fn centre(i: u32) -> vec3<f64> {
    return position[i].xyz;
}

// The centres of a pair as the contact law takes them: it reads x1 − x2 for the direction and
// `delta`, the overlap 2r − |x1 − x2|.
struct PairCentres {
    x1: vec3<f64>,
    x2: vec3<f64>,
    delta: f64,
}

fn pair_centres(i: u32, j: u32) -> PairCentres {
    let x1 = position[i].xyz;
    let x2 = position[j].xyz;
    return PairCentres(x1, x2, 2.0lf * params.radius - vec_length(x1 - x2));
}

fn pair_overlap_of(i: u32, j: u32) -> f64 {
    return pair_centres(i, j).delta;
}

// A monomer and a wall as the wall law takes them. The law reads x − point and x − anchor (an
// anchor is a point on the wall), so a frame with its origin elsewhere changes only rounding;
// here the frame is the box's and the anchors pass unchanged.
struct WallFrame {
    x: vec3<f64>,
    wall: Wall,
    // The overlap r − (x − point)·normal.
    delta: f64,
}

fn wall_frame(i: u32, wall: Wall) -> WallFrame {
    let x = position[i].xyz;
    return WallFrame(x, wall, wall_overlap(x, wall.point.xyz, wall.normal.xyz, params.radius));
}

fn anchor_into_frame(anchor: WallAnchor, frame: WallFrame) -> vec3<f64> {
    return anchor.p;
}

fn anchor_out_of_frame(anchor: vec3<f64>, frame: WallFrame) -> WallAnchor {
    return WallAnchor(anchor);
}

// Overlap of monomer i with the wall through `point` (low part `point_lo`, unused here) along
// `normal`; only these fields are passed, so a caller may read them from a uniform alone.
fn wall_overlap_at(i: u32, point: vec3<f64>, point_lo: vec3<f64>, normal: vec3<f64>) -> f64 {
    return wall_overlap(position[i].xyz, point, normal, params.radius);
}

// Moves monomer i by its velocity over one step; its new centre.
fn drift_centre(i: u32) -> vec3<f64> {
    let x = position[i].xyz + velocity[i].xyz * params.dt;
    position[i] = vec4<f64>(x, 0.0lf);
    return x;
}

// Moves wall w by its velocity over one step.
fn drift_wall(w: u32) {
    let wall = moving_walls[w];
    moving_walls[w].point = vec4<f64>(wall.point.xyz + wall.velocity.xyz * params.dt, 0.0lf);
}
