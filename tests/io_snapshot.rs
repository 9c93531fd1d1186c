//! Snapshot files are read back by readers that share no code with the writers: `vtkio` for
//! the VTK XML files, and small whitespace-splitting / string-scanning readers written here
//! for the LAMMPS dump, the FieldData and the `.pvd` collection.
//!
//! Values are compared bit for bit against the correctly rounded unit conversion (`x * 1e4`
//! for cm to µm, `v / 100` for cm/s to m/s): the conversion is the only rounding the files
//! may add.

use dustdem::output::snapshot::{
    write_failed_vtu, write_lammps_dump, write_pvd, write_vtu, write_walls_vtp, Snapshot,
    SnapshotFormat, WallPlane,
};
use dustdem::rng::Rng;
use std::fs;
use std::path::{Path, PathBuf};
use vtkio::model::{Attribute, DataSet, IOBuffer, Piece, VertexNumbers};
use vtkio::Vtk;

const UM_PER_CM: f64 = 1.0e4;
const CM_PER_S_PER_M_PER_S: f64 = 100.0;

/// A fresh directory per test, so that the "no leftover files" checks see only their own
/// output.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!(
            "dustdem-snapshot-test-{}-{name}",
            std::process::id()
        ));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    fn path(&self, file: &str) -> PathBuf {
        self.0.join(file)
    }

    fn entries(&self) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

struct Data {
    positions: Vec<[f64; 3]>,
    velocities: Vec<[f64; 3]>,
    angular_velocities: Vec<[f64; 3]>,
    contacts: Vec<u32>,
    walls: Vec<WallPlane>,
}

const RADIUS: f64 = 0.6e-4; // 0.6 µm in cm

fn data(n: usize, seed: u64) -> Data {
    let mut rng = Rng::new(seed);
    let mut v3 = |s: f64| {
        [
            rng.uniform_range(-1.0, 1.0) * s,
            rng.uniform_range(-1.0, 1.0) * s,
            rng.uniform_range(-1.0, 1.0) * s,
        ]
    };
    let mut positions: Vec<[f64; 3]> = (0..n).map(|_| v3(20.0e-4)).collect();
    let mut velocities: Vec<[f64; 3]> = (0..n).map(|_| v3(150.0)).collect();
    let angular_velocities: Vec<[f64; 3]> = (0..n).map(|_| v3(1.0e6)).collect();
    // Values that trip naive formatting: negative zero, subnormal, huge, tiny.
    if n >= 4 {
        positions[0] = [-0.0, 0.0, 5e-324];
        positions[1] = [1.0e-300, -1.0e300, 0.1];
        velocities[2] = [-0.0, 1.0e-310, f64::MAX / 1.0e3];
        positions[3] = [1.0 / 3.0, -2.0 / 3.0, 1.0e-4];
    }
    let contacts = (0..n).map(|i| (i % 13) as u32).collect();
    let walls = vec![
        WallPlane {
            name: "floor".into(),
            point: [0.0, 0.0, -25.0e-4],
            normal: [0.0, 0.0, 1.0],
        },
        WallPlane {
            name: "piston".into(),
            point: [3.0, 1.0, 25.0e-4],
            normal: [0.0, 0.0, -2.0],
        },
        WallPlane {
            name: "side--x".into(),
            point: [-30.0e-4, 0.0, 0.0],
            normal: [1.0, 0.0, 0.0],
        },
        // Tilted: bounds the domain but is no face of the dump's box.
        WallPlane {
            name: "slope".into(),
            point: [0.0, 40.0e-4, 0.0],
            normal: [0.0, -1.0, 1.0],
        },
    ];
    Data {
        positions,
        velocities,
        angular_velocities,
        contacts,
        walls,
    }
}

fn snapshot(d: &Data) -> Snapshot<'_> {
    Snapshot {
        step: 123_456_789_012,
        time: 1.234_567_890_123_456_7e-3,
        radius: RADIUS,
        positions: &d.positions,
        velocities: &d.velocities,
        angular_velocities: &d.angular_velocities,
        contacts: &d.contacts,
        walls: &d.walls,
    }
}

fn assert_bits(what: &str, i: usize, got: f64, want: f64) {
    assert_eq!(
        got.to_bits(),
        want.to_bits(),
        "{what} of monomer {i}: read {got:e}, expected {want:e}"
    );
}

// -------------------------------------------------------------------------------------------
// Independent readers
// -------------------------------------------------------------------------------------------

