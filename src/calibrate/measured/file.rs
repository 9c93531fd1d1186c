//! The measured-data file: TOML with every value optional as read, then each checked (finite,
//! in range, increasing, with a σ), so that a problem names its field and what is allowed;
//! curves may be given as points or as Eq. 13 parameters, sampled here.

use super::{log_spaced, CompressionCurve, Geometry, MeasuredSet, Provenance, StickingVelocity};
use crate::analysis::fit::Eq13;
use crate::config::ConfigError;
use serde::{Deserialize, Serialize};
use std::fmt::Display;
use std::path::Path;

// The file as written. Every value is optional here so that a missing one is reported with
// its field name and the allowed range rather than as a bare parse error.
#[derive(Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSet {
    #[serde(default)]
    source: Provenance,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    compression: Vec<FileCurve>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    sticking: Vec<FileSticking>,
}

#[derive(Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileCurve {
    name: Option<String>,
    geometry: Option<Geometry>,
    pressure_pa: Option<Vec<f64>>,
    phi: Option<Vec<f64>>,
    /// One value for all points, or one per point.
    phi_sigma: Option<Sigma>,
    /// A published Eq. 13 fit instead of points, sampled between these pressures.
    eq13: Option<FileEq13>,
    pressure_min_pa: Option<f64>,
    pressure_max_pa: Option<f64>,
    wall_speed_m_s: Option<f64>,
}

#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum Sigma {
    One(f64),
    Each(Vec<f64>),
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileEq13 {
    phi1: f64,
    phi2: f64,
    p_m_pa: f64,
    delta: f64,
}

#[derive(Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSticking {
    name: Option<String>,
    velocity_m_s: Option<f64>,
    sigma_m_s: Option<f64>,
}

/// Points a published Eq. 13 curve is sampled at: twelve, log-spaced.
const EQ13_POINTS: usize = 12;

struct Check<'a> {
    file: &'a str,
}

impl Check<'_> {
    fn err(&self, field: &str, value: impl Display, allowed: impl Into<String>) -> ConfigError {
        ConfigError {
            file: self.file.to_string(),
            field: field.to_string(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }

    fn need<T>(&self, v: Option<T>, field: &str, allowed: &str) -> Result<T, ConfigError> {
        v.ok_or_else(|| self.err(field, "(missing)", allowed))
    }

    fn finite_in(
        &self,
        field: &str,
        v: f64,
        ok: impl Fn(f64) -> bool,
        allowed: &str,
    ) -> Result<f64, ConfigError> {
        if v.is_finite() && ok(v) {
            Ok(v)
        } else {
            Err(self.err(field, v, allowed))
        }
    }
}

impl MeasuredSet {
    pub fn load(path: &Path) -> Result<MeasuredSet, ConfigError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError {
            file: file.clone(),
            field: String::new(),
            value: String::new(),
            allowed: format!("cannot read the measured-data file: {e}"),
        })?;
        MeasuredSet::parse(&text, &file)
    }

    /// Parses and validates TOML text; `file` names it in messages.
    pub fn parse(text: &str, file: &str) -> Result<MeasuredSet, ConfigError> {
        let raw: FileSet = toml::from_str(text).map_err(|e| parse_error(file, &e))?;
        let c = Check { file };
        let mut compression = Vec::new();
        for (i, curve) in raw.compression.into_iter().enumerate() {
            compression.push(validate_curve(&c, i, curve)?);
        }
        let mut sticking = Vec::new();
        for (i, s) in raw.sticking.into_iter().enumerate() {
            let at = |f: &str| format!("[[sticking]] #{} {f}", i + 1);
            let velocity = c.finite_in(
                &at("velocity_m_s"),
                c.need(s.velocity_m_s, &at("velocity_m_s"), "a speed > 0 m/s")?,
                |v| v > 0.0 && v < 1e3,
                "a finite speed > 0 and < 1000 m/s",
            )?;
            let sigma = c.finite_in(
                &at("sigma_m_s"),
                c.need(
                    s.sigma_m_s,
                    &at("sigma_m_s"),
                    "a 1-sigma uncertainty > 0 m/s",
                )?,
                |v| v > 0.0,
                "a finite 1-sigma uncertainty > 0 m/s",
            )?;
            sticking.push(StickingVelocity {
                name: s.name.unwrap_or_else(|| format!("sticking {}", i + 1)),
                velocity,
                sigma,
            });
        }
        if compression.is_empty() && sticking.is_empty() {
            return Err(c.err(
                "[[compression]] / [[sticking]]",
                "(none)",
                "at least one compression curve or sticking velocity",
            ));
        }
        Ok(MeasuredSet {
            source: raw.source,
            compression,
            sticking,
        })
    }

    /// The set as TOML in the format [`MeasuredSet::parse`] reads (points, not Eq. 13).
    pub fn to_toml(&self) -> String {
        let raw = FileSet {
            source: self.source.clone(),
            compression: self
                .compression
                .iter()
                .map(|c| FileCurve {
                    name: Some(c.name.clone()),
                    geometry: Some(c.geometry),
                    pressure_pa: Some(c.pressure.clone()),
                    phi: Some(c.phi.clone()),
                    phi_sigma: Some(Sigma::Each(c.phi_sigma.clone())),
                    wall_speed_m_s: c.wall_speed,
                    ..FileCurve::default()
                })
                .collect(),
            sticking: self
                .sticking
                .iter()
                .map(|s| FileSticking {
                    name: Some(s.name.clone()),
                    velocity_m_s: Some(s.velocity),
                    sigma_m_s: Some(s.sigma),
                })
                .collect(),
        };
        toml::to_string(&raw).expect("plain data serialises")
    }
}

