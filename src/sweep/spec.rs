//! The sweep file: a base config and the axes whose cartesian product gives the cases.
//!
//! Read as a TOML document walked key by key (not through serde's derive), so that every
//! problem names the field, the value and what is allowed, in the style of the config checks
//! ([`ConfigError`]), and so that the variants keep the order they are written in. Each case's
//! config is the base config with the variant's overrides and the axes' values put in, then
//! parsed and checked as any config is: a case the config checks refuse (a time step above
//! the stability limit of a stiffer variant, say) stops the sweep before anything runs.

use super::slurm_settings::{slurm_settings, SlurmSettings};
use crate::config::{Config, ConfigError};
use serde::de::{Deserializer, MapAccess, Visitor};
use serde::Deserialize;
use std::fmt;
use std::path::{Path, PathBuf};

/// The sections of a config, in the order `config.toml` lists them.
const SECTIONS: [&str; 7] = [
    "material",
    "model",
    "walls",
    "sample",
    "experiment",
    "integration",
    "output",
];

/// Config keys the axes (or the sweep itself) set: a variant may not.
const RESERVED: [(&str, &str, &str); 4] = [
    ("sample", "seed", "[axes] seed"),
    ("sample", "monomers", "[axes] monomers"),
    ("experiment", "wall_speed_m_s", "[axes] wall_speed_m_s"),
    (
        "output",
        "dir",
        "the sweep (each case writes into its own directory)",
    ),
];

/// A sweep as read from its file: the base config and the values of each axis.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The sweep file, as given.
    pub file: PathBuf,
    /// The base config file (relative paths in the sweep file are relative to the sweep file).
    pub base_path: PathBuf,
    pub base: Config,
    /// Output directory from the file's `out`, if it sets one (relative to the working
    /// directory, like a config's `[output] dir`).
    pub out: Option<PathBuf>,
    pub wall_speeds: Vec<f64>,
    pub seeds: Vec<u64>,
    /// Named sets of config overrides, in the order the file lists them.
    pub variants: Vec<Variant>,
    pub monomers: Vec<usize>,
    pub slurm: SlurmSettings,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Variant {
    pub name: String,
    /// Section → key → value, to be put over the base config.
    pub overrides: toml::Table,
}

/// One case of a sweep: its place in the product, its parameters and its config.
#[derive(Clone, Debug)]
pub struct Case {
    pub index: usize,
    /// Directory name, e.g. `v1.0_seed3_modified_n1000`.
    pub name: String,
    pub wall_speed: f64,
    pub seed: u64,
    pub variant: String,
    pub monomers: usize,
    pub config: Config,
    /// The case's complete config as `config.toml` holds it (the text a run writes too).
    pub config_text: String,
}

/// Collects problems, each naming the sweep file, the field, the value and what is allowed.
pub(super) struct Problems<'a> {
    file: &'a str,
    errors: Vec<ConfigError>,
}

impl Problems<'_> {
    pub(super) fn fail(
        &mut self,
        field: &str,
        value: impl fmt::Display,
        allowed: impl Into<String>,
    ) {
        self.errors.push(ConfigError {
            file: self.file.to_string(),
            field: field.to_string(),
            value: value.to_string(),
            allowed: allowed.into(),
        });
    }

    /// The first problem, with the others listed in its text (as the config checks do).
    fn finish(mut self) -> Result<(), ConfigError> {
        match self.errors.len() {
            0 => Ok(()),
            1 => Err(self.errors.remove(0)),
            n => {
                let mut first = self.errors.remove(0);
                let rest: Vec<String> = self.errors.iter().map(|e| e.to_string()).collect();
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

fn whole_file(file: &str, message: String) -> ConfigError {
    ConfigError {
        file: file.to_string(),
        field: String::new(),
        value: String::new(),
        allowed: message,
    }
}

/// A TOML table's entries in the order the document writes them (`toml::Table` sorts them).
struct Ordered(Vec<(String, toml::Value)>);

impl<'de> Deserialize<'de> for Ordered {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Ordered;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a table")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Ordered, A::Error> {
                let mut entries = Vec::new();
                while let Some(key) = map.next_key::<String>()? {
                    entries.push((key, map.next_value::<toml::Value>()?));
                }
                Ok(Ordered(entries))
            }
        }
        d.deserialize_map(V)
    }
}

