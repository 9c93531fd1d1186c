//! Reading and checking a config: TOML parsed with unknown keys refused, then every value
//! checked against what is allowed; each problem is a [`ConfigError`] naming the file, the
//! field, the value and what would be accepted.

use super::{stable_time_step, Config, ExperimentKind, FootprintKind, SampleSource, SampleTop};
use crate::model::Damping;
use crate::state::MAX_PAIR_SLOTS;
use std::fmt;
use std::path::Path;

/// A configuration problem: which file, which field, what value, what is allowed.
#[derive(Clone, Debug, PartialEq)]
pub struct ConfigError {
    pub file: String,
    pub field: String,
    pub value: String,
    pub allowed: String,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.field.is_empty() {
            write!(f, "{}: {}", self.file, self.allowed)
        } else {
            write!(
                f,
                "{}: {} = {} is not allowed: {}",
                self.file, self.field, self.value, self.allowed
            )
        }
    }
}

impl std::error::Error for ConfigError {}

struct Checker<'a> {
    file: &'a str,
    errors: Vec<ConfigError>,
}

impl Checker<'_> {
    fn fail(&mut self, field: &str, value: impl fmt::Display, allowed: impl Into<String>) {
        self.errors.push(ConfigError {
            file: self.file.to_string(),
            field: field.to_string(),
            value: value.to_string(),
            allowed: allowed.into(),
        });
    }

    fn positive(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(field, v, "must be a finite number > 0");
        }
    }

    fn non_negative(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v >= 0.0) {
            self.fail(field, v, "must be a finite number ≥ 0");
        }
    }

    fn range(&mut self, field: &str, v: f64, lo: f64, hi: f64, what: &str) {
        if !(v.is_finite() && v > lo && v < hi) {
            self.fail(field, v, format!("must be {what}"));
        }
    }
}