fn parse_error(file: &str, e: &toml::de::Error) -> ConfigError {
    let message = e.message().to_string();
    // serde names the offending key in backticks ("unknown field `x`, expected ...").
    let field = message
        .split('`')
        .nth(1)
        .filter(|_| message.contains("field") || message.contains("variant"))
        .unwrap_or("")
        .to_string();
    let line = e
        .span()
        .map(|s| format!(" (at byte {})", s.start))
        .unwrap_or_default();
    ConfigError {
        file: file.to_string(),
        value: if field.is_empty() {
            String::new()
        } else {
            "(as written)".into()
        },
        field,
        allowed: format!("invalid measured data{line}: {}", message.trim_end()),
    }
}

fn validate_curve(c: &Check, i: usize, f: FileCurve) -> Result<CompressionCurve, ConfigError> {
    let at = |field: &str| format!("[[compression]] #{} {field}", i + 1);
    let geometry = c.need(f.geometry, &at("geometry"), "\"omni\" or \"uni\"")?;
    let wall_speed = match f.wall_speed_m_s {
        None => None,
        Some(v) => Some(c.finite_in(
            &at("wall_speed_m_s"),
            v,
            |v| v > 0.0,
            "a finite speed > 0 m/s",
        )?),
    };
    let (pressure, phi) = match (f.eq13, f.pressure_pa, f.phi) {
        (Some(e), None, None) => sample_eq13(c, &at, e, f.pressure_min_pa, f.pressure_max_pa)?,
        (None, Some(p), Some(phi)) => (p, phi),
        (Some(_), _, _) => {
            return Err(c.err(
                &at("eq13"),
                "(given with points)",
                "either eq13 with pressure_min_pa/pressure_max_pa, or pressure_pa with phi",
            ))
        }
        (None, p, _) => {
            let missing = if p.is_none() { "pressure_pa" } else { "phi" };
            return Err(c.err(
                &at(missing),
                "(missing)",
                "a list of pressures [Pa] and a list of filling factors of the same length",
            ));
        }
    };
    check_points(c, &at, &pressure, &phi)?;
    let phi_sigma = check_sigma(c, &at, f.phi_sigma, pressure.len())?;
    Ok(CompressionCurve {
        name: f
            .name
            .unwrap_or_else(|| format!("{} {}", geometry.name(), i + 1)),
        geometry,
        pressure,
        phi,
        phi_sigma,
        wall_speed,
    })
}