/// The top level of a sweep file; `[variants]` is read again in document order.
struct Document {
    entries: Vec<(String, toml::Value)>,
    variants: Option<toml::Value>,
}

impl<'de> Deserialize<'de> for Document {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let Ordered(all) = Ordered::deserialize(d)?;
        let mut doc = Document {
            entries: Vec::new(),
            variants: None,
        };
        for (key, value) in all {
            if key == "variants" {
                doc.variants = Some(value);
            } else {
                doc.entries.push((key, value));
            }
        }
        Ok(doc)
    }
}

/// `[variants]` in document order: a second, ordered read of that one table.
fn ordered_variants(text: &str) -> Vec<(String, toml::Value)> {
    #[derive(Deserialize)]
    struct Only {
        variants: Option<Ordered>,
    }
    // Unknown top-level keys are the first pass's business; here they are ignored.
    toml::from_str::<Only>(text)
        .ok()
        .and_then(|o| o.variants)
        .map_or_else(Vec::new, |o| o.0)
}

fn type_name(v: &toml::Value) -> &'static str {
    v.type_str()
}

/// A number of a TOML value (integers count).
fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// An axis: a list of values, or one value standing for a list of one.
fn axis_items(v: &toml::Value) -> Vec<toml::Value> {
    match v {
        toml::Value::Array(items) => items.clone(),
        other => vec![other.clone()],
    }
}

/// A name that is safe and readable in a directory name.
fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 40
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// Whether `key` is a key of config section `section`.
fn is_config_key(section: &str, key: &str) -> bool {
    let defaults = toml::Value::try_from(Config::default()).expect("the default config serializes");
    // `[sample] file` has no default, so the serialized defaults leave it out.
    (section == "sample" && key == "file")
        || defaults
            .get(section)
            .and_then(|s| s.as_table())
            .is_some_and(|t| t.contains_key(key))
}

/// Which section a config key belongs to, for overrides written without their section
/// (`rolling_modifier = 8`). `None` for an unknown key or one found in more than one section.
fn section_of(key: &str) -> Option<&'static str> {
    let mut found = SECTIONS.iter().filter(|s| is_config_key(s, key));
    match (found.next(), found.next()) {
        (Some(s), None) => Some(s),
        _ => None,
    }
}

/// The decimal text of a wall speed in a case name: always with a decimal point (`1.0`,
/// `0.25`), shortest round trip otherwise.
pub fn speed_label(v: f64) -> String {
    let s = format!("{v}");
    if s.contains('.') || s.contains('e') {
        s
    } else {
        format!("{s}.0")
    }
}

