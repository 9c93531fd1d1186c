//! `integrate_pairs` four contacts at a time: the lane twin of `integrate_pair_contact`
//! (integrate.rs), of `rotate_pointer` (model/pointer.rs) and of the tests `test_pair_contact`
//! and `beyond_limits` make (state/interaction.rs).
//!
//! As in forces_lanes.rs, each lane does its contact's scalar operations in the scalar order
//! (lanes.rs), so pointers, twist and tests are the scalar code's bits; a pointer whose
//! monomer does not spin is kept as it is, as the scalar code returns it.

use super::forces_lanes::{ContactLanes, OwnerChunk};
use super::integrate::integrate_pair_contact;
#[cfg(target_arch = "x86_64")]
use super::lanes::Avx2;
use super::lanes::{Isa, Portable, F4, V4};
use crate::backend::script::{PAIR_TEST_BEYOND, PAIR_TEST_BREAKS};
use crate::model::ContactLaw;
use crate::state::{Monomers, PairContact};

/// `integrate_pairs`' chunk of owners: it advances the rows in place.
pub type PairChunk<'a> = OwnerChunk<'a, &'a mut [PairContact]>;

/// The chunk's pair contacts advanced and tested, `lanes` wide; `tests[k]` gets owner k's
/// tests.
pub fn chunk_pairs(
    lanes: ContactLanes,
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    chunk: PairChunk,
    tests: &mut [u32],
) {
    match lanes {
        ContactLanes::Scalar => chunk_scalar(law, dt, m, chunk, tests),
        ContactLanes::Portable => chunk_in_lanes::<Portable>(law, dt, m, chunk, tests),
        #[cfg(target_arch = "x86_64")]
        ContactLanes::Avx2 => {
            assert!(std::arch::is_x86_feature_detected!("avx2"));
            // SAFETY: the processor has AVX2 (checked above).
            unsafe { chunk_avx2(law, dt, m, chunk, tests) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        ContactLanes::Avx2 => chunk_in_lanes::<Portable>(law, dt, m, chunk, tests),
    }
}

fn chunk_scalar(law: &ContactLaw, dt: f64, m: &Monomers, chunk: PairChunk, tests: &mut [u32]) {
    for (k, test) in tests.iter_mut().enumerate() {
        chunk.prefetch_ahead(m, k, true);
        let mut bits = 0;
        for s in chunk.contacts_of(k) {
            bits |= integrate_pair_contact(law, dt, m, chunk.first + k, &mut chunk.rows[s]);
        }
        *test = bits;
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn chunk_avx2(law: &ContactLaw, dt: f64, m: &Monomers, chunk: PairChunk, tests: &mut [u32]) {
    chunk_in_lanes::<Avx2>(law, dt, m, chunk, tests)
}

/// The chunk's contacts in batches of four across owners; a last batch of fewer goes one at a
/// time.
#[inline(always)]
fn chunk_in_lanes<S: Isa>(
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    chunk: PairChunk,
    tests: &mut [u32],
) {
    let mut owner = [0usize; 4];
    let mut slot = [0usize; 4];
    let mut filled = 0;
    for k in 0..tests.len() {
        chunk.prefetch_ahead(m, k, true);
        tests[k] = 0;
        for s in chunk.contacts_of(k) {
            owner[filled] = k;
            slot[filled] = s;
            filled += 1;
            if filled == 4 {
                let bits = four_pairs::<S>(law, dt, m, chunk.rows, chunk.first, &owner, &slot);
                for l in 0..4 {
                    tests[owner[l]] |= bits[l];
                }
                filled = 0;
            }
        }
    }
    for l in 0..filled {
        let c = &mut chunk.rows[slot[l]];
        tests[owner[l]] |= integrate_pair_contact(law, dt, m, chunk.first + owner[l], c);
    }
}

/// Four contacts (owners `first + owner[l]`, slots `slot[l]`) advanced in place; their tests.
#[inline(always)]
fn four_pairs<S: Isa>(
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    rows: &mut [PairContact],
    first: usize,
    owner: &[usize; 4],
    slot: &[usize; 4],
) -> [u32; 4] {
    let (pos, vel, omega) = (&m.position, &m.velocity, &m.angular_velocity);
    let i = |l: usize| first + owner[l];
    let j = |l: usize| rows[slot[l]].partner as usize;
    let (x1, x2) = (
        V4::<S>::gather(|l| pos[i(l)]),
        V4::<S>::gather(|l| pos[j(l)]),
    );
    let (v1, v2) = (
        V4::<S>::gather(|l| vel[i(l)]),
        V4::<S>::gather(|l| vel[j(l)]),
    );
    let (w1, w2) = (
        V4::<S>::gather(|l| omega[i(l)]),
        V4::<S>::gather(|l| omega[j(l)]),
    );
    let n1 = V4::<S>::gather(|l| rows[slot[l]].n1);
    let n2 = V4::<S>::gather(|l| rows[slot[l]].n2);
    let twist = F4::<S>::new(slot.map(|s| rows[s].twist));
    // integrate_pair_contact, twist_increment
    let nc_mid = ((x1 - x2) + (v1 - v2).times(0.5 * dt)).normalize();
    let twist = twist + (w1 - w2).dot(nc_mid) * dt;
    let n1 = rotate_pointer_lanes(n1, w1.times(dt));
    let n2 = rotate_pointer_lanes(n2, w2.times(dt));
    let bits = test_pair_contact_lanes(law, x1 + v1.times(dt), x2 + v2.times(dt), n1, n2, twist);
    for (l, &s) in slot.iter().enumerate() {
        let c = &mut rows[s];
        c.twist = twist.0[l];
        c.n1 = n1.lane(l);
        c.n2 = n2.lane(l);
    }
    bits
}

/// Lane twin of `test_pair_contact` and `beyond_limits`: the lengths in lanes, the
/// comparisons lane by lane as the scalar code makes them.
#[inline(always)]
fn test_pair_contact_lanes<S: Isa>(
    law: &ContactLaw,
    x1: V4<S>,
    x2: V4<S>,
    n1: V4<S>,
    n2: V4<S>,
    twist: F4<S>,
) -> [u32; 4] {
    let k = &law.pair;
    let r = law.radius;
    let delta = 2.0 * r - (x1 - x2).length();
    let nc = (x1 - x2).normalize();
    let rolling = (n1 + n2).length() * k.reduced_radius;
    let p = n1.times(r) - n2.times(r);
    let sliding = (p - nc.scale(p.dot(nc))).length();
    // `!(x <= limit)`: a NaN displacement counts as beyond, as in `beyond_limits`.
    let beyond = |x: f64, limit: f64| {
        use std::cmp::Ordering::{Equal, Less};
        !matches!(x.partial_cmp(&limit), Some(Less | Equal))
    };
    std::array::from_fn(|l| {
        let breaks = delta.0[l] < -k.delta_c;
        let beyond = beyond(rolling.0[l], k.xi_crit)
            || beyond(sliding.0[l], k.zeta_crit)
            || twist.0[l].abs() > k.phi_crit;
        (if breaks { PAIR_TEST_BREAKS } else { 0 }) | (if beyond { PAIR_TEST_BEYOND } else { 0 })
    })
}

/// Lane twin of `rotate_pointer`: the same polynomials in θ², the same grouping.
#[inline(always)]
pub fn rotate_pointer_lanes<S: Isa>(n: V4<S>, w: V4<S>) -> V4<S> {
    let t2 = w.dot(w);
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
    let rotated = n.scale(cos) + w.cross(n).scale(sinc) + w.scale(w.dot(n) * cosc);
    V4::select(t2.eq(F4::<S>::splat(0.0)), n, rotated.normalize())
}