/// At least two points, as many φ as pressures, pressures positive and increasing, φ in (0, 1).
fn check_points(
    c: &Check,
    at: &dyn Fn(&str) -> String,
    pressure: &[f64],
    phi: &[f64],
) -> Result<(), ConfigError> {
    if pressure.len() < 2 {
        return Err(c.err(
            &at("pressure_pa"),
            format!("{} point(s)", pressure.len()),
            "at least 2 points",
        ));
    }
    if phi.len() != pressure.len() {
        return Err(c.err(
            &at("phi"),
            format!("{} values", phi.len()),
            format!("as many values as pressure_pa ({})", pressure.len()),
        ));
    }
    for (k, &p) in pressure.iter().enumerate() {
        c.finite_in(
            &at(&format!("pressure_pa[{k}]")),
            p,
            |p| p > 0.0,
            "a finite pressure > 0 Pa",
        )?;
        if k > 0 && p <= pressure[k - 1] {
            return Err(c.err(
                &at(&format!("pressure_pa[{k}]")),
                p,
                format!("pressures must increase (previous {})", pressure[k - 1]),
            ));
        }
    }
    for (k, &v) in phi.iter().enumerate() {
        c.finite_in(
            &at(&format!("phi[{k}]")),
            v,
            |v| v > 0.0 && v < 1.0,
            "a filling factor between 0 and 1 (exclusive)",
        )?;
    }
    Ok(())
}

/// One σ for all points or one per point, each finite in (0, 1).
fn check_sigma(
    c: &Check,
    at: &dyn Fn(&str) -> String,
    sigma: Option<Sigma>,
    points: usize,
) -> Result<Vec<f64>, ConfigError> {
    let sigma_allowed = "a finite 1-sigma uncertainty of phi > 0 and < 1";
    let phi_sigma = match c.need(
        sigma,
        &at("phi_sigma"),
        "one 1-sigma uncertainty of phi, or one per point",
    )? {
        Sigma::One(s) => vec![s; points],
        Sigma::Each(v) if v.len() == points => v,
        Sigma::Each(v) => {
            return Err(c.err(
                &at("phi_sigma"),
                format!("{} values", v.len()),
                format!("one value, or as many as pressure_pa ({})", points),
            ))
        }
    };
    for (k, &s) in phi_sigma.iter().enumerate() {
        c.finite_in(
            &at(&format!("phi_sigma[{k}]")),
            s,
            |s| s > 0.0 && s < 1.0,
            sigma_allowed,
        )?;
    }
    Ok(phi_sigma)
}

