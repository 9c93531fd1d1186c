//! Random ballistic deposition (RBD).
//!
//! Monomers are dropped one at a time at a uniformly random horizontal
//! position (the whole sphere inside the footprint), fall straight down along
//! -z and stick where they first touch something: an earlier monomer at centre
//! distance `contact_distance`, or the floor with the centre at `z = radius`.
//! There is no restructuring, so the result depends only on the random
//! horizontal positions.
//!
//! The first touch is found with a 2D grid of columns in x, y whose cells are
//! at least `contact_distance` wide, so only the 3 x 3 columns around the drop
//! point can hold a monomer that is hit. Each column keeps its monomers sorted
//! by height and is scanned from the top down, stopping once no lower monomer
//! could beat the best stop found so far; the work per monomer therefore does
//! not grow with the sample height and the whole deposition is O(N).

use super::{Footprint, Sample};
use crate::rng::Rng;

/// Inputs of [`generate_rbd`].
#[derive(Clone, Debug, PartialEq)]
pub struct RbdParams {
    /// Number of monomers.
    pub n: usize,
    /// Monomer radius (cm).
    pub radius: f64,
    /// Container cross-section.
    pub footprint: Footprint,
    /// Seed of the horizontal drop positions.
    pub seed: u64,
    /// Centre distance at which a falling monomer sticks (cm); `2 * radius`
    /// for touching spheres.
    pub contact_distance: f64,
}

/// Box side (cm) for which an RBD sample of `n` monomers at filling factor
/// `target_phi` is about as tall as it is wide: `side^3 * phi = n * V_mono`.
pub fn side_for_cube(n: usize, radius: f64, target_phi: f64) -> f64 {
    let v_mono = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    (n as f64 * v_mono / target_phi).cbrt()
}

/// Builds a sample by random ballistic deposition.
///
/// Deterministic: the same parameters give bit-identical positions.
///
/// # Panics
/// If the radius or contact distance is not positive and finite, or the
/// footprint is narrower than one monomer.
pub fn generate_rbd(p: &RbdParams) -> Sample {
    let half = validated_half_width(p);
    let mut rng = Rng::new(p.seed);
    let mut grid = ColumnGrid::new(half, p.contact_distance);
    let mut positions = Vec::with_capacity(p.n);
    for _ in 0..p.n {
        positions.push(deposit_one(p, &mut grid, &mut rng));
    }
    sample_of(p, positions)
}

/// The footprint's half width, after the checks [`generate_rbd`] documents.
fn validated_half_width(p: &RbdParams) -> f64 {
    assert!(
        p.radius.is_finite() && p.radius > 0.0,
        "RBD: radius must be positive and finite, got {}",
        p.radius
    );
    assert!(
        p.contact_distance.is_finite() && p.contact_distance > 0.0,
        "RBD: contact_distance must be positive and finite, got {}",
        p.contact_distance
    );
    let half = p.footprint.half_width();
    assert!(
        half.is_finite() && half >= p.radius,
        "RBD: footprint {:?} must be at least as wide as one monomer of radius {}",
        p.footprint,
        p.radius
    );
    half
}

/// Drops one monomer and returns where it stuck.
fn deposit_one(p: &RbdParams, grid: &mut ColumnGrid, rng: &mut Rng) -> [f64; 3] {
    let (x, y) = drop_point(&p.footprint, p.radius, rng);
    let z = grid.stop_height(x, y, p.radius, p.contact_distance);
    grid.insert([x, y, z]);
    [x, y, z]
}

