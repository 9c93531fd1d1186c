//! What a calibration answers to data with two hidden effects, judged against the truth: both
//! effects named (each hidden factor inside the interval of the fit that named it), or an
//! undetermined round with the hidden pair among its candidates. An effect of the damping's
//! other form counts as the damping (one family), but then its factor is not comparable and
//! is not checked. Anything else, one effect named alone above all, is a wrong answer.

use dustdem::calibrate::attribution::Decision;
use dustdem::calibrate::pairs::find_pair;
use dustdem::calibrate::{Calibration, Effect};

fn same_families(a: [Effect; 2], b: [Effect; 2]) -> bool {
    let f = |p: [Effect; 2]| {
        let mut v = p.map(|e| e.family());
        v.sort_by_key(|e| e.name());
        v
    };
    f(a) == f(b)
}

/// Whether the hidden factor of `named`'s family lies in `interval` (true for the other
/// damping form, whose factor is not comparable).
fn inside(hidden: &[(Effect, f64); 2], named: Effect, interval: (f64, f64)) -> bool {
    hidden
        .iter()
        .find(|(e, _)| e.family() == named.family())
        .is_some_and(|&(e, f)| e != named || (interval.0 <= f && f <= interval.1))
}

/// Ok with a one-line description of a right answer; Err with what was wrong.
pub fn pair_answer(cal: &Calibration, hidden: [(Effect, f64); 2]) -> Result<String, String> {
    let truth = hidden.map(|(e, _)| e);
    let mut named: Vec<(Effect, (f64, f64))> = Vec::new();
    for (k, round) in cal.rounds.iter().enumerate() {
        match &round.decision {
            Decision::NamedPair(p) if same_families(*p, truth) => {
                let fit = find_pair(&round.pairs, *p).ok_or("named pair without its fit")?;
                let ok = (0..2).all(|j| inside(&hidden, p[j], fit.intervals[j]));
                return match ok {
                    true => Ok(format!("round {}: both named, {}", k + 1, fit.label())),
                    false => Err(format!("both named, truth outside: {}", fit.label())),
                };
            }
            Decision::Undetermined { pairs, .. }
                if pairs.iter().any(|p| same_families(*p, truth)) =>
            {
                return Ok(format!(
                    "round {}: undetermined, the pair among {pairs:?}",
                    k + 1
                ));
            }
            Decision::Named(e) | Decision::Unpredictive { effect: e, .. } => {
                let fit = round.fits.iter().find(|f| f.effect == *e).ok_or("no fit")?;
                named.push((*e, fit.interval));
            }
            other => return Err(format!("round {}: {other:?} after {named:?}", k + 1)),
        }
        if named.len() == 2 {
            let both = [named[0].0, named[1].0];
            if !same_families(both, truth) {
                return Err(format!("named {both:?}"));
            }
            if named.iter().all(|&(e, i)| inside(&hidden, e, i)) {
                return Ok(format!("both named in two rounds: {named:?}"));
            }
            return Err(format!("both named, truth outside: {named:?}"));
        }
    }
    Err(format!("named alone: {named:?}"))
}
