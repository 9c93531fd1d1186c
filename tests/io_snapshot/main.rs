//! Snapshot files are read back by readers that share no code with the writers: `vtkio` for
//! the VTK XML files, and small whitespace-splitting / string-scanning readers written here
//! for the LAMMPS dump, the FieldData and the `.pvd` collection.
//!
//! Values are compared bit for bit against the correctly rounded unit conversion (`x * 1e4`
//! for cm to µm, `v / 100` for cm/s to m/s): the conversion is the only rounding the files
//! may add.

mod atomic_writes;
mod bad_values;
mod large;
mod pvd_collection;
mod readers;
mod round_trip;
mod walls_vtp;

use dustdem::output::snapshot::{Snapshot, WallPlane};
use dustdem::rng::Rng;
use std::fs;
use std::path::PathBuf;

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
