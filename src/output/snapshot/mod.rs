//! Snapshot output for visualisation: VTK XML files for ParaView and LAMMPS text dumps for
//! OVITO.
//!
//! The simulation works in CGS (cm, cm/s), but monomers are micrometre-sized and both viewers
//! show bare numbers, so the files carry positions and radii in µm, velocities in m/s,
//! angular velocities in rad/s and time in s. Every file states these units itself (XML
//! comments and FieldData in the VTK files, extra `ITEM:` sections in the dump), so a file
//! found years later on its own can still be read correctly.
//!
//! Floating-point values are written with Rust's shortest round-trip representation
//! (`{:e}`), so what a reader parses is bit for bit the `f64` that was written; the only
//! rounding is the unit conversion itself, which is correctly rounded (half an ulp).
//!
//! Monomer `i` carries the id `i + 1` in both formats: LAMMPS requires positive atom ids, and
//! using the same id in the VTU file lets a monomer be followed from one viewer to the other.
//!
//! All files are written atomically (`output::atomic::write_atomic_with`: temporary file in the
//! same directory, fsync, rename), so a viewer polling the output directory, or a run killed
//! mid-write, never leaves a truncated snapshot behind under the real name.
//!
//! Here: what a snapshot holds and the public writers; `vtu`, `dump`, `vtp` (walls as polygons)
//! and the `.pvd` collection below write the formats, `validate` refuses what a viewer could
//! not show, `format` holds the atomic write and the number and XML formatting, and `series`
//! writes a run's state into its snapshot directory.

mod dump;
mod format;
pub mod series;
mod validate;
mod vtp;
mod vtu;

use dump::dump_body;
use format::{unit, write_atomically, XmlAttr, F};
use std::io::{self, Write};
use std::path::Path;
use validate::{invalid, validate_snapshot, validate_walls, NonFinite};
use vtp::{clip_plane_to_box, vtp_body, WallPolygon};
use vtu::vtu_body;

/// Internal length unit (cm) to file length unit (µm): multiply by this. Exact in binary,
/// so the converted value is correctly rounded.
pub(super) const CM_TO_UM: f64 = 1.0e4;
/// Internal velocity unit (cm/s) to file velocity unit (m/s): *divide* by this, because
/// 100 is exact in binary and 0.01 is not, and a division by an exact constant is
/// correctly rounded.
pub(super) const CM_PER_S_PER_M_PER_S: f64 = 100.0;
/// A wall counts as axis-aligned (and so as a face of the dump's box) when the other two
/// components of its unit normal are below this. Loose enough for normals that went through
/// a rotation or a normalisation, tight enough that a deliberately tilted wall is never
/// mistaken for a box face.
pub(super) const AXIS_ALIGNED_TOL: f64 = 1.0e-9;

/// An infinite plane wall.
#[derive(Debug, Clone, PartialEq)]
pub struct WallPlane {
    /// Written into the files to tell walls apart; must be non-empty and free of whitespace
    /// and control characters because the dump is whitespace-separated.
    pub name: String,
    /// Any point on the plane, cm.
    pub point: [f64; 3],
    /// Points into the domain; need not be of unit length (it is normalised on output).
    pub normal: [f64; 3],
}

/// The state of one time step, borrowed from the simulation so that writing a snapshot
/// copies nothing.
#[derive(Debug, Clone, Copy)]
pub struct Snapshot<'a> {
    pub step: u64,
    /// Simulated time, s.
    pub time: f64,
    /// Monomer radius, cm.
    pub radius: f64,
    /// cm.
    pub positions: &'a [[f64; 3]],
    /// cm/s.
    pub velocities: &'a [[f64; 3]],
    /// rad/s.
    pub angular_velocities: &'a [[f64; 3]],
    /// Number of contacts of each monomer.
    pub contacts: &'a [u32],
    pub walls: &'a [WallPlane],
}

/// Which file a snapshot is written as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SnapshotFormat {
    /// VTK XML unstructured grid, for ParaView.
    Vtu,
    /// LAMMPS text dump, for OVITO.
    LammpsDump,
}

impl SnapshotFormat {
    /// File name extension (without the dot) that the viewers recognise.
    pub fn extension(self) -> &'static str {
        match self {
            SnapshotFormat::Vtu => "vtu",
            SnapshotFormat::LammpsDump => "dump",
        }
    }

    /// Writes `s` to `path` in this format.
    pub fn write(self, path: &Path, s: &Snapshot) -> io::Result<()> {
        match self {
            SnapshotFormat::Vtu => write_vtu(path, s),
            SnapshotFormat::LammpsDump => write_lammps_dump(path, s),
        }
    }
}

/// Writes `s` as a VTK XML unstructured grid (`.vtu`) of `VTK_VERTEX` cells for ParaView.
///
/// Point data: `id` (Int64), `velocity` (m/s), `angular_velocity` (rad/s), `radius` (µm) and
/// `contacts` (UInt32); points in µm. FieldData holds `TimeValue` (s; VTK's XML readers
/// report it as the file's time, so ParaView shows simulated time even when the `.vtu` files
/// are opened as a plain file series without the `.pvd`), `step`, and the walls as
/// `wall_point` (µm) and `wall_normal` (unit, into the domain); wall names are in an XML
/// comment.
///
/// Refuses (with `InvalidInput`, before touching the file system) slices of different
/// lengths, non-finite values, a non-positive radius and unusable walls.
pub fn write_vtu(path: &Path, s: &Snapshot) -> io::Result<()> {
    validate_snapshot(s, NonFinite::Refuse)?;
    write_atomically(path, |w| vtu_body(w, s))
}

