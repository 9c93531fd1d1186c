//! Reading a sample file's text: magic, header, positions, each checked, with every problem
//! reported by line, field, value and what is allowed.

use super::{SampleError, KEYS, MAGIC, POSITIONS, SLACK};
use crate::sample::{Footprint, Sample};
use std::path::Path;

/// Header value with the line it came from.
struct Entry<'a> {
    line: usize,
    value: &'a str,
}

pub(super) fn parse(text: &str, path: &Path) -> Result<Sample, SampleError> {
    let err = |line: usize, field: &str, value: &str, allowed: String| SampleError::Invalid {
        path: path.to_path_buf(),
        line,
        field: field.to_string(),
        value: value.to_string(),
        allowed,
    };
    let mut lines = text.lines().map(|l| l.trim_end_matches('\r')).enumerate();

    match lines.next() {
        Some((_, MAGIC)) => {}
        Some((_, first)) => {
            let allowed = if first.starts_with("dustdem-sample ") {
                format!("unsupported format version; this reader knows '{MAGIC}'")
            } else {
                format!("not a sample file; the first line must be '{MAGIC}'")
            };
            return Err(err(1, "magic", first, allowed));
        }
        None => {
            return Err(err(
                1,
                "magic",
                "(missing)",
                format!("empty file; the first line must be '{MAGIC}'"),
            ))
        }
    }

    // Header.
    let mut header: [Option<Entry>; KEYS.len()] = Default::default();
    let mut end_of_header = None;
    for (i, line) in lines.by_ref() {
        let lineno = i + 1;
        if line.trim() == POSITIONS {
            end_of_header = Some(lineno);
            break;
        }
        let Some((key, value)) = line.split_once('=') else {
            return Err(err(
                lineno,
                "header",
                line,
                format!("expected 'key = value' or '{POSITIONS}'"),
            ));
        };
        let (key, value) = (key.trim(), value.trim());
        let Some(k) = KEYS.iter().position(|&known| known == key) else {
            return Err(err(
                lineno,
                key,
                value,
                format!("unknown key; known keys are {}", KEYS.join(", ")),
            ));
        };
        if let Some(prev) = &header[k] {
            return Err(err(
                lineno,
                key,
                value,
                format!(
                    "each key may appear only once; first given on line {}",
                    prev.line
                ),
            ));
        }
        header[k] = Some(Entry {
            line: lineno,
            value,
        });
    }
    let total_lines = text.lines().count();
    let Some(header_end) = end_of_header else {
        return Err(err(
            total_lines + 1,
            POSITIONS,
            "(missing)",
            format!("the header must end with a line '{POSITIONS}'"),
        ));
    };

    let get = |key: &str| -> Result<&Entry, SampleError> {
        let k = KEYS.iter().position(|&known| known == key).unwrap_or(0);
        header[k].as_ref().ok_or_else(|| {
            err(
                header_end,
                key,
                "(missing)",
                format!("required header key, due before '{POSITIONS}'"),
            )
        })
    };
    // `min` is exclusive when `strict`, inclusive otherwise.
    let float = |key: &str, min: f64, strict: bool, bound: &str| -> Result<f64, SampleError> {
        let e = get(key)?;
        match e.value.parse::<f64>() {
            Ok(v) if v.is_finite() && (v > min || (!strict && v == min)) => Ok(v),
            _ => Err(err(
                e.line,
                key,
                e.value,
                format!(
                    "must be a finite number {} {bound}",
                    if strict { ">" } else { ">=" }
                ),
            )),
        }
    };
    let reject_if_present = |key: &str, kind: &str| -> Result<(), SampleError> {
        let k = KEYS.iter().position(|&known| known == key).unwrap_or(0);
        match &header[k] {
            Some(e) => Err(err(
                e.line,
                key,
                e.value,
                format!("not allowed with footprint = {kind}"),
            )),
            None => Ok(()),
        }
    };

    let radius = float("radius_cm", 0.0, true, "0")?;
    let fp = get("footprint")?;
    let footprint = match fp.value {
        "box" => {
            reject_if_present("cylinder_radius_cm", "box")?;
            Footprint::Box {
                side: float(
                    "side_cm",
                    2.0 * radius,
                    false,
                    &format!("2 radius_cm = {:e}", 2.0 * radius),
                )?,
            }
        }
        "cylinder" => {
            reject_if_present("side_cm", "cylinder")?;
            Footprint::Cylinder {
                radius: float(
                    "cylinder_radius_cm",
                    radius,
                    false,
                    &format!("radius_cm = {radius:e}"),
                )?,
            }
        }
        other => {
            return Err(err(
                fp.line,
                "footprint",
                other,
                "must be 'box' or 'cylinder'".to_string(),
            ))
        }
    };
    let seed_entry = get("seed")?;
    let seed = seed_entry.value.parse::<u64>().map_err(|_| {
        err(
            seed_entry.line,
            "seed",
            seed_entry.value,
            format!("must be a decimal integer in 0..={}", u64::MAX),
        )
    })?;
    let contact_distance = float("contact_distance_cm", 0.0, true, "0")?;
    let n_entry = get("n")?;
    let n = n_entry.value.parse::<usize>().map_err(|_| {
        err(
            n_entry.line,
            "n",
            n_entry.value,
            "must be a non-negative decimal integer".to_string(),
        )
    })?;

    // Monomers.
    let limit = footprint.half_width() - radius;
    let slack = SLACK * radius;
    let (where_allowed, inside): (String, Box<dyn Fn(f64, f64) -> bool>) = match footprint {
        Footprint::Box { .. } => (
            format!("|x|, |y| <= side_cm/2 - radius_cm = {limit:e}"),
            Box::new(move |x: f64, y: f64| x.abs() <= limit + slack && y.abs() <= limit + slack),
        ),
        Footprint::Cylinder { .. } => (
            format!("sqrt(x^2 + y^2) <= cylinder_radius_cm - radius_cm = {limit:e}"),
            Box::new(move |x: f64, y: f64| x.hypot(y) <= limit + slack),
        ),
    };
    // Never trust n for the allocation: a corrupt header must not abort.
    let mut positions = Vec::with_capacity(n.min(total_lines - header_end));
    for (i, line) in lines.by_ref() {
        let lineno = i + 1;
        let index = positions.len();
        if index == n {
            if line.trim().is_empty() {
                continue;
            }
            return Err(err(
                lineno,
                "n",
                &n.to_string(),
                format!("file has more monomer lines than n; extra line '{line}'"),
            ));
        }
        let mut p = [0.0; 3];
        let mut fields = line.split(' ');
        for (c, axis) in ["x", "y", "z"].iter().enumerate() {
            let field = format!("monomer {index} {axis}");
            let Some(s) = fields.next() else {
                return Err(err(
                    lineno,
                    &field,
                    "(missing)",
                    format!("each monomer line must be 'x y z'; got '{line}'"),
                ));
            };
            p[c] = match s.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                _ => {
                    return Err(err(
                        lineno,
                        &field,
                        s,
                        "must be a finite number [cm]".to_string(),
                    ))
                }
            };
        }
        if let Some(extra) = fields.next() {
            return Err(err(
                lineno,
                &format!("monomer {index}"),
                extra,
                format!("each monomer line must be exactly 'x y z'; got '{line}'"),
            ));
        }
        if !inside(p[0], p[1]) {
            return Err(err(
                lineno,
                &format!("monomer {index} (x, y)"),
                &format!("{:e} {:e}", p[0], p[1]),
                format!("sphere sticks out of the footprint; allowed {where_allowed}"),
            ));
        }
        if p[2] < radius - slack {
            return Err(err(
                lineno,
                &format!("monomer {index} z"),
                &format!("{:e}", p[2]),
                format!("sphere goes below the floor; allowed z >= radius_cm = {radius:e}"),
            ));
        }
        positions.push(p);
    }
    if positions.len() != n {
        return Err(err(
            total_lines + 1,
            "n",
            &n.to_string(),
            format!(
                "file is truncated: header says {n} monomers but only {} lines follow '{POSITIONS}'",
                positions.len()
            ),
        ));
    }
    Ok(Sample {
        radius,
        footprint,
        seed,
        contact_distance,
        positions,
    })
}
