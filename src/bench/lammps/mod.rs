//! The same compression in LAMMPS: the sample as a data file, an input deck with the nearest
//! granular model LAMMPS has (coefficients from dustdem's material and model), and a runner
//! that reads the rate from LAMMPS's log.

pub mod coeffs;
pub mod data;
pub mod deck;
pub mod run;

pub use coeffs::GranularCoeffs;
pub use deck::DeckSpec;
pub use run::{parse_log, Lammps, LammpsRun};

use crate::config::Config;
use crate::output::atomic::write_atomic;
use crate::sample::{Footprint, Sample};
use crate::state::{State, Wall};
use data::{data_file, Bounds};
use std::path::Path;

/// The deck's file name in its directory (the data file is `sample.data` beside it).
pub const DECK: &str = "in.compress";
pub const DATA: &str = "sample.data";

/// Writes `sample.data` and `in.compress` for `sample` and its `walls` (bottom, top, then the
/// four side walls of the omni box) into `dir`, atomically.
pub fn export(config: &Config, sample: &Sample, walls: &[Wall], dir: &Path) -> Result<(), String> {
    let half_side = match sample.footprint {
        Footprint::Box { side } => 0.5 * side,
        Footprint::Cylinder { .. } => {
            return Err("the LAMMPS deck needs the omni box (footprint = \"box\")".into())
        }
    };
    let title = format!(
        "dustdem RBD sample, {} monomers, seed {}, cgs units",
        sample.positions.len(),
        sample.seed
    );
    let exported = Exported {
        title,
        positions: &sample.positions,
        velocities: None,
        radius: sample.radius,
        half_side,
    };
    write_files(config, &exported, walls, dir)
}

/// Writes `sample.data` and `in.compress` for a state the engine reached (a compressed
/// benchmark sample): its positions, its velocities synchronised to the step, and the walls
/// where they are now. LAMMPS starts without the contacts' history: pointers, twist and the JKR
/// contacts stretched beyond touching are not carried.
pub fn export_state(config: &Config, state: &State, dir: &Path) -> Result<(), String> {
    let w = &state.walls;
    if w.len() != 6 {
        return Err("the LAMMPS deck needs the omni box's six walls".into());
    }
    let positions: Vec<[f64; 3]> = state
        .monomers
        .position
        .iter()
        .map(|p| p.to_array())
        .collect();
    let velocities: Vec<[f64; 6]> = (0..positions.len())
        .map(|i| {
            let (v, o) = (
                state.synchronized_velocity(i),
                state.synchronized_angular_velocity(i),
            );
            [v.x, v.y, v.z, o.x, o.y, o.z]
        })
        .collect();
    let exported = Exported {
        title: format!(
            "dustdem RBD sample, {} monomers, seed {}, compressed to step {}, cgs units",
            positions.len(),
            config.sample.seed,
            state.step
        ),
        positions: &positions,
        velocities: Some(&velocities),
        radius: state.law.radius,
        half_side: 0.5 * (w[3].point - w[2].point).dot(w[2].normal),
    };
    write_files(config, &exported, w, dir)
}

/// What the data file holds besides the material.
struct Exported<'a> {
    title: String,
    positions: &'a [[f64; 3]],
    velocities: Option<&'a [[f64; 6]]>,
    radius: f64,
    half_side: f64,
}

fn write_files(config: &Config, x: &Exported, walls: &[Wall], dir: &Path) -> Result<(), String> {
    let (bottom, top) = (walls[0].point.z, walls[1].point.z);
    let spec = DeckSpec::new(config, x.half_side, bottom, top);
    // Room of two radii around the walls: nothing crosses a wall, but LAMMPS drops atoms that
    // leave the box, and its bins want some margin.
    let margin = 2.0 * x.radius;
    let half_side = x.half_side;
    let bounds = Bounds {
        lo: [-half_side - margin, -half_side - margin, bottom - margin],
        hi: [half_side + margin, half_side + margin, top + margin],
    };
    let data = data_file(
        &x.title,
        x.positions,
        x.velocities,
        x.radius,
        config.material().density,
        bounds,
    );
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        write_atomic(&path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
    };
    write(DATA, &data)?;
    write(DECK, &spec.text())
}
