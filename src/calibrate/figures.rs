//! The calibration's figures: `calibration.png` (every curve, measured vs baseline vs
//! corrected, drawn on the built-in raster) and one SVG per compression curve.

use super::gap::{targets, Prediction};
use super::raster::{draw_panel, Canvas, Mark, Panel, PanelSeries, BLACK, BLUE, RED};
use super::workflow::Calibration;
use crate::output::plot::{Plot, Series, Style};

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

/// One panel per compression curve and one for the sticking velocities, side by side.
pub fn plot_png(cal: &Calibration) -> Canvas {
    let m = &cal.measured;
    let targets = targets(m);
    let mut panels = Vec::new();
    for (k, curve) in m.compression.iter().enumerate() {
        panels.push(Panel {
            title: curve.name.clone(),
            x_label: "P (Pa)".into(),
            y_label: "phi".into(),
            x_log: true,
            categories: Vec::new(),
            series: vec![
                PanelSeries {
                    label: "measured".into(),
                    colour: BLACK,
                    mark: Mark::ErrorBars,
                    points: curve
                        .pressure
                        .iter()
                        .zip(&curve.phi)
                        .zip(&curve.phi_sigma)
                        .map(|((&p, &v), &s)| (p, v, s))
                        .collect(),
                },
                PanelSeries {
                    label: "baseline".into(),
                    colour: RED,
                    mark: Mark::Line,
                    points: compression_points(&targets[k], &cal.baseline[k]),
                },
                PanelSeries {
                    label: "corrected".into(),
                    colour: BLUE,
                    mark: Mark::Line,
                    points: compression_points(&targets[k], &cal.final_predictions[k]),
                },
            ],
        });
    }
    let n = m.compression.len();
    for (k, stick) in m.sticking.iter().enumerate() {
        let at = |x: f64, v: f64| vec![(x, v, 0.0)];
        panels.push(Panel {
            title: stick.name.clone(),
            x_label: String::new(),
            y_label: "v stick (m/s)".into(),
            x_log: false,
            categories: vec!["measured".into(), "baseline".into(), "corrected".into()],
            series: vec![
                PanelSeries {
                    label: "measured".into(),
                    colour: BLACK,
                    mark: Mark::ErrorBars,
                    points: vec![(1.0, stick.velocity, stick.sigma)],
                },
                PanelSeries {
                    label: "baseline".into(),
                    colour: RED,
                    mark: Mark::Line,
                    points: at(2.0, sticking_velocity(&cal.baseline[n + k])),
                },
                PanelSeries {
                    label: "corrected".into(),
                    colour: BLUE,
                    mark: Mark::Line,
                    points: at(3.0, sticking_velocity(&cal.final_predictions[n + k])),
                },
            ],
        });
    }
    let (w, h) = (560.0, 420.0);
    let mut canvas = Canvas::new((w as usize) * panels.len().max(1), h as usize);
    for (k, panel) in panels.iter().enumerate() {
        draw_panel(&mut canvas, panel, k as f64 * w, 0.0, w, h);
    }
    canvas
}

/// The same comparison as labelled SVG (system fonts), one per compression curve.
pub fn plot_svgs(cal: &Calibration) -> Vec<String> {
    let targets = targets(&cal.measured);
    cal.measured
        .compression
        .iter()
        .enumerate()
        .map(|(k, curve)| {
            let xy = |pts: Vec<(f64, f64, f64)>| pts.into_iter().map(|p| (p.0, p.1)).collect();
            let mut plot = Plot::new(
                format!("{}: measured, baseline, corrected", curve.name),
                "P [Pa]",
                "filling factor φ",
            );
            plot.x_log = true;
            plot.series = vec![
                Series::new(
                    "measured",
                    curve
                        .pressure
                        .iter()
                        .copied()
                        .zip(curve.phi.clone())
                        .collect(),
                    Style::Markers,
                ),
                Series::new(
                    "baseline",
                    xy(compression_points(&targets[k], &cal.baseline[k])),
                    Style::Line,
                ),
                Series::new(
                    "corrected",
                    xy(compression_points(&targets[k], &cal.final_predictions[k])),
                    Style::Dashed,
                ),
            ];
            plot.to_svg()
        })
        .collect()
}
