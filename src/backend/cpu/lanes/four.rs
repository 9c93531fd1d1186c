//! Four f64 lanes ([`F4`]) and three-vectors of them ([`V4`]): the arithmetic of four contacts
//! at once, for the contact law evaluated across contacts (law/forces_lanes.rs).
//!
//! Every operation is the IEEE operation of each lane: + − × ÷ √ are correctly rounded in
//! scalar and vector form alike, and nothing here fuses a multiply into an add. The [`V4`]
//! methods group their operations exactly as glam's `DVec3` does (`dot` as (x·x′ + y·y′) +
//! z·z′, `cross` as y·z′ − y′·z, ...), so a lane computes what the scalar code computes for its
//! contact, to the bit.
//!
//! The instruction set is a type parameter ([`Isa`]): [`Portable`] writes each operation out
//! lane by lane for the compiler to vectorise as it can; [`Avx2`] issues one 256-bit
//! instruction per operation. Left to itself the compiler turned the lane code of an AVX2
//! function into mostly 128-bit and scalar instructions (of the integrate pass's square
//! roots, none 256-bit), so the AVX2 path says what it wants.

use std::marker::PhantomData;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// How the lanes' operations are issued. Every method gives each lane's IEEE result, whatever
/// the implementation.
pub trait Isa: Copy + Default + std::fmt::Debug + PartialEq + Send + Sync + 'static {
    #[inline(always)]
    fn add(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
    }
    #[inline(always)]
    fn sub(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3]]
    }
    #[inline(always)]
    fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        [a[0] * b[0], a[1] * b[1], a[2] * b[2], a[3] * b[3]]
    }
    #[inline(always)]
    fn div(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        [a[0] / b[0], a[1] / b[1], a[2] / b[2], a[3] / b[3]]
    }
    #[inline(always)]
    fn sqrt(a: [f64; 4]) -> [f64; 4] {
        [a[0].sqrt(), a[1].sqrt(), a[2].sqrt(), a[3].sqrt()]
    }
    /// `a <= b` per lane (false where either is NaN), as a mask.
    #[inline(always)]
    fn cmp_le(a: [f64; 4], b: [f64; 4]) -> [u64; 4] {
        std::array::from_fn(|l| mask(a[l] <= b[l]))
    }
    /// `a == b` per lane (false where either is NaN), as a mask.
    #[inline(always)]
    fn cmp_eq(a: [f64; 4], b: [f64; 4]) -> [u64; 4] {
        std::array::from_fn(|l| mask(a[l] == b[l]))
    }
    /// `a >= b` per lane (false where either is NaN), as a mask.
    #[inline(always)]
    fn cmp_ge(a: [f64; 4], b: [f64; 4]) -> [u64; 4] {
        std::array::from_fn(|l| mask(a[l] >= b[l]))
    }
    /// `a` where `m` is set, `b` where not, bit for bit.
    #[inline(always)]
    fn select(m: [u64; 4], a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        std::array::from_fn(|l| f64::from_bits((a[l].to_bits() & m[l]) | (b[l].to_bits() & !m[l])))
    }
}

/// Each operation written out lane by lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Portable;

impl Isa for Portable {}

