use super::*;
use crate::calibrate::gap::{CurveGap, Verdict};

fn curve(name: &str, rms: f64, chi2: f64) -> CurveGap {
    CurveGap {
        name: name.into(),
        residual: vec![rms],
        sigma: vec![0.01],
        rms,
        noise: 0.01,
        chi2,
        covered: 1,
        bands: Vec::new(),
        verdict: Verdict::WithinNoise,
    }
}

fn gap(curves: Vec<CurveGap>) -> Gap {
    let chi2 = curves.iter().map(|c| c.chi2).sum();
    Gap {
        threshold: chi2_quantile_95(curves.len()),
        curves,
        chi2,
    }
}

#[test]
fn only_curves_beyond_noise_at_the_baseline_are_judged_by_their_shrink() {
    let before = gap(vec![curve("omni", 0.08, 9.5), curve("uni", 0.012, 1.5)]);
    let after = gap(vec![curve("omni", 0.01, 0.7), curve("uni", 0.012, 1.5)]);
    let shrinks = curve_shrinks(&before, &after);
    assert_eq!(shrinks.len(), 1);
    assert_eq!(shrinks[0].name, "omni");
    assert!((shrinks[0].shrink() - 0.875).abs() < 1e-12);
    assert_eq!(describe_curve_shrinks(&before, &after), "omni 88%");
    // The data set's normalised shrink counts the control curve's noise too.
    assert!((gap_shrink(&before, &after) - (1.0 - (2.2f64 / 11.0).sqrt())).abs() < 1e-12);
    let quiet = gap(vec![curve("uni", 0.012, 1.5)]);
    assert_eq!(
        describe_curve_shrinks(&quiet, &quiet),
        "no curve was beyond noise"
    );
}
