//! The calibration's figures: one panel per compression curve and per sticking velocity
//! (measured with 1σ bars, baseline and corrected model), drawn through `output::plot` into
//! `calibration.png` and one SVG per compression curve.

use super::gap::{targets, Prediction};
use super::workflow::Calibration;
use crate::output::plot::{Plot, Series, Style, BLACK, PALETTE};

fn compression_points(p: &[f64], prediction: &Prediction) -> Vec<(f64, f64, f64)> {
    match prediction {
        Prediction::Compression { phi, scatter, .. } => p
            .iter()
            .zip(phi)
            .zip(scatter)
            .map(|((&p, &v), &s)| (p, v, s))
            .collect(),
        Prediction::Sticking { .. } => Vec::new(),
    }
}

fn sticking_velocity(prediction: &Prediction) -> f64 {
    match prediction {
        Prediction::Sticking { velocity, .. } => *velocity,
        Prediction::Compression { .. } => f64::NAN,
    }
}

/// One panel per compression curve and one per sticking velocity: baseline and corrected
/// model under the measured points (with 1σ bars); side by side in `calibration.png`.
pub fn plot_panels(cal: &Calibration) -> Vec<Plot> {
    let m = &cal.measured;
    let targets = targets(m);
    let model = |baseline: Vec<(f64, f64)>, corrected: Vec<(f64, f64)>, names: bool| {
        let name = |s: &str| if names { s.to_string() } else { String::new() };
        [
            Series::new(name("baseline"), baseline, Style::Dashed).color(PALETTE[1]),
            Series::new(name("corrected"), corrected, Style::Line).color(PALETTE[0]),
        ]
    };
    let mut panels = Vec::new();
    for (k, curve) in m.compression.iter().enumerate() {
        let xy = |pts: Vec<(f64, f64, f64)>| pts.into_iter().map(|p| (p.0, p.1)).collect();
        let mut measured = Series::new(
            "measured",
            curve
                .pressure
                .iter()
                .copied()
                .zip(curve.phi.clone())
                .collect(),
            Style::ErrorBars,
        );
        measured.sigma = curve.phi_sigma.clone();
        let mut plot = Plot::new(&curve.name, "pressure P [Pa]", "filling factor φ");
        plot.x_log = true;
        plot.series = model(
            xy(compression_points(&targets[k], &cal.baseline[k])),
            xy(compression_points(&targets[k], &cal.final_predictions[k])),
            true,
        )
        .into();
        plot.series.push(measured.color(BLACK));
        panels.push(plot);
    }
    let n = m.compression.len();
    for (k, stick) in m.sticking.iter().enumerate() {
        let mut measured = Series::new("", vec![(1.0, stick.velocity)], Style::ErrorBars);
        measured.sigma = vec![stick.sigma];
        let mut plot = Plot::new(&stick.name, "", "sticking speed v [m/s]");
        plot.x_range = Some((0.5, 3.5));
        plot.x_ticks = ["measured", "baseline", "corrected"]
            .into_iter()
            .enumerate()
            .map(|(k, name)| (k as f64 + 1.0, name.to_string()))
            .collect();
        plot.series = model(
            vec![(2.0, sticking_velocity(&cal.baseline[n + k]))],
            vec![(3.0, sticking_velocity(&cal.final_predictions[n + k]))],
            false,
        )
        .into();
        plot.series.push(measured.color(BLACK));
        panels.push(plot);
    }
    for p in &mut panels {
        (p.width, p.height) = (560, 420);
    }
    panels
}
