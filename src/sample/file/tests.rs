//! Sample files round-trip to the bit, and every malformed file is refused with its line and
//! field.

use super::*;
use crate::sample::{generate_rbd, side_for_cube, RbdParams};

/// Path in the temp directory, unique per test and process; removed on drop.
struct TempFile(PathBuf);

impl TempFile {
    fn new(name: &str) -> TempFile {
        // Tests run on parallel threads and several share a name: add a counter.
        static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let k = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let p = std::env::temp_dir().join(format!(
            "dustdem-sample-test-{}-{k}-{name}.txt",
            std::process::id()
        ));
        TempFile(p)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn rbd(n: usize, seed: u64, footprint: Footprint) -> Sample {
    generate_rbd(&RbdParams {
        n,
        radius: 6.0e-5,
        footprint,
        seed,
        contact_distance: 1.2e-4,
    })
}

fn cube(n: usize, seed: u64) -> Sample {
    rbd(
        n,
        seed,
        Footprint::Box {
            side: side_for_cube(n, 6.0e-5, 0.15),
        },
    )
}

#[test]
fn same_seed_gives_identical_bytes() {
    let (a, b) = (TempFile::new("bytes-a"), TempFile::new("bytes-b"));
    cube(3_000, 4).save(&a.0).unwrap();
    cube(3_000, 4).save(&b.0).unwrap();
    let (ba, bb) = (std::fs::read(&a.0).unwrap(), std::fs::read(&b.0).unwrap());
    assert!(!ba.is_empty());
    assert_eq!(ba, bb);
    let c = TempFile::new("bytes-c");
    cube(3_000, 5).save(&c.0).unwrap();
    assert_ne!(ba, std::fs::read(&c.0).unwrap());
}

#[test]
fn round_trip_is_exact() {
    let f = TempFile::new("round-trip");
    for s in [
        cube(2_000, 8),
        rbd(1_000, 9, Footprint::Cylinder { radius: 2.0e-3 }),
        rbd(0, 10, Footprint::Box { side: 1e-3 }),
    ] {
        s.save(&f.0).unwrap();
        let back = Sample::load(&f.0).unwrap();
        assert_eq!(back, s);
        for (p, q) in s.positions.iter().zip(&back.positions) {
            for c in 0..3 {
                assert_eq!(p[c].to_bits(), q[c].to_bits());
            }
        }
    }
}

#[test]
fn header_order_and_spacing_are_free() {
    let f = TempFile::new("order");
    let text = "dustdem-sample 1\nn=1\r\nseed = 3\nfootprint = cylinder\n\
                cylinder_radius_cm = 1.0\ncontact_distance_cm = 0.2\n\
                radius_cm = 0.1\npositions_cm\n0.5 0 0.1\n\n";
    std::fs::write(&f.0, text).unwrap();
    let s = Sample::load(&f.0).unwrap();
    assert_eq!(s.footprint, Footprint::Cylinder { radius: 1.0 });
    assert_eq!(s.positions, vec![[0.5, 0.0, 0.1]]);
}

#[test]
fn save_refuses_invalid_sample() {
    let f = TempFile::new("refuse");
    let mut s = cube(10, 1);
    s.positions[3][1] = f64::NAN;
    let e = s.save(&f.0).unwrap_err().to_string();
    assert!(e.contains("monomer 3 y") && e.contains("NaN"), "{e}");
    assert!(!f.0.exists());
}

const GOOD: &str = "dustdem-sample 1\n\
    radius_cm = 1.0e0\n\
    footprint = box\n\
    side_cm = 1.0e1\n\
    seed = 7\n\
    contact_distance_cm = 2.0e0\n\
    n = 2\n\
    positions_cm\n\
    0.0 0.0 1.0\n\
    3.0 -4.0 3.0\n";

/// Loads `text` and returns the error message, which must also name the file.
fn load_error(text: &str) -> String {
    let f = TempFile::new("bad");
    std::fs::write(&f.0, text).unwrap();
    let e = Sample::load(&f.0).expect_err("should be rejected");
    let msg = e.to_string();
    assert!(msg.contains(&f.0.display().to_string()), "{msg}");
    msg
}

fn assert_mentions(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "'{p}' not in: {msg}");
    }
}

