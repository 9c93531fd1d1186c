//! The sample as a LAMMPS data file (`atom_style sphere`, `units cgs`): one atom type, each
//! monomer's diameter, density and position.

use std::fmt::Write;

/// The box LAMMPS is given: every monomer inside it, with room for the walls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

/// The data file's text. Positions carry 17 significant digits, so they read back exactly.
/// `velocities` (vx vy vz ωx ωy ωz per monomer, cm/s and rad/s), where given, become the
/// `Velocities` section.
pub fn data_file(
    title: &str,
    positions: &[[f64; 3]],
    velocities: Option<&[[f64; 6]]>,
    radius: f64,
    density: f64,
    bounds: Bounds,
) -> String {
    let mut s = String::new();
    // The first line is a comment LAMMPS skips; it must not be empty of meaning to a reader.
    let _ = writeln!(s, "LAMMPS data file: {title}");
    let _ = writeln!(s);
    let _ = writeln!(s, "{} atoms", positions.len());
    let _ = writeln!(s, "1 atom types");
    let _ = writeln!(s);
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        let _ = writeln!(
            s,
            "{:.16e} {:.16e} {name}lo {name}hi",
            bounds.lo[axis], bounds.hi[axis]
        );
    }
    let _ = writeln!(s);
    // atom_style sphere: atom-ID atom-type diameter density x y z.
    let _ = writeln!(s, "Atoms # sphere");
    let _ = writeln!(s);
    let diameter = 2.0 * radius;
    for (i, p) in positions.iter().enumerate() {
        let _ = writeln!(
            s,
            "{} 1 {diameter:.16e} {density:.16e} {:.16e} {:.16e} {:.16e}",
            i + 1,
            p[0],
            p[1],
            p[2]
        );
    }
    if let Some(velocities) = velocities {
        let _ = writeln!(s);
        // atom_style sphere: atom-ID vx vy vz wx wy wz.
        let _ = writeln!(s, "Velocities");
        let _ = writeln!(s);
        for (i, v) in velocities.iter().enumerate() {
            let cells: Vec<String> = v.iter().map(|x| format!("{x:.16e}")).collect();
            let _ = writeln!(s, "{} {}", i + 1, cells.join(" "));
        }
    }
    s
}
