//! The random streams are part of a sample's identity: a seed must give the same sample file,
//! byte for byte, in every version. These digests were recorded from the generator as it was
//! when this test was written; a change of generator, seeding or derived arithmetic (uniform
//! floats, ranges, Box–Muller) shows up here.

use dustdem::rng::Rng;
use dustdem::sample::{generate_rbd, side_for_cube, Footprint, RbdParams};
use std::path::PathBuf;

/// 64-bit FNV-1a, written out here so the test depends on nothing it checks.
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The bytes of the sample file that `Sample::save` writes for these parameters.
fn sample_file_bytes(name: &str, footprint: Footprint, seed: u64) -> Vec<u8> {
    let sample = generate_rbd(&RbdParams {
        n: 300,
        radius: 6.0e-5,
        footprint,
        seed,
        contact_distance: 1.2e-4,
    });
    let path: PathBuf = std::env::temp_dir().join(format!(
        "dustdem-rng-stream-{}-{name}.txt",
        std::process::id()
    ));
    sample.save(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    bytes
}

#[test]
fn rbd_box_sample_file_is_pinned() {
    let side = side_for_cube(300, 6.0e-5, 0.15);
    let bytes = sample_file_bytes("box", Footprint::Box { side }, 7);
    assert_eq!(
        fnv1a(&bytes),
        0x59a4_4d82_b259_0ede,
        "{} bytes",
        bytes.len()
    );
}

#[test]
fn rbd_cylinder_sample_file_is_pinned() {
    // The cylinder draws by rejection, so it consumes a stream-dependent number of outputs.
    let radius = side_for_cube(300, 6.0e-5, 0.15) / 2.0;
    let bytes = sample_file_bytes("cylinder", Footprint::Cylinder { radius }, 7);
    assert_eq!(
        fnv1a(&bytes),
        0x6153_8034_5576_7469,
        "{} bytes",
        bytes.len()
    );
}

#[test]
fn derived_streams_are_pinned() {
    // Every public method, interleaved, digested through the bits of its results.
    let mut rng = Rng::new(7);
    let mut bytes = Vec::new();
    for _ in 0..1000 {
        bytes.extend_from_slice(&rng.next_u64().to_le_bytes());
        bytes.extend_from_slice(&rng.uniform().to_bits().to_le_bytes());
        bytes.extend_from_slice(&rng.uniform_range(-3.0, 5.0).to_bits().to_le_bytes());
        bytes.extend_from_slice(&rng.normal().to_bits().to_le_bytes());
    }
    assert_eq!(fnv1a(&bytes), 0x26e8_dc1f_105d_924c);
}
