//! A snapshot of 10⁵ monomers, the size of the CPU engine's large runs, read back whole by the
//! independent readers (vtkio for the VTU; a whitespace reader for the LAMMPS dump, as OVITO
//! parses it); its size and write time printed for the user guide.

use super::readers::{read_vtu, Dump};
use super::*;
use dustdem::output::snapshot::{write_lammps_dump, write_vtu};
use std::time::Instant;

#[test]
fn a_snapshot_of_1e5_monomers_reads_back_whole() {
    let dir = TempDir::new("large");
    let n = 100_000;
    let d = data(n, 11);
    let s = snapshot(&d);
    let (vtu, dump) = (dir.path("large.vtu"), dir.path("large.dump"));
    let clock = Instant::now();
    write_vtu(&vtu, &s).unwrap();
    let vtu_s = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    write_lammps_dump(&dump, &s).unwrap();
    let dump_s = clock.elapsed().as_secs_f64();
    let size = |p: &std::path::Path| fs::metadata(p).unwrap().len() as f64 / 1048576.0;
    eprintln!(
        "10^5 monomers: VTU {:.1} MiB in {vtu_s:.2} s, LAMMPS dump {:.1} MiB in {dump_s:.2} s",
        size(&vtu),
        size(&dump)
    );

    let r = read_vtu(&vtu);
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
    let read = Dump::read(&dump);
    assert_eq!(read.single("NUMBER OF ATOMS"), n.to_string());
    let (_, atoms) = read.section("ATOMS");
    assert_eq!(atoms.len(), n);
}
