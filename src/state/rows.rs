//! What one measurement row needs of the state, reduced in the fixed order a device sums in:
//! the mechanical energies (with the xy extent of the monomers), the solid volume per slab of
//! a filling-factor profile and the projected cross-section a unidirectional run divides by.
//!
//! A device cannot hand the host its state every row (3 GB at 10⁶ monomers), so it reduces
//! these on its side and the host reads a few numbers. These functions are the twins of the
//! entry points of shaders/passes/rows.wgsl (same names, same additions in the same order),
//! and every engine's rows come from them ([`State::row_measures`] on the CPU), so both
//! backends write the same bits. Block sizes are those of `reduction`.

use super::interaction::{pair_contact_potential, wall_contact_potential};
use super::reduction::{DIAG_THREADS, REDUCE_BLOCK};
use super::{EnergyReport, State};
use crate::model::normal::jkr_potential_at_overlap;
use crate::model::wall::wall_overlap;
use glam::DVec3;

/// Slabs of a filling-factor profile: `count` slabs of `thickness` [cm] stacked from `bottom`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slabs {
    pub bottom: f64,
    pub thickness: f64,
    pub count: usize,
}

impl Slabs {
    /// Slabs of `thickness` from `bottom` up to `top` (the last one may reach beyond it); none
    /// where `top` is not above `bottom`, as `sample::slab_profile` counts them.
    pub fn between(bottom: f64, top: f64, thickness: f64) -> Self {
        let count = if top > bottom {
            ((top - bottom) / thickness).ceil() as usize
        } else {
            0
        };
        Slabs {
            bottom,
            thickness,
            count,
        }
    }

    /// (slab centre, filling factor) of each slab, from the solid volume in it and the
    /// horizontal cross-section `area`.
    pub fn profile(&self, volumes: &[f64], area: f64) -> Vec<(f64, f64)> {
        let slab_volume = area * self.thickness;
        volumes
            .iter()
            .enumerate()
            .map(|(k, v)| {
                (
                    self.bottom + (k as f64 + 0.5) * self.thickness,
                    v / slab_volume,
                )
            })
            .collect()
    }
}

/// What a row asks for beyond the energies and contact counts, which every row has.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RowRequest {
    /// The solid volume per slab of a profile.
    pub slabs: Option<Slabs>,
    /// The projected cross-section (the uni runs' area).
    pub projected_area: bool,
}

/// One row's measures of the state.
#[derive(Clone, Debug, PartialEq)]
pub struct RowMeasures {
    pub energy: EnergyReport,
    /// (monomer–monomer contacts, monomer–wall contacts).
    pub contacts: (usize, usize),
    /// Solid volume in each requested slab [cm³] (empty without slabs).
    pub slab_volumes: Vec<f64>,
    /// Area of the union of the monomers' projections on the xy plane [cm²], if requested.
    pub projected_area: Option<f64>,
}

/// Numbers [`row_sums`] keeps per block of monomers: kinetic, rotational, normal and
/// tangential energy; then the least x, y and the greatest x, y of the centres.
pub const ROW_SUMS: usize = 8;

/// Kinetic and rotational energy of monomer `i` (synchronised velocities) and the JKR and
/// tangential potentials of the contacts it holds (its pair slots, then its wall slots).
pub fn monomer_energy(s: &State, i: usize) -> [f64; 4] {
    let m = &s.monomers;
    let law = &s.law;
    let mut e = [0.0; 4];
    if m.inverse_mass_scale[i] > 0.0 {
        e[0] = 0.5 * law.mass * s.synchronized_velocity(i).length_squared();
    }
    if m.inverse_inertia_scale[i] > 0.0 {
        e[1] = 0.5 * law.moment_of_inertia * s.synchronized_angular_velocity(i).length_squared();
    }
    let k = &law.pair;
    let x = m.position[i];
    for c in s.contacts.pairs_of(i) {
        let y = m.position[c.partner as usize];
        let total = pair_contact_potential(law, x, y, c);
        let normal = jkr_potential_at_overlap(
            (2.0 * law.radius - (x - y).length()) / k.delta0,
            k.f_c,
            k.delta0,
        );
        e[2] += normal;
        e[3] += total - normal;
    }
    for c in s.contacts.walls_of(i) {
        let w = &s.walls[c.wall as usize];
        let total = wall_contact_potential(law.radius, x, w, c);
        let delta = wall_overlap(x, w.point, w.normal, law.radius);
        let normal = jkr_potential_at_overlap(
            delta / w.constants.delta0,
            w.constants.f_c,
            w.constants.delta0,
        );
        e[2] += normal;
        e[3] += total - normal;
    }
    e
}

