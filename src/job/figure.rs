//! The curve plot a compression job writes: φ against P with the measured reference curve of
//! the same geometry.

use crate::analysis::envelope::{Envelope, MEDIAN_ROWS};
use crate::analysis::fit::Eq13;
use crate::config::ExperimentKind;
use crate::output::plot::{Plot, Series, Style, PALETTE};

/// Measured reference curves of docs/physics.md, Sect. 5.8 (Eq. 13 parameters, pressures in Pa).
pub const GUETTLER_2009_OMNI: Eq13 = Eq13 {
    phi1: 0.15,
    phi2: 0.58,
    p_m: 16_667.0,
    delta: 0.562,
};
pub const BLUM_SCHRAEPLER_2004_UNI: Eq13 = Eq13 {
    phi1: 0.15,
    phi2: 0.33,
    p_m: 5_600.0,
    delta: 0.33,
};

/// Light grey: the raw rows stay visible behind the envelope without competing with it.
const RAW_ROWS: u32 = 0xC8C8C8;

/// φ against P as the analysis reads it (the envelope: first passage of the running median of
/// log P, [`Envelope`]), the raw rows faint behind it, and the measured reference curve of the
/// same geometry. `rows` are (P [Pa], φ) in time order.
pub fn curve_plot(kind: ExperimentKind, rows: &[(f64, f64)]) -> Plot {
    let (name, reference) = match kind {
        ExperimentKind::Uni => ("Blum & Schräpler 2004 (Eq. 13)", BLUM_SCHRAEPLER_2004_UNI),
        _ => ("Güttler et al. 2009 (Eq. 13)", GUETTLER_2009_OMNI),
    };
    let measured: Vec<(f64, f64)> = (0..=80)
        .map(|k| {
            let p = 10f64.powf(1.0 + 6.0 * k as f64 / 80.0);
            (p, reference.phi(p))
        })
        .collect();
    let mut plot = Plot::new(
        "Compressive strength",
        "pressure P [Pa]",
        "filling factor φ",
    );
    plot.x_log = true;
    plot.x_range = Some((10.0, 1e7));
    plot.y_range = Some((0.0, 0.75));
    let raw: Vec<(f64, f64)> = rows.iter().copied().filter(|&(p, _)| p > 0.0).collect();
    let envelope = Envelope::from_rows(&rows.iter().map(|&(p, phi)| (phi, p)).collect::<Vec<_>>());
    // One point per new pressure: where the envelope is flat in P it only repeats.
    let mut first_passage: Vec<(f64, f64)> = Vec::new();
    for (&phi, &log_p) in envelope.phi.iter().zip(&envelope.log10_p) {
        if log_p > -10.0
            && first_passage
                .last()
                .is_none_or(|&(p, _)| 10f64.powf(log_p) > p)
        {
            first_passage.push((10f64.powf(log_p), phi));
        }
    }
    plot.series
        .push(Series::new("every row (top wall)", raw, Style::Line).color(RAW_ROWS));
    plot.series.push(
        Series::new(
            format!("simulation (first passage, median of {MEDIAN_ROWS} rows)"),
            first_passage,
            Style::Line,
        )
        .color(PALETTE[0]),
    );
    plot.series
        .push(Series::new(name, measured, Style::Dashed).color(PALETTE[1]));
    plot
}