impl Sweep {
    /// Reads and checks a sweep file and its base config.
    pub fn load(path: &Path) -> Result<Sweep, ConfigError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| whole_file(&file, format!("cannot read the sweep file: {e}")))?;
        Sweep::parse(&text, path)
    }

    /// Parses and checks sweep-file text; `path` names it and anchors the base config's path.
    pub fn parse(text: &str, path: &Path) -> Result<Sweep, ConfigError> {
        let file = path.display().to_string();
        let doc: Document = toml::from_str(text).map_err(|e| {
            whole_file(
                &file,
                format!("invalid sweep file: {}", e.to_string().trim_end()),
            )
        })?;
        let mut p = Problems {
            file: &file,
            errors: Vec::new(),
        };
        let mut base = None;
        let mut out = None;
        let mut axes = None;
        let mut slurm_table = None;
        for (key, value) in &doc.entries {
            match key.as_str() {
                "base" => match value.as_str() {
                    Some(s) if !s.trim().is_empty() => base = Some(PathBuf::from(s)),
                    _ => p.fail(
                        "base",
                        value,
                        "must be the path of the base config file (a string, relative to the \
                         sweep file)",
                    ),
                },
                "out" => match value.as_str() {
                    Some(s) if !s.trim().is_empty() => out = Some(PathBuf::from(s)),
                    _ => p.fail(
                        "out",
                        value,
                        "must be a directory path (a string; relative to the working directory)",
                    ),
                },
                "axes" => match value.as_table() {
                    Some(t) => axes = Some(t.clone()),
                    None => p.fail(
                        "axes",
                        value,
                        "must be a table: [axes] with wall_speed_m_s, seed, monomers",
                    ),
                },
                "slurm" => match value.as_table() {
                    Some(t) => slurm_table = Some(t.clone()),
                    None => p.fail(
                        "slurm",
                        value,
                        "must be a table: [slurm] with time, mem_mb, partition, account, \
                         max_running, signal_lead_s, requeue",
                    ),
                },
                other => p.fail(
                    other,
                    value,
                    "unknown key; allowed: base, out, [axes], [variants], [slurm]",
                ),
            }
        }
        if base.is_none() && !doc.entries.iter().any(|(k, _)| k == "base") {
            p.fail(
                "base",
                "(missing)",
                "the base config file is required (a path relative to the sweep file)",
            );
        }

        // [axes]
        let mut wall_speeds = None;
        let mut seeds = None;
        let mut monomers = None;
        for (key, value) in axes.iter().flatten() {
            let field = format!("[axes] {key}");
            let items = axis_items(value);
            if items.is_empty() {
                p.fail(&field, value, "must list at least one value");
                continue;
            }
            match key.as_str() {
                "wall_speed_m_s" => {
                    let mut v = Vec::new();
                    for item in &items {
                        match number(item) {
                            Some(x) if x.is_finite() && x > 0.0 && x < 1e4 => v.push(x),
                            _ => p.fail(&field, item, "each speed must be > 0 and < 10000 m/s"),
                        }
                    }
                    wall_speeds = Some(v);
                }
                "seed" => {
                    let mut v = Vec::new();
                    for item in &items {
                        match item.as_integer() {
                            Some(i) if i >= 0 => v.push(i as u64),
                            _ => p.fail(&field, item, "each seed must be an integer ≥ 0"),
                        }
                    }
                    seeds = Some(v);
                }
                "monomers" => {
                    let mut v = Vec::new();
                    for item in &items {
                        match item.as_integer() {
                            Some(i) if (1..=100_000_000).contains(&i) => v.push(i as usize),
                            _ => p.fail(
                                &field,
                                item,
                                "each sample size must be an integer between 1 and 100000000",
                            ),
                        }
                    }
                    monomers = Some(v);
                }
                _ => p.fail(
                    &field,
                    value,
                    "unknown axis; allowed: wall_speed_m_s, seed, monomers (model variants go \
                     in [variants])",
                ),
            }
        }
        for (name, labels) in [
            (
                "wall_speed_m_s",
                wall_speeds
                    .as_ref()
                    .map(|v: &Vec<f64>| v.iter().map(|x| speed_label(*x)).collect::<Vec<_>>()),
            ),
            (
                "seed",
                seeds
                    .as_ref()
                    .map(|v: &Vec<u64>| v.iter().map(u64::to_string).collect()),
            ),
            (
                "monomers",
                monomers
                    .as_ref()
                    .map(|v: &Vec<usize>| v.iter().map(usize::to_string).collect()),
            ),
        ] {
            let labels = labels.unwrap_or_default();
            for (i, l) in labels.iter().enumerate() {
                if labels[..i].contains(l) {
                    p.fail(
                        &format!("[axes] {name}"),
                        l,
                        "appears twice; each value may appear once",
                    );
                }
            }
        }

        // [variants]
        let mut variants = Vec::new();
        match &doc.variants {
            None => {}
            Some(value) if !value.is_table() => p.fail(
                "variants",
                value,
                "must be a table of named overrides, e.g. [variants] unmodified = {} and \
                 modified = { rolling_modifier = 8, sliding_modifier = 2.5 }",
            ),
            Some(_) => {
                let listed = ordered_variants(text);
                if listed.is_empty() {
                    p.fail(
                        "variants",
                        "{}",
                        "must name at least one variant (or be left out: the base config as it \
                         is)",
                    );
                }
                for (name, value) in listed {
                    let field = format!("[variants] {name}");
                    if !valid_name(&name) {
                        p.fail(
                            &field,
                            &value,
                            "a variant's name must be 1 to 40 letters, digits, '_' or '-'",
                        );
                        continue;
                    }
                    let Some(table) = value.as_table() else {
                        p.fail(
                            &field,
                            &value,
                            "must be a table of config overrides, e.g. { rolling_modifier = 8 } \
                             ({} for the base config as it is)",
                        );
                        continue;
                    };
                    let overrides = resolve_overrides(&mut p, &name, table);
                    variants.push(Variant { name, overrides });
                }
            }
        }

        let slurm = slurm_settings(&mut p, slurm_table.as_ref());
        p.finish()?;

        // The base config, read and checked as any config is.
        let base_rel = base.expect("checked above");
        let base_path = if base_rel.is_relative() {
            path.parent().unwrap_or(Path::new(".")).join(&base_rel)
        } else {
            base_rel.clone()
        };
        if !base_path.is_file() {
            return Err(ConfigError {
                file,
                field: "base".into(),
                value: format!("\"{}\"", base_rel.display()),
                allowed: format!(
                    "no config file at {} (the path is relative to the sweep file)",
                    base_path.display()
                ),
            });
        }
        let mut base = Config::load(&base_path)?;
        if let Some(f) = &base.sample.file {
            // Case configs live elsewhere: their sample file path must not depend on where.
            base.sample.file = Some(std::path::absolute(f).unwrap_or_else(|_| f.clone()));
        }
        if variants.is_empty() {
            variants.push(Variant {
                name: "base".into(),
                overrides: toml::Table::new(),
            });
        }
        Ok(Sweep {
            file: path.to_path_buf(),
            base_path,
            wall_speeds: wall_speeds.unwrap_or_else(|| vec![base.experiment.wall_speed_m_s]),
            seeds: seeds.unwrap_or_else(|| vec![base.sample.seed]),
            monomers: monomers.unwrap_or_else(|| vec![base.sample.monomers]),
            base,
            out,
            variants,
            slurm,
        })
    }

    /// The output directory: `--out`, else the file's `out`, else `runs/<sweep file stem>`.
    pub fn out_dir(&self, cli: Option<&Path>) -> PathBuf {
        if let Some(dir) = cli {
            return dir.to_path_buf();
        }
        self.out.clone().unwrap_or_else(|| {
            let stem = self
                .file
                .file_stem()
                .map_or("sweep".into(), |s| s.to_string_lossy().into_owned());
            Path::new("runs").join(stem)
        })
    }

    /// Number of cases (the product of the axes' lengths).
    pub fn case_count(&self) -> usize {
        self.wall_speeds.len() * self.seeds.len() * self.variants.len() * self.monomers.len()
    }

    /// Every case, in the order wall speed, seed, variant, sample size (the last varies
    /// fastest), each with its complete config writing into `out_dir/<name>`. A case whose
    /// config the checks refuse is an error naming the case and the field.
    pub fn cases(&self, out_dir: &Path) -> Result<Vec<Case>, ConfigError> {
        let file = self.file.display().to_string();
        let out_abs = std::path::absolute(out_dir).map_err(|e| {
            whole_file(
                &file,
                format!("output directory {}: {e}", out_dir.display()),
            )
        })?;
        let base_value = toml::Value::try_from(&self.base)
            .map_err(|e| whole_file(&file, format!("base config: {e}")))?;
        let mut cases = Vec::with_capacity(self.case_count());
        for &wall_speed in &self.wall_speeds {
            for &seed in &self.seeds {
                for variant in &self.variants {
                    for &monomers in &self.monomers {
                        let name = format!(
                            "v{}_seed{seed}_{}_n{monomers}",
                            speed_label(wall_speed),
                            variant.name
                        );
                        let mut value = base_value.clone();
                        let root = value.as_table_mut().expect("a config is a table");
                        for (section, keys) in &variant.overrides {
                            let target = root
                                .entry(section.clone())
                                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
                            if let (Some(target), Some(keys)) =
                                (target.as_table_mut(), keys.as_table())
                            {
                                for (k, v) in keys {
                                    target.insert(k.clone(), v.clone());
                                }
                            }
                        }
                        let set = |root: &mut toml::Table, section: &str, key: &str, v| {
                            root.get_mut(section)
                                .and_then(|s| s.as_table_mut())
                                .expect("every section is serialized")
                                .insert(key.to_string(), v);
                        };
                        set(root, "sample", "seed", toml::Value::Integer(seed as i64));
                        set(
                            root,
                            "sample",
                            "monomers",
                            toml::Value::Integer(monomers as i64),
                        );
                        set(
                            root,
                            "experiment",
                            "wall_speed_m_s",
                            toml::Value::Float(wall_speed),
                        );
                        let dir = out_abs.join(&name);
                        set(
                            root,
                            "output",
                            "dir",
                            toml::Value::String(dir.display().to_string()),
                        );
                        let text = toml::to_string(&value)
                            .map_err(|e| whole_file(&file, format!("case {name}: {e}")))?;
                        let label = format!(
                            "{file} (case {name}: base {} with variant {})",
                            self.base_path.display(),
                            variant.name
                        );
                        let config = Config::parse(&text, &label)?;
                        let config_text = toml::to_string(&config)
                            .map_err(|e| whole_file(&file, format!("case {name}: {e}")))?;
                        cases.push(Case {
                            index: cases.len(),
                            name,
                            wall_speed,
                            seed,
                            variant: variant.name.clone(),
                            monomers,
                            config,
                            config_text,
                        });
                    }
                }
            }
        }
        Ok(cases)
    }
}

