//! The report's figures: per family the seed-mean φ(P) at fixed φ, one line per speed, with
//! the study's reference curve; per study the fitted p_m and Δ against wall speed with the
//! paper's laws. SVG, written deterministically from the store.

use super::analysis::{reference, Family};
use super::report::Analysed;
use crate::analysis::speed_laws::{PAPER_DELTA, PAPER_PM_DYNAMIC, PAPER_PM_QUASI_STATIC};
use crate::output::plot::{Plot, Series, Style, PALETTE};
use crate::sweep::analyze::{law_series, reference_series};
use std::path::Path;

pub fn curve_name(study: &str, f: &Family) -> String {
    format!("{study}_phi_p_{}_n{}.svg", f.variant, f.monomers)
}

fn curve_plot(a: &Analysed, f: &Family) -> Plot {
    let mut plot = Plot::new(
        format!(
            "{} model, {} monomers: mean P at fixed φ",
            f.variant, f.monomers
        ),
        "pressure P [Pa]",
        "filling factor φ",
    );
    plot.x_log = true;
    for (k, s) in f.speeds.iter().enumerate() {
        let points = s
            .mean_curve
            .iter()
            .filter(|x| x.p_mean > 0.0)
            .map(|x| (x.p_mean, x.phi))
            .collect();
        plot.series.push(
            Series::new(format!("{} m/s", s.speed), points, Style::Line)
                .color(PALETTE[k % PALETTE.len()]),
        );
    }
    let (name, eq) = reference(a.study.kind);
    plot.series.push(reference_series(name, &eq, 0x000000));
    plot
}

/// p_m (`delta` false) or Δ against wall speed for every family of the study.
fn speed_plot(a: &Analysed, delta: bool) -> Option<Plot> {
    let (title, label) = if delta {
        ("Δ against wall speed", "Δ")
    } else {
        ("p_m against wall speed", "p_m [kPa]")
    };
    let mut plot = Plot::new(title, "wall speed v [m/s]", label);
    let mut top: f64 = 1.0;
    for (k, f) in a.families.iter().enumerate() {
        let mut points = Vec::new();
        let mut sigma = Vec::new();
        for s in &f.speeds {
            let Some(e) = &s.fixed else { continue };
            let (y, err) = if delta {
                (e.mean_fit.params.delta, e.err.delta)
            } else {
                (e.mean_fit.params.p_m / 1e3, e.err.p_m / 1e3)
            };
            points.push((s.speed, y));
            sigma.push(if err.is_finite() { err } else { 0.0 });
            top = top.max(s.speed);
        }
        let mut series = Series::new(
            format!("{}, {} monomers", f.variant, f.monomers),
            points,
            Style::ErrorBars,
        )
        .color(PALETTE[k % PALETTE.len()]);
        series.sigma = sigma;
        plot.series.push(series);
    }
    if plot.series.iter().all(|s| s.points.is_empty()) {
        return None;
    }
    if delta {
        plot.series.push(law_series(
            "paper, Eq. 17",
            |v| PAPER_DELTA.eval(v),
            0.0,
            top,
            0x000000,
        ));
    } else {
        plot.series.push(law_series(
            "paper, Eq. 14",
            |v| PAPER_PM_QUASI_STATIC.eval(v),
            0.0,
            1.0,
            0x000000,
        ));
        plot.series.push(law_series(
            "paper, Eq. 15",
            |v| PAPER_PM_DYNAMIC.eval(v),
            1.0,
            top,
            0x777777,
        ));
    }
    Some(plot)
}

/// Writes every figure of `all` into `dir`; returns the names of the speed figures written.
pub fn write_figures(all: &[Analysed], dir: &Path) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut speed_figures = Vec::new();
    for a in all {
        for f in &a.families {
            let path = dir.join(curve_name(a.study.name, f));
            curve_plot(a, f)
                .save(&path)
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
        if a.study.kind != super::StudyKind::Dynamic {
            continue;
        }
        for (delta, what) in [(false, "pm"), (true, "delta")] {
            if let Some(plot) = speed_plot(a, delta) {
                let name = format!("{}_{what}_v.svg", a.study.name);
                plot.save(dir.join(&name))
                    .map_err(|e| format!("{}: {e}", dir.join(&name).display()))?;
                speed_figures.push(name);
            }
        }
    }
    Ok(speed_figures)
}
