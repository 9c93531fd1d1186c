//! Property tests of the three parsers (config, sample file, checkpoint): mutated inputs give
//! an error or a value, never a panic.
//!
//! CI runs a fixed number of cases per parser. For a longer, time-bounded search:
//! `DUSTDEM_FUZZ_SECONDS=600 cargo test --release --test fuzz_parsers -- --nocapture`
//! (seconds per parser; a failing input is saved in a temp directory that the failure names
//! and that is kept).

mod common;

use common::exe::dustdem_ok;
use common::Scratch;
use dustdem::binary::fnv1a64;
use dustdem::config::Config;
use dustdem::job::load_checkpoint;
use dustdem::sample::Sample;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::time::{Duration, Instant};

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Bit flips, byte overwrites, deletions, insertions, truncation and chunk duplication.
fn mutate(rng: &mut Rng, input: &[u8], tokens: &[&[u8]]) -> Vec<u8> {
    let mut b = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(b.len() + 1);
        match rng.below(7) {
            0 if !b.is_empty() => {
                let k = rng.below(b.len());
                b[k] ^= 1 << rng.below(8);
            }
            1 if !b.is_empty() => {
                let k = rng.below(b.len());
                b[k] = rng.next() as u8;
            }
            2 if at < b.len() => {
                let end = (at + 1 + rng.below(16)).min(b.len());
                b.drain(at..end);
            }
            3 => {
                let t = tokens[rng.below(tokens.len())];
                b.splice(at..at, t.iter().copied());
            }
            4 => b.truncate(at),
            5 if at < b.len() => {
                let end = (at + 1 + rng.below(64)).min(b.len());
                let chunk = b[at..end].to_vec();
                b.splice(at..at, chunk);
            }
            _ => b.insert(at.min(b.len()), rng.next() as u8),
        }
    }
    b
}

fn budget() -> (usize, Duration) {
    match std::env::var("DUSTDEM_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse::<u64>().ok())
    {
        Some(s) => (usize::MAX, Duration::from_secs(s)),
        None => (400, Duration::from_secs(3600)),
    }
}

fn fuzz(name: &str, seed: &[u8], tokens: &[&[u8]], dir: &Path, check: &dyn Fn(&[u8])) {
    let (cases, time) = budget();
    let start = Instant::now();
    let mut rng = Rng(fnv1a64(name.as_bytes()));
    let mut done = 0;
    while done < cases && start.elapsed() < time {
        let input = mutate(&mut rng, seed, tokens);
        if catch_unwind(AssertUnwindSafe(|| check(&input))).is_err() {
            let saved = dir.join(format!("{name}-panic.bin"));
            std::fs::write(&saved, &input).unwrap();
            panic!(
                "{name}: parser panicked on the input saved in {}",
                saved.display()
            );
        }
        done += 1;
    }
    eprintln!("{name}: {done} mutated inputs, no panic");
}

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("fuzz-{name}"))
}

const TOML_TOKENS: &[&[u8]] = &[
    b"nan",
    b"inf",
    b"-1",
    b"1e400",
    b"\"",
    b"[",
    b"]",
    b"=",
    b"\n",
    b"{",
    b"}",
    b"0",
    b"true",
    b"[[sample]]",
    b"kind = \"uni\"",
    b"\xff",
];

#[test]
fn config_parser_never_panics() {
    let dir = scratch("config");
    let seed = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/omni_quick.toml"))
        .unwrap();
    let full = b"[material]\nradius_um = 0.6\n[model]\ndamping = { kind = \"viscoelastic\", t_vis = 1e-11 }\n[walls]\nside = { rolling = 0.001, sliding = 0.001, twisting = 0.001 }\n[integration]\ndt_ns = 0.2\n";
    let seed = [seed.as_slice(), full].concat();
    fuzz("config", &seed, TOML_TOKENS, &dir, &|input| {
        let text = String::from_utf8_lossy(input);
        let _ = Config::parse(&text, "fuzz.toml");
    });
}

#[test]
fn sample_parser_never_panics() {
    let dir = scratch("sample");
    let good = dir.join("good.sample");
    let config = dir.join("small.toml");
    std::fs::write(&config, "[sample]\nmonomers = 12\n").unwrap();
    dustdem_ok([
        "generate",
        config.to_str().unwrap(),
        "--out",
        good.to_str().unwrap(),
    ]);
    let seed = std::fs::read(&good).unwrap();
    let path = dir.join("mutated.sample");
    let tokens: &[&[u8]] = &[
        b"NaN",
        b"inf",
        b"-",
        b"e999",
        b" ",
        b"\n",
        b"=",
        b"n = 99999999999",
        b"cylinder",
        b"\r\n",
        b"\xc3",
    ];
    fuzz("sample", &seed, tokens, &dir, &|input| {
        std::fs::write(&path, input).unwrap();
        let _ = Sample::load(&path);
    });
}

#[test]
fn checkpoint_reader_never_panics() {
    let dir = scratch("checkpoint");
    let config = dir.join("ckpt.toml");
    std::fs::write(
        &config,
        "[sample]\nmonomers = 30\n[experiment]\nmax_steps = 200\n[output]\ncheckpoint_every_rows = 1\nsnapshot_format = \"none\"\n",
    )
    .unwrap();
    let out_dir = dir.join("ckpt-run");
    dustdem_ok([
        "run",
        config.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
        "--quiet",
    ]);
    let seed = std::fs::read(out_dir.join("checkpoint.bin")).unwrap();
    let path = dir.join("mutated.bin");
    let tokens: &[&[u8]] = &[
        &[0xff; 8],
        &[0; 8],
        &u64::MAX.to_le_bytes(),
        &f64::NAN.to_le_bytes(),
    ];
    // Half the cases keep the checksum valid, so the body decoder is exercised too.
    let counter = std::cell::Cell::new(0u64);
    fuzz("checkpoint", &seed, tokens, &dir, &|input| {
        let mut bytes = input.to_vec();
        counter.set(counter.get() + 1);
        if counter.get().is_multiple_of(2) && bytes.len() >= 36 {
            let body_len = (bytes.len() - 36) as u64;
            bytes[20..28].copy_from_slice(&body_len.to_le_bytes());
            let sum = fnv1a64(&bytes[36..]);
            bytes[28..36].copy_from_slice(&sum.to_le_bytes());
        }
        std::fs::write(&path, &bytes).unwrap();
        let _ = load_checkpoint(&path);
    });
}
