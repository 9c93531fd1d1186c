//! The paper's claims, one row each: the paper's value and conditions, ours with its error,
//! their ratio, the tolerance, a verdict and, for a "differs", the check that says why.
//! Rows carry the sample size they rest on, and the totals count each size apart: only rows
//! at the paper's own size count towards the headline.
//!
//! Tolerances. Seizinger et al. (2012) give no errors for their per-speed p_m and Δ nor for
//! the laws' coefficients, and average six samples where we may have fewer; a value agrees
//! when it lies within twice our seed-to-seed error plus 20 % of the paper's value (the
//! sample-to-sample spread of p_m at six 40 000-monomer samples is of that order in our own
//! runs). Filling factors agree within 0.03, a fifth of the rise of Güttler's curve from
//! 10² to 10⁴ Pa. Each row states its tolerance.

use crate::analysis::average::Spread;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Relative allowance for the paper's unstated errors.
pub const PAPER_SPREAD: f64 = 0.2;
/// Allowed difference of filling factors.
pub const PHI_TOL: f64 = 0.03;

#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    Agrees,
    Differs,
    NotTested(String),
}

impl Verdict {
    /// Agrees when `ok`, differs otherwise.
    pub fn agrees_if(ok: bool) -> Verdict {
        if ok {
            Verdict::Agrees
        } else {
            Verdict::Differs
        }
    }

    pub fn text(&self) -> String {
        match self {
            Verdict::Agrees => "agrees".into(),
            Verdict::Differs => "**differs**".into(),
            Verdict::NotTested(why) => format!("not tested: {why}"),
        }
    }
}

/// One row of the table.
#[derive(Clone, Debug)]
pub struct Claim {
    pub claim: String,
    pub paper: String,
    pub ours: String,
    pub ratio: Option<f64>,
    pub tolerance: String,
    pub verdict: Verdict,
    /// The sample size of the runs the row rests on (none for a claim on no runs).
    pub monomers: Option<usize>,
    /// Whether that is the paper's own size for the study.
    pub paper_size: bool,
    /// For a "differs": what a reader can re-run from the stored curves to see why.
    pub why: String,
}

impl Claim {
    /// A claim stated from `verdict` alone (size and reason filled in later).
    pub fn new(
        claim: &str,
        paper: &str,
        ours: String,
        tolerance: String,
        verdict: Verdict,
    ) -> Self {
        Claim {
            claim: claim.into(),
            paper: paper.into(),
            ours,
            ratio: None,
            tolerance,
            verdict,
            monomers: None,
            paper_size: false,
            why: String::new(),
        }
    }

    /// The row rests on runs of `monomers`, the paper's size when it equals `paper`.
    pub fn at_size(mut self, monomers: usize, paper: usize) -> Claim {
        self.monomers = Some(monomers);
        self.paper_size = monomers == paper;
        self
    }

    /// The reason a "differs" differs; ignored for any other verdict.
    pub fn because(mut self, why: impl FnOnce() -> String) -> Claim {
        if self.verdict == Verdict::Differs {
            self.why = why();
        }
        self
    }
}

pub fn untested(claim: &str, paper: &str, why: &str) -> Claim {
    Claim::new(
        claim,
        paper,
        "–".into(),
        "–".into(),
        Verdict::NotTested(why.into()),
    )
}

/// `ours ± err` against `paper` at twice `err` plus [`PAPER_SPREAD`].
pub fn compare(
    claim: String,
    paper: f64,
    unit: &str,
    ours: f64,
    err: f64,
    conditions: &str,
) -> Claim {
    let tol = 2.0 * if err.is_finite() { err } else { 0.0 } + PAPER_SPREAD * paper.abs();
    let err_text = if err.is_finite() {
        format!(" ± {}", sig(err))
    } else {
        " (one seed: no error)".into()
    };
    let verdict = Verdict::agrees_if((ours - paper).abs() <= tol);
    Claim {
        ratio: Some(ours / paper),
        ..Claim::new(
            &claim,
            &format!("{}{unit} ({conditions})", sig(paper)),
            format!("{}{err_text}{unit}", sig(ours)),
            format!("±{}{unit} (2σ + 20 %)", sig(tol)),
            verdict,
        )
    }
}

/// Three significant digits, plain.
pub fn sig(v: f64) -> String {
    if !v.is_finite() {
        return "–".into();
    }
    let a = v.abs();
    let decimals = if a == 0.0 {
        0
    } else {
        (2 - a.log10().floor() as i32).clamp(0, 6) as usize
    };
    format!("{v:.decimals$}")
}

pub fn spread_text(s: &Spread, unit: &str) -> String {
    if s.count > 1 {
        format!("{} ± {}{unit} ({} seeds)", sig(s.mean), sig(s.sem), s.count)
    } else {
        format!("{}{unit} (1 seed)", sig(s.mean))
    }
}

