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

use super::{Footprint, Sample};
use std::fmt;
use std::path::{Path, PathBuf};

/// First line of every sample file.
const MAGIC: &str = "dustdem-sample 1";
/// Line ending the header.
const POSITIONS: &str = "positions_cm";
/// How far (in radii) a monomer may stick out of the footprint or floor.
const SLACK: f64 = 1e-9;
const KEYS: [&str; 7] = [
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

/// Header value with the line it came from.
struct Entry<'a> {
    line: usize,
    value: &'a str,
}

fn parse(text: &str, path: &Path) -> Result<Sample, SampleError> {
    let err = |line: usize, field: &str, value: &str, allowed: String| SampleError::Invalid {
        path: path.to_path_buf(),
        line,
        field: field.to_string(),
        value: value.to_string(),
        allowed,
    };
    let mut lines = text.lines().map(|l| l.trim_end_matches('\r')).enumerate();

    match lines.next() {
        Some((_, MAGIC)) => {}
        Some((_, first)) => {
            let allowed = if first.starts_with("dustdem-sample ") {
                format!("unsupported format version; this reader knows '{MAGIC}'")
            } else {
                format!("not a sample file; the first line must be '{MAGIC}'")
            };
            return Err(err(1, "magic", first, allowed));
        }
        None => {
            return Err(err(
                1,
                "magic",
                "(missing)",
                format!("empty file; the first line must be '{MAGIC}'"),
            ))
        }
    }

    // Header.
    let mut header: [Option<Entry>; KEYS.len()] = Default::default();
    let mut end_of_header = None;
    for (i, line) in lines.by_ref() {
        let lineno = i + 1;
        if line.trim() == POSITIONS {
            end_of_header = Some(lineno);
            break;
        }
        let Some((key, value)) = line.split_once('=') else {
            return Err(err(
                lineno,
                "header",
                line,
                format!("expected 'key = value' or '{POSITIONS}'"),
            ));
        };
        let (key, value) = (key.trim(), value.trim());
        let Some(k) = KEYS.iter().position(|&known| known == key) else {
            return Err(err(
                lineno,
                key,
                value,
                format!("unknown key; known keys are {}", KEYS.join(", ")),
            ));
        };
        if let Some(prev) = &header[k] {
            return Err(err(
                lineno,
                key,
                value,
                format!(
                    "each key may appear only once; first given on line {}",
                    prev.line
                ),
            ));
        }
        header[k] = Some(Entry {
            line: lineno,
            value,
        });
    }
    let total_lines = text.lines().count();
    let Some(header_end) = end_of_header else {
        return Err(err(
            total_lines + 1,
            POSITIONS,
            "(missing)",
            format!("the header must end with a line '{POSITIONS}'"),
        ));
    };

    let get = |key: &str| -> Result<&Entry, SampleError> {
        let k = KEYS.iter().position(|&known| known == key).unwrap_or(0);
        header[k].as_ref().ok_or_else(|| {
            err(
                header_end,
                key,
                "(missing)",
                format!("required header key, due before '{POSITIONS}'"),
            )
        })
    };
    // `min` is exclusive when `strict`, inclusive otherwise.
    let float = |key: &str, min: f64, strict: bool, bound: &str| -> Result<f64, SampleError> {
        let e = get(key)?;
        match e.value.parse::<f64>() {
            Ok(v) if v.is_finite() && (v > min || (!strict && v == min)) => Ok(v),
            _ => Err(err(
                e.line,
                key,
                e.value,
                format!(
                    "must be a finite number {} {bound}",
                    if strict { ">" } else { ">=" }
                ),
            )),
        }
    };
    let reject_if_present = |key: &str, kind: &str| -> Result<(), SampleError> {
        let k = KEYS.iter().position(|&known| known == key).unwrap_or(0);
        match &header[k] {
            Some(e) => Err(err(
                e.line,
                key,
                e.value,
                format!("not allowed with footprint = {kind}"),
            )),
            None => Ok(()),
        }
    };

    let radius = float("radius_cm", 0.0, true, "0")?;
    let fp = get("footprint")?;
    let footprint = match fp.value {
        "box" => {
            reject_if_present("cylinder_radius_cm", "box")?;
            Footprint::Box {
                side: float(
                    "side_cm",
                    2.0 * radius,
                    false,
                    &format!("2 radius_cm = {:e}", 2.0 * radius),
                )?,
            }
        }
        "cylinder" => {
            reject_if_present("side_cm", "cylinder")?;
            Footprint::Cylinder {
                radius: float(
                    "cylinder_radius_cm",
                    radius,
                    false,
                    &format!("radius_cm = {radius:e}"),
                )?,
            }
        }
        other => {
            return Err(err(
                fp.line,
                "footprint",
                other,
                "must be 'box' or 'cylinder'".to_string(),
            ))
        }
    };
    let seed_entry = get("seed")?;
    let seed = seed_entry.value.parse::<u64>().map_err(|_| {
        err(
            seed_entry.line,
            "seed",
            seed_entry.value,
            format!("must be a decimal integer in 0..={}", u64::MAX),
        )
    })?;
    let contact_distance = float("contact_distance_cm", 0.0, true, "0")?;
    let n_entry = get("n")?;
    let n = n_entry.value.parse::<usize>().map_err(|_| {
        err(
            n_entry.line,
            "n",
            n_entry.value,
            "must be a non-negative decimal integer".to_string(),
        )
    })?;

    // Monomers.
    let limit = footprint.half_width() - radius;
    let slack = SLACK * radius;
    let (where_allowed, inside): (String, Box<dyn Fn(f64, f64) -> bool>) = match footprint {
        Footprint::Box { .. } => (
            format!("|x|, |y| <= side_cm/2 - radius_cm = {limit:e}"),
            Box::new(move |x: f64, y: f64| x.abs() <= limit + slack && y.abs() <= limit + slack),
        ),
        Footprint::Cylinder { .. } => (
            format!("sqrt(x^2 + y^2) <= cylinder_radius_cm - radius_cm = {limit:e}"),
            Box::new(move |x: f64, y: f64| x.hypot(y) <= limit + slack),
        ),
    };
    // Never trust n for the allocation: a corrupt header must not abort.
    let mut positions = Vec::with_capacity(n.min(total_lines - header_end));
    for (i, line) in lines.by_ref() {
        let lineno = i + 1;
        let index = positions.len();
        if index == n {
            if line.trim().is_empty() {
                continue;
            }
            return Err(err(
                lineno,
                "n",
                &n.to_string(),
                format!("file has more monomer lines than n; extra line '{line}'"),
            ));
        }
        let mut p = [0.0; 3];
        let mut fields = line.split(' ');
        for (c, axis) in ["x", "y", "z"].iter().enumerate() {
            let field = format!("monomer {index} {axis}");
            let Some(s) = fields.next() else {
                return Err(err(
                    lineno,
                    &field,
                    "(missing)",
                    format!("each monomer line must be 'x y z'; got '{line}'"),
                ));
            };
            p[c] = match s.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                _ => {
                    return Err(err(
                        lineno,
                        &field,
                        s,
                        "must be a finite number [cm]".to_string(),
                    ))
                }
            };
        }
        if let Some(extra) = fields.next() {
            return Err(err(
                lineno,
                &format!("monomer {index}"),
                extra,
                format!("each monomer line must be exactly 'x y z'; got '{line}'"),
            ));
        }
        if !inside(p[0], p[1]) {
            return Err(err(
                lineno,
                &format!("monomer {index} (x, y)"),
                &format!("{:e} {:e}", p[0], p[1]),
                format!("sphere sticks out of the footprint; allowed {where_allowed}"),
            ));
        }
        if p[2] < radius - slack {
            return Err(err(
                lineno,
                &format!("monomer {index} z"),
                &format!("{:e}", p[2]),
                format!("sphere goes below the floor; allowed z >= radius_cm = {radius:e}"),
            ));
        }
        positions.push(p);
    }
    if positions.len() != n {
        return Err(err(
            total_lines + 1,
            "n",
            &n.to_string(),
            format!(
                "file is truncated: header says {n} monomers but only {} lines follow '{POSITIONS}'",
                positions.len()
            ),
        ));
    }
    Ok(Sample {
        radius,
        footprint,
        seed,
        contact_distance,
        positions,
    })
}

#[cfg(test)]
mod tests {
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
        let m =
            load_error(&GOOD.replace("contact_distance_cm = 2.0e0", "contact_distance_cm = NaN"));
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
        let m =
            load_error(&GOOD.replace("contact_distance_cm = 2.0e0", "contact_distance_cm = 0.0"));
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
}