/// A LAMMPS text dump split into `ITEM:` sections, each a header line and its body lines.
struct Dump {
    sections: Vec<(String, Vec<String>)>,
}

impl Dump {
    fn read(path: &Path) -> Dump {
        let text = fs::read_to_string(path).unwrap();
        let mut sections: Vec<(String, Vec<String>)> = Vec::new();
        for line in text.lines() {
            if let Some(header) = line.strip_prefix("ITEM: ") {
                sections.push((header.to_string(), Vec::new()));
            } else {
                sections
                    .last_mut()
                    .expect("dump must start with an ITEM: line")
                    .1
                    .push(line.to_string());
            }
        }
        Dump { sections }
    }

    fn section(&self, prefix: &str) -> (&str, &[String]) {
        let found: Vec<_> = self
            .sections
            .iter()
            .filter(|(h, _)| h == prefix || h.starts_with(&format!("{prefix} ")))
            .collect();
        assert_eq!(found.len(), 1, "expected exactly one ITEM: {prefix}");
        (&found[0].0, &found[0].1)
    }

    fn single(&self, item: &str) -> String {
        let (_, body) = self.section(item);
        assert_eq!(body.len(), 1, "ITEM: {item} must have one value line");
        body[0].trim().to_string()
    }
}

struct VtuRead {
    points: Vec<f64>,
    point_data: Vec<(String, IOBuffer)>,
    connectivity: Vec<u64>,
    offsets: Vec<u64>,
    types: Vec<vtkio::model::CellType>,
}

fn read_vtu(path: &Path) -> VtuRead {
    let vtk = Vtk::import(path).expect("vtkio cannot read the .vtu");
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid");
    };
    assert_eq!(pieces.len(), 1);
    let Piece::Inline(piece) = pieces.into_iter().next().unwrap() else {
        panic!("piece not inline");
    };
    let IOBuffer::F64(points) = piece.points else {
        panic!("points are not Float64");
    };
    let VertexNumbers::XML {
        connectivity,
        offsets,
    } = piece.cells.cell_verts
    else {
        panic!("cells not in XML layout");
    };
    let point_data = piece
        .data
        .point
        .into_iter()
        .map(|a| match a {
            Attribute::DataArray(a) => (a.name, a.data),
            Attribute::Field { name, .. } => panic!("unexpected field attribute {name}"),
        })
        .collect();
    VtuRead {
        points,
        point_data,
        connectivity,
        offsets,
        types: piece.cells.types,
    }
}

impl VtuRead {
    fn array(&self, name: &str) -> &IOBuffer {
        &self
            .point_data
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("no point data {name}"))
            .1
    }
}

/// The text content of the first `<DataArray ... Name="name" ...>` element, split on
/// whitespace. vtkio does not expose FieldData, so this reads it by plain string search.
fn data_array_text(xml: &str, name: &str) -> Vec<String> {
    let key = format!("Name=\"{name}\"");
    let at = xml.find(&key).unwrap_or_else(|| panic!("no array {name}"));
    let open_end = at + xml[at..].find('>').unwrap() + 1;
    let close = open_end + xml[open_end..].find("</DataArray>").unwrap();
    xml[open_end..close]
        .split_whitespace()
        .map(str::to_string)
        .collect()
}

/// XML forbids `--` inside comments; VTK's expat parser rejects such a file, while vtkio's
/// quick-xml lets it through, so this is checked separately.
fn assert_comments_well_formed(xml: &str) {
    for part in xml.split("<!--").skip(1) {
        let body = &part[..part.find("-->").expect("unterminated comment")];
        assert!(!body.contains("--"), "'--' inside comment: {body}");
        assert!(!body.ends_with('-'), "comment ends in '-': {body}");
    }
}

// -------------------------------------------------------------------------------------------
// Tests
// -------------------------------------------------------------------------------------------

