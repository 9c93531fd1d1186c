//! Four f64 lanes ([`F4`]) and three-vectors of them ([`V4`]): the arithmetic of four contacts
//! at once, for the contact law evaluated across contacts (`forces_lanes.rs`).
//!
//! Every operation is the IEEE operation of each lane, written out lane by lane so the compiler
//! turns it into one vector instruction where the target has them (AVX2: one 256-bit register;
//! SSE2: two 128-bit halves) and leaves the bits as they are: + − × ÷ √ are correctly rounded
//! in scalar and vector form alike, and nothing here fuses a multiply into an add. The
//! [`V4`] methods group their operations exactly as glam's `DVec3` does (`dot` as
//! (x·x′ + y·y′) + z·z′, `cross` as y·z′ − y′·z, ...), so a lane computes what the scalar
//! code computes for its contact, to the bit.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// Four f64 lanes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct F4(pub [f64; 4]);

/// Four booleans, one per lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct M4(pub [bool; 4]);

macro_rules! lanewise {
    ($a:expr, $b:expr, $op:tt) => {
        F4([
            $a.0[0] $op $b.0[0],
            $a.0[1] $op $b.0[1],
            $a.0[2] $op $b.0[2],
            $a.0[3] $op $b.0[3],
        ])
    };
}

macro_rules! binary {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F4 {
            type Output = F4;
            #[inline(always)]
            fn $method(self, rhs: F4) -> F4 {
                lanewise!(self, rhs, $op)
            }
        }
        impl $trait<f64> for F4 {
            type Output = F4;
            #[inline(always)]
            fn $method(self, rhs: f64) -> F4 {
                lanewise!(self, F4::splat(rhs), $op)
            }
        }
        impl $trait<F4> for f64 {
            type Output = F4;
            #[inline(always)]
            fn $method(self, rhs: F4) -> F4 {
                lanewise!(F4::splat(self), rhs, $op)
            }
        }
    };
}

binary!(Add, add, +);
binary!(Sub, sub, -);
binary!(Mul, mul, *);
binary!(Div, div, /);

impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        F4(self.0.map(|a| -a))
    }
}

impl F4 {
    #[inline(always)]
    pub fn splat(a: f64) -> F4 {
        F4([a; 4])
    }

    #[inline(always)]
    pub fn sqrt(self) -> F4 {
        F4([
            self.0[0].sqrt(),
            self.0[1].sqrt(),
            self.0[2].sqrt(),
            self.0[3].sqrt(),
        ])
    }

    /// `f64::max` per lane.
    #[inline(always)]
    pub fn max(self, b: f64) -> F4 {
        F4(self.0.map(|a| a.max(b)))
    }

    /// `f64::min` per lane.
    #[inline(always)]
    pub fn min(self, b: F4) -> F4 {
        F4([
            self.0[0].min(b.0[0]),
            self.0[1].min(b.0[1]),
            self.0[2].min(b.0[2]),
            self.0[3].min(b.0[3]),
        ])
    }

    #[inline(always)]
    pub fn le(self, b: F4) -> M4 {
        M4([
            self.0[0] <= b.0[0],
            self.0[1] <= b.0[1],
            self.0[2] <= b.0[2],
            self.0[3] <= b.0[3],
        ])
    }

    #[inline(always)]
    pub fn eq(self, b: F4) -> M4 {
        M4([
            self.0[0] == b.0[0],
            self.0[1] == b.0[1],
            self.0[2] == b.0[2],
            self.0[3] == b.0[3],
        ])
    }

    #[inline(always)]
    pub fn ge(self, b: F4) -> M4 {
        M4([
            self.0[0] >= b.0[0],
            self.0[1] >= b.0[1],
            self.0[2] >= b.0[2],
            self.0[3] >= b.0[3],
        ])
    }
}

impl M4 {
    /// Lane by lane, `a` where set, `b` where not.
    #[inline(always)]
    pub fn select(self, a: F4, b: F4) -> F4 {
        F4([
            if self.0[0] { a.0[0] } else { b.0[0] },
            if self.0[1] { a.0[1] } else { b.0[1] },
            if self.0[2] { a.0[2] } else { b.0[2] },
            if self.0[3] { a.0[3] } else { b.0[3] },
        ])
    }

    #[inline(always)]
    pub fn and_not(self, b: M4) -> M4 {
        M4([
            self.0[0] && !b.0[0],
            self.0[1] && !b.0[1],
            self.0[2] && !b.0[2],
            self.0[3] && !b.0[3],
        ])
    }

    #[inline(always)]
    pub fn any(self) -> bool {
        self.0[0] | self.0[1] | self.0[2] | self.0[3]
    }
}

/// A three-vector per lane: structure of arrays.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct V4 {
    pub x: F4,
    pub y: F4,
    pub z: F4,
}

impl V4 {
    /// Lane `k` holds `get(k)`.
    #[inline(always)]
    pub fn gather(get: impl Fn(usize) -> glam::DVec3) -> V4 {
        let v = [get(0), get(1), get(2), get(3)];
        V4 {
            x: F4([v[0].x, v[1].x, v[2].x, v[3].x]),
            y: F4([v[0].y, v[1].y, v[2].y, v[3].y]),
            z: F4([v[0].z, v[1].z, v[2].z, v[3].z]),
        }
    }

    /// Lane `k` as a `DVec3`.
    #[inline(always)]
    pub fn lane(&self, k: usize) -> glam::DVec3 {
        glam::DVec3::new(self.x.0[k], self.y.0[k], self.z.0[k])
    }

    #[inline(always)]
    pub fn dot(self, b: V4) -> F4 {
        (self.x * b.x) + (self.y * b.y) + (self.z * b.z)
    }

    #[inline(always)]
    pub fn cross(self, b: V4) -> V4 {
        V4 {
            x: self.y * b.z - b.y * self.z,
            y: self.z * b.x - b.z * self.x,
            z: self.x * b.y - b.x * self.y,
        }
    }

    #[inline(always)]
    pub fn length(self) -> F4 {
        self.dot(self).sqrt()
    }

    /// Each component times the lane's `s`.
    #[inline(always)]
    pub fn scale(self, s: F4) -> V4 {
        V4 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Each component divided by the lane's `s`.
    #[inline(always)]
    pub fn divide(self, s: F4) -> V4 {
        V4 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }

    /// Lane by lane, `a` where `mask` is set, `b` where not.
    #[inline(always)]
    pub fn select(mask: M4, a: V4, b: V4) -> V4 {
        V4 {
            x: mask.select(a.x, b.x),
            y: mask.select(a.y, b.y),
            z: mask.select(a.z, b.z),
        }
    }

    /// glam's `normalize`: times the reciprocal of the length.
    #[inline(always)]
    pub fn normalize(self) -> V4 {
        self.scale(1.0 / self.length())
    }

    /// Each component times `s`, the same in every lane.
    #[inline(always)]
    pub fn times(self, s: f64) -> V4 {
        V4 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

impl Add for V4 {
    type Output = V4;
    #[inline(always)]
    fn add(self, b: V4) -> V4 {
        V4 {
            x: self.x + b.x,
            y: self.y + b.y,
            z: self.z + b.z,
        }
    }
}

impl Sub for V4 {
    type Output = V4;
    #[inline(always)]
    fn sub(self, b: V4) -> V4 {
        V4 {
            x: self.x - b.x,
            y: self.y - b.y,
            z: self.z - b.z,
        }
    }
}
