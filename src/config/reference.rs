//! The config reference: every key of a run config with its unit, default, allowed values and
//! meaning, rendered as Markdown (`dustdem config-reference`, committed as
//! `docs/guide/src/config-reference.md`).
//!
//! The defaults are not written here: they are read from `Config::default()` serialized to TOML,
//! and the stability limit from [`stable_time_step`]. `tests/config_reference.rs` holds the
//! committed page to this output byte for byte, the keys to those `Config::default()` writes,
//! the ranges to the checker (a value just outside each is refused, naming the key) and the
//! choices to the names serde accepts.

use super::{stable_time_step, Config};
use std::fmt::Write;

/// What a key accepts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Allowed {
    /// A finite number > 0.
    Positive,
    /// A finite number ≥ 0.
    NonNegative,
    /// A finite number strictly between the two bounds.
    Open(f64, f64),
    /// An integer between the two bounds, both included.
    Ints(u64, u64),
    /// An integer of at least this value.
    AtLeast(u64),
    /// Any integer ≥ 0.
    Count,
    /// `true` or `false`.
    Bool,
    /// One of these strings.
    Choice(&'static [&'static str]),
    /// A file system path.
    Path,
}

/// One key of the reference table.
#[derive(Clone, Copy, Debug)]
pub struct Key {
    /// Section and key as a message names it: `[sample] monomers`, `[walls] side.rolling`.
    pub path: &'static str,
    /// Unit, or "–" for a pure number or a name.
    pub unit: &'static str,
    pub allowed: Allowed,
    /// Said after the allowed values (conditions the checker adds).
    pub also: &'static str,
    /// A config (TOML) in which the key is in effect, for a key `Config::default()` leaves out
    /// or that needs another key's value; empty where the defaults will do.
    pub context: &'static str,
    /// What the reference says for the default of a key `Config::default()` leaves out.
    pub absent: &'static str,
    pub meaning: &'static str,
}

const fn key(
    path: &'static str,
    unit: &'static str,
    allowed: Allowed,
    meaning: &'static str,
) -> Key {
    Key {
        path,
        unit,
        allowed,
        also: "",
        context: "",
        absent: "",
        meaning,
    }
}

impl Key {
    const fn also(mut self, also: &'static str) -> Key {
        self.also = also;
        self
    }

    const fn absent(mut self, context: &'static str, absent: &'static str) -> Key {
        self.context = context;
        self.absent = absent;
        self
    }

    /// The section (`sample`) and the dotted key inside it (`side.rolling`).
    pub fn section_and_name(&self) -> (&'static str, &'static str) {
        let rest = self
            .path
            .strip_prefix('[')
            .expect("key paths start with [section]");
        let (section, name) = rest
            .split_once("] ")
            .expect("key paths are `[section] name`");
        (section, name)
    }

    /// The TOML path: section, then each part of the dotted name.
    pub fn toml_path(&self) -> Vec<&'static str> {
        let (section, name) = self.section_and_name();
        std::iter::once(section).chain(name.split('.')).collect()
    }
}

use Allowed::*;

const SNAPSHOTS: &[&str] = &["vtu", "lammps", "both", "none"];
const VISCOELASTIC: &str = "[model.damping]\nkind = \"viscoelastic\"\nt_vis = 1.25e-11\n";

