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
}

// x1 − x2 is all the law reads: the separation, with x2 at the origin. Whole voxels apart is
// exact in f32; the offsets' difference is rounded once.
fn pair_centres(i: u32, j: u32) -> PairCentres {
    let s = separation_between(split_of(j), split_of(i));
    return PairCentres(separation_vector(s), vec3<f32>(0.0f));
}

fn pair_overlap_of(i: u32, j: u32) -> f32 {
    let c = pair_centres(i, j);
    return 2.0f * params.radius - vec32_length(c.x1 - c.x2);
}

struct WallFrame {
    x: vec3<f32>,
    wall: Wall,
}

// x − point per axis: the voxel's corner less the point's high part is exact near the wall
// (two f32 within a factor two of each other, or a point at 0), then the fine parts.
fn wall_relative(p: SplitPosition, point: vec3<f32>, point_lo: vec3<f32>) -> vec3<f32> {
    let corner = vec3<f32>(p.voxel) * VOXEL;
    return (corner - point) + ((p.offset - point_lo) + p.offset_lo);
}

// The frame with its origin at the wall's point: the wall law sees x − point there.
fn wall_frame(i: u32, wall: Wall) -> WallFrame {
    var framed = wall;
    framed.point = vec4<f32>(0.0f);
    framed.point_lo = vec4<f32>(0.0f);
    return WallFrame(wall_relative(split_of(i), wall.point.xyz, wall.point_lo.xyz), framed);
}

// Anchors are stored in the box's frame (f32); into and out of the wall's.
fn anchor_into_frame(anchor: vec3<f32>, wall: Wall) -> vec3<f32> {
    return anchor - wall.point.xyz;
}

fn anchor_out_of_frame(anchor: vec3<f32>, wall: Wall) -> vec3<f32> {
    return anchor + wall.point.xyz;
}

fn wall_overlap_at(i: u32, point: vec3<f32>, point_lo: vec3<f32>, normal: vec3<f32>) -> f32 {
    let x = wall_relative(split_of(i), point, point_lo);
    return wall_overlap(x, vec3<f32>(0.0f), normal, params.radius);
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
