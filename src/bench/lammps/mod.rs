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
use crate::state::Wall;
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
    let (bottom, top) = (walls[0].point.z, walls[1].point.z);
    let spec = DeckSpec::new(config, half_side, bottom, top);
    // Room of two radii around the walls: nothing crosses a wall, but LAMMPS drops atoms that
    // leave the box, and its bins want some margin.
    let margin = 2.0 * sample.radius;
    let bounds = Bounds {
        lo: [-half_side - margin, -half_side - margin, bottom - margin],
        hi: [half_side + margin, half_side + margin, top + margin],
    };
    let title = format!(
        "dustdem RBD sample, {} monomers, seed {}, cgs units",
        sample.positions.len(),
        sample.seed
    );
    let data = data_file(
        &title,
        &sample.positions,
        sample.radius,
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
