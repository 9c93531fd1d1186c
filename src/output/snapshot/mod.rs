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
//! All files are written atomically (temporary file in the same directory, fsync, rename), so
//! a viewer polling the output directory, or a run killed mid-write, never leaves a
//! truncated snapshot behind under the real name.

pub mod series;

use std::ffi::OsString;
use std::fmt;
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// Internal length unit (cm) to file length unit (µm): multiply by this. Exact in binary,
/// so the converted value is correctly rounded.
const CM_TO_UM: f64 = 1.0e4;
/// Internal velocity unit (cm/s) to file velocity unit (m/s): *divide* by this, because
/// 100 is exact in binary and 0.01 is not, and a division by an exact constant is
/// correctly rounded.
const CM_PER_S_PER_M_PER_S: f64 = 100.0;
/// A wall counts as axis-aligned (and so as a face of the dump's box) when the other two
/// components of its unit normal are below this. Loose enough for normals that went through
/// a rotation or a normalisation, tight enough that a deliberately tilted wall is never
/// mistaken for a box face.
const AXIS_ALIGNED_TOL: f64 = 1.0e-9;

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
    validate_snapshot(s)?;
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
    validate_snapshot(s)?;
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

// ---------------------------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------------------------

fn invalid(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, msg)
}

/// Everything is checked before the temporary file is created, so that a refused snapshot
/// leaves nothing behind and the error names the offending monomer rather than surfacing as
/// an unreadable `NaN` in a viewer.
fn validate_snapshot(s: &Snapshot) -> io::Result<()> {
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
    for i in 0..n {
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

fn validate_walls(walls: &[WallPlane]) -> io::Result<()> {
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

// ---------------------------------------------------------------------------------------------
// Atomic writing
// ---------------------------------------------------------------------------------------------

/// Distinguishes temporary files of concurrent writers within one process.
static TMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes through `body` into a hidden temporary file next to `path`, fsyncs it and renames
/// it over `path`. Same directory, because a rename is only atomic within one file system.
/// The leading dot keeps ParaView's file-series grouping from picking the file up while it
/// is being written. On any error the temporary file is removed and `path` is untouched.
fn write_atomically<F>(path: &Path, body: F) -> io::Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> io::Result<()>,
{
    let file_name = path
        .file_name()
        .ok_or_else(|| invalid(format!("{} does not name a file", path.display())))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp_name = OsString::from(".");
    tmp_name.push(file_name);
    tmp_name.push(format!(
        ".{}.{}.tmp",
        std::process::id(),
        TMP_COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let tmp = dir.join(tmp_name);

    // Errors from the file system carry no path; a run's log should say which file failed.
    let context =
        |e: io::Error| io::Error::new(e.kind(), format!("writing {}: {e}", path.display()));
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .map_err(context)?;
    let written = (|| {
        let mut w = BufWriter::new(file);
        body(&mut w)?;
        let file = w.into_inner().map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        drop(file);
        fs::rename(&tmp, path)
    })();
    if let Err(e) = written {
        let _ = fs::remove_file(&tmp);
        return Err(context(e));
    }
    // Make the rename itself durable. Best effort: the new file is already in place and
    // complete, and some file systems refuse to fsync a directory; that is no reason to
    // abort a run.
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Formatting helpers
// ---------------------------------------------------------------------------------------------

/// An `f64` in the shortest form that parses back to the same bits (`1.5e-3`, `0e0`).
/// Scientific notation keeps tiny and huge values short, and every VTK, OVITO and C
/// `strtod` parser accepts it.
struct F(f64);

impl fmt::Display for F {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:e}", self.0)
    }
}

/// Three values separated by spaces.
struct V3([f64; 3]);

impl fmt::Display for V3 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} {}", F(self.0[0]), F(self.0[1]), F(self.0[2]))
    }
}

/// Text escaped for an XML attribute value.
struct XmlAttr<'a>(&'a str);

