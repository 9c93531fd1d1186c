//! Run configuration: TOML in user units, validated once, converted to CGS at this boundary.
//!
//! Every field has a default, so an empty file is the built-in omnidirectional quick run.
//! Unknown keys, wrong types and values out of range are errors that name the file, the field,
//! the value and what is allowed.
//!
//! Here: the sections and their defaults, and the conversions to the model's units; `check`
//! reads and validates.

mod check;
pub mod reference;

pub use check::ConfigError;

use crate::material::{Material, TwistingStiffness};
use crate::model::{ContactLaw, ModelOptions, WallFactors};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

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

/// What is done with the rough top of an RBD sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SampleTop {
    /// As deposited: the fluffy surface stays, and the top wall starts on its highest monomer.
    #[default]
    Rough,
    /// Deposited until `monomers` lie wholly below a height equal to the footprint's side (for
    /// a cylinder, the side of the square of the same area), the rest removed: a sample as tall
    /// as it is wide with the bulk's filling factor, as Seizinger et al. (2012, Sect. 5.2)
    /// describe theirs ("base length and height of ≈ 60 µm" at 40 000 monomers).
    Cut,
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
    /// The rough top as deposited, or cut flat (RBD only).
    pub top: SampleTop,
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
            top: SampleTop::Rough,
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
    /// Store the monomers along a space-filling curve (Morton order of their cell) instead
    /// of the sample's order: faster at large N; outputs keep the sample's monomer ids.
    pub space_filling_order: bool,
}

impl Default for IntegrationConfig {
    fn default() -> Self {
        IntegrationConfig {
            dt_ns: 0.3,
            allow_unstable_dt: false,
            pair_slots: crate::state::DEFAULT_PAIR_SLOTS,
            wall_slots: crate::state::DEFAULT_WALL_SLOTS,
            space_filling_order: true,
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
    /// Book what the inelastic rolling, sliding, twisting and wall corrections dissipate
    /// (`false`: those columns NaN, and the CPU engine skips their step energies). Written
    /// back only when off: a config's text is the key of cached calibration runs and of
    /// prepared benchmark states, which a key added with its default must not change.
    #[serde(skip_serializing_if = "is_true")]
    pub tally_corrections: bool,
}

fn is_true(flag: &bool) -> bool {
    *flag
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
            tally_corrections: true,
        }
    }
}

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

impl Config {
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