/// Deposits until `p.n` monomers lie wholly below `ceiling` (centre at most `ceiling - radius`)
/// and keeps only those, in deposition order: a sample as tall as `ceiling` whose rough top has
/// been cut away. Nothing kept loses its support: a falling monomer stops on the upper half of
/// what it hits (or on the floor), so every kept monomer rests on a chain of lower ones.
///
/// Fails when `4 n` drops have not put `n` monomers below the ceiling (a ceiling the deposit's
/// bulk filling factor cannot fill).
pub fn generate_rbd_below(p: &RbdParams, ceiling: f64) -> Result<Sample, String> {
    let half = validated_half_width(p);
    let mut rng = Rng::new(p.seed);
    let mut grid = ColumnGrid::new(half, p.contact_distance);
    let mut positions = Vec::with_capacity(p.n);
    let top = ceiling - p.radius;
    for _ in 0..4 * p.n {
        if positions.len() == p.n {
            return Ok(sample_of(p, positions));
        }
        let at = deposit_one(p, &mut grid, &mut rng);
        if at[2] <= top {
            positions.push(at);
        }
    }
    if positions.len() == p.n {
        return Ok(sample_of(p, positions));
    }
    Err(format!(
        "random ballistic deposition put only {} of {} monomers below {:.3e} cm in {} drops: \
         the footprint is too small for that many monomers under that height",
        positions.len(),
        p.n,
        ceiling,
        4 * p.n
    ))
}

fn sample_of(p: &RbdParams, positions: Vec<[f64; 3]>) -> Sample {
    Sample {
        radius: p.radius,
        footprint: p.footprint.clone(),
        seed: p.seed,
        contact_distance: p.contact_distance,
        positions,
    }
}

/// Uniform random centre such that the whole sphere lies in the footprint.
///
/// Box: x then y, each uniform in [-a, a] with a = side/2 - radius.
/// Cylinder: pairs drawn the same way in the enclosing square with
/// a = R - radius until x^2 + y^2 <= a^2 (rejection, uniform over the disc).
fn drop_point(footprint: &Footprint, radius: f64, rng: &mut Rng) -> (f64, f64) {
    let a = footprint.half_width() - radius;
    match footprint {
        Footprint::Box { .. } => {
            let x = rng.uniform_range(-a, a);
            let y = rng.uniform_range(-a, a);
            (x, y)
        }
        Footprint::Cylinder { .. } => loop {
            let x = rng.uniform_range(-a, a);
            let y = rng.uniform_range(-a, a);
            if x * x + y * y <= a * a {
                break (x, y);
            }
        },
    }
}

/// Vertical columns over a square grid covering [-half, half]^2.
struct ColumnGrid {
    half: f64,
    cell: f64,
    cells_per_side: usize,
    /// Per column, the centres in it sorted by increasing z.
    columns: Vec<Vec<[f64; 3]>>,
}

impl ColumnGrid {
    fn new(half: f64, contact_distance: f64) -> ColumnGrid {
        // Floor keeps the cell at least contact_distance wide.
        let cells_per_side = ((2.0 * half / contact_distance).floor() as usize).max(1);
        let cell = 2.0 * half / cells_per_side as f64;
        ColumnGrid {
            half,
            cell,
            cells_per_side,
            columns: vec![Vec::new(); cells_per_side * cells_per_side],
        }
    }

    fn cell_index(&self, c: f64) -> usize {
        let i = ((c + self.half) / self.cell).floor();
        (i.max(0.0) as usize).min(self.cells_per_side - 1)
    }

    fn insert(&mut self, p: [f64; 3]) {
        let (ix, iy) = (self.cell_index(p[0]), self.cell_index(p[1]));
        let column = &mut self.columns[iy * self.cells_per_side + ix];
        // New monomers land near the top, so the slot is found from the end.
        let mut at = column.len();
        while at > 0 && column[at - 1][2] > p[2] {
            at -= 1;
        }
        column.insert(at, p);
    }