#[test]
fn good_text_loads() {
    let f = TempFile::new("good");
    std::fs::write(&f.0, GOOD).unwrap();
    let s = Sample::load(&f.0).unwrap();
    assert_eq!(s.radius, 1.0);
    assert_eq!(s.seed, 7);
    assert_eq!(s.positions.len(), 2);
}

#[test]
fn missing_file() {
    let f = TempFile::new("does-not-exist");
    let e = Sample::load(&f.0).unwrap_err();
    assert!(matches!(e, SampleError::Io { .. }));
    assert!(std::error::Error::source(&e).is_some());
    assert_mentions(&e.to_string(), &["does-not-exist"]);
}

#[test]
fn wrong_magic_or_version() {
    let m = load_error(&GOOD.replace("dustdem-sample 1", "dustdem-sample 2"));
    assert_mentions(&m, &["line 1", "magic", "dustdem-sample 2", "version"]);
    let m = load_error(&GOOD.replace("dustdem-sample 1", "hello"));
    assert_mentions(&m, &["line 1", "'hello'", "dustdem-sample 1"]);
    let m = load_error("");
    assert_mentions(&m, &["line 1", "magic", "(missing)"]);
}

#[test]
fn missing_header_key() {
    let m = load_error(&GOOD.replace("seed = 7\n", ""));
    assert_mentions(&m, &["line 7", "seed", "(missing)", "required"]);
    let m = load_error(&GOOD.replace("side_cm = 1.0e1\n", ""));
    assert_mentions(&m, &["side_cm", "(missing)"]);
    let m = load_error(&GOOD.replace("positions_cm\n", ""));
    assert_mentions(&m, &["line 8", "'0.0 0.0 1.0'", "positions_cm"]);
    let header_only = &GOOD[..GOOD.find("positions_cm").unwrap()];
    let m = load_error(header_only);
    assert_mentions(&m, &["line 8", "positions_cm = '(missing)'"]);
}

#[test]
fn duplicate_header_key() {
    let m = load_error(&GOOD.replace("seed = 7\n", "seed = 7\nseed = 8\n"));
    assert_mentions(&m, &["line 6", "seed = '8'", "once", "line 5"]);
}

#[test]
fn unknown_header_key() {
    let m = load_error(&GOOD.replace("seed = 7\n", "seed = 7\ncolour = red\n"));
    assert_mentions(&m, &["line 6", "colour = 'red'", "unknown", "radius_cm"]);
    let m = load_error(&GOOD.replace("seed = 7\n", "seed 7\n"));
    assert_mentions(&m, &["line 5", "'seed 7'", "key = value"]);
}

#[test]
fn footprint_keys_must_match_kind() {
    let m = load_error(&GOOD.replace("footprint = box", "footprint = sphere"));
    assert_mentions(&m, &["footprint = 'sphere'", "'box' or 'cylinder'"]);
    let m = load_error(&GOOD.replace("footprint = box", "footprint = cylinder"));
    assert_mentions(&m, &["side_cm = '1.0e1'", "not allowed", "cylinder"]);
    let m = load_error(&GOOD.replace("seed = 7", "seed = 7\ncylinder_radius_cm = 3"));
    assert_mentions(&m, &["cylinder_radius_cm = '3'", "not allowed", "box"]);
}