#[test]
fn vtu_round_trips_through_vtkio() {
    let dir = TempDir::new("vtu");
    let d = data(100, 42);
    let s = snapshot(&d);
    let path = dir.path("snap_000001.vtu");
    write_vtu(&path, &s).unwrap();

    let r = read_vtu(&path);
    let n = d.positions.len();
    assert_eq!(r.points.len(), 3 * n);
    for i in 0..n {
        for k in 0..3 {
            assert_bits(
                "position",
                i,
                r.points[3 * i + k],
                d.positions[i][k] * UM_PER_CM,
            );
        }
    }

    let IOBuffer::I64(ids) = r.array("id") else {
        panic!("id is not Int64");
    };
    assert_eq!(ids, &(1..=n as i64).collect::<Vec<_>>());

    let IOBuffer::F64(vel) = r.array("velocity") else {
        panic!("velocity is not Float64");
    };
    let IOBuffer::F64(omega) = r.array("angular_velocity") else {
        panic!("angular_velocity is not Float64");
    };
    let IOBuffer::F64(radius) = r.array("radius") else {
        panic!("radius is not Float64");
    };
    let IOBuffer::U32(contacts) = r.array("contacts") else {
        panic!("contacts is not UInt32");
    };
    assert_eq!(vel.len(), 3 * n);
    assert_eq!(omega.len(), 3 * n);
    assert_eq!(radius.len(), n);
    assert_eq!(contacts, &d.contacts);
    for i in 0..n {
        for k in 0..3 {
            let want = d.velocities[i][k] / CM_PER_S_PER_M_PER_S;
            assert_bits("velocity", i, vel[3 * i + k], want);
            assert_bits(
                "angular velocity",
                i,
                omega[3 * i + k],
                d.angular_velocities[i][k],
            );
        }
        assert_bits("radius", i, radius[i], RADIUS * UM_PER_CM);
    }

    // One VTK_VERTEX cell per monomer.
    assert_eq!(r.connectivity, (0..n as u64).collect::<Vec<_>>());
    assert_eq!(r.offsets, (1..=n as u64).collect::<Vec<_>>());
    assert!(r.types.iter().all(|t| *t == vtkio::model::CellType::Vertex));
    assert_eq!(r.types.len(), n);

    // FieldData: time, step and the walls.
    let xml = fs::read_to_string(&path).unwrap();
    let time: f64 = data_array_text(&xml, "TimeValue")[0].parse().unwrap();
    assert_eq!(time.to_bits(), s.time.to_bits());
    assert_eq!(data_array_text(&xml, "step"), vec![s.step.to_string()]);
    let wp: Vec<f64> = data_array_text(&xml, "wall_point")
        .iter()
        .map(|x| x.parse().unwrap())
        .collect();
    let wn: Vec<f64> = data_array_text(&xml, "wall_normal")
        .iter()
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(wp.len(), 3 * d.walls.len());
    for (j, wall) in d.walls.iter().enumerate() {
        let len = wall.normal.iter().map(|x| x * x).sum::<f64>().sqrt();
        for k in 0..3 {
            assert_bits("wall point", j, wp[3 * j + k], wall.point[k] * UM_PER_CM);
            assert!((wn[3 * j + k] - wall.normal[k] / len).abs() < 1e-15);
        }
    }
    assert_comments_well_formed(&xml);
    assert!(xml.contains("velocity in m/s"), "units must be stated");
    assert!(xml.contains("floor") && xml.contains("piston"));
}

