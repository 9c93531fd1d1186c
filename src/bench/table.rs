//! The benchmark's tables: bench.md for reading, bench.csv (one row per N) for scripts.

use super::measure::{Side, SideKind};
use super::options::Threads;
use super::stats::{loglog_slope, median, range, round_ratios};
use super::{Report, SampleState, SideResult, SizeResult};
use crate::backend::gpu::shader::Precision;
use std::fmt::Write;

/// A ratio of two sides' rates, taken per round.
#[derive(Clone, Debug, PartialEq)]
pub struct RatioSpec {
    /// Column prefix in bench.csv.
    pub key: String,
    pub label: String,
    pub numerator: usize,
    pub denominator: usize,
}

/// The ratios the sides allow: dustdem's CPU on all threads against LAMMPS on 2 ranks, on one
/// thread against 1 rank, and the GPU against the CPU on all threads (else one thread).
pub fn ratio_specs(sides: &[Side]) -> Vec<RatioSpec> {
    let find = |kind: SideKind| sides.iter().position(|s| s.kind == kind);
    let all = find(SideKind::Cpu(Threads::All));
    let one = find(SideKind::Cpu(Threads::Count(1)));
    let gpu = find(SideKind::Gpu(Precision::Exact));
    let mixed = find(SideKind::Gpu(Precision::Mixed));
    let mut specs = Vec::new();
    let mut add = |num: Option<usize>, den: Option<usize>| {
        if let (Some(a), Some(b)) = (num, den) {
            specs.push(RatioSpec {
                key: format!("{}_over_{}", sides[a].key, sides[b].key),
                label: format!("{} / {}", sides[a].label, sides[b].label),
                numerator: a,
                denominator: b,
            });
        }
    };
    add(all, find(SideKind::Lammps { ranks: 2 }));
    add(one, find(SideKind::Lammps { ranks: 1 }));
    add(gpu, all.or(one));
    add(mixed, gpu.or(all).or(one));
    add(all, find(SideKind::CpuSampleOrder(Threads::All)));
    add(
        find(SideKind::CpuUntallied(Threads::All)),
        find(SideKind::Lammps { ranks: 2 }),
    );
    specs
}

fn ratios(size: &SizeResult, spec: &RatioSpec) -> Vec<f64> {
    round_ratios(
        &size.sides[spec.numerator].rates,
        &size.sides[spec.denominator].rates,
    )
}

/// Least-squares slope of ln(cost per step) against ln N for side `i` over the sizes it ran
/// on the fresh sample.
pub fn cost_slope(report: &Report, i: usize) -> Option<f64> {
    let points: Vec<(f64, f64)> = report
        .sizes
        .iter()
        .filter(|s| s.sample == SampleState::Fresh)
        .filter_map(|s| {
            let rate = median(&s.sides[i].rates)?;
            Some((s.n as f64, s.n as f64 / rate))
        })
        .collect();
    loglog_slope(&points)
}

const MIB: f64 = 1048576.0;

fn rate_cell(r: &SideResult) -> String {
    match (median(&r.rates), &r.skipped) {
        (Some(rate), _) => format!("{rate:.3e} ({} steps)", r.steps),
        (None, Some(_)) => "not run".into(),
        (None, None) => "–".into(),
    }
}

/// `median (min–max)` of per-round ratios, `–` without any.
pub(super) fn ratio_cell(values: &[f64]) -> String {
    match (median(values), range(values)) {
        (Some(m), Some((lo, hi))) => format!("{m:.2} ({lo:.2}–{hi:.2})"),
        _ => "–".into(),
    }
}

fn opt(value: Option<f64>, digits: usize) -> String {
    value.map_or_else(|| "–".into(), |v| format!("{v:.digits$}"))
}