impl fmt::Display for XmlAttr<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for c in self.0.chars() {
            match c {
                '&' => f.write_str("&amp;")?,
                '<' => f.write_str("&lt;")?,
                '>' => f.write_str("&gt;")?,
                '"' => f.write_str("&quot;")?,
                '\'' => f.write_str("&apos;")?,
                // Parsers normalise literal line breaks and tabs in attributes to spaces.
                '\n' => f.write_str("&#10;")?,
                '\r' => f.write_str("&#13;")?,
                '\t' => f.write_str("&#9;")?,
                _ => write!(f, "{c}")?,
            }
        }
        Ok(())
    }
}

/// Text that is safe inside an XML comment, which may not contain `--`. Only used for wall
/// names, which are for people to read, so bending a doubled hyphen is harmless.
struct XmlComment<'a>(&'a str);

impl fmt::Display for XmlComment<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut prev_hyphen = false;
        for c in self.0.chars() {
            if c == '-' && prev_hyphen {
                f.write_str("~")?;
                prev_hyphen = false;
            } else {
                write!(f, "{c}")?;
                prev_hyphen = c == '-';
            }
        }
        Ok(())
    }
}

fn scale(v: [f64; 3], k: f64) -> [f64; 3] {
    [v[0] * k, v[1] * k, v[2] * k]
}