#[test]
fn lammps_dump_round_trips_through_a_whitespace_reader() {
    let dir = TempDir::new("dump");
    let d = data(100, 7);
    let s = snapshot(&d);
    let path = dir.path("snap_000001.dump");
    write_lammps_dump(&path, &s).unwrap();

    // OVITO recognises a dump by its first line and wants NUMBER OF ATOMS within 20 lines.
    let text = fs::read_to_string(&path).unwrap();
    let first = text.lines().next().unwrap();
    assert!(
        first == "ITEM: TIME" || first == "ITEM: TIMESTEP",
        "{first}"
    );
    assert!(text
        .lines()
        .take(20)
        .any(|l| l.starts_with("ITEM: NUMBER OF ATOMS")));

    let dump = Dump::read(&path);
    // The order OVITO was checked against (see `write_lammps_dump` for why each other
    // place for the extra sections breaks something in OVITO).
    let order: Vec<&str> = dump
        .sections
        .iter()
        .map(|(h, _)| {
            [
                "TIMESTEP",
                "TIME",
                "NUMBER OF ATOMS",
                "BOX BOUNDS",
                "COLUMN UNITS",
                "WALLS",
                "ATOMS",
            ]
            .into_iter()
            .find(|k| h == k || h.starts_with(&format!("{k} ")))
            .unwrap_or_else(|| panic!("unexpected section {h}"))
        })
        .collect();
    assert_eq!(
        order,
        [
            "TIME",
            "TIMESTEP",
            "NUMBER OF ATOMS",
            "COLUMN UNITS",
            "WALLS",
            "BOX BOUNDS",
            "ATOMS"
        ]
    );
    assert_eq!(dump.single("TIMESTEP"), s.step.to_string());
    let time: f64 = dump.single("TIME").parse().unwrap();
    assert_eq!(time.to_bits(), s.time.to_bits());
    let n: usize = dump.single("NUMBER OF ATOMS").parse().unwrap();
    assert_eq!(n, d.positions.len());

    let (header, rows) = dump.section("ATOMS");
    let columns: Vec<&str> = header.split_whitespace().skip(1).collect();
    assert_eq!(
        columns,
        "id type x y z vx vy vz omegax omegay omegaz radius contacts"
            .split(' ')
            .collect::<Vec<_>>()
    );
    assert_eq!(rows.len(), n);
    let col = |name: &str| columns.iter().position(|c| *c == name).unwrap();
    for (i, row) in rows.iter().enumerate() {
        let f: Vec<&str> = row.split_whitespace().collect();
        assert_eq!(f.len(), columns.len(), "row {i}: {row}");
        let num = |name: &str| f[col(name)].parse::<f64>().unwrap();
        assert_eq!(f[col("id")].parse::<u64>().unwrap(), i as u64 + 1);
        assert_eq!(f[col("type")], "1");
        assert_eq!(f[col("contacts")].parse::<u32>().unwrap(), d.contacts[i]);
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            assert_bits("position", i, num(axis), d.positions[i][k] * UM_PER_CM);
            let want = d.velocities[i][k] / CM_PER_S_PER_M_PER_S;
            assert_bits("velocity", i, num(&format!("v{axis}")), want);
            let want = d.angular_velocities[i][k];
            assert_bits("angular velocity", i, num(&format!("omega{axis}")), want);
        }
        assert_bits("radius", i, num("radius"), RADIUS * UM_PER_CM);
    }

    // Box: z from floor and piston, x low side from the wall, the rest from the particles
    // (the tilted wall is not a box face).
    let (header, lines) = dump.section("BOX BOUNDS");
    assert_eq!(header, "BOX BOUNDS fs ss ff");
    let b: Vec<Vec<f64>> = lines
        .iter()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    let r = RADIUS * UM_PER_CM;
    let ext = |k: usize, hi: bool| {
        d.positions
            .iter()
            .map(|p| {
                if hi {
                    p[k] * UM_PER_CM + r
                } else {
                    p[k] * UM_PER_CM - r
                }
            })
            .fold(if hi { f64::MIN } else { f64::MAX }, |a, x| {
                if hi {
                    a.max(x)
                } else {
                    a.min(x)
                }
            })
    };
    assert_eq!(b[0], vec![-30.0e-4 * UM_PER_CM, ext(0, true)]);
    assert_eq!(b[1], vec![ext(1, false), ext(1, true)]);
    assert_eq!(b[2], vec![-25.0e-4 * UM_PER_CM, 25.0e-4 * UM_PER_CM]);

    // Units and walls travel with the file.
    let (_, units) = dump.section("COLUMN UNITS");
    assert!(units[0].contains("m/s") && units[0].contains("um"));
    let (_, walls) = dump.section("WALLS");
    assert_eq!(walls.len(), d.walls.len());
    for (wall, line) in d.walls.iter().zip(walls) {
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(f.len(), 7);
        assert_eq!(f[0], wall.name);
        for k in 0..3 {
            let p: f64 = f[1 + k].parse().unwrap();
            assert_bits("wall point", 0, p, wall.point[k] * UM_PER_CM);
        }
    }
}

#[test]
fn many_walls_keep_the_dump_recognisable() {
    let dir = TempDir::new("many-walls");
    let mut d = data(3, 2);
    d.walls = (0..40)
        .map(|i| WallPlane {
            name: format!("w{i}"),
            point: [0.0, 0.0, i as f64 * 1.0e-4],
            normal: [0.0, 0.0, 1.0],
        })
        .collect();
    let path = dir.path("w.dump");
    write_lammps_dump(&path, &snapshot(&d)).unwrap();
    let text = fs::read_to_string(&path).unwrap();
    assert!(text
        .lines()
        .take(20)
        .any(|l| l.starts_with("ITEM: NUMBER OF ATOMS")));
    assert_eq!(Dump::read(&path).section("WALLS").1.len(), 40);
}