/// The table as Markdown.
pub fn table(claims: &[Claim]) -> String {
    let mut s = String::from(
        "| claim | paper (conditions) | ours | ours / paper | tolerance | verdict | why it differs |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for c in claims {
        let ratio = c.ratio.map_or("–".into(), |r| format!("{r:.2}"));
        let why = if c.why.is_empty() { "–" } else { &c.why };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {ratio} | {} | {} | {why} |",
            c.claim,
            c.paper,
            c.ours,
            c.tolerance,
            c.verdict.text()
        );
    }
    s
}

/// Counts of agree, differ and not tested.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    pub agree: usize,
    pub differ: usize,
    pub not_tested: usize,
}

/// The verdicts counted per sample size (`None`: rows on no runs), and whether each size is
/// the paper's own for its rows.
pub fn totals(claims: &[Claim]) -> BTreeMap<(bool, Option<usize>), Tally> {
    let mut out: BTreeMap<(bool, Option<usize>), Tally> = BTreeMap::new();
    for c in claims {
        let t = out.entry((c.paper_size, c.monomers)).or_default();
        match c.verdict {
            Verdict::Agrees => t.agree += 1,
            Verdict::Differs => t.differ += 1,
            Verdict::NotTested(_) => t.not_tested += 1,
        }
    }
    out
}

/// The totals as a Markdown table, rows at the paper's sizes first: they are the headline.
pub fn totals_table(claims: &[Claim]) -> String {
    let mut s =
        String::from("| rows | monomers | agree | differ | not tested |\n|---|---|---|---|---|\n");
    for ((paper, monomers), t) in totals(claims).iter().rev() {
        let size = monomers.map_or("–".into(), |n| n.to_string());
        let kind = if *paper {
            "at the paper's size (headline)"
        } else {
            "at another size"
        };
        let _ = writeln!(
            s,
            "| {kind} | {size} | {} | {} | {} |",
            t.agree, t.differ, t.not_tested
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_agrees_within_twice_its_error_plus_a_fifth_of_the_paper() {
        // Paper 100, ours 70 ± 5: allowed 2·5 + 20 = 30, off by 30.
        let at = compare("x".into(), 100.0, "", 70.0, 5.0, "c");
        assert_eq!(at.verdict, Verdict::Agrees);
        let beyond = compare("x".into(), 100.0, "", 69.9, 5.0, "c");
        assert_eq!(beyond.verdict, Verdict::Differs);
        // One seed: no error, the 20 % alone.
        let one = compare("x".into(), 100.0, "", 81.0, f64::NAN, "c");
        assert_eq!(one.verdict, Verdict::Agrees);
        assert!(one.ours.contains("one seed"));
        assert!((one.ratio.unwrap() - 0.81).abs() < 1e-12);
    }

    #[test]
    fn totals_count_each_size_apart_and_put_the_paper_size_first() {
        let row = |v: Verdict, n: usize, paper: usize| {
            Claim::new("c", "p", "o".into(), "t".into(), v).at_size(n, paper)
        };
        let claims = [
            row(Verdict::Agrees, 40_000, 40_000),
            row(Verdict::Differs, 40_000, 40_000),
            row(Verdict::Differs, 40_000, 40_000),
            row(Verdict::Differs, 2000, 11_000),
            row(Verdict::NotTested("x".into()), 2000, 11_000),
            untested("c", "p", "no runs"),
        ];
        let t = totals(&claims);
        let tally = |agree, differ, not_tested| Tally {
            agree,
            differ,
            not_tested,
        };
        assert_eq!(t[&(true, Some(40_000))], tally(1, 2, 0));
        assert_eq!(t[&(false, Some(2000))], tally(0, 1, 1));
        assert_eq!(t[&(false, None)], tally(0, 0, 1));
        let text = totals_table(&claims);
        let first = text.lines().nth(2).unwrap();
        assert_eq!(
            first,
            "| at the paper's size (headline) | 40000 | 1 | 2 | 0 |"
        );
    }

    #[test]
    fn only_a_differs_carries_a_reason() {
        let differs = compare("x".into(), 100.0, "", 50.0, 1.0, "c").because(|| "r".into());
        assert_eq!(differs.why, "r");
        let agrees = compare("x".into(), 100.0, "", 99.0, 1.0, "c").because(|| "r".into());
        assert_eq!(agrees.why, "");
        assert!(table(&[agrees]).ends_with("| agrees | – |\n"));
    }

    #[test]
    fn numbers_print_with_three_significant_digits() {
        assert_eq!(sig(6.98), "6.98");
        assert_eq!(sig(141.23), "141");
        assert_eq!(sig(0.04663), "0.0466");
        assert_eq!(sig(-44.298), "-44.3");
        assert_eq!(sig(f64::NAN), "–");
    }
}
