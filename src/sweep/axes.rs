//! `[axes]` and `[variants]` of a sweep file: the wall speeds, seeds and sample sizes, and the
//! named config overrides, checked value by value so that every problem names the field, the
//! value and what is allowed. A variant may set any config key except those the axes or the
//! sweep itself set.

use super::cases::speed_label;
use super::spec::{ordered_variants, Problems, Variant};
use crate::config::Config;

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

/// The values of `[axes]`; `None` for an axis the file leaves to the base config.
#[derive(Default)]
pub(super) struct Axes {
    pub wall_speeds: Option<Vec<f64>>,
    pub seeds: Option<Vec<u64>>,
    pub monomers: Option<Vec<usize>>,
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

fn speed(v: &toml::Value) -> Option<f64> {
    number(v).filter(|x| x.is_finite() && *x > 0.0 && *x < 1e4)
}

fn seed(v: &toml::Value) -> Option<u64> {
    v.as_integer().filter(|i| *i >= 0).map(|i| i as u64)
}

fn sample_size(v: &toml::Value) -> Option<usize> {
    v.as_integer()
        .filter(|i| (1..=100_000_000).contains(i))
        .map(|i| i as usize)
}

/// The items `read` accepts; each other item is a problem of `field` with `allowed`.
fn axis_values<T>(
    p: &mut Problems,
    field: &str,
    items: &[toml::Value],
    read: impl Fn(&toml::Value) -> Option<T>,
    allowed: &str,
) -> Vec<T> {
    let mut values = Vec::new();
    for item in items {
        match read(item) {
            Some(v) => values.push(v),
            None => p.fail(field, item, allowed),
        }
    }
    values
}

/// Reads `[axes]` (absent: every axis from the base config), then refuses repeated values.
pub(super) fn read_axes(p: &mut Problems, axes: Option<&toml::Table>) -> Axes {
    let mut out = Axes::default();
    for (key, value) in axes.into_iter().flatten() {
        let field = format!("[axes] {key}");
        let items = axis_items(value);
        if items.is_empty() {
            p.fail(&field, value, "must list at least one value");
            continue;
        }
        match key.as_str() {
            "wall_speed_m_s" => {
                let allowed = "each speed must be > 0 and < 10000 m/s";
                out.wall_speeds = Some(axis_values(p, &field, &items, speed, allowed));
            }
            "seed" => {
                let allowed = "each seed must be an integer ≥ 0";
                out.seeds = Some(axis_values(p, &field, &items, seed, allowed));
            }
            "monomers" => {
                let allowed = "each sample size must be an integer between 1 and 100000000";
                out.monomers = Some(axis_values(p, &field, &items, sample_size, allowed));
            }
            _ => p.fail(
                &field,
                value,
                "unknown axis; allowed: wall_speed_m_s, seed, monomers (model variants go \
                 in [variants])",
            ),
        }
    }
    refuse_repeats(p, &out);
    out
}

/// A value written twice on one axis would give two cases of one name.
fn refuse_repeats(p: &mut Problems, axes: &Axes) {
    for (name, labels) in [
        (
            "wall_speed_m_s",
            axes.wall_speeds
                .as_ref()
                .map(|v| v.iter().map(|x| speed_label(*x)).collect::<Vec<_>>()),
        ),
        (
            "seed",
            axes.seeds
                .as_ref()
                .map(|v| v.iter().map(u64::to_string).collect()),
        ),
        (
            "monomers",
            axes.monomers
                .as_ref()
                .map(|v| v.iter().map(usize::to_string).collect()),
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
}

/// A name that is safe and readable in a directory name.
fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 40
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// Reads `[variants]` (`value`, from the sweep-file `text`) in the order the file lists them;
/// absent: no variants.
pub(super) fn read_variants(
    p: &mut Problems,
    value: Option<&toml::Value>,
    text: &str,
) -> Vec<Variant> {
    let mut variants = Vec::new();
    match value {
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
                let overrides = resolve_overrides(p, &name, table);
                variants.push(Variant { name, overrides });
            }
        }
    }
    variants
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
    fn bare_keys_find_their_section() {
        assert_eq!(section_of("rolling_modifier"), Some("model"));
        assert_eq!(section_of("dt_ns"), Some("integration"));
        assert_eq!(section_of("file"), Some("sample"));
        assert_eq!(section_of("no_such_key"), None);
    }
}