/// A variant's overrides as section → key → value: keys written with their section
/// (`model = { rolling_modifier = 8 }`) or without (`rolling_modifier = 8`). Unknown keys and
/// keys the axes set are refused, naming the variant and the key.
fn resolve_overrides(p: &mut Problems, variant: &str, table: &toml::Table) -> toml::Table {
    let mut out = toml::Table::new();
    let mut put = |p: &mut Problems, section: &str, key: &str, value: &toml::Value| {
        let field = format!("[variants] {variant}.{key}");
        if let Some((_, _, owner)) = RESERVED.iter().find(|(s, k, _)| *s == section && *k == key) {
            p.fail(
                &field,
                value,
                format!("[{section}] {key} is set by {owner}, not by a variant"),
            );
            return;
        }
        let entry = out
            .entry(section.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        entry
            .as_table_mut()
            .expect("sections are tables")
            .insert(key.to_string(), value.clone());
    };
    for (key, value) in table {
        if SECTIONS.contains(&key.as_str()) {
            let Some(keys) = value.as_table() else {
                p.fail(
                    &format!("[variants] {variant}.{key}"),
                    value,
                    format!(
                        "a section must be a table of its keys, e.g. {key} = {{ ... }} ({})",
                        type_name(value)
                    ),
                );
                continue;
            };
            for (k, v) in keys {
                if !is_config_key(key, k) {
                    p.fail(
                        &format!("[variants] {variant}.{key}.{k}"),
                        v,
                        format!("unknown key of [{key}] (see the config reference)"),
                    );
                    continue;
                }
                put(p, key, k, v);
            }
            continue;
        }
        match section_of(key) {
            Some(section) => put(p, section, key, value),
            None => p.fail(
                &format!("[variants] {variant}.{key}"),
                value,
                "unknown config key; allowed: a key of a config section (e.g. rolling_modifier, \
                 sliding_modifier, twisting_modifier, damping, dt_ns) or a section table \
                 (e.g. model = { ... })",
            ),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_labels_keep_a_decimal_point() {
        assert_eq!(speed_label(1.0), "1.0");
        assert_eq!(speed_label(0.25), "0.25");
        assert_eq!(speed_label(10.0), "10.0");
    }

    #[test]
    fn bare_keys_find_their_section() {
        assert_eq!(section_of("rolling_modifier"), Some("model"));
        assert_eq!(section_of("dt_ns"), Some("integration"));
        assert_eq!(section_of("file"), Some("sample"));
        assert_eq!(section_of("no_such_key"), None);
    }
}
