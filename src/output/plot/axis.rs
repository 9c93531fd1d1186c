//! Owns the drawing space of `output::plot`'s charts (log10 of the value on a log axis): axis
//! limits fitted to the data, labelled ticks (1-2-5 steps, or decades as 10ⁿ) and light grid
//! lines, handed to plotters as its coordinate type, and the clipping of lines at the frame.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use std::ops::Range;

/// One axis in drawing space (log10 of the value on a log axis): limits, labelled ticks and
/// the light grid lines between them (2…9 × 10ᵏ on log axes of few decades).
#[derive(Clone)]
pub(super) struct Axis {
    pub(super) lo: f64,
    pub(super) hi: f64,
    log: bool,
    major: Vec<(f64, String)>,
    minor: Vec<f64>,
}

impl Axis {
    pub(super) fn new(
        log: bool,
        range: Option<(f64, f64)>,
        values: impl Iterator<Item = f64>,
        ticks: &[(f64, String)],
    ) -> Axis {
        let to = |v: f64| if log { v.log10() } else { v };
        let ok = |v: &f64| v.is_finite() && (!log || *v > 0.0);
        let fixed = range.filter(|r| ok(&r.0) && ok(&r.1) && r.0 != r.1);
        let (lo, hi) = fixed.map_or_else(
            || {
                let (min, max) = values
                    .filter(ok)
                    .map(to)
                    .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
                if min > max {
                    (0.0, 1.0)
                } else if log {
                    (min.floor(), max.ceil().max(min.floor() + 1.0))
                } else {
                    let pad = if max > min {
                        0.05 * (max - min)
                    } else {
                        0.1 * min.abs().max(1.0)
                    };
                    let step = nice_step((max - min + 2.0 * pad) / 6.0);
                    (
                        ((min - pad) / step).floor() * step,
                        ((max + pad) / step).ceil() * step,
                    )
                }
            },
            |(a, b)| (to(a.min(b)), to(a.max(b))),
        );
        // Log axes show at least two labelled decades.
        let (lo, hi) = match log && hi.floor() <= lo.ceil() {
            true => (lo.floor(), hi.ceil().max(lo.floor() + 1.0)),
            false => (lo, hi),
        };
        let (first, last) = (lo.ceil() as i32, hi.floor() as i32);
        let inside = |v: &f64| (lo - 1e-9..=hi + 1e-9).contains(v);
        let mut minor = Vec::new();
        let major: Vec<(f64, String)>;
        if !ticks.is_empty() {
            major = ticks.iter().map(|(v, s)| (to(*v), s.clone())).collect();
        } else if log {
            const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
            let sup = |k: i32| {
                k.to_string()
                    .chars()
                    .map(|c| c.to_digit(10).map_or('⁻', |d| SUP[d as usize]))
                    .collect::<String>()
            };
            let stride = (last - first + 10) / 10;
            major = (first..=last)
                .step_by(stride as usize)
                .map(|k| (f64::from(k), format!("10{}", sup(k))))
                .collect();
            if stride == 1 && last - first <= 7 {
                let logs = (first - 1..=last)
                    .flat_map(|k| (2..=9).map(move |m| f64::from(k) + f64::from(m).log10()));
                minor = logs.filter(inside).collect();
            }
        } else {
            let step = nice_step((hi - lo) / 6.0);
            let decimals = (-step.log10().floor()).max(0.0) as usize;
            let big = !(1e-3..1e6).contains(&lo.abs().max(hi.abs()));
            let label = |v: f64| match v {
                _ if v.abs() < 1e-9 * step => "0".into(),
                _ if big => format!("{v:.1e}"),
                _ => format!("{v:.decimals$}"),
            };
            let ks = (lo / step - 1e-9).ceil() as i64..=(hi / step + 1e-9).floor() as i64;
            major = ks
                .map(|k| (k as f64 * step, label(k as f64 * step)))
                .collect();
        }
        let major = major
            .into_iter()
            .map(|(v, s)| (v, s.replace('-', "−")))
            .collect();
        Axis {
            lo,
            hi,
            log,
            major,
            minor,
        }
    }

    /// Drawing-space coordinate of a value, `None` where it cannot be placed.
    pub(super) fn place(&self, v: f64) -> Option<f64> {
        let v = if self.log { v.log10() } else { v };
        v.is_finite().then_some(v)
    }

    pub(super) fn label(&self, v: f64) -> String {
        let tick = self.major.iter().find(|t| t.0 == v);
        tick.map(|t| t.1.clone()).unwrap_or_default()
    }
}

/// The axis as plotters' coordinate: linear in drawing space, ticks from [`Axis::new`].
impl Ranged for Axis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let t = (v - self.lo) / (self.hi - self.lo);
        limit.0 + (t * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        match hint.weight().allow_light_points() {
            true => self.minor.clone(),
            false => self.major.iter().map(|t| t.0).collect(),
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

/// Smallest of 1, 2, 5 × 10ᵏ not below `raw`.
fn nice_step(raw: f64) -> f64 {
    let mag = 10f64.powf(raw.log10().floor());
    let m = [1.0, 2.0, 5.0].into_iter().find(|m| raw / mag <= m + 1e-9);
    if mag.is_finite() && mag > 0.0 {
        mag * m.unwrap_or(10.0)
    } else {
        1.0
    }
}

/// Liang–Barsky: the part of segment a→b inside the box x × y, if any.
type Segment = ((f64, f64), (f64, f64));
pub(super) fn clip((a, b): Segment, x: (f64, f64), y: (f64, f64)) -> Option<Segment> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - x.0),
        (dx, x.1 - a.0),
        (-dy, a.1 - y.0),
        (dy, y.1 - a.1),
    ] {
        match p {
            _ if p == 0.0 && q < 0.0 => return None,
            _ if p < 0.0 => t0 = t0.max(q / p),
            _ if p > 0.0 => t1 = t1.min(q / p),
            _ => {}
        }
    }
    let at = |t: f64| (a.0 + t * dx, a.1 + t * dy);
    (t0 <= t1).then(|| (at(t0), at(t1)))
}

/// Polylines through the placeable points, broken at the others and clipped to the box.
pub(super) fn runs(
    pts: &[Option<(f64, f64)>],
    x: (f64, f64),
    y: (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut pen = None;
    for w in pts.windows(2) {
        let Some((a, b)) = w[0].zip(w[1]).and_then(|s| clip(s, x, y)) else {
            pen = None;
            continue;
        };
        match out.last_mut() {
            Some(run) if pen == Some(a) => run.push(b),
            _ => out.push(vec![a, b]),
        }
        pen = Some(b);
    }
    out
}