impl Config {
    /// Reads and validates a config file.
    pub fn load(path: &Path) -> Result<Config, ConfigError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError {
            file: file.clone(),
            field: String::new(),
            value: String::new(),
            allowed: format!("cannot read the config file: {e}"),
        })?;
        let mut config = Config::parse(&text, &file)?;
        if let Some(sample) = &config.sample.file {
            if sample.is_relative() {
                let base = path.parent().unwrap_or(Path::new("."));
                config.sample.file = Some(base.join(sample));
            }
        }
        Ok(config)
    }

    /// Parses and validates TOML text; `file` names it in messages.
    pub fn parse(text: &str, file: &str) -> Result<Config, ConfigError> {
        let config: Config = toml::from_str(text).map_err(|e| ConfigError {
            file: file.to_string(),
            field: String::new(),
            value: String::new(),
            allowed: format!("invalid config: {}", e.to_string().trim_end()),
        })?;
        config.validate(file)?;
        Ok(config)
    }

    /// Checks every value; reports the first problem (all problems are listed in its text).
    pub fn validate(&self, file: &str) -> Result<(), ConfigError> {
        let mut c = Checker {
            file,
            errors: Vec::new(),
        };
        let m = &self.material;
        c.positive("[material] radius_um", m.radius_um);
        c.positive("[material] density_g_cm3", m.density_g_cm3);
        c.positive("[material] surface_energy_mj_m2", m.surface_energy_mj_m2);
        c.positive("[material] youngs_modulus_gpa", m.youngs_modulus_gpa);
        c.range(
            "[material] poisson_ratio",
            m.poisson_ratio,
            -1.0,
            0.5,
            "between -1 and 0.5 (exclusive)",
        );
        c.positive(
            "[material] critical_rolling_length_nm",
            m.critical_rolling_length_nm,
        );
        let o = &self.model;
        c.positive("[model] rolling_modifier", o.rolling_modifier);
        c.positive("[model] sliding_modifier", o.sliding_modifier);
        c.positive("[model] twisting_modifier", o.twisting_modifier);
        match o.damping {
            Damping::None => {}
            Damping::Viscous { kappa } => c.non_negative("[model] damping.kappa (g/s)", kappa),
            Damping::Viscoelastic { t_vis } => c.non_negative("[model] damping.t_vis (s)", t_vis),
        }
        for (name, f) in [
            ("side", &self.walls.side),
            ("top_bottom", &self.walls.top_bottom),
        ] {
            c.non_negative(&format!("[walls] {name}.rolling"), f.rolling);
            c.non_negative(&format!("[walls] {name}.sliding"), f.sliding);
            c.non_negative(&format!("[walls] {name}.twisting"), f.twisting);
        }
        let s = &self.sample;
        if s.monomers == 0 || s.monomers > 100_000_000 {
            c.fail(
                "[sample] monomers",
                s.monomers,
                "must be between 1 and 100000000",
            );
        }
        c.non_negative("[sample] side_um", s.side_um);
        c.non_negative("[sample] cylinder_radius_um", s.cylinder_radius_um);
        if s.source == SampleSource::File && s.file.is_none() {
            c.fail(
                "[sample] file",
                "(missing)",
                "a sample file path is required when source = \"file\"",
            );
        }
        if s.source == SampleSource::File && s.top == SampleTop::Cut {
            c.fail(
                "[sample] top",
                "\"cut\"",
                "\"cut\" shapes a generated sample; with source = \"file\" use \"rough\"",
            );
        }
        if s.side_um > 0.0 && s.side_um < 2.0 * m.radius_um {
            c.fail(
                "[sample] side_um",
                s.side_um,
                format!(
                    "must be 0 (automatic) or ≥ one diameter, {} µm",
                    2.0 * m.radius_um
                ),
            );
        }
        let e = &self.experiment;
        if e.kind == ExperimentKind::Omni
            && s.source == SampleSource::Rbd
            && s.footprint == FootprintKind::Cylinder
        {
            c.fail(
                "[sample] footprint",
                "\"cylinder\"",
                "the omnidirectional box (kind = \"omni\") needs footprint = \"box\"",
            );
        }
        c.range(
            "[experiment] wall_speed_m_s",
            e.wall_speed_m_s,
            0.0,
            1e4,
            "> 0 and < 10000 m/s",
        );
        c.range(
            "[experiment] phi_stop",
            e.phi_stop,
            0.0,
            0.75,
            "between 0 and 0.75 (exclusive)",
        );
        c.positive("[experiment] pressure_stop_pa", e.pressure_stop_pa);
        if e.max_steps == 0 {
            c.fail("[experiment] max_steps", e.max_steps, "must be ≥ 1");
        }
        if e.average_steps == 0 || e.average_steps > 1_000_000 {
            c.fail(
                "[experiment] average_steps",
                e.average_steps,
                "must be between 1 and 1000000",
            );
        }
        c.range(
            "[experiment] collision_speed_m_s",
            e.collision_speed_m_s,
            0.0,
            1e4,
            "> 0 and < 10000 m/s",
        );
        c.non_negative(
            "[output] checkpoint_minutes",
            self.output.checkpoint_minutes,
        );
        let i = &self.integration;
        c.positive("[integration] dt_ns", i.dt_ns);
        if !(1..=MAX_PAIR_SLOTS).contains(&i.pair_slots) {
            c.fail(
                "[integration] pair_slots",
                i.pair_slots,
                format!("must be between 1 and {MAX_PAIR_SLOTS}"),
            );
        }
        if !(1..=6).contains(&i.wall_slots) {
            c.fail(
                "[integration] wall_slots",
                i.wall_slots,
                "must be between 1 and 6",
            );
        }
        if c.errors.is_empty() && !i.allow_unstable_dt {
            let limit = stable_time_step(&self.contact_law(), &self.wall_factors());
            if i.dt_ns * 1e-9 > limit {
                c.fail(
                    "[integration] dt_ns",
                    i.dt_ns,
                    format!(
                        "must be ≤ {:.3} ns, the stability limit 1/ω of the stiffest contact mode \
                         for this material and model (set allow_unstable_dt = true to run anyway)",
                        limit * 1e9
                    ),
                );
            }
        }
        match c.errors.len() {
            0 => Ok(()),
            1 => Err(c.errors.remove(0)),
            n => {
                let mut first = c.errors.remove(0);
                let rest: Vec<String> = c.errors.iter().map(|e| e.to_string()).collect();
                first.allowed = format!(
                    "{} ({} more problem{}: {})",
                    first.allowed,
                    n - 1,
                    if n > 2 { "s" } else { "" },
                    rest.join("; ")
                );
                Err(first)
            }
        }
    }
}
