//! REPRODUCTION.md: each of the paper's results (physics.md, "The paper's results") beside
//! what the tier's runs give.

use super::{Request, Study, StudyKind, Tier};
use crate::analysis::fit::Eq13;
use crate::job::figure::{BLUM_SCHRAEPLER_2004_UNI, GUETTLER_2009_OMNI};
use crate::sweep::analyze::{
    analyze_cases, first_seeds, profile_figure_name, rms_against, CaseData, Family,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One study after its sweep ran and was analysed.
pub struct Analysed {
    pub study: Study,
    pub runs: PathBuf,
    pub cases: Vec<CaseData>,
    /// Wall-clock seconds of its sweep in this call (None: run earlier, e.g. by Slurm).
    pub seconds: Option<f64>,
    /// Wall-clock seconds of each case's attempts (from the cases' status files), whenever
    /// they ran.
    pub case_seconds: Vec<f64>,
}

/// Pressures at which the measured curves' φ is listed beside ours [Pa].
const LISTED_PRESSURES: [f64; 4] = [1e2, 1e3, 1e4, 1e5];

fn relative(path: &Path, base: &Path) -> String {
    path.strip_prefix(base)
        .unwrap_or(path)
        .display()
        .to_string()
}

/// The seed-mean φ at `p`, by linear interpolation in log P of the family's average at
/// `speed` (None beyond the pressures the seeds reached).
fn mean_phi_at(f: &Family, speed: f64, p: f64) -> Option<f64> {
    let g = f.speeds.iter().find(|g| g.wall_speed == speed)?;
    let a = &g.average;
    let k = a.iter().position(|x| x.p >= p)?;
    if k == 0 {
        return (a[0].p == p).then_some(a[0].mean);
    }
    let (lo, hi) = (&a[k - 1], &a[k]);
    let t = (p.log10() - lo.p.log10()) / (hi.p.log10() - lo.p.log10());
    Some(lo.mean + t * (hi.mean - lo.mean))
}

fn header(s: &mut String, a: &Analysed, base: &Path) {
    let st = &a.study;
    let time = a.seconds.map_or("not timed in this call".into(), |t| {
        format!("{t:.0} s wall-clock in this call")
    });
    let cases = &a.case_seconds;
    let case_time = if cases.is_empty() {
        String::new()
    } else {
        let lo = cases.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = cases.iter().copied().fold(0.0, f64::max);
        format!(
            " The cases took {:.0} s in all ({lo:.0}–{hi:.0} s each).",
            cases.iter().sum::<f64>()
        )
    };
    let _ = writeln!(
        s,
        "{n} monomers, wall speeds {v:?} m/s, seeds {seeds:?}, models: {models}; {time}.\
         {case_time} Runs and the full analysis: `{runs}/` (`analysis.md`, figures).\n",
        n = st.monomers,
        v = st.speeds,
        seeds = st.seeds,
        models = if st.modified_too {
            "unmodified and modified (m_r = 8, m_s = 2.5)"
        } else {
            "unmodified"
        },
        runs = relative(&a.runs, base),
    );
}

fn figure(s: &mut String, a: &Analysed, base: &Path, prefix: &str, f: &Family) {
    let name = format!("{prefix}_{}_n{}.svg", f.variant, f.monomers);
    let _ = writeln!(
        s,
        "![{prefix} {}]({})\n",
        f.variant,
        relative(&a.runs.join(name), base)
    );
}

/// φ of each model beside a measured curve at the listed pressures, and the RMS difference.
fn comparison(
    s: &mut String,
    families: &[Family],
    speed: f64,
    reference: (&str, &Eq13),
    range: (f64, f64),
) {
    let _ = write!(s, "| model | ");
    for p in LISTED_PRESSURES {
        let _ = write!(s, "φ at {p:.0e} Pa | ");
    }
    let _ = writeln!(s, "RMS Δφ over {:.0e}–{:.0e} Pa |", range.0, range.1);
    let _ = writeln!(s, "|---|{}---|", "---|".repeat(LISTED_PRESSURES.len()));
    let _ = write!(s, "| {} (Eq. 13) | ", reference.0);
    for p in LISTED_PRESSURES {
        let _ = write!(s, "{:.4} | ", reference.1.phi(p));
    }
    let _ = writeln!(s, "– |");
    for f in families {
        let _ = write!(s, "| {} | ", f.variant);
        for p in LISTED_PRESSURES {
            let cell = mean_phi_at(f, speed, p).map_or("not reached".into(), |x| format!("{x:.4}"));
            let _ = write!(s, "{cell} | ");
        }
        let rms = f
            .speeds
            .iter()
            .find(|g| g.wall_speed == speed)
            .and_then(|g| {
                let points: Vec<(f64, f64)> = g.average.iter().map(|a| (a.p, a.mean)).collect();
                rms_against(&points, reference.1, range)
            })
            .map_or("–".into(), |(r, n)| format!("{r:.4} ({n} points)"));
        let _ = writeln!(s, "{rms} |");
    }
    s.push('\n');
}

fn limits(tier: Tier) -> &'static str {
    match tier {
        Tier::Smoke => {
            "The smoke tier's samples (150–300 monomers) are far too small for any of the \
             paper's effects; it exists to test the pipeline."
        }
        Tier::Quick => {
            "Scaled down from the paper: 1000 monomers (paper: about 11 000) make a box of \
             about 18 µm, a few monomer chains across, so the curve's low-pressure part scatters \
             between seeds by about 0.01 in φ; 5 cm/s is the paper's upper quasi-static speed \
             (it found 5 cm/s and below to differ little). The dynamic runs' 4000 monomers \
             (paper: 40 000) give a sample of about 30 µm height, about 25 slabs, in which the \
             compaction front crosses a few slabs before it reaches the bottom: v_p rests on \
             few profiles. The unidirectional cylinder of 1000 monomers (paper: 18 000) has a \
             large free surface for its volume, and runs at 10 cm/s (paper: 5 cm/s). The full tier (`--tier full`, for a GPU or a \
             cluster with `--slurm`) uses the paper's sizes."
        }
        Tier::Full => "The paper's sizes and six seeds per case.",
    }
}

