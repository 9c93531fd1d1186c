//! One float mode's GPU results against the Rust twins: per-function tallies of identical
//! results and the worst difference, and the check against the mode's tolerance.

use super::Record;
use dustdem::backend::gpu::shader::FloatMode;
use std::collections::BTreeMap;

/// |gpu − cpu| relative to the largest |cpu| component: 0 when bit-identical or NaN on both
/// sides, infinite when only one side is NaN.
pub(crate) fn relative_difference(gpu: &[f64], cpu: &[f64]) -> f64 {
    if gpu.iter().zip(cpu).all(|(g, c)| g.to_bits() == c.to_bits()) {
        return 0.0;
    }
    let scale = cpu.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    let diff = gpu
        .iter()
        .zip(cpu)
        .fold(0.0f64, |m, (g, c)| m.max((g - c).abs()));
    if diff.is_nan() {
        f64::INFINITY
    } else if diff == 0.0 {
        // Only signed zeros differ.
        0.0
    } else {
        diff / scale
    }
}

#[derive(Default)]
struct Tally {
    results: usize,
    identical: usize,
    worst: f64,
    worst_case: usize,
}

/// One mode's run compared with the Rust twins.
pub(crate) struct Comparison {
    tallies: BTreeMap<&'static str, Tally>,
    flag_mismatches: Vec<String>,
}

impl Comparison {
    pub(crate) fn new(gpu: &[f64], expected: &[Record], in_stride: usize) -> Self {
        let written = expected[0].values.len();
        let mut tallies: BTreeMap<&'static str, Tally> = BTreeMap::new();
        let mut flag_mismatches = Vec::new();
        for (i, (record, rust)) in gpu.chunks(written + 2).zip(expected).enumerate() {
            assert_eq!(
                (record[0] as usize, record[1] as usize),
                (in_stride, written),
                "record {i}: the probe read/wrote a different number of values than the test \
                 laid out"
            );
            let values = &record[2..];
            for (name, range) in &rust.groups {
                let (g, c) = (&values[range.clone()], &rust.values[range.clone()]);
                if name.ends_with("(fired)") && g != c {
                    flag_mismatches.push(format!("record {i}: {name} GPU {g:?} CPU {c:?}"));
                }
                let rel = relative_difference(g, c);
                let t = tallies.entry(name).or_default();
                t.results += 1;
                t.identical += usize::from(rel == 0.0);
                if rel > t.worst {
                    t.worst = rel;
                    t.worst_case = i;
                }
            }
        }
        Comparison {
            tallies,
            flag_mismatches,
        }
    }

    pub(crate) fn print(&self, title: &str) {
        println!("{title}");
        println!(
            "  {:<34} {:>8} {:>10} {:>11}  worst record",
            "function", "results", "identical", "max rel"
        );
        for (name, t) in &self.tallies {
            println!(
                "  {name:<34} {:>8} {:>10} {:>11.3e}  {}",
                t.results, t.identical, t.worst, t.worst_case
            );
        }
    }

    pub(crate) fn check(&self, mode: FloatMode, tolerance: f64) {
        assert!(
            self.flag_mismatches.is_empty(),
            "{mode:?}: inelastic corrections fired on different records:\n{}",
            self.flag_mismatches.join("\n")
        );
        let over: Vec<_> = self
            .tallies
            .iter()
            .filter(|(_, t)| t.worst > tolerance)
            .map(|(name, t)| format!("{name}: {:.3e} (record {})", t.worst, t.worst_case))
            .collect();
        assert!(
            over.is_empty(),
            "{mode:?}: GPU and CPU twins differ by more than {tolerance:e}:\n{}",
            over.join("\n")
        );
    }
}
