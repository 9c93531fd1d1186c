//! Filling factor (solid volume fraction) of a sample.

use super::Sample;

/// Volume of a sphere of radius `r` below a plane at height `t` above its
/// centre (spherical cap formula, clamped outside [-r, r]).
fn volume_below(r: f64, t: f64) -> f64 {
    if t <= -r {
        0.0
    } else if t >= r {
        4.0 / 3.0 * std::f64::consts::PI * r.powi(3)
    } else {
        std::f64::consts::PI * (r + t).powi(2) * (2.0 * r - t) / 3.0
    }
}

/// Filling factor in horizontal slabs of thickness `slab` (cm) from the
/// floor up to the top of the highest monomer.
///
/// Each entry is `(z centre of the slab, phi)` where phi is the exact volume
/// of all sphere parts inside the slab divided by `footprint area * slab`.
/// The whole footprint is used, including the layer of one radius along the
/// walls that no centre can enter, so for a box the values run about
/// `4 radius / side` below the interior density.
///
/// # Panics
/// If `slab` is not positive and finite.
pub fn filling_factor_profile(s: &Sample, slab: f64) -> Vec<(f64, f64)> {
    if s.positions.is_empty() {
        return Vec::new();
    }
    let top = s.z_max() + s.radius;
    slab_profile(
        s.positions.iter().map(|p| p[2]),
        s.radius,
        s.footprint.area(),
        0.0,
        top,
        slab,
    )
}

/// Filling factor of spheres of radius `r` with centre heights `z` in slabs of thickness `slab`
/// between `bottom` and `top`, over the horizontal `area`: `(slab centre, φ)` per slab.
///
/// # Panics
/// If `slab` is not positive and finite.
pub fn slab_profile(
    z: impl Iterator<Item = f64>,
    r: f64,
    area: f64,
    bottom: f64,
    top: f64,
    slab: f64,
) -> Vec<(f64, f64)> {
    assert!(
        slab.is_finite() && slab > 0.0,
        "slab thickness must be positive and finite, got {slab}"
    );
    if top <= bottom {
        return Vec::new();
    }
    let n_slabs = ((top - bottom) / slab).ceil() as usize;
    let mut volume = vec![0.0; n_slabs];
    for zc in z {
        let zc = zc - bottom;
        let first = ((zc - r) / slab).floor().max(0.0) as usize;
        let last = (((zc + r) / slab).floor().max(0.0) as usize).min(n_slabs - 1);
        for (k, v) in volume.iter_mut().enumerate().take(last + 1).skip(first) {
            let lo = k as f64 * slab - zc;
            let hi = (k + 1) as f64 * slab - zc;
            *v += volume_below(r, hi) - volume_below(r, lo);
        }
    }
    let slab_volume = area * slab;
    volume
        .into_iter()
        .enumerate()
        .map(|(k, v)| (bottom + (k as f64 + 0.5) * slab, v / slab_volume))
        .collect()
}

/// Horizontal inset of the interior region from the side walls, in units of
/// `contact_distance`.
pub const INTERIOR_MARGIN_CONTACTS: f64 = 3.0;
/// Bottom of the interior region as a fraction of the sample height.
pub const INTERIOR_Z_LO_FRACTION: f64 = 0.2;
/// Top of the interior region as a fraction of the sample height.
pub const INTERIOR_Z_HI_FRACTION: f64 = 0.6;

