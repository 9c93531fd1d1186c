//! Run configuration: TOML in user units, validated once, converted to CGS at this boundary.
//!
//! Every field has a default, so an empty file is the built-in omnidirectional quick run.
//! Unknown keys, wrong types and values out of range are errors that name the file, the field,
//! the value and what is allowed.

use crate::material::{Material, TwistingStiffness};
use crate::model::{ContactLaw, Damping, ModelOptions, WallFactors};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Config {
    pub material: MaterialConfig,
    pub model: ModelOptions,
    pub walls: WallConfig,
    pub sample: SampleConfig,
    pub experiment: ExperimentConfig,
    pub integration: IntegrationConfig,
    pub output: OutputConfig,
}

/// Table 1 of Seizinger et al. (2012), in the units it is usually quoted in.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MaterialConfig {
    pub radius_um: f64,
    pub density_g_cm3: f64,
    pub surface_energy_mj_m2: f64,
    pub youngs_modulus_gpa: f64,
    pub poisson_ratio: f64,
    pub critical_rolling_length_nm: f64,
}

impl Default for MaterialConfig {
    fn default() -> Self {
        MaterialConfig {
            radius_um: 0.6,
            density_g_cm3: 2.65,
            surface_energy_mj_m2: 20.0,
            youngs_modulus_gpa: 54.0,
            poisson_ratio: 0.17,
            critical_rolling_length_nm: 2.0,
        }
    }
}

impl MaterialConfig {
    pub fn to_material(&self) -> Material {
        Material {
            radius: self.radius_um * 1e-4,
            density: self.density_g_cm3,
            surface_energy: self.surface_energy_mj_m2,
            youngs_modulus: self.youngs_modulus_gpa * 1e10,
            poisson: self.poisson_ratio,
            xi_crit: self.critical_rolling_length_nm * 1e-7,
        }
    }
}

/// Strength factors of the walls' rolling, sliding and twisting stiffness.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WallConfig {
    /// Side walls of the omnidirectional box; the paper weakens them 1000×.
    pub side: WallFactors,
    /// Top and bottom plates.
    pub top_bottom: WallFactors,
}