#[test]
fn unparsable_numbers() {
    let m = load_error(&GOOD.replace("radius_cm = 1.0e0", "radius_cm = one"));
    assert_mentions(&m, &["line 2", "radius_cm = 'one'", "finite number"]);
    let m = load_error(&GOOD.replace("seed = 7", "seed = -7"));
    assert_mentions(&m, &["seed = '-7'", "integer"]);
    let m = load_error(&GOOD.replace("n = 2", "n = 2.5"));
    assert_mentions(&m, &["n = '2.5'", "integer"]);
    let m = load_error(&GOOD.replace("3.0 -4.0 3.0", "3.0 -4.0x 3.0"));
    assert_mentions(&m, &["line 10", "monomer 1 y = '-4.0x'", "finite number"]);
    let m = load_error(&GOOD.replace("3.0 -4.0 3.0", "3.0 -4.0"));
    assert_mentions(&m, &["line 10", "monomer 1 z", "(missing)"]);
    let m = load_error(&GOOD.replace("3.0 -4.0 3.0", "3.0 -4.0 3.0 1.0"));
    assert_mentions(&m, &["line 10", "monomer 1 = '1.0'", "exactly"]);
}

#[test]
fn nan_and_infinity() {
    let m = load_error(&GOOD.replace("contact_distance_cm = 2.0e0", "contact_distance_cm = NaN"));
    assert_mentions(&m, &["line 6", "contact_distance_cm = 'NaN'", "finite"]);
    let m = load_error(&GOOD.replace("side_cm = 1.0e1", "side_cm = inf"));
    assert_mentions(&m, &["side_cm = 'inf'", "finite"]);
    let m = load_error(&GOOD.replace("0.0 0.0 1.0", "0.0 0.0 -inf"));
    assert_mentions(&m, &["line 9", "monomer 0 z = '-inf'", "finite"]);
}

#[test]
fn non_positive_sizes() {
    let m = load_error(&GOOD.replace("radius_cm = 1.0e0", "radius_cm = 0"));
    assert_mentions(&m, &["radius_cm = '0'", "> 0"]);
    let m = load_error(&GOOD.replace("radius_cm = 1.0e0", "radius_cm = -1e-5"));
    assert_mentions(&m, &["radius_cm = '-1e-5'", "> 0"]);
    let m = load_error(&GOOD.replace("contact_distance_cm = 2.0e0", "contact_distance_cm = 0.0"));
    assert_mentions(&m, &["contact_distance_cm = '0.0'", "> 0"]);
    let m = load_error(&GOOD.replace("side_cm = 1.0e1", "side_cm = 1.5"));
    assert_mentions(&m, &["side_cm = '1.5'", ">= 2 radius_cm = 2e0"]);
}

#[test]
fn n_must_match_monomer_lines() {
    let m = load_error(&GOOD.replace("n = 2", "n = 3"));
    assert_mentions(&m, &["line 11", "n = '3'", "truncated", "only 2"]);
    let m = load_error(&GOOD.replace("n = 2", "n = 1"));
    assert_mentions(&m, &["line 10", "n = '1'", "more monomer lines"]);
    // A huge n must be reported, not allocated.
    let m = load_error(&GOOD.replace("n = 2", &format!("n = {}", usize::MAX)));
    assert_mentions(&m, &["truncated", &usize::MAX.to_string()]);
}

#[test]
fn monomer_outside_footprint() {
    // Box side 10, radius 1: centres allowed in |x|, |y| <= 4.
    let m = load_error(&GOOD.replace("3.0 -4.0 3.0", "3.0 -4.5 3.0"));
    assert_mentions(
        &m,
        &[
            "line 10",
            "monomer 1 (x, y) = '3e0 -4.5e0'",
            "radius_cm = 4e0",
        ],
    );
    let m = load_error(&GOOD.replace("3.0 -4.0 3.0", "3.0 -4.0 0.5"));
    assert_mentions(&m, &["line 10", "monomer 1 z = '5e-1'", "floor"]);
    // Cylinder radius 5: centres allowed within 4 of the axis; (3, -4) is 5 away.
    let cyl = GOOD.replace(
        "footprint = box\nside_cm = 1.0e1",
        "footprint = cylinder\ncylinder_radius_cm = 5",
    );
    let m = load_error(&cyl);
    assert_mentions(
        &m,
        &[
            "line 10",
            "monomer 1 (x, y)",
            "sqrt(x^2 + y^2) <= cylinder_radius_cm - radius_cm = 4e0",
        ],
    );
}
