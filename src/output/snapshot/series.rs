//! Snapshots of a run's state for ParaView (VTU + PVD collections) and OVITO (LAMMPS dump),
//! written into `<out>/snapshots/`.

use super::{
    write_failed_vtu, write_lammps_dump, write_pvd, write_vtu, write_walls_vtp, Snapshot, WallPlane,
};
use crate::config::SnapshotChoice;
use crate::state::{simulated_time, State};
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
    let owned = Owned::of(state);
    let snapshot = owned.snapshot(state);
    let stem = format!("snap_{:010}{tag}", state.step);
    let mut written = Vec::new();
    if matches!(choice, SnapshotChoice::Vtu | SnapshotChoice::Both) {
        let path = dir.join(format!("{stem}.vtu"));
        write_vtu(&path, &snapshot)?;
        written.push(path);
        written.push(write_walls(&dir, state, &owned.walls, tag)?);
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

/// Writes a state a run-time guard stopped as `snap_<step>_failed.vtu` and
/// `walls_<step>_failed.vtp`, whatever the snapshot format of the run: non-finite values are
/// kept as they are (in binary arrays, see [`write_failed_vtu`]) and a point array `finite`
/// marks the monomers that hold one. The series files are left as they are.
pub fn write_failed_snapshot(out_dir: &Path, state: &State) -> io::Result<Vec<PathBuf>> {
    let dir = out_dir.join("snapshots");
    std::fs::create_dir_all(&dir)?;
    let owned = Owned::of(state);
    let path = dir.join(format!("snap_{:010}_failed.vtu", state.step));
    write_failed_vtu(&path, &owned.snapshot(state))?;
    let walls = write_walls(&dir, state, &owned.walls, "_failed")?;
    Ok(vec![path, walls])
}

/// The per-monomer arrays and walls of a snapshot, in the files' layout.
struct Owned {
    positions: Vec<[f64; 3]>,
    velocities: Vec<[f64; 3]>,
    spins: Vec<[f64; 3]>,
    contacts: Vec<u32>,
    walls: Vec<WallPlane>,
}

impl Owned {
    /// The state's monomers in sample-id order (the engines may store them in another
    /// order), so monomer `id` is line `id + 1` in every snapshot of a run.
    fn of(state: &State) -> Owned {
        let m = &state.monomers;
        let order: Vec<usize> = m.index_of_ids().unwrap_or_else(|| (0..m.len()).collect());
        let coordination = state.contacts.coordination();
        Owned {
            positions: order.iter().map(|&i| arr(m.position[i])).collect(),
            velocities: order
                .iter()
                .map(|&i| arr(state.synchronized_velocity(i)))
                .collect(),
            spins: order
                .iter()
                .map(|&i| arr(state.synchronized_angular_velocity(i)))
                .collect(),
            contacts: order.iter().map(|&i| coordination[i]).collect(),
            walls: state
                .walls
                .iter()
                .map(|w| WallPlane {
                    name: w.name.replace(' ', "_"),
                    point: arr(w.point),
                    normal: arr(w.normal),
                })
                .collect(),
        }
    }

    fn snapshot<'a>(&'a self, state: &State) -> Snapshot<'a> {
        Snapshot {
            step: state.step,
            time: simulated_time(state.step, state.dt),
            radius: state.law.radius,
            positions: &self.positions,
            velocities: &self.velocities,
            angular_velocities: &self.spins,
            contacts: &self.contacts,
            walls: &self.walls,
        }
    }
}

/// `walls_<step><tag>.vtp`: the wall planes clipped to the monomers' bounding box.
fn write_walls(dir: &Path, state: &State, walls: &[WallPlane], tag: &str) -> io::Result<PathBuf> {
    let path = dir.join(format!("walls_{:010}{tag}.vtp", state.step));
    write_walls_vtp(&path, walls, bounds(state))?;
    Ok(path)
}

/// Bounding box of monomers and wall points, padded by a diameter, for clipping wall planes.
/// Non-finite positions (a failed state) are left out, and where the finite ones span more
/// than the files can hold, the box is that of the wall points alone.
fn bounds(state: &State) -> ([f64; 3], [f64; 3]) {
    let pad = glam::DVec3::splat(2.0 * state.law.radius);
    let wall_points = state.walls.iter().map(|w| w.point);
    let finite = state
        .monomers
        .position
        .iter()
        .copied()
        .filter(|p| p.is_finite());
    let fits =
        |(lo, hi): &(glam::DVec3, glam::DVec3)| (*lo * 1e4).is_finite() && (*hi * 1e4).is_finite();
    let all = extent(finite.chain(wall_points.clone()), pad);
    match all
        .filter(fits)
        .or_else(|| extent(wall_points, pad).filter(fits))
    {
        Some((lo, hi)) => (arr(lo), arr(hi)),
        None => ([0.0; 3], [0.0; 3]),
    }
}

/// The smallest box holding `points`, widened by `pad` on every side (`None` for no points).
fn extent(
    points: impl Iterator<Item = glam::DVec3>,
    pad: glam::DVec3,
) -> Option<(glam::DVec3, glam::DVec3)> {
    let mut lo = glam::DVec3::splat(f64::INFINITY);
    let mut hi = glam::DVec3::splat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    lo.is_finite().then_some((lo - pad, hi + pad))
}

/// Lists `<prefix><step><suffix>` files (untagged) in step order, with their simulated time.
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
        .map(|(step, file)| (simulated_time(step, dt), file))
        .collect();
    write_pvd(&dir.join(name), &list)
}