/// Per block of [`REDUCE_BLOCK`] consecutive monomers (one workgroup): the energies of
/// [`monomer_energy`] added in index order from zero, and the extent of the centres in x and y.
pub fn row_sums(s: &State) -> Vec<[f64; ROW_SUMS]> {
    let n = s.monomers.len();
    (0..n.div_ceil(REDUCE_BLOCK))
        .map(|b| {
            let first = b * REDUCE_BLOCK;
            let p = s.monomers.position[first];
            let mut sums = [0.0, 0.0, 0.0, 0.0, p.x, p.y, p.x, p.y];
            for i in first..(first + REDUCE_BLOCK).min(n) {
                let e = monomer_energy(s, i);
                for c in 0..4 {
                    sums[c] += e[c];
                }
                let p = s.monomers.position[i];
                sums[4] = sums[4].min(p.x);
                sums[5] = sums[5].min(p.y);
                sums[6] = sums[6].max(p.x);
                sums[7] = sums[7].max(p.y);
            }
            sums
        })
        .collect()
}

/// The blocks of [`row_sums`] as one workgroup of [`DIAG_THREADS`] adds them: invocation t
/// takes blocks t, t + DIAG_THREADS, …, then the partial results are added in invocation order.
/// Zero energies and an empty extent (least ±f64::MAX) for no blocks.
pub fn row_sums_final(blocks: &[[f64; ROW_SUMS]]) -> [f64; ROW_SUMS] {
    let empty = [0.0, 0.0, 0.0, 0.0, f64::MAX, f64::MAX, -f64::MAX, -f64::MAX];
    let combine = |into: &mut [f64; ROW_SUMS], b: &[f64; ROW_SUMS]| {
        for c in 0..4 {
            into[c] += b[c];
        }
        into[4] = into[4].min(b[4]);
        into[5] = into[5].min(b[5]);
        into[6] = into[6].max(b[6]);
        into[7] = into[7].max(b[7]);
    };
    let mut total = empty;
    for t in 0..DIAG_THREADS {
        let mut part = empty;
        for b in blocks.iter().skip(t).step_by(DIAG_THREADS) {
            combine(&mut part, b);
        }
        combine(&mut total, &part);
    }
    total
}

/// Volume of a sphere of radius `r` below a plane at height `t` above its centre; `sphere` is
/// its whole volume, computed once by the host ([`sphere_volume`]).
fn volume_below(r: f64, sphere: f64, t: f64) -> f64 {
    if t <= -r {
        0.0
    } else if t >= r {
        sphere
    } else {
        std::f64::consts::PI * ((r + t) * (r + t)) * (2.0 * r - t) / 3.0
    }
}

/// 4/3 π r³.
pub fn sphere_volume(r: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * (r * r * r)
}

/// Volume of the sphere of radius `r` centred at height `z` inside slab `k`.
fn slab_share(slabs: &Slabs, r: f64, sphere: f64, z: f64, k: usize) -> f64 {
    let zc = z - slabs.bottom;
    let first = ((zc - r) / slabs.thickness).floor().max(0.0);
    let last = ((zc + r) / slabs.thickness)
        .floor()
        .max(0.0)
        .min((slabs.count - 1) as f64);
    let kf = k as f64;
    if kf < first || kf > last {
        return 0.0;
    }
    let lo = kf * slabs.thickness - zc;
    let hi = (kf + 1.0) * slabs.thickness - zc;
    volume_below(r, sphere, hi) - volume_below(r, sphere, lo)
}

/// Solid volume per (slab, block of [`REDUCE_BLOCK`] monomers), at `k * blocks + b`: each
/// block's shares of slab k added in index order from zero (one invocation per pair).
pub fn row_profile(z: &[f64], r: f64, slabs: &Slabs) -> Vec<f64> {
    let blocks = z.len().div_ceil(REDUCE_BLOCK);
    let sphere = sphere_volume(r);
    let mut out = vec![0.0; slabs.count * blocks];
    for k in 0..slabs.count {
        for b in 0..blocks {
            let mut sum = 0.0;
            for &zi in &z[b * REDUCE_BLOCK..((b + 1) * REDUCE_BLOCK).min(z.len())] {
                sum += slab_share(slabs, r, sphere, zi, k);
            }
            out[k * blocks + b] = sum;
        }
    }
    out
}