fn to_m_per_s(v: [f64; 3]) -> [f64; 3] {
    [
        v[0] / CM_PER_S_PER_M_PER_S,
        v[1] / CM_PER_S_PER_M_PER_S,
        v[2] / CM_PER_S_PER_M_PER_S,
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `v / |v|`; non-finite for a zero or non-finite `v`, which validation turns into an error.
fn unit(v: [f64; 3]) -> [f64; 3] {
    // hypot avoids overflow/underflow for normals given with extreme magnitudes.
    let len = v[0].hypot(v[1]).hypot(v[2]);
    if len > 0.0 {
        scale(v, 1.0 / len)
    } else {
        [f64::NAN; 3]
    }
}

/// Writes a `DataArray` of vectors, one tuple per line.
fn vector_array<W: Write>(
    w: &mut W,
    name: &str,
    values: impl Iterator<Item = [f64; 3]>,
) -> io::Result<()> {
    writeln!(
        w,
        r#"        <DataArray type="Float64" Name="{name}" NumberOfComponents="3" format="ascii">"#
    )?;
    for v in values {
        writeln!(w, "          {}", V3(v))?;
    }
    writeln!(w, "        </DataArray>")
}

/// Writes a single-component `DataArray`, a handful of values per line.
fn scalar_array<W: Write, T: fmt::Display>(
    w: &mut W,
    ty: &str,
    name: &str,
    values: impl Iterator<Item = T>,
) -> io::Result<()> {
    writeln!(
        w,
        r#"        <DataArray type="{ty}" Name="{name}" format="ascii">"#
    )?;
    for (i, v) in values.enumerate() {
        if i % 8 == 0 {
            if i > 0 {
                writeln!(w)?;
            }
            write!(w, "         ")?;
        }
        write!(w, " {v}")?;
    }
    writeln!(w)?;
    writeln!(w, "        </DataArray>")
}

// ---------------------------------------------------------------------------------------------
// VTU
// ---------------------------------------------------------------------------------------------

fn wall_comment<W: Write>(w: &mut W, walls: &[WallPlane], indent: &str) -> io::Result<()> {
    if walls.is_empty() {
        return writeln!(w, "{indent}walls: none");
    }
    writeln!(
        w,
        "{indent}walls (point in um, unit normal into the domain):"
    )?;
    for (i, wall) in walls.iter().enumerate() {
        writeln!(
            w,
            "{indent}  {i} {}: point {} normal {}",
            XmlComment(&wall.name),
            V3(scale(wall.point, CM_TO_UM)),
            V3(unit(wall.normal))
        )?;
    }
    Ok(())
}

fn vtu_body<W: Write>(w: &mut W, s: &Snapshot) -> io::Result<()> {
    let n = s.positions.len();
    let r_um = s.radius * CM_TO_UM;
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        "<!-- dustdem snapshot: step {}, time {} s",
        s.step,
        F(s.time)
    )?;
    writeln!(
        w,
        "     units: points and radius in um, velocity in m/s, angular_velocity in rad/s, \
         time in s"
    )?;
    writeln!(
        w,
        "     id = monomer index + 1, the same id as in the LAMMPS dump"
    )?;
    wall_comment(w, s.walls, "     ")?;
    writeln!(w, "-->")?;
    writeln!(
        w,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">"#
    )?;
    writeln!(w, "  <UnstructuredGrid>")?;

    writeln!(w, "    <FieldData>")?;
    writeln!(
        w,
        r#"      <DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="ascii">{}</DataArray>"#,
        F(s.time)
    )?;
    writeln!(
        w,
        r#"      <DataArray type="UInt64" Name="step" NumberOfTuples="1" format="ascii">{}</DataArray>"#,
        s.step
    )?;
    // Zero-tuple arrays upset some readers, so without walls there are simply no wall arrays.
    if !s.walls.is_empty() {
        for (name, values) in [
            (
                "wall_point",
                s.walls
                    .iter()
                    .map(|wall| scale(wall.point, CM_TO_UM))
                    .collect::<Vec<_>>(),
            ),
            (
                "wall_normal",
                s.walls.iter().map(|wall| unit(wall.normal)).collect(),
            ),
        ] {
            writeln!(
                w,
                r#"      <DataArray type="Float64" Name="{name}" NumberOfComponents="3" NumberOfTuples="{}" format="ascii">"#,
                values.len()
            )?;
            for v in values {
                writeln!(w, "        {}", V3(v))?;
            }
            writeln!(w, "      </DataArray>")?;
        }
    }
    writeln!(w, "    </FieldData>")?;

    writeln!(w, r#"    <Piece NumberOfPoints="{n}" NumberOfCells="{n}">"#)?;
    writeln!(
        w,
        r#"      <PointData Scalars="radius" Vectors="velocity">"#
    )?;
    scalar_array(w, "Int64", "id", (1..=n as u64).map(|id| id as i64))?;
    vector_array(w, "velocity", s.velocities.iter().map(|&v| to_m_per_s(v)))?;
    vector_array(w, "angular_velocity", s.angular_velocities.iter().copied())?;
    scalar_array(w, "Float64", "radius", (0..n).map(|_| F(r_um)))?;
    scalar_array(w, "UInt32", "contacts", s.contacts.iter())?;
    writeln!(w, "      </PointData>")?;
    writeln!(w, "      <Points>")?;
    vector_array(
        w,
        "position",
        s.positions.iter().map(|&p| scale(p, CM_TO_UM)),
    )?;
    writeln!(w, "      </Points>")?;
    writeln!(w, "      <Cells>")?;
    scalar_array(w, "Int64", "connectivity", 0..n as u64)?;
    scalar_array(w, "Int64", "offsets", 1..=n as u64)?;
    // 1 = VTK_VERTEX: each monomer is a cell of its own, so ParaView renders the points
    // without a filter and cell-based filters see every monomer.
    scalar_array(w, "UInt8", "types", (0..n).map(|_| 1u8))?;
    writeln!(w, "      </Cells>")?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")
}

// ---------------------------------------------------------------------------------------------
// LAMMPS dump
// ---------------------------------------------------------------------------------------------

/// Box bounds in µm, `[lo, hi]` per axis, and the LAMMPS boundary flags: `f` for a side
/// bounded by a wall, `s` (shrink-wrapped) for a side taken from the particles.
fn box_bounds(s: &Snapshot) -> ([[f64; 2]; 3], [[char; 2]; 3]) {
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

fn dump_body<W: Write>(w: &mut W, s: &Snapshot) -> io::Result<()> {
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

// ---------------------------------------------------------------------------------------------
// Walls as polygons
// ---------------------------------------------------------------------------------------------

/// Where one wall cuts the box.
struct WallPolygon {
    /// Index into the caller's walls.
    wall: usize,
    /// Unit normal, into the domain.
    normal: [f64; 3],
    /// cm, counter-clockwise about `normal`.
    vertices: Vec<[f64; 3]>,
}

/// The polygon in which the plane through `p` with unit normal `n` cuts the box `[lo, hi]`,
/// in cm, wound counter-clockwise about `n`. Fewer than three vertices when the plane
/// misses the box or only grazes an edge or a corner.
fn clip_plane_to_box(p: [f64; 3], n: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
    let size = dot(sub(hi, lo), sub(hi, lo)).sqrt();
    // Distances below this count as "on the plane", so that a wall lying exactly on a face
    // of the box (the usual floor) yields that face rather than a sliver or nothing.
    let eps = 1.0e-12 * size;
    let corner = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    let dist: Vec<f64> = (0..8).map(|i| dot(n, sub(corner(i), p))).collect();

    let mut pts: Vec<[f64; 3]> = Vec::new();
    for (i, d) in dist.iter().enumerate() {
        if d.abs() <= eps {
            pts.push(corner(i));
        }
    }
    for i in 0..8 {
        for bit in [1, 2, 4] {
            if i & bit != 0 {
                continue;
            }
            let j = i | bit;
            let (da, db) = (dist[i], dist[j]);
            if da.abs() > eps && db.abs() > eps && (da < 0.0) != (db < 0.0) {
                let t = da / (da - db);
                let (a, b) = (corner(i), corner(j));
                pts.push([
                    a[0] + t * (b[0] - a[0]),
                    a[1] + t * (b[1] - a[1]),
                    a[2] + t * (b[2] - a[2]),
                ]);
            }
        }
    }

    // A corner on the plane is reached from several edges; keep it once.
    let merge = 1.0e-9 * size;
    let mut unique: Vec<[f64; 3]> = Vec::with_capacity(pts.len());
    for q in pts {
        if unique.iter().all(|u| {
            let d = sub(q, *u);
            dot(d, d).sqrt() > merge
        }) {
            unique.push(q);
        }
    }
    if unique.len() < 3 {
        return Vec::new();
    }

    // In-plane basis (u, v) with u x v = n, so ascending angle is counter-clockwise about n.
    let k = (0..3)
        .min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let u = unit(cross(n, e));
    let v = cross(n, u);
    let m = unique.len() as f64;
    let c = unique.iter().fold([0.0; 3], |acc, q| {
        [acc[0] + q[0] / m, acc[1] + q[1] / m, acc[2] + q[2] / m]
    });
    let angle = |q: &[f64; 3]| {
        let d = sub(*q, c);
        dot(d, v).atan2(dot(d, u))
    };
    unique.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
    unique
}

fn vtp_body<W: Write>(w: &mut W, walls: &[WallPlane], polygons: &[WallPolygon]) -> io::Result<()> {
    let n_points: usize = polygons.iter().map(|p| p.vertices.len()).sum();
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        "<!-- dustdem walls clipped to the domain's bounding box; points in um"
    )?;
    wall_comment(w, walls, "     ")?;
    writeln!(w, "     cell data wall = index in the list above -->")?;
    writeln!(
        w,
        r#"<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian">"#
    )?;
    writeln!(w, "  <PolyData>")?;
    writeln!(
        w,
        r#"    <Piece NumberOfPoints="{n_points}" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="{}">"#,
        polygons.len()
    )?;
    writeln!(w, "      <PointData>")?;
    writeln!(w, "      </PointData>")?;
    writeln!(w, r#"      <CellData Scalars="wall" Normals="normal">"#)?;
    scalar_array(w, "Int32", "wall", polygons.iter().map(|p| p.wall))?;
    vector_array(w, "normal", polygons.iter().map(|p| p.normal))?;
    writeln!(w, "      </CellData>")?;
    writeln!(w, "      <Points>")?;
    vector_array(
        w,
        "position",
        polygons
            .iter()
            .flat_map(|p| p.vertices.iter().map(|&q| scale(q, CM_TO_UM))),
    )?;
    writeln!(w, "      </Points>")?;
    writeln!(w, "      <Polys>")?;
    scalar_array(w, "Int64", "connectivity", 0..n_points as u64)?;
    scalar_array(
        w,
        "Int64",
        "offsets",
        polygons.iter().scan(0usize, |end, p| {
            *end += p.vertices.len();
            Some(*end)
        }),
    )?;
    writeln!(w, "      </Polys>")?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </PolyData>")?;
    writeln!(w, "</VTKFile>")
}