/// Every key of a run config, in the order of the sections of `Config`.
pub const KEYS: &[Key] = &[
    key("[material] radius_um", "µm", Positive, "monomer radius r"),
    key("[material] density_g_cm3", "g/cm³", Positive, "density ρ"),
    key("[material] surface_energy_mj_m2", "mJ/m²", Positive, "surface energy γ"),
    key("[material] youngs_modulus_gpa", "GPa", Positive, "Young's modulus E"),
    key("[material] poisson_ratio", "–", Open(-1.0, 0.5), "Poisson's ratio ν"),
    key("[material] critical_rolling_length_nm", "nm", Positive, "critical rolling length ξ_crit"),
    key("[model] rolling_modifier", "–", Positive, "m_r: k_r → m_r k_r (the paper's calibrated model: 8)"),
    key("[model] sliding_modifier", "–", Positive, "m_s: k_s → m_s k_s (the paper's calibrated model: 2.5)"),
    key("[model] twisting_modifier", "–", Positive, "m_t: k_t → m_t k_t"),
    key(
        "[model] twisting_stiffness",
        "–",
        Choice(&["printed", "reduced_shear", "effective_shear"]),
        "k_t = 16/3 G a₀³ as printed (`printed`), with G/2 (`reduced_shear`) or with G* (`effective_shear`)",
    ),
    key(
        "[model] wall_twisting",
        "–",
        Choice(&["pair", "wall_contact_radius"]),
        "k_t,wall = k_t as Seizinger et al. (2012, Sect. 2.2.4) set it (`pair`), or 16/3 G a₀,wall³ = 4 k_t with the wall contact's own radius (`wall_contact_radius`)",
    ),
    key(
        "[model] damping.kind",
        "–",
        Choice(&["none", "viscous", "viscoelastic"]),
        "normal damping: none, viscous F = −κ v_rel or viscoelastic F = −(2E* T_vis/ν²) a v_rel; a table such as `damping = { kind = \"viscoelastic\", t_vis = 1.25e-11 }`",
    ),
    key("[model] damping.kappa", "g/s", NonNegative, "κ of `kind = \"viscous\"` (Seizinger et al. 2012: 1e-6 g/s)"),
    key("[model] damping.t_vis", "s", NonNegative, "T_vis of `kind = \"viscoelastic\"` (Seizinger & Kley 2013: 1.25e-11 s)")
        .absent(VISCOELASTIC, "– (needed with `kind = \"viscoelastic\"`)"),
    key("[walls] side.rolling", "–", NonNegative, "rolling strength factor of the omni box's four side walls"),
    key("[walls] side.sliding", "–", NonNegative, "sliding strength factor of the side walls"),
    key("[walls] side.twisting", "–", NonNegative, "twisting strength factor of the side walls"),
    key("[walls] top_bottom.rolling", "–", NonNegative, "rolling strength factor of the top and bottom plates"),
    key("[walls] top_bottom.sliding", "–", NonNegative, "sliding strength factor of the plates"),
    key("[walls] top_bottom.twisting", "–", NonNegative, "twisting strength factor of the plates"),
    key("[sample] source", "–", Choice(&["rbd", "file"]), "random ballistic deposition generated at start-up (`rbd`) or a sample file (`file`)"),
    key("[sample] monomers", "–", Ints(1, 100_000_000), "number of monomers N"),
    key(
        "[sample] footprint",
        "–",
        Choice(&["box", "cylinder"]),
        "square box or cylinder base; `kind = \"omni\"` with an RBD sample needs `box`",
    ),
    key(
        "[sample] side_um",
        "µm",
        NonNegative,
        "box side; 0 picks a side that makes the sample about as tall as wide",
    )
    .also("; 0 (automatic) or at least one diameter"),
    key("[sample] cylinder_radius_um", "µm", NonNegative, "cylinder radius; 0 picks one of the same base area as the automatic box"),
    key("[sample] seed", "–", Count, "RBD seed: the same seed gives the byte-identical sample"),
    key("[sample] file", "path", Path, "sample file written by `dustdem generate`, relative to the config file")
        .absent("[sample]\nsource = \"file\"\nfile = \"sample.txt\"\n", "– (needed with `source = \"file\"`)"),
    key(
        "[sample] top",
        "–",
        Choice(&["rough", "cut"]),
        "`rough`: the RBD deposit as it grew (a fluffy top); `cut`: deposited until `monomers` lie wholly below a height equal to the footprint's side, the rest removed (φ₀ = 0.150, as tall as wide)",
    )
    .also("; `cut` only with `source = \"rbd\"`"),
    key(
        "[experiment] kind",
        "–",
        Choice(&["omni", "uni", "collision"]),
        "box with fixed bottom and sides and a moving top wall (`omni`), two plates with free sides (`uni`), or two monomers colliding head-on (`collision`)",
    ),
    key("[experiment] wall_speed_m_s", "m/s", Open(0.0, 1e4), "speed of the top wall"),
    key("[experiment] phi_stop", "–", Open(0.0, 0.75), "stop when the filling factor exceeds this"),
    key("[experiment] pressure_stop_pa", "Pa", Positive, "stop when the top-wall pressure exceeds this"),
    key("[experiment] max_steps", "–", AtLeast(1), "hard limit on the number of steps"),
    key("[experiment] average_steps", "–", Ints(1, 1_000_000), "wall forces are averaged over this many steps; one row of `curve.csv` each"),
    key("[experiment] profile_every_rows", "–", Count, "a filling-factor profile every this many rows (0: at the start and the end only)"),
    key("[experiment] collision_speed_m_s", "m/s", Open(0.0, 1e4), "relative speed of the two monomers (`collision` only)"),
    key("[integration] dt_ns", "ns", Positive, "time step").also(STABILITY),
    key("[integration] allow_unstable_dt", "–", Bool, "run with a step above the stability limit anyway"),
    key("[integration] pair_slots", "–", Ints(1, 64), "contact slots per monomer for partners of higher index; a full slot stops the run naming this key"),
    key("[integration] wall_slots", "–", Ints(1, 6), "wall-contact slots per monomer"),
    key(
        "[integration] space_filling_order",
        "–",
        Bool,
        "store the monomers along a Morton curve of their cells (faster at large N; outputs keep the sample's monomer ids); `false` keeps the sample's order",
    ),
    key("[output] dir", "path", Path, "output directory, relative to the working directory (`--out` overrides it)"),
    key("[output] checkpoint_every_rows", "–", Count, "a checkpoint every this many rows (0: by time only)"),
    key("[output] checkpoint_minutes", "min", NonNegative, "a checkpoint at least this often, counted from the start (0: by rows only)"),
    key("[output] snapshot_format", "–", Choice(SNAPSHOTS), "`vtu` (ParaView), `lammps` (LAMMPS dump for OVITO), `both` or `none`"),
    key("[output] snapshot_every_rows", "–", Count, "a snapshot every this many rows (0: at the start and the end only)"),
    key(
        "[output] tally_corrections",
        "–",
        Bool,
        "book the energy the inelastic rolling, sliding, twisting and wall corrections dissipate; `false` leaves `d_rolling_erg`, `d_sliding_erg`, `d_twisting_erg`, `d_walls_erg` and `energy_balance_erg` NaN and spares the CPU engine their step energies (the trajectory is the same)",
    )
    .absent(
        "[output]\ntally_corrections = false\n",
        "`true` (a config written back names it only when `false`)",
    ),
];

