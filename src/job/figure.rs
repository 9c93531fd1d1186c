//! The curve plot a compression job writes: φ against P with the measured reference curve of
//! the same geometry.

use crate::analysis::fit::Eq13;
use crate::config::ExperimentKind;
use crate::output::plot::{Plot, Series, Style};

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

/// φ against P with the measured reference curve of the same geometry.
pub fn curve_plot(kind: ExperimentKind, points: &[(f64, f64)]) -> Plot {
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
    plot.series.push(Series::new(
        "simulation (top wall)",
        points.to_vec(),
        Style::Line,
    ));
    plot.series.push(Series::new(name, measured, Style::Dashed));
    plot
}
