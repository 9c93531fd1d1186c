//! Snapshots of a run's state for ParaView (VTU + PVD collections) and OVITO (LAMMPS dump),
//! written into `<out>/snapshots/`.

use super::{write_lammps_dump, write_pvd, write_vtu, write_walls_vtp, Snapshot, WallPlane};
use crate::config::SnapshotChoice;
use crate::state::State;
use std::io;
use std::path::{Path, PathBuf};

/// The snapshot directory inside an output directory.
pub const SNAPSHOT_DIR: &str = "snapshots";

/// Whether `name` is a file [`write_snapshot`] writes: `snap_<step>[tag].vtu|.dump`,
/// `walls_<step>[tag].vtp`, `run.pvd` or `walls.pvd`.
pub fn is_snapshot_file(name: &str) -> bool {
    let numbered = |prefix: &str, suffixes: &[&str]| {
        name.strip_prefix(prefix).is_some_and(|rest| {
            rest.starts_with(|c: char| c.is_ascii_digit())
                && suffixes.iter().any(|s| rest.ends_with(s))
        })
    };
    name == "run.pvd"
        || name == "walls.pvd"
        || numbered("snap_", &[".vtu", ".dump"])
        || numbered("walls_", &[".vtp"])
}

fn arr(v: glam::DVec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// Writes the state as `snap_<step>.vtu` / `.dump` (and the walls as
/// `walls_<step>.vtp`), then rewrites `run.pvd` and `walls.pvd` to list every snapshot in the
/// directory, so a resumed run extends the same series. `tag` names special snapshots
/// (e.g. "failed"). Returns the files written.
pub fn write_snapshot(
    out_dir: &Path,
    choice: SnapshotChoice,
    state: &State,
    tag: &str,
) -> io::Result<Vec<PathBuf>> {
    if choice == SnapshotChoice::None {
        return Ok(Vec::new());
    }
    let dir = out_dir.join(SNAPSHOT_DIR);
    std::fs::create_dir_all(&dir)?;
    let m = &state.monomers;
    let n = m.len();
    let positions: Vec<[f64; 3]> = m.position.iter().map(|p| arr(*p)).collect();
    let velocities: Vec<[f64; 3]> = (0..n)
        .map(|i| arr(state.synchronized_velocity(i)))
        .collect();
    let spins: Vec<[f64; 3]> = (0..n)
        .map(|i| arr(state.synchronized_angular_velocity(i)))
        .collect();
    let contacts = state.contacts.coordination();
    let walls: Vec<WallPlane> = state
        .walls
        .iter()
        .map(|w| WallPlane {
            name: w.name.replace(' ', "_"),
            point: arr(w.point),
            normal: arr(w.normal),
        })
        .collect();
    let snapshot = Snapshot {
        step: state.step,
        time: state.time,
        radius: state.law.radius,
        positions: &positions,
        velocities: &velocities,
        angular_velocities: &spins,
        contacts: &contacts,
        walls: &walls,
    };
    let stem = format!("snap_{:010}{tag}", state.step);
    let mut written = Vec::new();
    if matches!(choice, SnapshotChoice::Vtu | SnapshotChoice::Both) {
        let path = dir.join(format!("{stem}.vtu"));
        write_vtu(&path, &snapshot)?;
        written.push(path);
        let (lo, hi) = bounds(state);
        let walls_path = dir.join(format!("walls_{:010}{tag}.vtp", state.step));
        write_walls_vtp(&walls_path, &walls, (lo, hi))?;
        written.push(walls_path);
    }
    if matches!(choice, SnapshotChoice::Lammps | SnapshotChoice::Both) {
        let path = dir.join(format!("{stem}.dump"));
        write_lammps_dump(&path, &snapshot)?;
        written.push(path);
    }
    if tag.is_empty() && matches!(choice, SnapshotChoice::Vtu | SnapshotChoice::Both) {
        write_collection(&dir, "snap_", ".vtu", "run.pvd", state.dt)?;
        write_collection(&dir, "walls_", ".vtp", "walls.pvd", state.dt)?;
    }
    Ok(written)
}

/// Bounding box of monomers and wall points, padded by a diameter, for clipping wall planes.
fn bounds(state: &State) -> ([f64; 3], [f64; 3]) {
    let pad = glam::DVec3::splat(2.0 * state.law.radius);
    let mut lo = glam::DVec3::splat(f64::INFINITY);
    let mut hi = glam::DVec3::splat(f64::NEG_INFINITY);
    for p in state
        .monomers
        .position
        .iter()
        .chain(state.walls.iter().map(|w| &w.point))
    {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if !lo.is_finite() {
        return ([0.0; 3], [0.0; 3]);
    }
    (arr(lo - pad), arr(hi + pad))
}

/// Lists `<prefix><step><suffix>` files (untagged) in step order, with time ≈ step·dt.
fn write_collection(dir: &Path, prefix: &str, suffix: &str, name: &str, dt: f64) -> io::Result<()> {
    let mut entries: Vec<(u64, String)> = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let file = entry?.file_name().to_string_lossy().into_owned();
        if let Some(step) = file
            .strip_prefix(prefix)
            .and_then(|rest| rest.strip_suffix(suffix))
            .and_then(|digits| digits.parse::<u64>().ok())
        {
            entries.push((step, file));
        }
    }
    entries.sort();
    let list: Vec<(f64, String)> = entries
        .into_iter()
        .map(|(step, file)| (step as f64 * dt, file))
        .collect();
    write_pvd(&dir.join(name), &list)
}
