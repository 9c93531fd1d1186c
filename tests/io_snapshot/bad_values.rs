//! NaN, infinities, mismatched lengths and bad walls: refused naming what is wrong and leaving
//! no file, or kept and marked in the failed-state VTU.

use super::readers::{assert_comments_well_formed, data_array_text, read_vtu};
use super::*;
use dustdem::output::snapshot::{write_failed_vtu, write_lammps_dump, write_vtu};
use vtkio::model::IOBuffer;

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
