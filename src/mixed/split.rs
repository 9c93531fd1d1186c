//! Split positions: a voxel index (i32 per axis) and an f32 offset inside the voxel.
//!
//! The voxel edge is a power of two, so index × edge is exact in f32, and the offset (below one
//! edge) keeps 24 bits of a 9.5-nm length: 5.7·10⁻¹⁴ cm, a three-hundred-thousandth of the JKR
//! overlap scale δ₀, anywhere in a ±2 km box (i32 voxels). A pair's overlap is evaluated in
//! pieces that f32 holds exactly or nearly so (see [`pair_overlap`]); a plain f32 difference of
//! the two centres would round at ulp(2R) = 7.3·10⁻¹² cm, and plain f32 absolute positions at
//! ulp(box).
//!
//! Measured in `tests/precision_budget.rs`; the design is Chrono DEM-Engine's voxel-plus-offset
//! position (Zhang et al. 2024) with the overlap evaluated as a difference of squares.

use super::double_f32::{two_sum, DoubleF32};
use glam::{DVec3, IVec3, Vec3};

/// Voxel edge: 2⁻²⁰ cm ≈ 9.5 nm (a 63rd of a monomer radius of 0.6 µm).
pub const VOXEL: f32 = 1.0 / 1_048_576.0;

/// Largest |index difference| per axis for which [`pair_overlap`]'s sum of squared voxel
/// differences stays exact in f32 (3 k² < 2²⁴): pairs up to 2.2·10⁻³ cm apart, 18 radii.
pub const MAX_PAIR_VOXELS: i32 = 2364;

/// A position as voxel · [`VOXEL`] + offset + offset_lo. The offset is in [0, VOXEL] after
/// [`SplitPosition::advance`]; `offset_lo` (below half an ulp of the offset) keeps what the
/// offset's rounding dropped, so steps far below its ulp add up (see `advance`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplitPosition {
    pub voxel: IVec3,
    pub offset: Vec3,
    pub offset_lo: Vec3,
}

impl SplitPosition {
    /// The split form of `p` [cm]: the offset is the f32 nearest to the rest (error ≤ 2⁻⁴⁵ cm).
    pub fn from_f64(p: DVec3) -> Self {
        let edge = f64::from(VOXEL);
        let voxel = (p / edge).floor();
        let offset = p - voxel * edge;
        let hi = offset.as_vec3();
        SplitPosition {
            voxel: voxel.as_ivec3(),
            offset: hi,
            offset_lo: (offset - hi.as_dvec3()).as_vec3(),
        }
    }

    pub fn to_f64(self) -> DVec3 {
        self.voxel.as_dvec3() * f64::from(VOXEL)
            + self.offset.as_dvec3()
            + self.offset_lo.as_dvec3()
    }

    /// Moves by `dx` [cm] (an integration step, |dx| below a few voxels) and carries whole
    /// voxels from the offset to the index.
    ///
    /// The offset and `offset_lo` form a double-f32 per axis: a plain f32 offset would round
    /// every step by the same fraction of its ulp while the velocity holds (a monomer at
    /// 1 cm/s drifts 0.08 δ₀ from its f64 track in 10⁵ steps), the pair keeps each step to 2⁻⁴⁸.
    /// The carry moves k·VOXEL (exact in f32) from the offset to the index with TwoSum, so
    /// nothing of the offset is lost either.
    pub fn advance(&mut self, dx: Vec3) {
        for axis in 0..3 {
            let sum = DoubleF32 {
                hi: self.offset[axis],
                lo: self.offset_lo[axis],
            }
            .add_f32(dx[axis]);
            let carry = (sum.hi / VOXEL).floor();
            let (kept, dropped) = two_sum(sum.hi, -carry * VOXEL);
            let (hi, lo) = two_sum(kept, dropped + sum.lo);
            self.voxel[axis] += carry as i32;
            self.offset[axis] = hi;
            self.offset_lo[axis] = lo;
        }
    }
}

/// The separation b − a of two split positions as an exact coarse part (whole voxels) and a
/// fine part (the offsets' difference, below two voxels per axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Separation {
    pub coarse: Vec3,
    pub fine: Vec3,
}

