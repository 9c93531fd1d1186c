//! What a snapshot must satisfy before any file is touched: equal lengths, finite values, a
//! positive radius and usable walls.

use super::format::unit;
use super::{Snapshot, WallPlane, CM_PER_S_PER_M_PER_S, CM_TO_UM};
use std::io;

pub(super) fn invalid(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, msg)
}

/// What validation does with non-finite monomer values.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum NonFinite {
    Refuse,
    /// The failed-state snapshot: kept, written in binary (see [`super::write_failed_vtu`]).
    Keep,
}

/// Everything is checked before the temporary file is created, so that a refused snapshot
/// leaves nothing behind and the error names the offending monomer rather than surfacing as
/// an unreadable `NaN` in a viewer.
pub(super) fn validate_snapshot(s: &Snapshot, non_finite: NonFinite) -> io::Result<()> {
    let n = s.positions.len();
    for (what, len) in [
        ("velocities", s.velocities.len()),
        ("angular velocities", s.angular_velocities.len()),
        ("contact counts", s.contacts.len()),
    ] {
        if len != n {
            return Err(invalid(format!(
                "snapshot of step {} has {n} positions but {len} {what}",
                s.step
            )));
        }
    }
    if !s.time.is_finite() {
        return Err(invalid(format!(
            "snapshot of step {}: non-finite time {}",
            s.step, s.time
        )));
    }
    if !(s.radius.is_finite() && s.radius > 0.0 && (s.radius * CM_TO_UM).is_finite()) {
        return Err(invalid(format!(
            "snapshot of step {}: monomer radius must be finite and positive, got {}",
            s.step, s.radius
        )));
    }
    for i in (0..n).filter(|_| non_finite == NonFinite::Refuse) {
        let checks = [
            ("position", s.positions[i], CM_TO_UM),
            ("velocity", s.velocities[i], 1.0 / CM_PER_S_PER_M_PER_S),
            ("angular velocity", s.angular_velocities[i], 1.0),
        ];
        for (what, v, scale) in checks {
            // Checking the converted value too catches the (absurd) positions that are finite
            // in cm but overflow in µm.
            if v.iter().any(|x| !x.is_finite() || !(x * scale).is_finite()) {
                return Err(invalid(format!(
                    "monomer {i} (id {}) at step {}: non-finite {what} {v:?}",
                    i + 1,
                    s.step
                )));
            }
        }
    }
    validate_walls(s.walls)
}

pub(super) fn validate_walls(walls: &[WallPlane]) -> io::Result<()> {
    for (i, wall) in walls.iter().enumerate() {
        if wall.name.is_empty()
            || wall
                .name
                .chars()
                .any(|c| c.is_whitespace() || c.is_control())
        {
            return Err(invalid(format!(
                "wall {i} ({:?}): name must be non-empty, without whitespace or control \
                 characters",
                wall.name
            )));
        }
        if wall
            .point
            .iter()
            .any(|x| !x.is_finite() || !(x * CM_TO_UM).is_finite())
        {
            return Err(invalid(format!(
                "wall {i} ({}): non-finite point {:?}",
                wall.name, wall.point
            )));
        }
        let n = unit(wall.normal);
        if n.iter().any(|x| !x.is_finite()) {
            return Err(invalid(format!(
                "wall {i} ({}): normal {:?} cannot be normalised",
                wall.name, wall.normal
            )));
        }
    }
    Ok(())
}