/// Solid volume per slab: the blocks of [`row_profile`] added in block order from zero.
pub fn row_profile_final(partials: &[f64], blocks: usize, slabs: usize) -> Vec<f64> {
    (0..slabs)
        .map(|k| {
            partials[k * blocks..(k + 1) * blocks]
                .iter()
                .fold(0.0, |s, v| s + v)
        })
        .collect()
}

/// The pixel grid of the projected area: pixels of r/10 over the extent of the centres
/// widened by r (what `experiment::measure::projected_area` rasterises on).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Raster {
    pub x0: f64,
    pub y0: f64,
    pub pixel: f64,
    pub nx: usize,
    pub ny: usize,
}

impl Raster {
    /// The grid for centres within (lo_x, lo_y)–(hi_x, hi_y) and monomers of radius `r`.
    pub fn new(lo: [f64; 2], hi: [f64; 2], r: f64) -> Self {
        let pixel = r / 10.0;
        let x0 = lo[0] - r;
        let y0 = lo[1] - r;
        Raster {
            x0,
            y0,
            pixel,
            nx: ((hi[0] + r - x0) / pixel).ceil() as usize + 1,
            ny: ((hi[1] + r - y0) / pixel).ceil() as usize + 1,
        }
    }

    /// 32-bit words of the coverage bitmap (pixel iy · nx + ix is bit p % 32 of word p / 32).
    pub fn words(&self) -> usize {
        (self.nx * self.ny).div_ceil(32)
    }
}

/// Sets the pixels of the coverage bitmap whose centres lie in the disk of radius `r` about
/// each centre (one invocation per monomer; the bits are ORed, so the order cannot matter).
pub fn row_raster(positions: &[DVec3], r: f64, grid: &Raster, bits: &mut [u32]) {
    let h = grid.pixel;
    let r2 = r * r;
    for p in positions {
        let iy0 = ((p.y - r - grid.y0) / h).floor().max(0.0) as usize;
        let iy1 = (((p.y + r - grid.y0) / h).ceil() as usize).min(grid.ny - 1);
        for iy in iy0..=iy1 {
            let dy = grid.y0 + (iy as f64 + 0.5) * h - p.y;
            let rest = r2 - dy * dy;
            if rest < 0.0 {
                continue;
            }
            let half = rest.sqrt();
            let ix0 = ((p.x - half - grid.x0) / h - 0.5).ceil().max(0.0) as usize;
            let ix1 =
                (((p.x + half - grid.x0) / h - 0.5).floor().max(0.0) as usize).min(grid.nx - 1);
            for ix in ix0..=ix1 {
                let at = iy * grid.nx + ix;
                bits[at / 32] |= 1 << (at % 32);
            }
        }
    }
}

/// Pixels set in the coverage bitmap (an integer sum: any order gives the same count).
pub fn row_area(bits: &[u32]) -> u64 {
    bits.iter().map(|w| u64::from(w.count_ones())).sum()
}

impl State {
    /// The row's measures, reduced as a device reduces them (the functions above): what
    /// every engine reports for a row.
    pub fn row_measures(&self, request: &RowRequest) -> RowMeasures {
        let n = self.monomers.len();
        let r = self.law.radius;
        let sums = row_sums_final(&row_sums(self));
        let energy = EnergyReport {
            kinetic: sums[0],
            rotational: sums[1],
            normal_potential: sums[2],
            tangential_potential: sums[3],
            dissipated: self.tally,
            wall_work: self.wall_work,
        };
        let slab_volumes = match request.slabs {
            Some(slabs) if slabs.count > 0 && n > 0 => {
                let z: Vec<f64> = self.monomers.position.iter().map(|p| p.z).collect();
                row_profile_final(
                    &row_profile(&z, r, &slabs),
                    n.div_ceil(REDUCE_BLOCK),
                    slabs.count,
                )
            }
            Some(slabs) => vec![0.0; slabs.count],
            None => Vec::new(),
        };
        let projected_area = request.projected_area.then(|| {
            if n == 0 {
                return 0.0;
            }
            let grid = Raster::new([sums[4], sums[5]], [sums[6], sums[7]], r);
            let mut bits = vec![0u32; grid.words()];
            row_raster(&self.monomers.position, r, &grid, &mut bits);
            row_area(&bits) as f64 * grid.pixel * grid.pixel
        });
        RowMeasures {
            energy,
            contacts: (
                self.contacts.pair_contact_count(),
                self.contacts.wall_contact_count(),
            ),
            slab_volumes,
            projected_area,
        }
    }
}