/// Placeholder in `also` for the stability limit of the default config.
const STABILITY: &str = "; at most the stability limit";

/// A number as the reference prints it: plain in [1e-3, 1e5), otherwise with an exponent.
fn number(v: f64) -> String {
    if v != 0.0 && !(1e-3..1e5).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

impl Allowed {
    /// The allowed values in words.
    pub fn describe(&self) -> String {
        match self {
            Positive => "> 0".into(),
            NonNegative => "≥ 0".into(),
            Open(lo, hi) => format!("> {} and < {}", number(*lo), number(*hi)),
            Ints(lo, hi) => format!("integer {lo} to {hi}"),
            AtLeast(lo) => format!("integer ≥ {lo}"),
            Count => "integer ≥ 0".into(),
            Bool => "`true`, `false`".into(),
            Choice(names) => names
                .iter()
                .map(|n| format!("`\"{n}\"`"))
                .collect::<Vec<_>>()
                .join(", "),
            Path => "a path".into(),
        }
    }
}

/// `Config::default()` as a TOML table.
pub fn default_table() -> toml::Table {
    toml::Table::try_from(Config::default()).expect("the default config serializes to TOML")
}

/// The value at a TOML path, if the table has one.
pub fn lookup<'a>(table: &'a toml::Table, path: &[&str]) -> Option<&'a toml::Value> {
    let (first, rest) = path.split_first()?;
    let value = table.get(*first)?;
    match rest {
        [] => Some(value),
        _ => lookup(value.as_table()?, rest),
    }
}

/// A default as TOML would write it (floats plain in [1e-3, 1e5), otherwise with an exponent).
fn render_value(value: &toml::Value) -> String {
    match value {
        toml::Value::Float(v) => format!("`{}`", number(*v)),
        toml::Value::String(s) => format!("`\"{s}\"`"),
        other => format!("`{other}`"),
    }
}

/// Escapes what would end a Markdown table cell.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// The reference page, as committed in `docs/guide/src/config-reference.md`.
pub fn render_markdown() -> String {
    let defaults = default_table();
    let limit_ns = {
        let c = Config::default();
        stable_time_step(&c.contact_law(), &c.wall_factors()) * 1e9
    };
    let mut out = String::new();
    out.push_str(HEADER);
    let mut section = "";
    for k in KEYS {
        let (s, _) = k.section_and_name();
        if s != section {
            section = s;
            let _ = write!(out, "\n## `[{s}]`\n\n| key | unit | default | allowed | meaning |\n|---|---|---|---|---|\n");
        }
        let default = match lookup(&defaults, &k.toml_path()) {
            Some(v) => render_value(v),
            None => k.absent.to_string(),
        };
        let also = if k.also == STABILITY {
            format!("; at most the stability limit ({limit_ns:.3} ns for the defaults)")
        } else {
            k.also.to_string()
        };
        let _ = writeln!(
            out,
            "| `{}` | {} | {} | {}{} | {} |",
            k.path,
            k.unit,
            cell(&default),
            cell(&k.allowed.describe()),
            cell(&also),
            cell(k.meaning)
        );
    }
    out.push_str(FOOTER);
    out
}

const HEADER: &str = "# Config reference

<!-- Generated by `dustdem config-reference` from src/config/reference.rs and the defaults of
`Config::default()`; tests/config_reference.rs fails when this page and that output differ. -->

A run config is a TOML file of up to seven sections. Every key has the default below, so a
config names only what it changes (`configs/omni_quick.toml`, the built-in job of `dustdem run`,
differs from the defaults only in `pressure_stop_pa = 1e6`). Unknown keys, wrong types and
values outside the allowed range are errors that name the file, the key, the value and what is
allowed (exit status 2). `dustdem run` writes the effective config, every key included, to
`config.toml` in its output directory.

Keys are written as error messages name them: `[walls] side.rolling` is the key `rolling` of
the table `side` in the section `[walls]`, written
`side = { rolling = 1e-3, sliding = 1e-3, twisting = 1e-3 }`, and `[model] damping.kind` the
key `kind` of the table `damping`. A table given in a config replaces the default table whole.
";

const FOOTER: &str = "
The stability limit is 1/ω of the stiffest two-body mode (normal; sliding with rotation; the
same against the walls; rolling and twisting, far softer, included): the leap-frog is stable
below ω dt = 2, and the factor 2 leaves room for monomers with several contacts. It depends on
the material, the modifiers and the wall factors; `dustdem info CONFIG` prints it for a config
(0.47 ns with the paper's m_s = 2.5). `allow_unstable_dt = true` runs above it anyway.
";
