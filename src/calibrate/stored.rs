//! The on-disk form of a run's output: a header, the run's full key (its config, compared on
//! reading so a hash collision reads as a miss), and the values as exact f64 bit patterns.

use super::simulate::{Envelope, Output};
use std::path::Path;

const HEADER: &str = "dustdem calibration run 1";

fn bits(x: f64) -> String {
    format!("{:016x}", x.to_bits())
}

fn value(text: &str) -> Option<f64> {
    u64::from_str_radix(text, 16).ok().map(f64::from_bits)
}

pub fn write(key: &str, out: &Output) -> String {
    let mut s = format!("{HEADER}\n{}\n{key}\n", key.len());
    match out {
        Output::Sticking(v) => s.push_str(&format!("sticking {}\n", bits(*v))),
        Output::Envelope(e) => {
            s.push_str(&format!("envelope {}\n", e.phi.len()));
            for (phi, p) in e.phi.iter().zip(&e.log10_p) {
                s.push_str(&format!("{} {}\n", bits(*phi), bits(*p)));
            }
            if let Some(f) = &e.failure {
                s.push_str(&format!("failure {}\n", f.replace('\n', " ")));
            }
        }
    }
    s
}

/// The stored output of the run with `key`, or None (no file, another run, damaged).
pub fn read(path: &Path, key: &str) -> Option<Output> {
    let text = std::fs::read_to_string(path).ok()?;
    let rest = text.strip_prefix(HEADER)?.strip_prefix('\n')?;
    let (len, rest) = rest.split_once('\n')?;
    let len: usize = len.parse().ok()?;
    let stored_key = rest.get(..len)?;
    if stored_key != key {
        return None;
    }
    let mut lines = rest.get(len..)?.strip_prefix('\n')?.lines();
    let (kind, n) = lines.next()?.split_once(' ')?;
    match kind {
        "sticking" => Some(Output::Sticking(value(n)?)),
        "envelope" => {
            let n: usize = n.parse().ok()?;
            let mut e = Envelope {
                phi: Vec::with_capacity(n),
                log10_p: Vec::with_capacity(n),
                failure: None,
            };
            for _ in 0..n {
                let (a, b) = lines.next()?.split_once(' ')?;
                e.phi.push(value(a)?);
                e.log10_p.push(value(b)?);
            }
            if let Some(line) = lines.next() {
                e.failure = Some(line.strip_prefix("failure ")?.to_string());
            }
            Some(Output::Envelope(e))
        }
        _ => None,
    }
}