/// bench.md.
pub fn markdown(report: &Report) -> String {
    let o = &report.options;
    let specs = ratio_specs(&report.sides);
    let mut s = String::new();
    let mut line = |text: &str| {
        let _ = writeln!(s, "{text}");
    };
    line("# dustdem benchmark");
    line("");
    line(&format!(
        "RBD samples (seed 1) compressed omnidirectionally, the top wall at 1 m/s, dt 0.3 ns, \
         the unmodified model of Seizinger et al. (2012). Per N every engine starts from the \
         same state, warmed up past the first contact changes, and runs about {} s per \
         measurement; each of the {} round(s) runs every engine once in turn, so the engines of \
         one round meet the same load. Rates are particle-steps per second (N × steps / \
         wall-clock seconds), the median over the rounds, with the steps of one measurement; \
         ratios are the median of the per-round ratios with their range (min–max).",
        o.seconds, o.rounds
    ));
    if o.samples.iter().any(|s| *s != SampleState::Fresh) {
        line("");
        line(&format!(
            "Compressed samples: the same RBD sample compressed by dustdem at {} m/s until the \
             wall gap's filling factor reached the value, then measured with the top wall still \
             at {} m/s (a compressed sample that a wall suddenly pushes at 1 m/s, above the \
             critical speed, is shaken apart within a few hundred steps).",
            o.prepare_speed_m_s, o.prepare_speed_m_s
        ));
    }
    line("");
    line(&format!("Host: {}.", report.host));
    if let Some(a) = &report.gpu_adapter {
        line(&format!("GPU adapter: {a}."));
    }
    if let Some(v) = &report.lammps_version {
        line(&format!(
            "LAMMPS: {v}, the deck in lammps/n<N>/in.compress (the nearest model it has; the \
             deck's header lists what differs)."
        ));
    }
    line("");
    let mut head = vec![
        "N".to_string(),
        "sample".into(),
        "φ".into(),
        "contacts/monomer".into(),
    ];
    head.extend(report.sides.iter().map(|s| s.label.clone()));
    head.extend(specs.iter().map(|r| r.label.clone()));
    head.push("peak RSS MiB (process)".into());
    for side in &report.sides {
        match side.kind {
            SideKind::Gpu(_) => head.push(format!("{} buffers MiB", side.label)),
            SideKind::Lammps { .. } => head.push(format!("{} MiB/rank", side.label)),
            _ => {}
        }
    }
    if o.lammps {
        head.push("LAMMPS contacts/monomer".into());
    }
    line(&format!("| {} |", head.join(" | ")));
    line(&format!("|{}", "---|".repeat(head.len())));
    for size in &report.sizes {
        let mut row = vec![
            size.n.to_string(),
            size.sample.label(),
            format!("{:.3}", size.phi),
            format!("{:.2}", size.contacts_per_monomer),
        ];
        row.extend(size.sides.iter().map(rate_cell));
        row.extend(specs.iter().map(|r| ratio_cell(&ratios(size, r))));
        row.push(opt(size.peak_rss_bytes.map(|b| b as f64 / MIB), 0));
        for (side, r) in report.sides.iter().zip(&size.sides) {
            if !side.kind.is_cpu() {
                row.push(opt(r.memory_mib, 1));
            }
        }
        if o.lammps {
            row.push(opt(size.lammps_contacts_per_monomer, 2));
        }
        line(&format!("| {} |", row.join(" | ")));
    }
    line("");
    let sizes: Vec<String> = report
        .sizes
        .iter()
        .filter(|s| s.sample == SampleState::Fresh)
        .map(|s| s.n.to_string())
        .collect();
    let slopes: Vec<String> = report
        .sides
        .iter()
        .enumerate()
        .map(|(i, side)| format!("{} {}", side.label, opt(cost_slope(report, i), 2)))
        .collect();
    line(&format!(
        "**Cost per step ∝ N^slope** (least squares of ln(N / rate) on ln N over the fresh \
         samples, N = {}): {}.",
        sizes.join(", "),
        slopes.join("; ")
    ));
    line("");
    line(
        "Sample: the fresh RBD sample, or that sample compressed by dustdem until the wall \
         gap's filling factor reached the value (the notes say at which speed); φ: by the wall \
         gap at the measured start, after the warm-up. Contacts/monomer: 2 × pair contacts / N \
         of dustdem's starting state. Peak RSS: the \
         whole process while that N ran (all dustdem engines and copies of the state; a GPU \
         engine on a software adapter keeps its buffers in it too). LAMMPS contacts/monomer: \
         overlapping pairs at the end of its one-rank runs (LAMMPS does not count JKR contacts \
         stretched beyond touching).",
    );
    if report.sizes.iter().any(|s| !s.peak_rss_per_size) {
        line("The peak RSS could not be reset between sizes: it covers the earlier sizes too.");
    }
    for (i, side) in report.sides.iter().enumerate() {
        if report.sizes.iter().all(|s| s.sides[i].passes.is_empty()) {
            continue;
        }
        let names = side.pass_names();
        line("");
        line(&format!(
            "### {}: µs per step by {}",
            side.label,
            match side.kind {
                SideKind::Lammps { .. } => "section of LAMMPS's timing breakdown (mean over ranks)",
                SideKind::Gpu(_) => "kernel (timestamps around every dispatch of 20 steps)",
                _ => "pass",
            }
        ));
        line("");
        line(&format!("| N | sample | {} |", names.join(" | ")));
        line(&format!("|---|---|{}", "---|".repeat(names.len())));
        for size in &report.sizes {
            let passes = &size.sides[i].passes;
            let cells: Vec<String> = (0..names.len())
                .map(|k| opt(passes.get(k).map(|s| s * 1e6), 1))
                .collect();
            line(&format!(
                "| {} | {} | {} |",
                size.n,
                size.sample.label(),
                cells.join(" | ")
            ));
        }
    }
    s.push_str(&super::whole_run::markdown(&report.sizes));
    let mut line = |text: &str| {
        let _ = writeln!(s, "{text}");
    };
    if !report.notes.is_empty() {
        line("");
        line("### Notes");
        line("");
        for note in &report.notes {
            line(&format!("- {note}"));
        }
    }
    s
}

