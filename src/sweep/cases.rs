//! The cases of a sweep: the cartesian product of its axes, each named after its parameters
//! and given its complete config, checked as any config is.

use super::spec::{whole_file, Case, Sweep, Variant};
use crate::config::{Config, ConfigError};
use std::path::Path;

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

/// One point of the product: the axes' values for a case.
struct Point<'a> {
    wall_speed: f64,
    seed: u64,
    variant: &'a Variant,
    monomers: usize,
}

impl Point<'_> {
    /// The case's directory name, e.g. `v1.0_seed3_modified_n1000`.
    fn name(&self) -> String {
        format!(
            "v{}_seed{}_{}_n{}",
            speed_label(self.wall_speed),
            self.seed,
            self.variant.name,
            self.monomers
        )
    }

    /// The base config (as a TOML value) with the variant's overrides and the axes' values put
    /// in, writing into `dir`.
    fn config_value(&self, base: &toml::Value, dir: &Path) -> toml::Value {
        let mut value = base.clone();
        let root = value.as_table_mut().expect("a config is a table");
        for (section, keys) in &self.variant.overrides {
            let target = root
                .entry(section.clone())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            if let (Some(target), Some(keys)) = (target.as_table_mut(), keys.as_table()) {
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
        let seed = toml::Value::Integer(self.seed as i64);
        set(root, "sample", "seed", seed);
        let monomers = toml::Value::Integer(self.monomers as i64);
        set(root, "sample", "monomers", monomers);
        let speed = toml::Value::Float(self.wall_speed);
        set(root, "experiment", "wall_speed_m_s", speed);
        let dir = toml::Value::String(dir.display().to_string());
        set(root, "output", "dir", dir);
        value
    }
}

impl Sweep {
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
                        let point = Point {
                            wall_speed,
                            seed,
                            variant,
                            monomers,
                        };
                        let case = self.case(&file, &base_value, &out_abs, &point, cases.len())?;
                        cases.push(case);
                    }
                }
            }
        }
        Ok(cases)
    }

    /// Case number `index` at `point`, its config parsed and checked as any config is.
    fn case(
        &self,
        file: &str,
        base_value: &toml::Value,
        out_abs: &Path,
        point: &Point,
        index: usize,
    ) -> Result<Case, ConfigError> {
        let name = point.name();
        let value = point.config_value(base_value, &out_abs.join(&name));
        let text =
            toml::to_string(&value).map_err(|e| whole_file(file, format!("case {name}: {e}")))?;
        let label = format!(
            "{file} (case {name}: base {} with variant {})",
            self.base_path.display(),
            point.variant.name
        );
        let config = Config::parse(&text, &label)?;
        let config_text =
            toml::to_string(&config).map_err(|e| whole_file(file, format!("case {name}: {e}")))?;
        Ok(Case {
            index,
            name,
            wall_speed: point.wall_speed,
            seed: point.seed,
            variant: point.variant.name.clone(),
            monomers: point.monomers,
            config,
            config_text,
        })
    }
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
}