impl Separation {
    pub fn between(a: &SplitPosition, b: &SplitPosition) -> Self {
        let k = b.voxel - a.voxel;
        debug_assert!(
            k.abs().max_element() <= MAX_PAIR_VOXELS,
            "pair too far apart: {k}"
        );
        Separation {
            coarse: k.as_vec3() * VOXEL,
            fine: b.offset - a.offset,
        }
    }

    /// The separation as one f32 vector (its direction is all a contact normal needs).
    pub fn vector(&self) -> Vec3 {
        self.coarse + self.fine
    }
}

/// Overlap 2R − |r| [cm] of spheres whose contact distance is 2R, from the separation r and
/// (2R)² as a double-f32 (host-computed in f64).
///
/// |r|² − (2R)² = (Σc² − (2R)²) + Σ(2c + f)·f with c the coarse and f the fine part. Σc² is a
/// sum of integers times VOXEL², exact; it is within a few percent of (2R)² for a pair near
/// contact, so its difference with (2R)²'s high part is exact too (Sterbenz). The rest is a sum
/// of terms 10⁴ times smaller than |r|², each rounded once. Dividing by |r| + 2R (only needed
/// to 10⁻⁷) gives the overlap to about 10⁻¹³ cm.
pub fn pair_overlap(separation: &Separation, two_r: f32, two_r_squared: DoubleF32) -> f32 {
    let c = separation.coarse;
    let f = separation.fine;
    let head = (c.dot(c) - two_r_squared.hi) - two_r_squared.lo;
    let tail = (2.0 * c + f).dot(f);
    let excess = head + tail;
    let distance = separation.vector().length();
    -excess / (distance + two_r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_voxel_is_two_to_the_minus_twenty_centimetres() {
        assert_eq!(f64::from(VOXEL), 2f64.powi(-20));
        // 3k² < 2²⁴ at the limit, not one voxel beyond.
        let sq = |k: i32| 3 * i64::from(k) * i64::from(k);
        assert!(sq(MAX_PAIR_VOXELS) < 1 << 24 && sq(MAX_PAIR_VOXELS + 1) >= 1 << 24);
    }

    #[test]
    fn a_split_position_round_trips_to_its_offset_resolution() {
        for p in [
            DVec3::new(0.0, 1e-2, -3.3e-3),
            DVec3::new(12.345_678_9, -0.002, 1.0 / 3.0),
        ] {
            let s = SplitPosition::from_f64(p);
            assert!(
                (s.to_f64() - p).abs().max_element() <= 2f64.powi(-45),
                "{p} {s:?}"
            );
            assert!(s.offset.min_element() >= 0.0 && s.offset.max_element() < VOXEL);
        }
    }

    #[test]
    fn advancing_carries_whole_voxels() {
        let start = DVec3::new(1e-2, 2e-3, -5e-3);
        let mut s = SplitPosition::from_f64(start);
        let step = Vec3::new(3.7e-7, -2.5 * VOXEL, 1e-12);
        for _ in 0..1000 {
            s.advance(step);
            assert!(
                s.offset.min_element() >= 0.0 && s.offset.max_element() <= VOXEL,
                "{s:?}"
            );
        }
        let moved = s.to_f64() - start;
        let expected = step.as_dvec3() * 1000.0;
        // Each step rounds the double-f32 offset once: 2⁻⁶⁸ cm, far below this bound.
        assert!((moved - expected).abs().max_element() <= 1e-18, "{moved}");
    }

    #[test]
    fn the_overlap_of_touching_spheres_is_resolved_far_below_delta0() {
        // Centres 2R − δ apart along a skew direction, δ = 1.7e-9 cm (δ₀/10), far from the origin.
        let (r, delta) = (0.6e-4f64, 1.7e-9f64);
        let dir = DVec3::new(0.3, -0.8, 0.52).normalize();
        let a = DVec3::new(4.1e-3, 7.7e-3, 2.9e-3);
        let b = a + dir * (2.0 * r - delta);
        let (sa, sb) = (SplitPosition::from_f64(a), SplitPosition::from_f64(b));
        let two_r = (2.0 * r) as f32;
        let got = pair_overlap(
            &Separation::between(&sa, &sb),
            two_r,
            DoubleF32::from_f64(4.0 * r * r),
        );
        assert!((f64::from(got) - delta).abs() < 1e-13, "{got} for {delta}");
    }
}