#[test]
fn snapshot_format_dispatches_and_names_extensions() {
    let dir = TempDir::new("format");
    let d = data(5, 3);
    let s = snapshot(&d);
    for format in [SnapshotFormat::Vtu, SnapshotFormat::LammpsDump] {
        let path = dir.path(&format!("s.{}", format.extension()));
        format.write(&path, &s).unwrap();
    }
    assert_eq!(dir.entries(), vec!["s.dump", "s.vtu"]);
    assert_eq!(read_vtu(&dir.path("s.vtu")).points.len(), 15);
    assert_eq!(
        Dump::read(&dir.path("s.dump")).single("NUMBER OF ATOMS"),
        "5"
    );
}

#[test]
fn empty_snapshot_writes_valid_files() {
    let dir = TempDir::new("empty");
    let d = data(0, 1);
    let mut s = snapshot(&d);
    s.walls = &[];
    write_vtu(&dir.path("e.vtu"), &s).unwrap();
    write_lammps_dump(&dir.path("e.dump"), &s).unwrap();

    let dump = Dump::read(&dir.path("e.dump"));
    assert_eq!(dump.single("NUMBER OF ATOMS"), "0");
    assert!(dump.section("ATOMS").1.is_empty());
    let (header, lines) = dump.section("BOX BOUNDS");
    assert_eq!(header, "BOX BOUNDS ss ss ss");
    assert_eq!(lines.len(), 3);
    assert!(dump.section("WALLS").1.is_empty());

    // vtkio cannot convert zero-length ASCII arrays into its model, so check the structure
    // by hand: zero points and cells, every array present and empty.
    let xml = fs::read_to_string(dir.path("e.vtu")).unwrap();
    assert!(xml.contains(r#"NumberOfPoints="0" NumberOfCells="0""#));
    for name in [
        "id",
        "velocity",
        "angular_velocity",
        "radius",
        "contacts",
        "position",
    ] {
        assert!(data_array_text(&xml, name).is_empty(), "{name}");
    }
    assert!(xml.trim_end().ends_with("</VTKFile>"));
}

#[test]
fn nan_is_refused_naming_the_monomer_and_leaves_no_file() {
    let dir = TempDir::new("nan");
    let mut d = data(100, 9);
    d.velocities[37][1] = f64::NAN;
    let s = snapshot(&d);
    for result in [
        write_vtu(&dir.path("n.vtu"), &s),
        write_lammps_dump(&dir.path("n.dump"), &s),
    ] {
        let err = result.unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::InvalidInput);
        let msg = err.to_string();
        assert!(msg.contains("monomer 37"), "{msg}");
        assert!(msg.contains("velocity"), "{msg}");
    }

    let mut d = data(10, 9);
    d.positions[4][2] = f64::INFINITY;
    let msg = write_vtu(&dir.path("n.vtu"), &snapshot(&d))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("monomer 4") && msg.contains("position"),
        "{msg}"
    );

    assert!(dir.entries().is_empty(), "{:?}", dir.entries());
}

