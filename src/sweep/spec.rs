//! The sweep file: a base config and the axes whose cartesian product gives the cases.
//!
//! Read as a TOML document walked key by key (not through serde's derive), so that every
//! problem names the field, the value and what is allowed, in the style of the config checks
//! ([`ConfigError`]), and so that the variants keep the order they are written in. Each case's
//! config is the base config with the variant's overrides and the axes' values put in, then
//! parsed and checked as any config is: a case the config checks refuse (a time step above
//! the stability limit of a stiffer variant, say) stops the sweep before anything runs.
//!
//! Here: what a sweep is, the file's top level and its base config. `axes` checks `[axes]` and
//! `[variants]`, `cases` expands the product into named cases.

use super::axes::{read_axes, read_variants};
use super::slurm_settings::{slurm_settings, SlurmSettings};
use crate::config::{Config, ConfigError};
use serde::de::{Deserializer, MapAccess, Visitor};
use serde::Deserialize;
use std::fmt;
use std::path::{Path, PathBuf};

// Case naming lives with the expansion; this path is the one callers know.
pub use super::cases::speed_label;

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

impl Case {
    /// `text` is the case's config but for its output directory: the sweep directory was
    /// moved (copied back from a cluster or a lent machine). Checkpoints name their outputs
    /// relative to themselves, so the case continues where it now is; its `config.toml` is
    /// rewritten when it runs.
    pub fn moved_here(&self, text: &str) -> bool {
        let Ok(mut there) = Config::parse(text, "a case's config.toml") else {
            return false;
        };
        there.output.dir.clone_from(&self.config.output.dir);
        toml::to_string(&there).is_ok_and(|t| t == self.config_text)
    }
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

pub(super) fn whole_file(file: &str, message: String) -> ConfigError {
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
pub(super) fn ordered_variants(text: &str) -> Vec<(String, toml::Value)> {
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

/// The top-level keys of a sweep file besides `[variants]`, as far as they are valid.
#[derive(Default)]
struct TopLevel {
    base: Option<PathBuf>,
    out: Option<PathBuf>,
    axes: Option<toml::Table>,
    slurm: Option<toml::Table>,
}

/// Reads `base`, `out`, `[axes]` and `[slurm]`; anything else is a problem.
fn read_top_level(p: &mut Problems, entries: &[(String, toml::Value)]) -> TopLevel {
    let mut top = TopLevel::default();
    for (key, value) in entries {
        match key.as_str() {
            "base" => match value.as_str() {
                Some(s) if !s.trim().is_empty() => top.base = Some(PathBuf::from(s)),
                _ => p.fail(
                    "base",
                    value,
                    "must be the path of the base config file (a string, relative to the \
                     sweep file)",
                ),
            },
            "out" => match value.as_str() {
                Some(s) if !s.trim().is_empty() => top.out = Some(PathBuf::from(s)),
                _ => p.fail(
                    "out",
                    value,
                    "must be a directory path (a string; relative to the working directory)",
                ),
            },
            "axes" => match value.as_table() {
                Some(t) => top.axes = Some(t.clone()),
                None => p.fail(
                    "axes",
                    value,
                    "must be a table: [axes] with wall_speed_m_s, seed, monomers",
                ),
            },
            "slurm" => match value.as_table() {
                Some(t) => top.slurm = Some(t.clone()),
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
    if top.base.is_none() && !entries.iter().any(|(k, _)| k == "base") {
        p.fail(
            "base",
            "(missing)",
            "the base config file is required (a path relative to the sweep file)",
        );
    }
    top
}

/// The base config `base_rel` names (relative to the sweep file `path`), read and checked as
/// any config is; returns its path and the config.
fn load_base(file: String, path: &Path, base_rel: &Path) -> Result<(PathBuf, Config), ConfigError> {
    let base_path = if base_rel.is_relative() {
        path.parent().unwrap_or(Path::new(".")).join(base_rel)
    } else {
        base_rel.to_path_buf()
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
    Ok((base_path, base))
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
        // Every problem of the file is collected before the first one is reported.
        let top = read_top_level(&mut p, &doc.entries);
        let axes = read_axes(&mut p, top.axes.as_ref());
        let mut variants = read_variants(&mut p, doc.variants.as_ref(), text);
        let slurm = slurm_settings(&mut p, top.slurm.as_ref());
        p.finish()?;

        let base_rel = top.base.expect("checked above");
        let (base_path, base) = load_base(file, path, &base_rel)?;
        if variants.is_empty() {
            variants.push(Variant {
                name: "base".into(),
                overrides: toml::Table::new(),
            });
        }
        Ok(Sweep {
            file: path.to_path_buf(),
            base_path,
            wall_speeds: axes
                .wall_speeds
                .unwrap_or_else(|| vec![base.experiment.wall_speed_m_s]),
            seeds: axes.seeds.unwrap_or_else(|| vec![base.sample.seed]),
            monomers: axes.monomers.unwrap_or_else(|| vec![base.sample.monomers]),
            base,
            out: top.out,
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
}