/// One AVX instruction per operation (`vaddpd`, `vsqrtpd`, `vcmppd` with the ordered, quiet
/// predicates of Rust's comparisons, `vblendvpd` on all-or-nothing masks).
///
/// Only code that runs where the processor has AVX2 may use it: inside the `#[target_feature
/// (enable = "avx2")]` functions of the lane passes, which check `is_x86_feature_detected!`
/// first (`in_lanes!`, lanes/mod.rs). Its methods are safe to name but not to run elsewhere,
/// so the type, and every function generic over [`Isa`], stay private to the crate: public
/// code reaches AVX2 only through the passes' entry points, which take a `ContactLanes` and
/// check the processor.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Avx2;

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{Avx2, Isa};
    use std::arch::x86_64::*;

    #[inline(always)]
    fn load(a: [f64; 4]) -> __m256d {
        // SAFETY: `Avx2` runs only where AVX2 is (see its docs); the array is 4 f64.
        unsafe { _mm256_loadu_pd(a.as_ptr()) }
    }

    #[inline(always)]
    fn store(v: __m256d) -> [f64; 4] {
        let mut out = [0.0; 4];
        // SAFETY: as in `load`.
        unsafe { _mm256_storeu_pd(out.as_mut_ptr(), v) };
        out
    }

    #[inline(always)]
    fn mask_bits(v: __m256d) -> [u64; 4] {
        store(v).map(f64::to_bits)
    }

    #[inline(always)]
    fn bits_mask(m: [u64; 4]) -> __m256d {
        load(m.map(f64::from_bits))
    }

    // SAFETY (every block below): `Avx2` runs only where AVX2 is (see its docs).
    impl Isa for Avx2 {
        #[inline(always)]
        fn add(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
            store(unsafe { _mm256_add_pd(load(a), load(b)) })
        }
        #[inline(always)]
        fn sub(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
            store(unsafe { _mm256_sub_pd(load(a), load(b)) })
        }
        #[inline(always)]
        fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
            store(unsafe { _mm256_mul_pd(load(a), load(b)) })
        }
        #[inline(always)]
        fn div(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
            store(unsafe { _mm256_div_pd(load(a), load(b)) })
        }
        #[inline(always)]
        fn sqrt(a: [f64; 4]) -> [f64; 4] {
            store(unsafe { _mm256_sqrt_pd(load(a)) })
        }
        #[inline(always)]
        fn cmp_le(a: [f64; 4], b: [f64; 4]) -> [u64; 4] {
            mask_bits(unsafe { _mm256_cmp_pd::<_CMP_LE_OQ>(load(a), load(b)) })
        }
        #[inline(always)]
        fn cmp_eq(a: [f64; 4], b: [f64; 4]) -> [u64; 4] {
            mask_bits(unsafe { _mm256_cmp_pd::<_CMP_EQ_OQ>(load(a), load(b)) })
        }
        #[inline(always)]
        fn cmp_ge(a: [f64; 4], b: [f64; 4]) -> [u64; 4] {
            mask_bits(unsafe { _mm256_cmp_pd::<_CMP_GE_OQ>(load(a), load(b)) })
        }
        #[inline(always)]
        fn select(m: [u64; 4], a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
            // The masks are all ones or all zeros per lane, so the sign bit picks the lane.
            store(unsafe { _mm256_blendv_pd(load(b), load(a), bits_mask(m)) })
        }
    }
}

/// All bits where `b`, none where not.
#[inline(always)]
fn mask(b: bool) -> u64 {
    (b as u64).wrapping_neg()
}

/// Four f64 lanes, aligned as one 256-bit register, operated on by `S`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct F4<S: Isa>(pub [f64; 4], PhantomData<S>);

/// A mask per lane, all 64 bits set or none, as vector comparisons leave them: selecting with
/// it is a bitwise blend.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct M4<S: Isa>(pub [u64; 4], PhantomData<S>);

macro_rules! binary {
    ($trait:ident, $method:ident) => {
        impl<S: Isa> $trait for F4<S> {
            type Output = F4<S>;
            #[inline(always)]
            fn $method(self, rhs: F4<S>) -> F4<S> {
                F4::new(S::$method(self.0, rhs.0))
            }
        }
        impl<S: Isa> $trait<f64> for F4<S> {
            type Output = F4<S>;
            #[inline(always)]
            fn $method(self, rhs: f64) -> F4<S> {
                F4::new(S::$method(self.0, [rhs; 4]))
            }
        }
        impl<S: Isa> $trait<F4<S>> for f64 {
            type Output = F4<S>;
            #[inline(always)]
            fn $method(self, rhs: F4<S>) -> F4<S> {
                F4::new(S::$method([self; 4], rhs.0))
            }
        }
    };
}

binary!(Add, add);
binary!(Sub, sub);
binary!(Mul, mul);
binary!(Div, div);

impl<S: Isa> Neg for F4<S> {
    type Output = F4<S>;
    #[inline(always)]
    fn neg(self) -> F4<S> {
        F4::new(self.0.map(|a| -a))
    }
}

impl<S: Isa> F4<S> {
    #[inline(always)]
    pub fn new(lanes: [f64; 4]) -> F4<S> {
        F4(lanes, PhantomData)
    }

    #[inline(always)]
    pub fn splat(a: f64) -> F4<S> {
        F4::new([a; 4])
    }

    #[inline(always)]
    pub fn sqrt(self) -> F4<S> {
        F4::new(S::sqrt(self.0))
    }

    /// `f64::max` per lane (its NaN rule, lane by lane: rare, in the Newton start and steps).
    #[inline(always)]
    pub fn max(self, b: f64) -> F4<S> {
        F4::new(self.0.map(|a| a.max(b)))
    }

