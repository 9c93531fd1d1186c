//! The config reference (src/config/reference.rs) cannot drift from the code: the committed
//! page is its rendered output byte for byte, its keys are exactly those `Config::default()`
//! writes (plus the ones the defaults leave out, each shown to be accepted), its numeric ranges
//! are the checker's (a value just outside is refused naming the key, one just inside is
//! accepted) and its choices are the names serde accepts.

mod common;

use common::exe::dustdem_ok;
use dustdem::config::reference::{default_table, lookup, render_markdown, Allowed, Key, KEYS};
use dustdem::config::Config;
use std::collections::BTreeSet;
use std::path::Path;
use toml::{Table, Value};

const PAGE: &str = "docs/guide/src/config-reference.md";

#[test]
fn the_committed_page_is_the_rendered_reference() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(PAGE);
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == render_markdown(),
        "{PAGE} is not the rendered reference; regenerate it with\n  \
         cargo run --release -- config-reference > {PAGE}"
    );
}

#[test]
fn the_config_reference_command_prints_the_page() {
    let out = dustdem_ok(["config-reference"]);
    assert_eq!(String::from_utf8(out.stdout).unwrap(), render_markdown());
}

/// Every leaf of a TOML table as `[section] a.b`.
fn leaves(table: &Table, prefix: &str, out: &mut BTreeSet<String>) {
    for (k, v) in table {
        let name = if prefix.is_empty() {
            format!("[{k}] ")
        } else if prefix.ends_with(' ') {
            format!("{prefix}{k}")
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            Value::Table(t) => leaves(t, &name, out),
            _ => {
                out.insert(name);
            }
        }
    }
}

#[test]
fn every_key_of_the_defaults_is_in_the_table_and_back() {
    let mut written = BTreeSet::new();
    leaves(&default_table(), "", &mut written);
    let listed: BTreeSet<String> = KEYS.iter().map(|k| k.path.to_string()).collect();
    assert_eq!(listed.len(), KEYS.len(), "a key is listed twice");
    let with_default: BTreeSet<String> = KEYS
        .iter()
        .filter(|k| k.absent.is_empty())
        .map(|k| k.path.to_string())
        .collect();
    assert_eq!(
        written, with_default,
        "keys Config::default() writes vs keys the reference gives a default"
    );
    // The keys the defaults leave out are accepted in the context the reference gives them.
    for k in KEYS.iter().filter(|k| !k.absent.is_empty()) {
        let context: Table = toml::from_str(k.context).unwrap();
        assert!(
            lookup(&context, &k.toml_path()).is_some(),
            "{}: context lacks it",
            k.path
        );
        let config = config_text(k, None);
        Config::parse(&config, "context.toml").unwrap_or_else(|e| panic!("{}: {e}", k.path));
    }
}

/// The defaults with the key's context merged in (a section's key replaced whole) and, if
/// given, the key set to a value; as TOML text.
fn config_text(k: &Key, value: Option<Value>) -> String {
    let mut doc = default_table();
    let context: Table = toml::from_str(k.context).unwrap();
    for (section, entries) in context {
        let target = doc.get_mut(&section).and_then(Value::as_table_mut).unwrap();
        for (name, v) in entries.as_table().unwrap() {
            target.insert(name.clone(), v.clone());
        }
    }
    if let Some(value) = value {
        let path = k.toml_path();
        let (last, parents) = path.split_last().unwrap();
        let mut table = &mut doc;
        for p in parents {
            table = table.get_mut(*p).and_then(Value::as_table_mut).unwrap();
        }
        table.insert(last.to_string(), value);
    }
    toml::to_string(&doc).unwrap()
}

/// Values just outside and just inside the allowed range, where the range is numeric.
fn probes(allowed: Allowed) -> Option<(Vec<Value>, Vec<Value>)> {
    let f = Value::Float;
    let i = |v: u64| Value::Integer(v as i64);
    let tiny = f64::MIN_POSITIVE;
    Some(match allowed {
        Allowed::Positive => (
            vec![f(0.0), f(-1.0), f(f64::INFINITY)],
            vec![f(tiny), f(1e300)],
        ),
        Allowed::NonNegative => (vec![f(-tiny), f(f64::INFINITY)], vec![f(0.0), f(1e300)]),
        Allowed::Open(lo, hi) => {
            let eps = (hi - lo) * 1e-9;
            (
                vec![f(lo), f(hi), f(f64::NAN)],
                vec![f(lo + eps), f(hi - eps)],
            )
        }
        Allowed::Ints(lo, hi) => (vec![i(lo - 1), i(hi + 1)], vec![i(lo), i(hi)]),
        Allowed::AtLeast(lo) => (vec![i(lo - 1)], vec![i(lo), i(i64::MAX as u64)]),
        _ => return None,
    })
}

#[test]
fn values_just_outside_each_range_are_refused_naming_the_key() {
    let mut probed = 0;
    for k in KEYS {
        let Some((outside, inside)) = probes(k.allowed) else {
            continue;
        };
        for v in outside {
            let text = config_text(k, Some(v.clone()));
            let e = Config::parse(&text, "probe.toml")
                .err()
                .unwrap_or_else(|| panic!("{} = {v} was accepted", k.path));
            assert!(
                e.field == k.path || e.field.starts_with(&format!("{} (", k.path)),
                "{} = {v}: the error names {:?}: {e}",
                k.path,
                e.field
            );
            probed += 1;
        }
        for v in inside {
            // The stability check would judge the step, not this key's range (it has a test
            // of its own below).
            let text = config_text(k, Some(v.clone()))
                .replace("allow_unstable_dt = false", "allow_unstable_dt = true");
            Config::parse(&text, "probe.toml")
                .unwrap_or_else(|e| panic!("{} = {v} was refused: {e}", k.path));
        }
    }
    assert!(probed >= 40, "only {probed} probes");
}

#[test]
fn the_time_step_is_refused_above_the_stability_limit_the_page_gives() {
    let page = render_markdown();
    let row = page
        .lines()
        .find(|l| l.starts_with("| `[integration] dt_ns`"))
        .unwrap();
    let limit: f64 = row
        .split("stability limit (")
        .nth(1)
        .and_then(|s| s.split(" ns").next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no limit in {row}"));
    let step = |dt: f64| format!("[integration]\ndt_ns = {dt}\n");
    Config::parse(&step(limit - 0.001), "below.toml").unwrap();
    let e = Config::parse(&step(limit + 0.001), "above.toml").unwrap_err();
    assert_eq!(e.field, "[integration] dt_ns", "{e}");
}

#[test]
fn the_choices_are_the_names_serde_accepts() {
    for k in KEYS {
        let Allowed::Choice(names) = k.allowed else {
            continue;
        };
        let text = config_text(k, Some(Value::String("no_such_choice".into())));
        let e = toml::from_str::<Config>(&text)
            .err()
            .unwrap_or_else(|| panic!("{}: a name outside the choices was accepted", k.path))
            .to_string();
        // serde lists the variants it accepts between backticks after the rejected one.
        let listed: BTreeSet<&str> = e.split('`').skip(1).step_by(2).collect();
        let mut expected: BTreeSet<&str> = names.iter().copied().collect();
        expected.insert("no_such_choice");
        assert_eq!(listed, expected, "{}: {e}", k.path);
    }
}