/// The column names of bench.csv.
pub fn csv_header(report: &Report) -> Vec<String> {
    let mut h = vec![
        "n".to_string(),
        "sample".into(),
        "phi".into(),
        "warmup_steps".into(),
        "contacts_per_monomer".into(),
    ];
    for side in &report.sides {
        for suffix in ["steps", "rate", "rate_min", "rate_max"] {
            h.push(format!("{}_{suffix}", side.key));
        }
    }
    for spec in ratio_specs(&report.sides) {
        for suffix in ["median", "min", "max"] {
            h.push(format!("{}_{suffix}", spec.key));
        }
    }
    h.push("peak_rss_mib".into());
    for side in &report.sides {
        match side.kind {
            SideKind::Gpu(_) => h.push(format!("{}_buffers_mib", side.key)),
            SideKind::Lammps { .. } => h.push(format!("{}_mib_per_rank", side.key)),
            _ => {}
        }
    }
    if report.options.lammps {
        h.push("lammps_contacts_per_monomer".into());
        h.extend(super::whole_run::CSV_COLUMNS.map(String::from));
    }
    for side in &report.sides {
        for name in side.pass_names() {
            h.push(format!("{}_us_{name}", side.key));
        }
    }
    h
}

/// bench.csv: `#` comment lines (what, where, slopes), the header, one row per N; empty cells
/// where a side did not run.
pub fn csv(report: &Report) -> String {
    let specs = ratio_specs(&report.sides);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# dustdem bench: particle-steps/s, RBD samples, 1 m/s omnidirectional compression; \
         medians over {} round(s) of about {} s; host: {}",
        report.options.rounds, report.options.seconds, report.host
    );
    if let Some(a) = &report.gpu_adapter {
        let _ = writeln!(s, "# gpu adapter: {a}");
    }
    if let Some(v) = &report.lammps_version {
        let _ = writeln!(s, "# lammps: {v}");
    }
    for (i, side) in report.sides.iter().enumerate() {
        let _ = writeln!(
            s,
            "# cost_per_step_loglog_slope {} {}",
            side.key,
            cost_slope(report, i).map_or(String::new(), |v| format!("{v:.4}"))
        );
    }
    let _ = writeln!(s, "{}", csv_header(report).join(","));
    let cell = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6e}"));
    for size in &report.sizes {
        let mut row = vec![
            size.n.to_string(),
            size.sample.key(),
            format!("{:.4}", size.phi),
            size.warmup_steps.to_string(),
            format!("{:.4}", size.contacts_per_monomer),
        ];
        for r in &size.sides {
            let (lo, hi) = range(&r.rates).unzip();
            row.push(if r.rates.is_empty() {
                String::new()
            } else {
                r.steps.to_string()
            });
            row.extend([cell(median(&r.rates)), cell(lo), cell(hi)]);
        }
        for spec in &specs {
            let v = ratios(size, spec);
            let (lo, hi) = range(&v).unzip();
            row.extend([cell(median(&v)), cell(lo), cell(hi)]);
        }
        row.push(cell(size.peak_rss_bytes.map(|b| b as f64 / MIB)));
        for (side, r) in report.sides.iter().zip(&size.sides) {
            if !side.kind.is_cpu() {
                row.push(cell(r.memory_mib));
            }
        }
        if report.options.lammps {
            row.push(cell(size.lammps_contacts_per_monomer));
            row.extend(super::whole_run::csv_cells(size.whole_run.as_ref()));
        }
        for (side, r) in report.sides.iter().zip(&size.sides) {
            for k in 0..side.pass_names().len() {
                row.push(cell(r.passes.get(k).map(|s| s * 1e6)));
            }
        }
        let _ = writeln!(s, "{}", row.join(","));
    }
    s
}