/// Writes a state that a run-time guard stopped (a blow-up) as [`write_vtu`] does, but keeps
/// non-finite positions, velocities and angular velocities as they are instead of refusing
/// them, so that the state can be inspected in ParaView.
///
/// VTK's ASCII readers do not parse `nan` or `inf` tokens reliably, so each array that holds a
/// non-finite value is written as inline binary data (`format="binary"`: base64 of a UInt64
/// byte count and the little-endian f64 values, the file declaring `header_type="UInt64"`),
/// which ParaView reads bit for bit, NaN and ±inf included; the other arrays stay ASCII. An
/// extra point array `finite` (UInt8) is 0 for the monomers holding a non-finite value
/// (threshold on it to find them) and an XML comment says so.
///
/// Everything else is checked as by [`write_vtu`]: lengths, time, radius and walls.
pub fn write_failed_vtu(path: &Path, s: &Snapshot) -> io::Result<()> {
    validate_snapshot(s, NonFinite::Keep)?;
    write_atomically(path, |w| vtu_body(w, s))
}

/// Writes `s` as a LAMMPS text dump for OVITO.
///
/// The layout is what LAMMPS itself writes with `dump_modify time yes`: `ITEM: TIME` (s),
/// `ITEM: TIMESTEP`, `ITEM: NUMBER OF ATOMS`, `ITEM: BOX BOUNDS` (µm) and
/// `ITEM: ATOMS id type x y z vx vy vz omegax omegay omegaz radius contacts`, all monomers of
/// type 1. The box is taken from the axis-aligned walls where they bound the domain
/// (flag `f`) and from the particle extent, including the radius, elsewhere (flag `s`).
///
/// Units and walls go in two extra sections, `ITEM: COLUMN UNITS` and `ITEM: WALLS`, which
/// OVITO skips as unknown items. They sit between `NUMBER OF ATOMS` and `BOX BOUNDS` because
/// every other place trips OVITO up: before `NUMBER OF ATOMS` an arbitrarily long wall list
/// could push it out of the first 20 lines, where OVITO looks to recognise a dump; after
/// the atom lines OVITO stops finding frames in concatenated dumps (`cat snap_*.dump`); and
/// directly before `ATOMS` OVITO misses the `ATOMS` line of an empty snapshot, where it is
/// the last line of the file. Readers that expect every header line at a fixed position
/// cannot read these files, but they cannot read LAMMPS's own `ITEM: TIME` either.
pub fn write_lammps_dump(path: &Path, s: &Snapshot) -> io::Result<()> {
    validate_snapshot(s, NonFinite::Refuse)?;
    write_atomically(path, |w| dump_body(w, s))
}

/// Writes the walls as polygons (`.vtp`) for ParaView, each plane clipped to the axis-aligned
/// box `extent = (min corner, max corner)` in cm.
///
/// Walls parallel to a face of the box come out as rectangles; a tilted wall becomes the
/// convex polygon (up to a hexagon) where it cuts the box, wound counter-clockwise about
/// its normal so that the polygon's normal points into the domain. A wall that misses the
/// box, or only touches it along an edge or at a corner, has no polygon. Cell data `wall`
/// is the index into `walls` and `normal` the unit normal; names are in an XML comment.
pub fn write_walls_vtp(
    path: &Path,
    walls: &[WallPlane],
    extent: ([f64; 3], [f64; 3]),
) -> io::Result<()> {
    validate_walls(walls)?;
    let (lo, hi) = extent;
    for k in 0..3 {
        let ok = lo[k].is_finite()
            && hi[k].is_finite()
            && (lo[k] * CM_TO_UM).is_finite()
            && (hi[k] * CM_TO_UM).is_finite()
            && lo[k] <= hi[k];
        if !ok {
            return Err(invalid(format!(
                "wall extent is not a finite box with min <= max: min {lo:?}, max {hi:?}"
            )));
        }
    }
    let polygons: Vec<WallPolygon> = walls
        .iter()
        .enumerate()
        .filter_map(|(i, wall)| {
            let n = unit(wall.normal);
            let vertices = clip_plane_to_box(wall.point, n, lo, hi);
            (vertices.len() >= 3).then_some(WallPolygon {
                wall: i,
                normal: n,
                vertices,
            })
        })
        .collect();
    write_atomically(path, |w| vtp_body(w, walls, &polygons))
}

/// Writes a ParaView collection (`.pvd`) listing `entries` as `(time in s, file name)`, so
/// that ParaView opens a whole run as one time series with the simulated time on its time
/// axis. File names are taken relative to the directory of the `.pvd` file, which is how
/// ParaView resolves them.
pub fn write_pvd(path: &Path, entries: &[(f64, String)]) -> io::Result<()> {
    for (i, (time, file)) in entries.iter().enumerate() {
        if !time.is_finite() {
            return Err(invalid(format!(
                "pvd entry {i} ({file}): non-finite time {time}"
            )));
        }
        if file.is_empty() {
            return Err(invalid(format!("pvd entry {i}: empty file name")));
        }
    }
    write_atomically(path, |w| {
        writeln!(w, r#"<?xml version="1.0"?>"#)?;
        writeln!(
            w,
            "<!-- dustdem snapshot series; timestep is the simulated time in s -->"
        )?;
        writeln!(
            w,
            r#"<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">"#
        )?;
        writeln!(w, "  <Collection>")?;
        for (time, file) in entries {
            writeln!(
                w,
                r#"    <DataSet timestep="{}" group="" part="0" file="{}"/>"#,
                F(*time),
                XmlAttr(file)
            )?;
        }
        writeln!(w, "  </Collection>")?;
        writeln!(w, "</VTKFile>")
    })
}
