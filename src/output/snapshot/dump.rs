//! The LAMMPS text dump of one snapshot, for OVITO.

use super::format::*;
use super::{Snapshot, AXIS_ALIGNED_TOL, CM_TO_UM};
use std::io::{self, Write};

/// Box bounds in µm, `[lo, hi]` per axis, and the LAMMPS boundary flags: `f` for a side
/// bounded by a wall, `s` (shrink-wrapped) for a side taken from the particles.
pub(super) fn box_bounds(s: &Snapshot) -> ([[f64; 2]; 3], [[char; 2]; 3]) {
    let mut wall_lo = [f64::NEG_INFINITY; 3];
    let mut wall_hi = [f64::INFINITY; 3];
    for wall in s.walls {
        let n = unit(wall.normal);
        for k in 0..3 {
            let aligned = (0..3).all(|j| j == k || n[j].abs() <= AXIS_ALIGNED_TOL);
            if !aligned {
                continue;
            }
            // The domain is the intersection of the walls' half-spaces, so the innermost
            // wall on each side is the bound.
            let p = wall.point[k] * CM_TO_UM;
            if n[k] > 0.0 {
                wall_lo[k] = wall_lo[k].max(p);
            } else {
                wall_hi[k] = wall_hi[k].min(p);
            }
        }
    }

    let r = s.radius * CM_TO_UM;
    let mut part_lo = [f64::INFINITY; 3];
    let mut part_hi = [f64::NEG_INFINITY; 3];
    for p in s.positions {
        for k in 0..3 {
            let x = p[k] * CM_TO_UM;
            part_lo[k] = part_lo[k].min(x - r);
            part_hi[k] = part_hi[k].max(x + r);
        }
    }

    let mut bounds = [[0.0; 2]; 3];
    let mut flags = [['s'; 2]; 3];
    for k in 0..3 {
        let lo_wall = wall_lo[k].is_finite();
        let hi_wall = wall_hi[k].is_finite();
        if lo_wall {
            flags[k][0] = 'f';
        }
        if hi_wall {
            flags[k][1] = 'f';
        }
        bounds[k] = match (lo_wall, hi_wall, s.positions.is_empty()) {
            (true, true, _) => [wall_lo[k], wall_hi[k]],
            // A side taken from the particles must not cross the wall on the other side,
            // or the box would be inverted when the particles sit outside the walls.
            (true, false, false) => [wall_lo[k], part_hi[k].max(wall_lo[k])],
            (false, true, false) => [part_lo[k].min(wall_hi[k]), wall_hi[k]],
            (false, false, false) => [part_lo[k], part_hi[k]],
            (true, false, true) => [wall_lo[k], wall_lo[k]],
            (false, true, true) => [wall_hi[k], wall_hi[k]],
            (false, false, true) => [0.0, 0.0],
        };
    }
    (bounds, flags)
}

pub(super) fn dump_body<W: Write>(w: &mut W, s: &Snapshot) -> io::Result<()> {
    let n = s.positions.len();
    let r_um = F(s.radius * CM_TO_UM);
    let (bounds, flags) = box_bounds(s);

    writeln!(w, "ITEM: TIME")?;
    writeln!(w, "{}", F(s.time))?;
    writeln!(w, "ITEM: TIMESTEP")?;
    writeln!(w, "{}", s.step)?;
    writeln!(w, "ITEM: NUMBER OF ATOMS")?;
    writeln!(w, "{n}")?;
    writeln!(
        w,
        "ITEM: COLUMN UNITS time box x y z vx vy vz omegax omegay omegaz radius contacts"
    )?;
    writeln!(w, "s um um um um m/s m/s m/s rad/s rad/s rad/s um 1")?;
    writeln!(
        w,
        "ITEM: WALLS name px py pz nx ny nz (point in um, unit normal into the domain)"
    )?;
    for wall in s.walls {
        writeln!(
            w,
            "{} {} {}",
            wall.name,
            V3(scale(wall.point, CM_TO_UM)),
            V3(unit(wall.normal))
        )?;
    }
    writeln!(
        w,
        "ITEM: BOX BOUNDS {}{} {}{} {}{}",
        flags[0][0], flags[0][1], flags[1][0], flags[1][1], flags[2][0], flags[2][1]
    )?;
    for b in bounds {
        writeln!(w, "{} {}", F(b[0]), F(b[1]))?;
    }
    writeln!(
        w,
        "ITEM: ATOMS id type x y z vx vy vz omegax omegay omegaz radius contacts"
    )?;
    for i in 0..n {
        writeln!(
            w,
            "{} 1 {} {} {} {} {}",
            i + 1,
            V3(scale(s.positions[i], CM_TO_UM)),
            V3(to_m_per_s(s.velocities[i])),
            V3(s.angular_velocities[i]),
            r_um,
            s.contacts[i]
        )?;
    }
    Ok(())
}