/// The whole report.
pub fn markdown(request: &Request, studies: &[Analysed]) -> String {
    let base = std::path::absolute(&request.out).unwrap_or_else(|_| request.out.clone());
    let mut s = format!(
        "# Reproducing Seizinger, Speith & Kley (2012): {} tier\n\n",
        request.tier
    );
    let _ = writeln!(
        s,
        "Command: `dustdem reproduce --tier {} --out {} --jobs {}`, dustdem {}, on {}. Every \
         number below comes from the runs under this directory; the model is the paper's, not \
         tuned to its results.\n",
        request.tier,
        request.out.display(),
        request.jobs,
        env!("CARGO_PKG_VERSION"),
        crate::bench::host()
    );
    for a in studies {
        let families = analyze_cases(&a.cases);
        let _ = writeln!(s, "## {}\n", a.study.title);
        header(&mut s, a, &base);
        match a.study.kind {
            StudyKind::QuasiStatic => {
                s += "Paper: the unmodified model's curve lies well above Güttler et al. (2009) \
                      at low pressure (too soft); with m_r = 8, m_s = 2.5 it agrees very well \
                      below 100 kPa, and above 300 kPa needs more than 1 MPa beyond φ ≈ 0.52.\n\n";
                for &v in &a.study.speeds {
                    let _ = writeln!(s, "At {v} m/s, seed means:\n");
                    comparison(
                        &mut s,
                        &families,
                        v,
                        ("Güttler et al. 2009", &GUETTLER_2009_OMNI),
                        (1e2, 1e5),
                    );
                }
                for f in &families {
                    figure(&mut s, a, &base, "phi_p", f);
                }
            }
            StudyKind::Dynamic => {
                s += "Paper: three regimes (no compaction until a critical pressure, a plateau, \
                      a steep rise); a dense layer forms under the wall and moves down at \
                      v_p = 6.98 ± 0.16 m/s; p_m(v) = 1.340 v^1.93 + 0.307 kPa (or 1.087 v² + \
                      0.560), Δ(v) = (v + 1.598)^−1.997 + 0.170.\n\n";
                for f in &families {
                    let table = crate::sweep::analyze::markdown(std::slice::from_ref(f), &[]);
                    // The family's section of the sweep report, without its title lines.
                    let body: Vec<&str> = table
                        .lines()
                        .skip_while(|l| !l.starts_with("## "))
                        .skip(1)
                        .collect();
                    s += &body.join("\n");
                    s += "\n";
                    figure(&mut s, a, &base, "phi_p", f);
                    figure(&mut s, a, &base, "pm_v", f);
                    figure(&mut s, a, &base, "delta_v", f);
                }
                s += "Filling-factor profiles of the first seed at six times each, with the \
                      compaction front (dotted, where found: the lowest height where φ exceeds \
                      the initial profile by 0.05):\n\n";
                for c in first_seeds(&a.cases) {
                    let path = a.runs.join(profile_figure_name(c));
                    if path.is_file() {
                        let _ = writeln!(
                            s,
                            "![profiles at {} m/s]({})\n",
                            c.wall_speed,
                            relative(&path, &base)
                        );
                    }
                }
            }
            StudyKind::Uni => {
                s += "Paper: the unmodified model is too soft; the modified one agrees with Blum \
                      & Schräpler (2004) below 10⁴ Pa but reaches higher φ.\n\n";
                for &v in &a.study.speeds {
                    let _ = writeln!(s, "At {v} m/s, seed means:\n");
                    comparison(
                        &mut s,
                        &families,
                        v,
                        ("Blum & Schräpler 2004", &BLUM_SCHRAEPLER_2004_UNI),
                        (1e2, 1e4),
                    );
                }
                for f in &families {
                    figure(&mut s, a, &base, "phi_p", f);
                }
            }
        }
    }
    let _ = writeln!(
        s,
        "## What this tier cannot show\n\n{}",
        limits(request.tier)
    );
    s
}
