//! Space-filling storage order: touching monomers are stored close together, and every output
//! still names monomers by their number in the sample.

mod common;

use common::Scratch;
use dustdem::backend::cpu::CpuEngine;
use dustdem::config::{Config, SnapshotChoice};
use dustdem::experiment::compression::Compression;
use dustdem::experiment::setup::build_sample;
use dustdem::output::snapshot::series::write_snapshot;

fn config(ordered: bool) -> Config {
    Config::parse(
        &format!(
            "[sample]\nmonomers = 3000\nseed = 4\n[integration]\nspace_filling_order = {ordered}\n"
        ),
        "storage order test",
    )
    .unwrap()
}

/// Median |i − j| over the pair contacts: how far apart touching monomers are stored.
fn median_index_distance(engine: &CpuEngine) -> f64 {
    let mut d = Vec::new();
    for i in 0..engine.monomers.len() {
        for c in engine.contacts.pairs_of(i) {
            d.push(c.partner as usize - i);
        }
    }
    d.sort_unstable();
    d[d.len() / 2] as f64
}

#[test]
fn touching_monomers_are_stored_close_together() {
    let sample_order = Compression::with_engine(&config(false), CpuEngine::new).unwrap();
    let curve_order = Compression::with_engine(&config(true), CpuEngine::new).unwrap();
    let (a, b) = (
        median_index_distance(&sample_order.engine),
        median_index_distance(&curve_order.engine),
    );
    eprintln!(
        "median index distance of touching monomers: sample order {a:.1}, Morton order {b:.1}"
    );
    // The same contacts either way, only stored elsewhere.
    assert_eq!(
        sample_order.engine.contacts.pair_contact_count(),
        curve_order.engine.contacts.pair_contact_count()
    );
    // Ballistic deposition puts a monomer on one deposited long before; the curve keeps
    // neighbours within a few cells' worth of monomers.
    assert!(b < a / 10.0, "{a} vs {b}");
    let ids = &curve_order.engine.monomers.id;
    assert!(ids.iter().enumerate().any(|(k, &id)| id as usize != k));
}

/// Atom lines of a LAMMPS dump: (id, x, y, z) as written.
fn atoms(dump: &str) -> Vec<(usize, [f64; 3])> {
    let start = dump.find("ITEM: ATOMS").unwrap();
    dump[start..]
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            let v = |k: usize| f[k].parse::<f64>().unwrap();
            (f[0].parse().unwrap(), [v(2), v(3), v(4)])
        })
        .collect()
}

#[test]
fn snapshots_name_monomers_by_their_sample_number_in_any_storage_order() {
    let mut dumps = Vec::new();
    for ordered in [false, true] {
        let config = config(ordered);
        let run = Compression::with_engine(&config, CpuEngine::new).unwrap();
        let dir = Scratch::new(&format!("storage-order-{ordered}"));
        let files =
            write_snapshot(dir.path(), SnapshotChoice::Lammps, &run.engine.state, "").unwrap();
        dumps.push(std::fs::read_to_string(&files[0]).unwrap());
    }
    // Line k is sample monomer k, at the sample's position, whichever order the engine keeps.
    let sample = build_sample(&config(true), &config(true).contact_law()).unwrap();
    let lines = atoms(&dumps[1]);
    assert_eq!(lines.len(), sample.positions.len());
    for (k, (id, x)) in lines.iter().enumerate() {
        assert_eq!(*id, k + 1);
        for (a, b) in x.iter().zip(sample.positions[k]) {
            // µm in the dump, cm in the sample; the dump prints 9 significant digits.
            assert!(
                (a * 1e-4 - b).abs() <= 1e-8 * b.abs().max(1e-4),
                "{a} vs {b}"
            );
        }
    }
    assert_eq!(dumps[0], dumps[1]);
}
