//! VTU and LAMMPS dump files read back bit for bit, the format dispatch, and empty snapshots.

use super::readers::{assert_comments_well_formed, data_array_text, read_vtu, Dump};
use super::*;
use dustdem::output::snapshot::{write_lammps_dump, write_vtu, SnapshotFormat};
use vtkio::model::IOBuffer;

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