/// Filling factor of the sample's interior, away from the floor, the rough
/// top and the side walls.
///
/// Definition: with `H = z_max + radius` (top of the highest monomer, as in
/// [`Sample::filling_factor_bulk`]) and
/// `m = INTERIOR_MARGIN_CONTACTS * contact_distance`, the interior region is
/// the footprint shrunk by `m` on every side (box of side `side - 2m`, or
/// disc of radius `R - m`) between heights `INTERIOR_Z_LO_FRACTION * H`
/// (inclusive) and `INTERIOR_Z_HI_FRACTION * H` (exclusive). The result is
/// `N_in * V_mono / V_region`, where `N_in` counts the monomer centres in the
/// region. Counting centres is unbiased for a statistically uniform packing
/// and needs no sphere-region intersection volumes; unlike
/// [`filling_factor_profile`] it does not see the sphere-free layer of one
/// radius along the walls.
///
/// Why these bounds: in cube-shaped RBD samples the floor-ordered layer is
/// densest at the floor and relaxes over roughly ten contact distances, the
/// rough top starts thinning out at about 0.65-0.7 H, and no depletion is seen
/// next to the walls beyond the one-radius layer. The RBD profile is never
/// strictly flat, though: it keeps falling slowly with height, so the value
/// drifts down a little as samples get taller.
///
/// Returns NaN when the region is empty (no monomers or a footprint
/// narrower than `2 m`).
pub fn interior_filling_factor(s: &Sample) -> f64 {
    let margin = INTERIOR_MARGIN_CONTACTS * s.contact_distance;
    let inner = s.footprint.inset(margin);
    let height = s.z_max() + s.radius;
    let (z_lo, z_hi) = (
        INTERIOR_Z_LO_FRACTION * height,
        INTERIOR_Z_HI_FRACTION * height,
    );
    if s.positions.is_empty() || inner.half_width() <= 0.0 {
        return f64::NAN;
    }
    let count = s
        .positions
        .iter()
        .filter(|p| p[2] >= z_lo && p[2] < z_hi && inner.contains(p[0], p[1]))
        .count();
    count as f64 * s.monomer_volume() / (inner.area() * (z_hi - z_lo))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::{generate_rbd, side_for_cube, Footprint, RbdParams};

    #[test]
    fn cap_volume_limits() {
        let r = 2.0;
        let v = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
        assert_eq!(volume_below(r, -3.0), 0.0);
        assert_eq!(volume_below(r, 3.0), v);
        assert!((volume_below(r, 0.0) - v / 2.0).abs() < 1e-12 * v);
        assert!((volume_below(r, r) - v).abs() < 1e-12 * v);
        // Symmetry: below t plus below -t is the whole sphere.
        assert!((volume_below(r, 0.7) + volume_below(r, -0.7) - v).abs() < 1e-12 * v);
    }

    fn sample(n: usize, seed: u64) -> Sample {
        let r = 6.0e-5;
        generate_rbd(&RbdParams {
            n,
            radius: r,
            footprint: Footprint::Box {
                side: side_for_cube(n, r, 0.15),
            },
            seed,
            contact_distance: 2.0 * r,
        })
    }

    #[test]
    fn profile_integrates_to_total_volume() {
        let s = sample(3_000, 2);
        for slab in [0.3 * s.radius, s.radius, 5.0 * s.radius] {
            let prof = filling_factor_profile(&s, slab);
            let total: f64 =
                prof.iter().map(|&(_, phi)| phi).sum::<f64>() * s.footprint.area() * slab;
            let expect = s.positions.len() as f64 * s.monomer_volume();
            assert!(
                (total / expect - 1.0).abs() < 1e-9,
                "slab {slab}: {total} vs {expect}"
            );
            assert!(prof.last().unwrap().0 + 0.5 * slab >= s.z_max() + s.radius);
        }
    }

    #[test]
    fn profile_of_single_floor_layer() {
        // One floor monomer in a box of area 4 r^2: each of the two unit
        // slabs holds exactly half of the sphere.
        let r = 1.0;
        let s = Sample {
            radius: r,
            footprint: Footprint::Box { side: 2.0 },
            seed: 0,
            contact_distance: 2.0,
            positions: vec![[0.0, 0.0, 1.0]],
        };
        let prof = filling_factor_profile(&s, 1.0);
        assert_eq!(prof.len(), 2);
        let half = 2.0 / 3.0 * std::f64::consts::PI;
        assert!((prof[0].1 - half / 4.0).abs() < 1e-12);
        assert!((prof[1].1 - half / 4.0).abs() < 1e-12);
        assert_eq!(prof[0].0, 0.5);
    }

    #[test]
    fn interior_of_uniform_lattice_is_exact() {
        // A simple cubic lattice of spacing a has phi = V_mono / a^3; the
        // estimator must recover it when the region spans whole cells.
        let r = 1.0;
        let a = 2.5;
        let k = 40;
        let side = k as f64 * a;
        let mut positions = Vec::new();
        for iz in 0..k {
            for iy in 0..k {
                for ix in 0..k {
                    let c = |i: usize| (i as f64 + 0.5) * a - 0.5 * side;
                    positions.push([c(ix), c(iy), r + iz as f64 * a]);
                }
            }
        }
        let s = Sample {
            radius: r,
            footprint: Footprint::Box { side },
            seed: 0,
            contact_distance: 2.0,
            positions,
        };
        let phi = interior_filling_factor(&s);
        let expect = s.monomer_volume() / a.powi(3);
        // Region edges cut the lattice at most one plane off per side.
        assert!((phi / expect - 1.0).abs() < 0.1, "{phi} vs {expect}");
    }

    #[test]
    fn interior_is_nan_for_empty_sample() {
        let s = Sample {
            radius: 1.0,
            footprint: Footprint::Cylinder { radius: 10.0 },
            seed: 0,
            contact_distance: 2.0,
            positions: Vec::new(),
        };
        assert!(interior_filling_factor(&s).is_nan());
        assert!(filling_factor_profile(&s, 1.0).is_empty());
    }
}
