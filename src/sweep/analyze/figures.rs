//! The figures of `sweep analyze`: seed-mean curves, p_m(v) and Δ(v) with the paper's laws,
//! and the profiles of one run per dynamic speed.

use super::*;

/// A measured Eq. 13 curve over 10–10⁷ Pa, dashed.
pub fn reference_series(name: &str, eq: &Eq13, color: u32) -> Series {
    let points = (0..=60)
        .map(|k| {
            let p = 10f64.powf(1.0 + 6.0 * k as f64 / 60.0);
            (p, eq.phi(p))
        })
        .collect();
    Series::new(name, points, Style::Dashed).color(color)
}

pub(super) fn curves_plot(f: &Family) -> Plot {
    let mut plot = Plot::new(
        format!("{} model, {} monomers: seed means", f.variant, f.monomers),
        "pressure P [Pa]",
        "filling factor φ",
    );
    plot.x_log = true;
    for (k, g) in f.speeds.iter().enumerate() {
        let points = g.average.iter().map(|a| (a.p, a.mean)).collect();
        plot.series.push(
            Series::new(format!("{} m/s", g.wall_speed), points, Style::Line)
                .color(PALETTE[k % PALETTE.len()]),
        );
    }
    plot.series.push(reference_series(
        "Güttler et al. 2009",
        &GUETTLER_2009_OMNI,
        0x000000,
    ));
    plot.series.push(reference_series(
        "Blum & Schräpler 2004",
        &BLUM_SCHRAEPLER_2004_UNI,
        0x777777,
    ));
    plot
}

/// A speed law drawn from `from` to `to`, dashed.
pub fn law_series(name: &str, eval: impl Fn(f64) -> f64, from: f64, to: f64, color: u32) -> Series {
    let points = (0..=50)
        .map(|k| {
            let v = from + (to - from) * k as f64 / 50.0;
            (v, eval(v))
        })
        .collect();
    Series::new(name, points, Style::Dashed).color(color)
}

/// A plot of fitted values against wall speed with their errors, and the largest speed (at
/// least 1 m/s) for the laws drawn over it.
fn speed_plot(title: &str, y_label: &str, v: &[f64], y: Vec<f64>, err: Vec<f64>) -> (Plot, f64) {
    let mut plot = Plot::new(title, "wall speed v [m/s]", y_label);
    let mut points = Series::new(
        "this sweep (φ₁, φ₂ held)",
        v.iter().copied().zip(y).collect(),
        Style::ErrorBars,
    )
    .color(PALETTE[0]);
    points.sigma = err;
    plot.series.push(points);
    (plot, v.iter().copied().fold(1.0, f64::max))
}

pub(super) fn pm_plot(f: &Family) -> Plot {
    let Fitted {
        v, pm, pm_err: err, ..
    } = fitted(&f.speeds, |_| true);
    let (mut plot, top) = speed_plot("p_m against wall speed", "p_m [kPa]", &v, pm, err);
    plot.series.push(law_series(
        "paper, v ≤ 1",
        |v| PAPER_PM_QUASI_STATIC.eval(v),
        0.0,
        1.0,
        0x000000,
    ));
    plot.series.push(law_series(
        "paper, v ≥ 1",
        |v| PAPER_PM_DYNAMIC.eval(v),
        1.0,
        top,
        0x777777,
    ));
    if let Some(l) = f.laws.pm_square.fitted() {
        let law = l.law;
        plot.series.push(law_series(
            "fit a v² + c",
            move |v| law.eval(v),
            1.0,
            top,
            PALETTE[1],
        ));
    }
    plot
}

pub(super) fn delta_plot(f: &Family) -> Plot {
    let Fitted {
        v,
        delta,
        delta_err: err,
        ..
    } = fitted(&f.speeds, |_| true);
    let (mut plot, top) = speed_plot("Δ against wall speed", "Δ [decades]", &v, delta, err);
    plot.series.push(law_series(
        "paper",
        |v| PAPER_DELTA.eval(v),
        0.0,
        top,
        0x000000,
    ));
    if let Some(l) = f.laws.delta.fitted() {
        let law = l.law;
        plot.series.push(law_series(
            "fit (v + a)^b + c",
            move |v| law.eval(v),
            0.0,
            top,
            PALETTE[1],
        ));
    }
    plot
}

/// The case of the lowest seed of each dynamic (variant, size, speed).
pub fn first_seeds(cases: &[CaseData]) -> Vec<&CaseData> {
    let mut first: BTreeMap<(String, usize, u64), &CaseData> = BTreeMap::new();
    for c in cases.iter().filter(|c| c.wall_speed >= DYNAMIC_FROM) {
        let key = (c.variant.clone(), c.monomers, c.wall_speed.to_bits());
        let entry = first.entry(key).or_insert(c);
        if c.seed < entry.seed {
            *entry = c;
        }
    }
    first.into_values().collect()
}

/// File name of the profile figure of a case.
pub fn profile_figure_name(c: &CaseData) -> String {
    format!(
        "profiles_v{}_{}_n{}.svg",
        c.wall_speed, c.variant, c.monomers
    )
}

/// φ against height at six times of one run, each with its front (dotted) where found: the
/// dense layer under the wall and how it moves down.
pub(super) fn profiles_plot(case_dir: &Path, c: &CaseData) -> Option<Plot> {
    let profiles = read_run_profiles(case_dir).ok()?;
    if profiles.len() < 2 {
        return None;
    }
    let fronts = front_heights(&profiles, &FrontOptions::default());
    let mut plot = Plot::new(
        format!(
            "{} model, {} m/s, seed {}: profiles",
            c.variant, c.wall_speed, c.seed
        ),
        "height z [µm]",
        "filling factor φ",
    );
    plot.y_range = Some((0.0, 0.8));
    let picks: Vec<usize> = (0..6).map(|k| k * (profiles.len() - 1) / 5).collect();
    for (n, &k) in picks.iter().enumerate() {
        let p = &profiles[k];
        let color = PALETTE[n % PALETTE.len()];
        let points = p
            .z_m
            .iter()
            .zip(&p.phi)
            .map(|(z, phi)| (z * 1e6, *phi))
            .collect();
        plot.series.push(
            Series::new(format!("t = {:.2} µs", p.time_s * 1e6), points, Style::Line).color(color),
        );
        if let Some(f) = fronts
            .iter()
            .find(|f| f.time_s == p.time_s && !f.reached_bottom)
        {
            let z = f.front_m * 1e6;
            plot.series
                .push(Series::new("", vec![(z, 0.0), (z, 0.8)], Style::Dashed).color(color));
        }
    }
    Some(plot)
}
