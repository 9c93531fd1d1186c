// requires: bindings wall split double_f32 math32
//
// shaders/engine/positions.wgsl in the mixed precision, the same functions. `position` holds
// each centre's offset in its voxel, `position_voxel` the voxel and `position_lo` the offset's
// low part (src/mixed/split.rs); a wall's point is the double-f32 point + point_lo. Pairs and
// walls reach the contact law in frames where their differences are exact or rounded once in
// f32, never the f32 rounding of a coordinate (DESIGN.md, "Precision").

fn split_of(i: u32) -> SplitPosition {
    return SplitPosition(position_voxel[i].xyz, position[i].xyz, position_lo[i].xyz);
}

fn split_to_f32(p: SplitPosition) -> vec3<f32> {
    return vec3<f32>(p.voxel) * VOXEL + (p.offset + p.offset_lo);
}

fn centre(i: u32) -> vec3<f32> {
    return split_to_f32(split_of(i));
}

struct PairCentres {
    x1: vec3<f32>,
    x2: vec3<f32>,
    delta: f32,
}

// The law reads x1 − x2 (the separation, with x2 at the origin: whole voxels apart is exact in
// f32, the offsets' difference rounded once) and the overlap, from the split parts and the
// double-f32 (2r)² (pair_overlap: 10⁻⁵ δ₀ where a rounded separation gives 10⁻³).
fn pair_centres(i: u32, j: u32) -> PairCentres {
    let s = separation_between(split_of(j), split_of(i));
    let two_r_squared = DoubleF32(params.two_r_squared, params.two_r_squared_lo);
    let delta = pair_overlap(s, 2.0f * params.radius, two_r_squared);
    return PairCentres(separation_vector(s), vec3<f32>(0.0f), delta);
}

fn pair_overlap_of(i: u32, j: u32) -> f32 {
    return pair_centres(i, j).delta;
}

// The frame of a monomer's own voxel corner (`origin`): its centre, the anchors of its wall
// contacts and the wall's point along the normal are all small numbers there.
struct WallFrame {
    x: vec3<f32>,
    wall: Wall,
    delta: f32,
    origin: vec3<f32>,
}

// x − point per axis: the voxel's corner less the point's high part is exact near the wall
// (two f32 within a factor two of each other, or a point at 0), then the fine parts.
fn wall_relative(p: SplitPosition, point: vec3<f32>, point_lo: vec3<f32>) -> vec3<f32> {
    let corner = vec3<f32>(p.voxel) * VOXEL;
    return (corner - point) + ((p.offset - point_lo) + p.offset_lo);
}

// r − (x − point)·n in pieces: r's high part less the coarse distance (exact for an axis
// normal: two f32 within a factor two), then the fine distance and r's low part, each small.
fn wall_overlap_split(p: SplitPosition, point: vec3<f32>, point_lo: vec3<f32>, normal: vec3<f32>) -> f32 {
    let coarse = vec3<f32>(p.voxel) * VOXEL - point;
    let fine = (p.offset - point_lo) + p.offset_lo;
    return ((params.radius - vec32_dot(coarse, normal)) - vec32_dot(fine, normal)) + params.radius_lo;
}

fn wall_frame(i: u32, wall: Wall) -> WallFrame {
    let p = split_of(i);
    let origin = vec3<f32>(p.voxel) * VOXEL;
    var framed = wall;
    // Only its normal component is read (the overlap itself is `delta`).
    framed.point = vec4<f32>((wall.point.xyz - origin) + wall.point_lo.xyz, 0.0f);
    framed.point_lo = vec4<f32>(0.0f);
    let delta = wall_overlap_split(p, wall.point.xyz, wall.point_lo.xyz, wall.normal.xyz);
    return WallFrame(p.offset + p.offset_lo, framed, delta, origin);
}

// Anchors are stored in the box's frame as double-f32; into the frame, the high part less the
// origin is exact (both within a few radii of each other), and back, TwoSum keeps all of it.
fn anchor_into_frame(anchor: WallAnchor, frame: WallFrame) -> vec3<f32> {
    return (anchor.p - frame.origin) + anchor.p_lo;
}

fn anchor_out_of_frame(anchor: vec3<f32>, frame: WallFrame) -> WallAnchor {
    var out = WallAnchor(vec3<f32>(0.0f), vec3<f32>(0.0f));
    for (var axis = 0u; axis < 3u; axis++) {
        let s = two_sum(frame.origin[axis], anchor[axis]);
        out.p[axis] = s.x;
        out.p_lo[axis] = s.y;
    }
    return out;
}

fn wall_overlap_at(i: u32, point: vec3<f32>, point_lo: vec3<f32>, normal: vec3<f32>) -> f32 {
    return wall_overlap_split(split_of(i), point, point_lo, normal);
}

// The step added to the offset as a double-f32 with whole voxels carried to the index
// (split_position_advance): a step far below the offset's ulp still adds up.
fn drift_centre(i: u32) -> vec3<f32> {
    let p = split_position_advance(split_of(i), velocity[i].xyz * params.dt);
    position_voxel[i] = vec4<i32>(p.voxel, 0);
    position[i] = vec4<f32>(p.offset, 0.0f);
    position_lo[i] = vec4<f32>(p.offset_lo, 0.0f);
    return split_to_f32(p);
}

// The point as a double-f32 per axis: a wall at 1 cm/s moves 3·10⁻¹⁰ cm per step, below
// half an ulp of a coordinate of 0.01 cm, so an f32 point would not move at all.
fn drift_wall(w: u32) {
    let wall = moving_walls[w];
    let step = wall.velocity.xyz * params.dt;
    var point = wall.point.xyz;
    var lo = wall.point_lo.xyz;
    for (var axis = 0u; axis < 3u; axis++) {
        let sum = double_f32_add_f32(DoubleF32(point[axis], lo[axis]), step[axis]);
        point[axis] = sum.hi;
        lo[axis] = sum.lo;
    }
    moving_walls[w].point = vec4<f32>(point, 0.0f);
    moving_walls[w].point_lo = vec4<f32>(lo, 0.0f);
}