    /// `f64::min` per lane (as `max`).
    #[inline(always)]
    pub fn min(self, b: F4<S>) -> F4<S> {
        F4::new(std::array::from_fn(|l| self.0[l].min(b.0[l])))
    }

    #[inline(always)]
    pub fn le(self, b: F4<S>) -> M4<S> {
        M4(S::cmp_le(self.0, b.0), PhantomData)
    }

    #[inline(always)]
    pub fn eq(self, b: F4<S>) -> M4<S> {
        M4(S::cmp_eq(self.0, b.0), PhantomData)
    }

    #[inline(always)]
    pub fn ge(self, b: F4<S>) -> M4<S> {
        M4(S::cmp_ge(self.0, b.0), PhantomData)
    }
}

impl<S: Isa> M4<S> {
    /// Every lane set.
    pub const ALL: M4<S> = M4([u64::MAX; 4], PhantomData);

    /// Lane by lane, `a` where set, `b` where not.
    #[inline(always)]
    pub fn select(self, a: F4<S>, b: F4<S>) -> F4<S> {
        F4::new(S::select(self.0, a.0, b.0))
    }

    #[inline(always)]
    pub fn and_not(self, b: M4<S>) -> M4<S> {
        M4(std::array::from_fn(|l| self.0[l] & !b.0[l]), PhantomData)
    }

    #[inline(always)]
    pub fn any(self) -> bool {
        (self.0[0] | self.0[1] | self.0[2] | self.0[3]) != 0
    }
}

/// A three-vector per lane: structure of arrays.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct V4<S: Isa> {
    pub x: F4<S>,
    pub y: F4<S>,
    pub z: F4<S>,
}

impl<S: Isa> V4<S> {
    /// Lane `k` holds `get(k)`.
    #[inline(always)]
    pub fn gather(get: impl Fn(usize) -> glam::DVec3) -> V4<S> {
        let v = [get(0), get(1), get(2), get(3)];
        V4 {
            x: F4::new([v[0].x, v[1].x, v[2].x, v[3].x]),
            y: F4::new([v[0].y, v[1].y, v[2].y, v[3].y]),
            z: F4::new([v[0].z, v[1].z, v[2].z, v[3].z]),
        }
    }

    /// Lane `k` as a `DVec3`.
    #[inline(always)]
    pub fn lane(&self, k: usize) -> glam::DVec3 {
        glam::DVec3::new(self.x.0[k], self.y.0[k], self.z.0[k])
    }

    #[inline(always)]
    pub fn dot(self, b: V4<S>) -> F4<S> {
        (self.x * b.x) + (self.y * b.y) + (self.z * b.z)
    }

    #[inline(always)]
    pub fn cross(self, b: V4<S>) -> V4<S> {
        V4 {
            x: self.y * b.z - b.y * self.z,
            y: self.z * b.x - b.z * self.x,
            z: self.x * b.y - b.x * self.y,
        }
    }

    #[inline(always)]
    pub fn length(self) -> F4<S> {
        self.dot(self).sqrt()
    }

    /// Each component times the lane's `s`.
    #[inline(always)]
    pub fn scale(self, s: F4<S>) -> V4<S> {
        V4 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Each component divided by the lane's `s`.
    #[inline(always)]
    pub fn divide(self, s: F4<S>) -> V4<S> {
        V4 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }

    /// Lane by lane, `a` where `mask` is set, `b` where not.
    #[inline(always)]
    pub fn select(mask: M4<S>, a: V4<S>, b: V4<S>) -> V4<S> {
        V4 {
            x: mask.select(a.x, b.x),
            y: mask.select(a.y, b.y),
            z: mask.select(a.z, b.z),
        }
    }

    /// glam's `normalize`: times the reciprocal of the length.
    #[inline(always)]
    pub fn normalize(self) -> V4<S> {
        self.scale(1.0 / self.length())
    }

    /// Each component times `s`, the same in every lane.
    #[inline(always)]
    pub fn times(self, s: f64) -> V4<S> {
        V4 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

impl<S: Isa> Add for V4<S> {
    type Output = V4<S>;
    #[inline(always)]
    fn add(self, b: V4<S>) -> V4<S> {
        V4 {
            x: self.x + b.x,
            y: self.y + b.y,
            z: self.z + b.z,
        }
    }
}

impl<S: Isa> Sub for V4<S> {
    type Output = V4<S>;
    #[inline(always)]
    fn sub(self, b: V4<S>) -> V4<S> {
        V4 {
            x: self.x - b.x,
            y: self.y - b.y,
            z: self.z - b.z,
        }
    }
}
