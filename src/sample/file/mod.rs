//! Sample files.
//!
//! A sample is stored as UTF-8 text, one item per line, so that it can be
//! read, diffed and checked by hand:
//!
//! ```text
//! dustdem-sample 1
//! radius_cm = 6.00000000000000015e-5
//! footprint = box
//! side_cm = 4.94113855722134229e-3
//! seed = 1
//! contact_distance_cm = 1.20000000000000003e-4
//! n = 20000
//! positions_cm
//! 9.78314273944170393e-4 9.85277763665016321e-5 6.00000000000000015e-5
//! 3.57273847674962307e-4 -5.23919866762919111e-4 6.00000000000000015e-5
//! ...
//! ```
//!
//! - Line 1 is the magic and format version, exactly `dustdem-sample 1`.
//! - Header lines follow, each `key = value` (spaces around `=` optional),
//!   in any order, each key at most once and all required except that only
//!   the size key matching `footprint` (`side_cm` or `cylinder_radius_cm`)
//!   is given:
//!   - `radius_cm`: monomer radius (cm), finite and > 0;
//!   - `footprint`: `box` or `cylinder`, centred on x = y = 0;
//!   - `side_cm` (box only): edge length (cm), finite and >= 2 `radius_cm`;
//!   - `cylinder_radius_cm` (cylinder only): footprint radius (cm), finite
//!     and >= `radius_cm`;
//!   - `seed`: decimal unsigned 64-bit integer;
//!   - `contact_distance_cm`: sticking centre distance (cm), finite and > 0;
//!   - `n`: number of monomers, decimal.
//! - The line `positions_cm` ends the header.
//! - Exactly `n` lines follow, one per monomer in deposition order, each
//!   `x y z` (cm) separated by single spaces. Every sphere must lie in the
//!   footprint (|x|, |y| <= side/2 - radius for a box, sqrt(x^2 + y^2) <=
//!   R - radius for a cylinder) and on or above the floor (z >= radius), each
//!   to within 1e-9 radius to allow for rounding in other tools.
//! - Blank lines are allowed only at the very end; lines may end in LF or
//!   CRLF.
//!
//! Writers use `{:.17e}` for every float, which round-trips any f64 exactly,
//! and always emit the keys in the order above, so a given sample always
//! gives the same bytes. Readers check everything and report the file, line,
//! field, offending value and what is allowed.
//!
//! Here: the format's constants, its error and `Sample::save`/`load`; `parse` reads and checks a
//! file's text.

mod parse;
#[cfg(test)]
mod tests;

use super::{Footprint, Sample};
use parse::parse;
use std::fmt;
use std::path::{Path, PathBuf};

/// First line of every sample file.
pub(super) const MAGIC: &str = "dustdem-sample 1";
/// Line ending the header.
pub(super) const POSITIONS: &str = "positions_cm";
/// How far (in radii) a monomer may stick out of the footprint or floor.
pub(super) const SLACK: f64 = 1e-9;
pub(super) const KEYS: [&str; 7] = [
    "radius_cm",
    "footprint",
    "side_cm",
    "cylinder_radius_cm",
    "seed",
    "contact_distance_cm",
    "n",
];

/// Why a sample file could not be read or written.
#[derive(Debug)]
pub enum SampleError {
    /// The file could not be opened, read or written.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The file was read but its content is not a valid sample.
    Invalid {
        path: PathBuf,
        /// 1-based line; for something missing, the line where it was due.
        line: usize,
        /// Header key, `magic`, or `monomer <index>` (0-based) with a coordinate.
        field: String,
        /// Offending text as found, or `(missing)`.
        value: String,
        /// What would have been accepted.
        allowed: String,
    },
}

impl fmt::Display for SampleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SampleError::Io { path, source } => {
                write!(f, "sample file {}: {source}", path.display())
            }
            SampleError::Invalid {
                path,
                line,
                field,
                value,
                allowed,
            } => write!(
                f,
                "sample file {}, line {line}: {field} = '{value}' is invalid: {allowed}",
                path.display()
            ),
        }
    }
}

impl std::error::Error for SampleError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SampleError::Io { source, .. } => Some(source),
            SampleError::Invalid { .. } => None,
        }
    }
}

impl Sample {
    /// Writes the sample in the format described in this module.
    ///
    /// Refuses, without touching the file, a sample that [`Sample::load`]
    /// would reject, so every saved file can be read back.
    pub fn save(&self, path: &Path) -> Result<(), SampleError> {
        let text = self.to_text();
        parse(&text, path)?;
        std::fs::write(path, text).map_err(|source| SampleError::Io {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads and validates a sample file.
    pub fn load(path: &Path) -> Result<Sample, SampleError> {
        let text = std::fs::read_to_string(path).map_err(|source| SampleError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        parse(&text, path)
    }

    fn to_text(&self) -> String {
        use std::fmt::Write;
        let mut t = String::with_capacity(128 + 72 * self.positions.len());
        // Writing to a String cannot fail.
        let _ = writeln!(t, "{MAGIC}");
        let _ = writeln!(t, "radius_cm = {:.17e}", self.radius);
        match self.footprint {
            Footprint::Box { side } => {
                let _ = writeln!(t, "footprint = box\nside_cm = {side:.17e}");
            }
            Footprint::Cylinder { radius } => {
                let _ = writeln!(
                    t,
                    "footprint = cylinder\ncylinder_radius_cm = {radius:.17e}"
                );
            }
        }
        let _ = writeln!(t, "seed = {}", self.seed);
        let _ = writeln!(t, "contact_distance_cm = {:.17e}", self.contact_distance);
        let _ = writeln!(t, "n = {}", self.positions.len());
        let _ = writeln!(t, "{POSITIONS}");
        for p in &self.positions {
            let _ = writeln!(t, "{:.17e} {:.17e} {:.17e}", p[0], p[1], p[2]);
        }
        t
    }
}