fn sample_eq13(
    c: &Check,
    at: &dyn Fn(&str) -> String,
    e: FileEq13,
    p_min: Option<f64>,
    p_max: Option<f64>,
) -> Result<(Vec<f64>, Vec<f64>), ConfigError> {
    let unit = |v: f64| v > 0.0 && v < 1.0;
    c.finite_in(&at("eq13.phi1"), e.phi1, unit, "between 0 and 1")?;
    c.finite_in(&at("eq13.phi2"), e.phi2, unit, "between 0 and 1")?;
    c.finite_in(&at("eq13.p_m_pa"), e.p_m_pa, |v| v > 0.0, "> 0 Pa")?;
    c.finite_in(&at("eq13.delta"), e.delta, |v| v > 0.0, "> 0 decades")?;
    let range = "a finite pressure > 0 Pa (the range the fit describes)";
    let lo = c.need(p_min, &at("pressure_min_pa"), range)?;
    let lo = c.finite_in(&at("pressure_min_pa"), lo, |v| v > 0.0, range)?;
    let hi = c.need(p_max, &at("pressure_max_pa"), range)?;
    let hi = c.finite_in(
        &at("pressure_max_pa"),
        hi,
        |v| v > lo,
        "a finite pressure above pressure_min_pa",
    )?;
    let curve = Eq13 {
        phi1: e.phi1,
        phi2: e.phi2,
        p_m: e.p_m_pa,
        delta: e.delta,
    };
    let pressure = log_spaced(lo, hi, EQ13_POINTS);
    let phi = pressure.iter().map(|&p| curve.phi(p)).collect();
    Ok((pressure, phi))
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[source]
citation = "test"
[[compression]]
geometry = "omni"
pressure_pa = [1e2, 1e3, 1e4]
phi = [0.15, 0.2, 0.3]
phi_sigma = 0.01
[[sticking]]
velocity_m_s = 1.2
sigma_m_s = 0.1
"#;

    fn error_of(text: &str) -> ConfigError {
        MeasuredSet::parse(text, "m.toml").unwrap_err()
    }

    #[test]
    fn reads_points_and_sticking() {
        let m = MeasuredSet::parse(GOOD, "m.toml").unwrap();
        assert_eq!(m.compression[0].phi_sigma, vec![0.01; 3]);
        assert_eq!(m.sticking[0].velocity, 1.2);
        let (phi, _) = m.compression[0].at(10f64.powf(2.5));
        assert!((phi - 0.175).abs() < 1e-12);
        // The written form reads back to the same set.
        let again = MeasuredSet::parse(&m.to_toml(), "again").unwrap();
        assert_eq!(again, m);
        let both = MeasuredSet::merge(vec![m.clone(), again]);
        assert_eq!(both.curve_count(), 4);
        assert_eq!(both.source.citation, "test; test");
    }

    #[test]
    fn samples_a_published_fit() {
        let text = r#"
[[compression]]
geometry = "omni"
eq13 = { phi1 = 0.15, phi2 = 0.58, p_m_pa = 16667, delta = 0.562 }
pressure_min_pa = 1e2
pressure_max_pa = 1e6
phi_sigma = 0.02
"#;
        let m = MeasuredSet::parse(text, "m.toml").unwrap();
        let c = &m.compression[0];
        assert_eq!(c.pressure.len(), EQ13_POINTS);
        // docs/physics.md, Sect. 5.8: 0.1581 at 1e2 Pa, 0.5626 at 1e6 Pa.
        assert!((c.phi[0] - 0.1581).abs() < 1e-4 && (c.phi[11] - 0.5626).abs() < 1e-4);
    }

    #[test]
    fn bad_values_name_file_field_value_and_range() {
        let e = error_of(&GOOD.replace("1e3, 1e4", "-1e3, 1e4"));
        assert_eq!(e.file, "m.toml");
        assert_eq!(e.field, "[[compression]] #1 pressure_pa[1]");
        assert_eq!(e.value, "-1000");
        assert!(e.allowed.contains("> 0 Pa"), "{e}");
        let e = error_of(&GOOD.replace("0.2, 0.3", "nan, 0.3"));
        assert_eq!(e.field, "[[compression]] #1 phi[1]");
        assert_eq!(e.value, "NaN");
        let e = error_of(&GOOD.replace("phi = [0.15, 0.2, 0.3]\n", ""));
        assert_eq!(e.field, "[[compression]] #1 phi");
        assert_eq!(e.value, "(missing)");
        let e = error_of(&GOOD.replace("sigma_m_s = 0.1", "sigma_m_s = 0.1\ncolour = 1"));
        assert_eq!(e.field, "colour");
        assert!(e.to_string().contains("m.toml"), "{e}");
        let e = error_of(&GOOD.replace("\"omni\"", "\"sideways\""));
        assert!(e.to_string().contains("sideways"), "{e}");
        let e = error_of("[source]\ncitation = \"x\"\n");
        assert!(e.allowed.contains("at least one"), "{e}");
        let e = error_of(&GOOD.replace("1e2, 1e3", "1e3, 1e2"));
        assert!(e.allowed.contains("increase"), "{e}");
    }
}