/// The failed-state snapshot of a blow-up keeps NaN and ±inf: the arrays holding one are
/// binary (which VTK reads exactly), `finite` marks the monomers, everything else is as in an
/// ordinary snapshot.
#[test]
fn a_failed_state_vtu_keeps_nan_and_inf_and_marks_the_monomers() {
    let dir = TempDir::new("failed");
    let d = data(100, 9);
    // Without a non-finite value the failed-state file is the ordinary one, byte for byte.
    write_vtu(&dir.path("ok.vtu"), &snapshot(&d)).unwrap();
    write_failed_vtu(&dir.path("ok_failed.vtu"), &snapshot(&d)).unwrap();
    assert_eq!(
        fs::read(dir.path("ok.vtu")).unwrap(),
        fs::read(dir.path("ok_failed.vtu")).unwrap()
    );

    let mut d = d;
    d.velocities[37][1] = f64::NAN;
    d.positions[4][2] = f64::INFINITY;
    d.angular_velocities[50][0] = f64::NEG_INFINITY;
    let s = snapshot(&d);
    let path = dir.path("snap_failed.vtu");
    write_failed_vtu(&path, &s).unwrap();

    let same = |what: &str, i: usize, got: f64, want: f64| {
        if want.is_nan() {
            assert!(
                got.is_nan(),
                "{what} of monomer {i}: read {got:e}, expected NaN"
            );
        } else {
            assert_bits(what, i, got, want);
        }
    };
    let r = read_vtu(&path);
    let n = d.positions.len();
    let (IOBuffer::F64(vel), IOBuffer::F64(omega)) =
        (r.array("velocity"), r.array("angular_velocity"))
    else {
        panic!("velocities are not Float64");
    };
    let IOBuffer::U8(finite) = r.array("finite") else {
        panic!("finite is not UInt8");
    };
    let IOBuffer::U32(contacts) = r.array("contacts") else {
        panic!("contacts is not UInt32");
    };
    assert_eq!(
        (r.points.len(), vel.len(), omega.len()),
        (3 * n, 3 * n, 3 * n)
    );
    assert_eq!(contacts, &d.contacts);
    for i in 0..n {
        for k in 0..3 {
            same(
                "position",
                i,
                r.points[3 * i + k],
                d.positions[i][k] * UM_PER_CM,
            );
            let v = d.velocities[i][k] / CM_PER_S_PER_M_PER_S;
            same("velocity", i, vel[3 * i + k], v);
            same(
                "angular velocity",
                i,
                omega[3 * i + k],
                d.angular_velocities[i][k],
            );
        }
        assert_eq!(
            finite[i] == 0,
            [4, 37, 50].contains(&i),
            "finite of monomer {i}"
        );
    }
    assert_eq!(
        r.point_data.len(),
        6,
        "id, velocity, angular_velocity, radius, contacts, finite"
    );

    let xml = fs::read_to_string(&path).unwrap();
    assert!(xml.contains(r#"header_type="UInt64""#));
    for name in ["position", "velocity", "angular_velocity"] {
        assert!(
            xml.contains(&format!(
                r#"Name="{name}" NumberOfComponents="3" format="binary""#
            )),
            "{name} is binary"
        );
    }
    assert!(xml.contains(r#"Name="radius" format="ascii""#));
    assert!(xml.contains("3 of 100 monomers hold a non-finite value"));
    assert_comments_well_formed(&xml);
    let time: f64 = data_array_text(&xml, "TimeValue")[0].parse().unwrap();
    assert_eq!(time.to_bits(), s.time.to_bits());

    // A non-finite time is still refused: it is the simulation's clock, never a result.
    let mut s = snapshot(&d);
    s.time = f64::NAN;
    assert!(write_failed_vtu(&dir.path("t.vtu"), &s).is_err());
}

#[test]
fn mismatched_lengths_and_bad_walls_are_refused() {
    let dir = TempDir::new("bad");
    let d = data(10, 5);
    let mut s = snapshot(&d);
    s.contacts = &d.contacts[..9];
    let msg = write_vtu(&dir.path("b.vtu"), &s).unwrap_err().to_string();
    assert!(msg.contains("contact"), "{msg}");

    let walls = [WallPlane {
        name: "two words".into(),
        point: [0.0; 3],
        normal: [0.0, 0.0, 1.0],
    }];
    let mut s = snapshot(&d);
    s.walls = &walls;
    assert!(write_lammps_dump(&dir.path("b.dump"), &s).is_err());

    let walls = [WallPlane {
        name: "flat".into(),
        point: [0.0; 3],
        normal: [0.0; 3],
    }];
    s.walls = &walls;
    let msg = write_lammps_dump(&dir.path("b.dump"), &s)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("flat"), "{msg}");
    assert!(dir.entries().is_empty(), "{:?}", dir.entries());
}

#[test]
fn atomic_write_leaves_only_the_target_and_replaces_it() {
    let dir = TempDir::new("atomic");
    let d = data(100, 11);
    let s = snapshot(&d);
    let path = dir.path("snap.vtu");
    fs::write(&path, "stale").unwrap();
    write_vtu(&path, &s).unwrap();
    write_lammps_dump(&dir.path("snap.dump"), &s).unwrap();
    write_walls_vtp(&dir.path("walls.vtp"), &d.walls, ([-1.0; 3], [1.0; 3])).unwrap();
    write_pvd(&dir.path("run.pvd"), &[(0.0, "snap.vtu".into())]).unwrap();
    assert_eq!(
        dir.entries(),
        vec!["run.pvd", "snap.dump", "snap.vtu", "walls.vtp"]
    );
    assert!(fs::read_to_string(&path).unwrap().starts_with("<?xml"));

    // A write that fails at the file system leaves nothing behind either, and says where.
    let missing = dir.path("no-such-dir").join("x.vtu");
    let msg = write_vtu(&missing, &s).unwrap_err().to_string();
    assert!(msg.contains("no-such-dir"), "{msg}");
    assert_eq!(dir.entries().len(), 4);

    // A write that fails after the temporary file exists (here the final rename, because a
    // directory is in the way) removes it again.
    fs::create_dir(dir.path("blocked.vtu")).unwrap();
    assert!(write_vtu(&dir.path("blocked.vtu"), &s).is_err());
    assert_eq!(
        dir.entries(),
        vec![
            "blocked.vtu",
            "run.pvd",
            "snap.dump",
            "snap.vtu",
            "walls.vtp"
        ]
    );
}

/// Reads a `.vtp` written by `write_walls_vtp` through vtkio: polygons with their wall index
/// and normal.
fn read_walls_vtp(path: &Path) -> Vec<(i32, [f64; 3], Vec<[f64; 3]>)> {
    let vtk = Vtk::import(path).expect("vtkio cannot read the .vtp");
    let DataSet::PolyData { pieces, .. } = vtk.data else {
        panic!("not poly data");
    };
    let Piece::Inline(piece) = pieces.into_iter().next().unwrap() else {
        panic!("piece not inline");
    };
    let points = piece.points.cast_into::<f64>().unwrap();
    let Some(VertexNumbers::XML {
        connectivity,
        offsets,
    }) = piece.polys
    else {
        panic!("no polys");
    };
    let mut wall = Vec::new();
    let mut normal = Vec::new();
    for a in piece.data.cell {
        let Attribute::DataArray(a) = a else {
            panic!("field attribute")
        };
        match a.name.as_str() {
            "wall" => wall = a.data.cast_into::<i32>().unwrap(),
            "normal" => normal = a.data.cast_into::<f64>().unwrap(),
            other => panic!("unexpected cell data {other}"),
        }
    }
    let mut start = 0usize;
    offsets
        .iter()
        .enumerate()
        .map(|(c, &end)| {
            let poly = connectivity[start..end as usize]
                .iter()
                .map(|&v| {
                    let v = v as usize;
                    [points[3 * v], points[3 * v + 1], points[3 * v + 2]]
                })
                .collect();
            start = end as usize;
            (
                wall[c],
                [normal[3 * c], normal[3 * c + 1], normal[3 * c + 2]],
                poly,
            )
        })
        .collect()
}

#[test]
fn walls_are_clipped_to_the_box_and_wound_about_their_normal() {
    let dir = TempDir::new("vtp");
    // Box 0..2 x 0..2 x 0..1 cm = 0..2e4 x 0..2e4 x 0..1e4 µm.
    let extent = ([0.0, 0.0, 0.0], [2.0, 2.0, 1.0]);
    let walls = vec![
        // Lies exactly on the bottom face.
        WallPlane {
            name: "floor".into(),
            point: [5.0, 5.0, 0.0],
            normal: [0.0, 0.0, 1.0],
        },
        // Misses the box.
        WallPlane {
            name: "far".into(),
            point: [0.0, 0.0, 3.0],
            normal: [0.0, 0.0, -1.0],
        },
        // Through the centre, perpendicular to the space diagonal: a hexagon.
        WallPlane {
            name: "diag---".into(),
            point: [1.0, 1.0, 0.5],
            normal: [1.0, 1.0, 1.0],
        },
        // Only touches the box at one corner.
        WallPlane {
            name: "corner".into(),
            point: [2.0, 2.0, 1.0],
            normal: [-1.0, -1.0, -1.0],
        },
        // Shaves the top corner by far less than the box size: the three cut points are
        // numerically one point, and must not become a degenerate sliver polygon.
        WallPlane {
            name: "shave".into(),
            point: [2.0 - 1.0e-11, 2.0, 1.0],
            normal: [-1.0, -1.0, -1.0],
        },
    ];
    let path = dir.path("walls.vtp");
    write_walls_vtp(&path, &walls, extent).unwrap();
    assert_comments_well_formed(&fs::read_to_string(&path).unwrap());
    let polys = read_walls_vtp(&path);

    assert_eq!(
        polys.iter().map(|p| (p.0, p.2.len())).collect::<Vec<_>>(),
        vec![(0, 4), (2, 6)]
    );
    let floor = &polys[0].2;
    let mut corners: Vec<[f64; 3]> = floor.clone();
    corners.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(
        corners,
        vec![
            [0.0, 0.0, 0.0],
            [0.0, 2.0e4, 0.0],
            [2.0e4, 0.0, 0.0],
            [2.0e4, 2.0e4, 0.0]
        ]
    );

    for (w, n, poly) in &polys {
        let wall = &walls[*w as usize];
        let len = wall.normal.iter().map(|x| x * x).sum::<f64>().sqrt();
        let unit = [
            wall.normal[0] / len,
            wall.normal[1] / len,
            wall.normal[2] / len,
        ];
        for k in 0..3 {
            assert!((n[k] - unit[k]).abs() < 1e-15);
        }
        let p = [
            wall.point[0] * UM_PER_CM,
            wall.point[1] * UM_PER_CM,
            wall.point[2] * UM_PER_CM,
        ];
        for q in poly {
            let dist: f64 = (0..3).map(|k| (q[k] - p[k]) * unit[k]).sum();
            assert!(dist.abs() < 1e-9, "vertex {q:?} off the plane by {dist}");
            for (k, &x) in q.iter().enumerate() {
                let tol = 1e-9;
                assert!(
                    x >= extent.0[k] * UM_PER_CM - tol,
                    "vertex {q:?} outside the box"
                );
                assert!(
                    x <= extent.1[k] * UM_PER_CM + tol,
                    "vertex {q:?} outside the box"
                );
            }
        }
        // Newell's formula: the polygon's own normal must point along the wall normal, and
        // a convex polygon traversed in order has all edge turns on the same side.
        let m = poly.len();
        let mut area = [0.0; 3];
        for i in 0..m {
            let (a, b) = (poly[i], poly[(i + 1) % m]);
            area[0] += (a[1] - b[1]) * (a[2] + b[2]);
            area[1] += (a[2] - b[2]) * (a[0] + b[0]);
            area[2] += (a[0] - b[0]) * (a[1] + b[1]);
        }
        let along: f64 = (0..3).map(|k| area[k] * unit[k]).sum();
        assert!(along > 0.0, "wall {w} wound against its normal");
        for i in 0..m {
            let (a, b, c) = (poly[i], poly[(i + 1) % m], poly[(i + 2) % m]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [c[0] - b[0], c[1] - b[1], c[2] - b[2]];
            let turn = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let t: f64 = (0..3).map(|k| turn[k] * unit[k]).sum();
            assert!(t > 0.0, "wall {w} polygon not convex/ordered at vertex {i}");
        }
    }
}

#[test]
fn walls_vtp_without_polygons_is_still_valid() {
    let dir = TempDir::new("vtp-empty");
    let path = dir.path("none.vtp");
    write_walls_vtp(&path, &[], ([0.0; 3], [1.0; 3])).unwrap();
    let xml = fs::read_to_string(&path).unwrap();
    assert!(xml.contains(r#"NumberOfPoints="0""#) && xml.contains(r#"NumberOfPolys="0""#));
    assert!(write_walls_vtp(&path, &[], ([1.0; 3], [0.0; 3])).is_err());
}

/// Attribute value of `attr` in an XML start tag, unescaping the five predefined entities.
fn attr(tag: &str, attr: &str) -> String {
    let key = format!(" {attr}=\"");
    let start = tag.find(&key).unwrap() + key.len();
    let end = start + tag[start..].find('"').unwrap();
    tag[start..end]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

#[test]
fn pvd_lists_every_step_with_its_time() {
    let dir = TempDir::new("pvd");
    let entries: Vec<(f64, String)> = vec![
        (0.0, "snap_000000.vtu".into()),
        (1.0e-7 / 3.0, "snap_000001.vtu".into()),
        (2.5e-3, "odd <&\"'> name.vtu".into()),
        // Only a correctly escaping writer gets this back unchanged.
        (3.0e-3, "a&lt;b.vtu".into()),
    ];
    let path = dir.path("run.pvd");
    write_pvd(&path, &entries).unwrap();

    let xml = fs::read_to_string(&path).unwrap();
    assert!(xml.contains(r#"type="Collection""#));
    let tags: Vec<&str> = xml
        .split("<DataSet ")
        .skip(1)
        .map(|t| &t[..t.find("/>").unwrap()])
        .collect();
    assert_eq!(tags.len(), entries.len());
    for ((time, file), tag) in entries.iter().zip(&tags) {
        let tag = format!(" {tag}");
        let t: f64 = attr(&tag, "timestep").parse().unwrap();
        assert_eq!(t.to_bits(), time.to_bits());
        assert_eq!(&attr(&tag, "file"), file);
    }

    assert!(write_pvd(&path, &[(f64::NAN, "x.vtu".into())]).is_err());
}
