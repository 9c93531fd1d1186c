//! How many walls each monomer touches, the question the contacts scan asks of every monomer
//! every step, four walls at a time: the overlap r − (x − p)·n of each wall in lanes (the
//! scalar `wall_overlap`'s operations in its order, so the same values), then the scan's
//! touching test lane by lane. With six walls the scalar loop was a third of the scan.

use crate::backend::cpu::lanes::{in_lanes, ContactLanes, Isa, F4, M4, V4};
use crate::model::wall as wall_law;
use crate::state::Wall;
use glam::DVec3;

/// The walls' points and normals, four to a batch, component by component (a last batch's
/// lanes past the walls repeat the last wall and are not counted).
#[derive(Clone, Debug)]
pub struct WallPlanes {
    batches: Vec<[[[f64; 4]; 3]; 2]>,
    count: usize,
}

impl WallPlanes {
    /// Panics above 255 walls, the most a per-monomer count of one byte holds (an engine has
    /// six; the device takes eight).
    pub fn new(walls: &[Wall]) -> WallPlanes {
        assert!(
            walls.len() <= usize::from(u8::MAX),
            "{} walls: the contacts scan counts at most 255",
            walls.len()
        );
        let batches = walls
            .chunks(4)
            .map(|four| {
                let wall = |l: usize| &four[l.min(four.len() - 1)];
                let lanes = |v: &dyn Fn(usize) -> DVec3| {
                    [0, 1, 2].map(|axis| std::array::from_fn(|l| v(l)[axis]))
                };
                [lanes(&|l| wall(l).point), lanes(&|l| wall(l).normal)]
            })
            .collect();
        WallPlanes {
            batches,
            count: walls.len(),
        }
    }
}

/// For each monomer at `x`, how many of `walls` (`planes`, the same walls) it touches
/// (overlap ≥ 0, or NaN, as the contact events test it) into `out`.
pub fn count_touching(
    lanes: ContactLanes,
    walls: &[Wall],
    planes: &WallPlanes,
    r: f64,
    x: &[DVec3],
    out: &mut [u8],
) {
    in_lanes!(
        lanes,
        count_in_lanes(planes, r, x, out)
            as (planes: &WallPlanes, r: f64, x: &[DVec3], out: &mut [u8]),
        scalar => {
            for (x, out) in x.iter().zip(out) {
                let touching = walls
                    .iter()
                    .filter(|w| touching(wall_law::wall_overlap(*x, w.point, w.normal, r)));
                *out = touching.count() as u8;
            }
        },
    )
}

/// An overlap that is not negative: touching, as the events test it (`!(δ < 0)`, so a NaN
/// overlap counts, as in the WGSL).
pub fn touching(overlap: f64) -> bool {
    overlap.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less)
}

#[inline(always)]
fn count_in_lanes<S: Isa>(planes: &WallPlanes, r: f64, x: &[DVec3], out: &mut [u8]) {
    let v4 = |c: &[[f64; 4]; 3]| V4::<S> {
        x: F4::new(c[0]),
        y: F4::new(c[1]),
        z: F4::new(c[2]),
    };
    // Each batch's planes and its lanes that are walls.
    let batches: Vec<(V4<S>, V4<S>, M4<S>)> = planes
        .batches
        .iter()
        .enumerate()
        .map(|(b, [point, normal])| {
            let wall = F4::<S>::new(std::array::from_fn(|l| (4 * b + l) as f64));
            let walls = wall.le(F4::splat(planes.count as f64 - 1.0));
            (v4(point), v4(normal), walls)
        })
        .collect();
    let zero = F4::<S>::splat(0.0);
    for (x, out) in x.iter().zip(out) {
        let at = V4::<S>::gather(|_| *x);
        let mut count = 0;
        for (point, normal, walls) in &batches {
            let overlap = r - (at - *point).dot(*normal);
            // Below zero (a NaN is not): the lanes not touching, as `touching` decides.
            let below = overlap.le(zero).and_not(overlap.eq(zero));
            let touching = walls.and_not(below);
            count += touching.0.iter().map(|m| (m & 1) as u8).sum::<u8>();
        }
        *out = count;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;
    use crate::model::{ContactLaw, ModelOptions, WallFactors};

    #[test]
    fn every_lane_choice_counts_what_the_scalar_overlaps_give() {
        let law = ContactLaw::new(&Material::silicate(), &ModelOptions::default());
        let r = law.radius;
        let k = law.wall_constants(WallFactors::FULL);
        // Six walls of a 10-radius box, one tilted; monomers along lines across it.
        let normals = [
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            -DVec3::X,
            DVec3::new(0.0, 0.6, 0.8),
            -DVec3::Y,
        ];
        let walls: Vec<Wall> = normals
            .iter()
            .enumerate()
            .map(|(w, &normal)| Wall {
                name: format!("w{w}"),
                point: -normal * (10.0 * r),
                normal,
                velocity: DVec3::ZERO,
                constants: k,
            })
            .collect();
        let mut x = vec![
            DVec3::new(0.0, 0.0, -9.5 * r),
            DVec3::new(f64::NAN, 0.0, 0.0),
        ];
        for step in 0..=400 {
            let t = f64::from(step) / 400.0 * 20.0 * r - 10.0 * r;
            x.push(DVec3::new(t, 0.3 * t, -t));
            x.push(DVec3::new(9.0 * r, t, 9.0 * r));
        }
        let planes = WallPlanes::new(&walls);
        let mut reference = vec![0; x.len()];
        count_touching(ContactLanes::Scalar, &walls, &planes, r, &x, &mut reference);
        assert_eq!(reference[0], 1, "pressed into the floor");
        assert_eq!(
            reference[1], 6,
            "a NaN position touches every wall, as the events see it"
        );
        let counts = |c: u8| reference.iter().filter(|&&n| n == c).count();
        assert!(
            counts(0) > 100 && counts(1) > 10 && counts(2) > 10,
            "{reference:?}"
        );
        // A monomer whose overlap with a wall through the origin is exactly zero: touching.
        let floor = [Wall {
            point: DVec3::ZERO,
            normal: DVec3::Z,
            ..walls[0].clone()
        }];
        let at_zero = [DVec3::new(0.0, 0.0, r)];
        assert_eq!(
            wall_law::wall_overlap(at_zero[0], DVec3::ZERO, DVec3::Z, r),
            0.0
        );
        for lanes in [
            ContactLanes::Scalar,
            ContactLanes::Portable,
            ContactLanes::detected(),
        ] {
            let mut got = [0];
            count_touching(
                lanes,
                &floor,
                &WallPlanes::new(&floor),
                r,
                &at_zero,
                &mut got,
            );
            assert_eq!(got, [1], "{lanes:?}: a zero overlap touches");
        }
        for lanes in [ContactLanes::Portable, ContactLanes::detected()] {
            for n in [0, 1, 4, 5, 6] {
                let mut got = vec![0; x.len()];
                let planes = WallPlanes::new(&walls[..n]);
                count_touching(lanes, &walls[..n], &planes, r, &x, &mut got);
                let mut expected = vec![0; x.len()];
                count_touching(
                    ContactLanes::Scalar,
                    &walls[..n],
                    &planes,
                    r,
                    &x,
                    &mut expected,
                );
                assert_eq!(got, expected, "{lanes:?}, {n} walls");
            }
        }
    }
}
