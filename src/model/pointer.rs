//! Contact pointers: unit vectors fixed in their monomer, turned by its rotation.

use glam::DVec3;

/// Turns `n` by the rotation vector `w` (axis w/|w|, angle |w|) and renormalises.
///
/// sin and cos come from their Taylor series (to θ¹¹ and θ¹⁰), exact to rounding for the angles a
/// stable step produces (|w| ≲ 0.3; a stable step turns by ≲ 0.01), because f64 transcendental
/// builtins are unreliable on some GPU drivers; the GPU twin uses the same polynomial.
pub fn rotate_pointer(n: DVec3, w: DVec3) -> DVec3 {
    let t2 = w.length_squared();
    if t2 == 0.0 {
        return n;
    }
    // sin(θ)/θ and (1 − cos θ)/θ² as polynomials in θ², with the reciprocals 1/6, 1/20, …
    // written out (the f64 nearest to each; a multiplication costs a fraction of a division).
    let sinc = 1.0
        - t2 * 0.16666666666666666
            * (1.0
                - t2 * 0.05
                    * (1.0
                        - t2 * 0.023809523809523808
                            * (1.0
                                - t2 * 0.013888888888888888 * (1.0 - t2 * 0.00909090909090909))));
    let cosc = 0.5
        * (1.0
            - t2 * 0.08333333333333333
                * (1.0
                    - t2 * 0.03333333333333333
                        * (1.0 - t2 * 0.017857142857142856 * (1.0 - t2 * 0.011111111111111112))));
    let cos = 1.0 - t2 * cosc;
    let rotated = n * cos + w.cross(n) * sinc + w * (w.dot(n) * cosc);
    rotated.normalize()
}

#[cfg(test)]
mod reciprocal_tests {
    /// The literals in `rotate_pointer` (and its WGSL twin) are the correctly rounded 1/k.
    #[test]
    fn the_written_out_reciprocals_are_the_nearest_f64() {
        let written = [
            (6.0, 0.16666666666666666),
            (20.0, 0.05),
            (42.0, 0.023809523809523808),
            (72.0, 0.013888888888888888),
            (110.0, 0.00909090909090909),
            (12.0, 0.08333333333333333),
            (30.0, 0.03333333333333333),
            (56.0, 0.017857142857142856),
            (90.0, 0.011111111111111112),
        ];
        for (k, r) in written {
            assert_eq!(1.0 / k, r, "1/{k}");
        }
        let source = include_str!("pointer.rs");
        let shader = include_str!("../../shaders/model/pointer.wgsl");
        let lanes = include_str!("../backend/cpu/law/integrate_lanes.rs");
        for (_, r) in written {
            let literal = format!("{r:?}");
            assert!(source.contains(&format!("t2 * {literal}")), "{literal}");
            assert!(
                lanes.contains(&format!("t2 * {literal}")),
                "{literal} in lanes"
            );
            assert!(
                shader.contains(&format!("t2 * {literal}lf")),
                "{literal} in WGSL"
            );
        }
    }
}