    /// Centre height where a monomer falling at (x, y) first touches a
    /// deposited monomer or the floor.
    fn stop_height(&self, x: f64, y: f64, radius: f64, contact_distance: f64) -> f64 {
        let dc2 = contact_distance * contact_distance;
        let (ix, iy) = (self.cell_index(x), self.cell_index(y));
        let mut best = radius;
        let n = self.cells_per_side;
        for jy in iy.saturating_sub(1)..=(iy + 1).min(n - 1) {
            for jx in ix.saturating_sub(1)..=(ix + 1).min(n - 1) {
                for q in self.columns[jy * n + jx].iter().rev() {
                    // Any stop on q is below q.z + contact_distance, and the
                    // rest of the column is lower still.
                    if q[2] + contact_distance <= best {
                        break;
                    }
                    let (dx, dy) = (x - q[0], y - q[1]);
                    let rho2 = dx * dx + dy * dy;
                    if rho2 < dc2 {
                        best = best.max(q[2] + (dc2 - rho2).sqrt());
                    }
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::interior_filling_factor;

    const R: f64 = 6.0e-5;

    fn box_params(n: usize, seed: u64) -> RbdParams {
        RbdParams {
            n,
            radius: R,
            footprint: Footprint::Box {
                side: side_for_cube(n, R, 0.15),
            },
            seed,
            contact_distance: 2.0 * R,
        }
    }

    /// Pairs (i, j), i < j, with centre distance below `cut`, found by a
    /// sweep over x independent of the column grid.
    fn close_pairs(pos: &[[f64; 3]], cut: f64) -> Vec<(usize, usize, f64)> {
        let mut order: Vec<usize> = (0..pos.len()).collect();
        order.sort_by(|&a, &b| pos[a][0].total_cmp(&pos[b][0]));
        let mut out = Vec::new();
        for (k, &i) in order.iter().enumerate() {
            for &j in &order[k + 1..] {
                if pos[j][0] - pos[i][0] >= cut {
                    break;
                }
                let d = ((pos[i][0] - pos[j][0]).powi(2)
                    + (pos[i][1] - pos[j][1]).powi(2)
                    + (pos[i][2] - pos[j][2]).powi(2))
                .sqrt();
                if d < cut {
                    out.push((i.min(j), i.max(j), d));
                }
            }
        }
        out
    }

    /// No overlaps, every monomer in the footprint and above the floor, and
    /// every monomer off the floor touching one deposited before it.
    fn check_hit_and_stick(s: &Sample) {
        let dc = s.contact_distance;
        let lim = s.footprint.half_width() - s.radius;
        for (i, p) in s.positions.iter().enumerate() {
            assert!(
                s.footprint.inset(s.radius).contains(p[0], p[1]),
                "monomer {i} at {p:?} sticks out of {:?} (limit {lim})",
                s.footprint
            );
            assert!(p[2] >= s.radius, "monomer {i} below the floor: {p:?}");
        }
        let pairs = close_pairs(&s.positions, dc * 1.001);
        let mut touches_earlier = vec![false; s.positions.len()];
        for &(i, j, d) in &pairs {
            assert!(
                d >= dc * (1.0 - 1e-12),
                "monomers {i} and {j} overlap: distance {d:e}, contact {dc:e}"
            );
            if (d - dc).abs() <= 1e-9 * dc {
                touches_earlier[j] = true;
            }
        }
        let mut on_floor = 0;
        for (i, p) in s.positions.iter().enumerate() {
            if p[2] == s.radius {
                on_floor += 1;
            } else {
                assert!(
                    touches_earlier[i],
                    "monomer {i} at {p:?} neither on the floor nor touching an earlier one"
                );
            }
        }
        assert!(on_floor > 0);
    }

    #[test]
    fn box_sample_is_hit_and_stick() {
        check_hit_and_stick(&generate_rbd(&box_params(20_000, 1)));
    }

    #[test]
    fn cylinder_sample_is_hit_and_stick() {
        let n = 20_000;
        let side = side_for_cube(n, R, 0.15);
        let s = generate_rbd(&RbdParams {
            n,
            radius: R,
            // Same area as the cube's base.
            footprint: Footprint::Cylinder {
                radius: side / std::f64::consts::PI.sqrt(),
            },
            seed: 3,
            contact_distance: 2.0 * R,
        });
        assert_eq!(s.positions.len(), n);
        check_hit_and_stick(&s);
        let phi = interior_filling_factor(&s);
        assert!((phi - 0.15).abs() <= 0.01, "cylinder interior phi {phi}");
    }

    #[test]
    fn first_monomer_lands_on_floor_and_second_on_first() {
        // A footprint barely wider than a monomer forces a vertical stack.
        let s = generate_rbd(&RbdParams {
            n: 3,
            radius: 1.0,
            footprint: Footprint::Box { side: 2.0 },
            seed: 0,
            contact_distance: 2.0,
        });
        assert_eq!(s.positions[0], [0.0, 0.0, 1.0]);
        assert_eq!(s.positions[1], [0.0, 0.0, 3.0]);
        assert_eq!(s.positions[2], [0.0, 0.0, 5.0]);
    }

    #[test]
    fn stops_at_highest_of_several_contacts() {
        // Monomers dropped by hand: the grid must return the highest stop,
        // not the first one scanned, nor the one in its own cell.
        let dc = 2.0;
        let mut grid = ColumnGrid::new(10.0, dc);
        grid.insert([0.0, 0.0, 1.0]);
        grid.insert([2.4, 0.0, 1.5]);
        grid.insert([-5.0, 0.0, 30.0]);
        let z = grid.stop_height(1.5, 0.0, 1.0, dc);
        let (d1, d2) = (1.5f64 - 0.0, 1.5f64 - 2.4);
        let expect = 1.5 + (dc * dc - d2 * d2).sqrt();
        assert!(expect > 1.0 + (dc * dc - d1 * d1).sqrt());
        assert_eq!(z, expect);
        // Far from everything it reaches the floor.
        assert_eq!(grid.stop_height(8.0, 8.0, 1.0, dc), 1.0);
    }

    #[test]
    fn same_seed_same_positions_other_seed_differs() {
        let a = generate_rbd(&box_params(2_000, 5));
        let b = generate_rbd(&box_params(2_000, 5));
        let c = generate_rbd(&box_params(2_000, 6));
        assert_eq!(a, b);
        assert!(a
            .positions
            .iter()
            .zip(&b.positions)
            .all(|(p, q)| p.iter().zip(q).all(|(u, v)| u.to_bits() == v.to_bits())));
        assert_ne!(a.positions, c.positions);
    }

    #[test]
    fn interior_filling_factor_of_cube_sample() {
        // Published RBD value for equal spheres: about 0.15.
        let s = generate_rbd(&box_params(20_000, 1));
        let phi = interior_filling_factor(&s);
        assert!((phi - 0.15).abs() <= 0.01, "interior phi {phi}");
        // The whole column includes the rough top, so it is less dense.
        assert!(s.filling_factor_bulk() < phi);
    }

    #[test]
    fn a_cut_sample_is_as_tall_as_wide_at_the_bulk_filling_factor_and_fully_supported() {
        let p = box_params(4000, 3);
        let side = side_for_cube(p.n, R, 0.15);
        let s = generate_rbd_below(&p, side).unwrap();
        assert_eq!(s.positions.len(), p.n);
        assert!(s.positions.iter().all(|q| q[2] + R <= side));
        // Kept monomers rest on kept ones: each touches an earlier one or the floor.
        check_hit_and_stick(&s);
        // n monomers under a side³ box sized for φ = 0.15: exactly 0.15 by construction.
        let v = 4.0 / 3.0 * std::f64::consts::PI * R.powi(3);
        assert!((p.n as f64 * v / side.powi(3) - 0.15).abs() < 1e-12);
        // The top is flat to within the deposit's roughness: the highest monomer reaches to
        // within two diameters of the ceiling.
        let top = s.positions.iter().map(|q| q[2]).fold(0.0, f64::max);
        assert!(side - (top + R) < 4.0 * R, "top at {top}, ceiling {side}");
        // The same inputs give the same sample; the uncut deposit differs.
        assert_eq!(generate_rbd_below(&p, side).unwrap().positions, s.positions);
        assert_ne!(generate_rbd(&p).positions, s.positions);
    }

    #[test]
    fn a_ceiling_too_low_for_the_monomers_is_an_error() {
        let p = box_params(2000, 1);
        let side = side_for_cube(p.n, R, 0.15);
        let e = generate_rbd_below(&p, 0.5 * side).unwrap_err();
        assert!(e.contains("of 2000 monomers below"), "{e}");
    }

    #[test]
    fn side_for_cube_gives_requested_volume() {
        let side = side_for_cube(1000, 1.0, 0.2);
        let v = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI;
        assert!((side.powi(3) * 0.2 / v - 1.0).abs() < 1e-12);
    }

    #[test]
    #[should_panic(expected = "at least as wide as one monomer")]
    fn rejects_footprint_narrower_than_monomer() {
        generate_rbd(&RbdParams {
            n: 1,
            radius: 1.0,
            footprint: Footprint::Cylinder { radius: 0.5 },
            seed: 0,
            contact_distance: 2.0,
        });
    }
}
