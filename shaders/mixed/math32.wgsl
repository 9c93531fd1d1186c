// f32 vector helpers in glam's Vec3 operation order (the twin of the f32 code in src/mixed/,
// as math.wgsl is of DVec3): same operations, same order, same last bit where the driver
// keeps the order.

// Vec3::dot: (x·x') + (y·y') + (z·z').
fn vec32_dot(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return (a.x * b.x) + (a.y * b.y) + (a.z * b.z);
}

fn vec32_length_squared(a: vec3<f32>) -> f32 {
    return vec32_dot(a, a);
}

fn vec32_length(a: vec3<f32>) -> f32 {
    return sqrt(vec32_dot(a, a));
}

// Vec3::cross.
fn vec32_cross(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        a.y * b.z - b.y * a.z,
        a.z * b.x - b.z * a.x,
        a.x * b.y - b.x * a.y,
    );
}
