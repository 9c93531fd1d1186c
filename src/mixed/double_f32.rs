//! Double-f32 numbers: an unevaluated sum hi + lo of two f32 with |lo| ≤ ulp(hi)/2, good to
//! about 2⁻⁴⁸ relative (Dekker 1971; Knuth's TwoSum). Every operation uses only f32 + and −,
//! which every GPU rounds correctly, so a WGSL twin gives the same bits where the driver keeps
//! the order (no reassociation).

/// hi + lo, with |lo| ≤ ulp(hi)/2 after every operation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DoubleF32 {
    pub hi: f32,
    pub lo: f32,
}

/// The exact sum a + b as (rounded sum, rounding error): Knuth's TwoSum, six operations, no
/// condition on the magnitudes.
pub fn two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    let b_virtual = s - a;
    let a_virtual = s - b_virtual;
    let b_error = b - b_virtual;
    let a_error = a - a_virtual;
    (s, a_error + b_error)
}

/// As [`two_sum`] where |a| ≥ |b| (or a = 0): three operations (Dekker's FastTwoSum).
pub fn fast_two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    (s, b - (s - a))
}

impl DoubleF32 {
    pub const ZERO: DoubleF32 = DoubleF32 { hi: 0.0, lo: 0.0 };

    /// The nearest double-f32 to `v` (hi the nearest f32, lo the nearest f32 to the rest).
    pub fn from_f64(v: f64) -> Self {
        let hi = v as f32;
        let lo = (v - f64::from(hi)) as f32;
        DoubleF32 { hi, lo }
    }

    pub fn to_f64(self) -> f64 {
        f64::from(self.hi) + f64::from(self.lo)
    }

    /// self + v for an f32 `v` (an accumulator's step).
    pub fn add_f32(self, v: f32) -> Self {
        let (s, e) = two_sum(self.hi, v);
        let (hi, lo) = fast_two_sum(s, e + self.lo);
        DoubleF32 { hi, lo }
    }

    /// self + other.
    pub fn add_double(self, other: DoubleF32) -> Self {
        let (s, e) = two_sum(self.hi, other.hi);
        let (hi, lo) = fast_two_sum(s, e + (self.lo + other.lo));
        DoubleF32 { hi, lo }
    }

    /// The nearest f32 to the value.
    pub fn to_f32(self) -> f32 {
        self.hi + self.lo
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_sum_is_exact() {
        // 1 + 2⁻³⁰: the sum rounds to 1, the error term holds 2⁻³⁰ exactly.
        let tiny = 2f32.powi(-30);
        assert_eq!(two_sum(1.0, tiny), (1.0, tiny));
        assert_eq!(two_sum(tiny, 1.0), (1.0, tiny));
        assert_eq!(fast_two_sum(1.0, tiny), (1.0, tiny));
        // 3 + 2⁻²³ is a tie (half an ulp of 3) and rounds to the even 3; the error term keeps it.
        let (s, e) = two_sum(3.0, 2f32.powi(-23));
        assert_eq!((s, e), (3.0, 2f32.powi(-23)));
        // 3 + 3·2⁻²³ rounds up to 3 + 2⁻²¹; the error term is −2⁻²³.
        let (s, e) = two_sum(3.0, 3.0 * 2f32.powi(-23));
        assert_eq!(f64::from(s) + f64::from(e), 3.0 + 3.0 * 2f64.powi(-23));
        assert_eq!(e, -(2f32.powi(-23)));
    }

    #[test]
    fn a_double_f32_holds_48_bits() {
        let v = std::f64::consts::PI * 1e-2;
        let d = DoubleF32::from_f64(v);
        assert!(((d.to_f64() - v) / v).abs() < 2f64.powi(-47), "{d:?}");
        assert_eq!(d.to_f32(), v as f32);
        assert!(d.lo.abs() <= d.hi.abs() * 2f32.powi(-24));
    }

    #[test]
    fn an_accumulator_of_small_steps_keeps_them() {
        // 10⁶ steps of 3·10⁻¹⁰ onto 10⁻²: plain f32 never moves (the step is a third of an
        // ulp), the double-f32 sum is right to its 48 bits.
        let (start, step, n) = (1e-2f64, 3e-10f32, 1_000_000);
        let mut plain = start as f32;
        let mut split = DoubleF32::from_f64(start);
        for _ in 0..n {
            plain += step;
            split = split.add_f32(step);
        }
        let exact = start + f64::from(step) * n as f64;
        assert_eq!(plain, start as f32, "plain f32 stands still");
        let moved = f64::from(step) * n as f64;
        assert!(((split.to_f64() - exact) / moved).abs() < 1e-6, "{split:?}");
        let both = DoubleF32::from_f64(start).add_double(DoubleF32::from_f64(moved));
        assert!(((both.to_f64() - exact) / exact).abs() < 2f64.powi(-46));
    }
}