impl Default for WallConfig {
    fn default() -> Self {
        WallConfig {
            side: WallFactors {
                rolling: 1e-3,
                sliding: 1e-3,
                twisting: 1e-3,
            },
            top_bottom: WallFactors::FULL,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SampleSource {
    /// Random ballistic deposition, generated at start-up.
    Rbd,
    /// A sample file written by `dustdem generate`.
    File,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FootprintKind {
    Box,
    Cylinder,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SampleConfig {
    pub source: SampleSource,
    pub monomers: usize,
    pub footprint: FootprintKind,
    /// Box side [µm]; 0 picks a side that makes the RBD sample about as tall as wide.
    pub side_um: f64,
    /// Cylinder radius [µm]; 0 picks one of the same base area as the cube rule.
    pub cylinder_radius_um: f64,
    pub seed: u64,
    /// Sample file, for `source = "file"` (relative paths are relative to the config file).
    pub file: Option<PathBuf>,
}

impl Default for SampleConfig {
    fn default() -> Self {
        SampleConfig {
            source: SampleSource::Rbd,
            monomers: 1000,
            footprint: FootprintKind::Box,
            side_um: 0.0,
            cylinder_radius_um: 0.0,
            seed: 1,
            file: None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ExperimentKind {
    /// Box with fixed bottom and sides, top wall moving down.
    Omni,
    /// Two plates, free sides.
    Uni,
    /// Two monomers colliding head-on.
    Collision,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExperimentConfig {
    pub kind: ExperimentKind,
    /// Speed of the top wall [m/s].
    pub wall_speed_m_s: f64,
    /// Stop when the filling factor exceeds this.
    pub phi_stop: f64,
    /// Stop when the top-wall pressure exceeds this [Pa].
    pub pressure_stop_pa: f64,
    /// Hard limit on the number of steps.
    pub max_steps: u64,
    /// Wall forces are averaged over this many steps; one CSV row per average.
    pub average_steps: u64,
    /// A filling-factor profile every this many rows (0: none).
    pub profile_every_rows: u64,
    /// Relative speed of the two monomers [m/s] (collision only).
    pub collision_speed_m_s: f64,
}

impl Default for ExperimentConfig {
    fn default() -> Self {
        ExperimentConfig {
            kind: ExperimentKind::Omni,
            wall_speed_m_s: 1.0,
            phi_stop: 0.7,
            pressure_stop_pa: 1e9,
            max_steps: 100_000_000,
            average_steps: 100,
            profile_every_rows: 100,
            collision_speed_m_s: 0.05,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IntegrationConfig {
    pub dt_ns: f64,
    /// Run with a step above the stability limit anyway.
    pub allow_unstable_dt: bool,
    /// Contact slots per monomer for partners of higher index.
    pub pair_slots: usize,
    /// Wall contact slots per monomer.
    pub wall_slots: usize,
}

impl Default for IntegrationConfig {
    fn default() -> Self {
        IntegrationConfig {
            dt_ns: 0.3,
            allow_unstable_dt: false,
            pair_slots: crate::state::DEFAULT_PAIR_SLOTS,
            wall_slots: crate::state::DEFAULT_WALL_SLOTS,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputConfig {
    /// Directory for the results (relative paths are relative to the working directory).
    pub dir: PathBuf,
    /// Write `checkpoint.bin` every this many rows (0: by time only).
    pub checkpoint_every_rows: u64,
    /// Write `checkpoint.bin` at least this often [minutes] (0: by rows only).
    pub checkpoint_minutes: f64,
    /// Snapshot format for ParaView (`vtu`), OVITO (`lammps`), both, or `none`.
    pub snapshot_format: SnapshotChoice,
    /// A snapshot every this many rows (0: at the start and the end only).
    pub snapshot_every_rows: u64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SnapshotChoice {
    Vtu,
    Lammps,
    Both,
    None,
}

impl Default for OutputConfig {
    fn default() -> Self {
        OutputConfig {
            dir: PathBuf::from("runs/omni_quick"),
            checkpoint_every_rows: 0,
            checkpoint_minutes: 10.0,
            snapshot_format: SnapshotChoice::Vtu,
            snapshot_every_rows: 0,
        }
    }
}

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

/// The largest stable time step: 1/ω of the stiffest two-body mode.
///
/// Modes (ω²): normal oscillation of a pair 2k_n/m; sliding of a free pair with both monomers
/// translating and rotating k_s(2/m + 2r²/I) = 7 m_s k_s/m; the same against a wall (the wall
/// does not move) k_n,w/m and k_s,w(1/m + r²/I); rolling and twisting are far softer but are
/// included. The leap-frog is stable for ω dt < 2; requiring ω dt ≤ 1 leaves room for monomers
/// with several contacts. With the paper's m_s = 2.5 this gives 0.47 ns, above its 0.3 ns.
pub fn stable_time_step(law: &ContactLaw, walls: &[WallFactors]) -> f64 {
    let m = law.mass;
    let i = law.moment_of_inertia;
    let r = law.radius;
    let p = &law.pair;
    let mut omega2: f64 = 2.0 * p.normal_stiffness_at_equilibrium() / m;
    omega2 = omega2.max(p.k_s * (2.0 / m + 2.0 * r * r / i));
    omega2 = omega2.max(2.0 * p.k_r * p.reduced_radius * p.reduced_radius / i);
    omega2 = omega2.max(2.0 * p.k_t / i);
    for f in walls {
        let w = law.wall_constants(*f);
        omega2 = omega2.max(w.normal_stiffness_at_equilibrium() / m);
        omega2 = omega2.max(w.k_s * (1.0 / m + r * r / i));
        omega2 = omega2.max(w.k_r * r * r / i);
        omega2 = omega2.max(w.k_t / i);
    }
    1.0 / omega2.sqrt()
}

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
        if !(1..=64).contains(&i.pair_slots) {
            c.fail(
                "[integration] pair_slots",
                i.pair_slots,
                "must be between 1 and 64",
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

    pub fn material(&self) -> Material {
        self.material.to_material()
    }

    pub fn contact_law(&self) -> ContactLaw {
        ContactLaw::new(&self.material(), &self.model)
    }

    /// Strength factors of the walls this experiment uses.
    pub fn wall_factors(&self) -> Vec<WallFactors> {
        match self.experiment.kind {
            ExperimentKind::Omni => vec![self.walls.top_bottom, self.walls.side],
            ExperimentKind::Uni => vec![self.walls.top_bottom],
            ExperimentKind::Collision => Vec::new(),
        }
    }

    pub fn dt(&self) -> f64 {
        self.integration.dt_ns * 1e-9
    }

    /// The twisting-stiffness form, for reports.
    pub fn twisting_stiffness(&self) -> TwistingStiffness {
        self.model.twisting_stiffness
    }
}
