//! Reading a sample file's text: magic, header, positions, each checked, with every problem
//! reported by line, field, value and what is allowed.

use super::{SampleError, KEYS, MAGIC, POSITIONS, SLACK};
use crate::sample::{Footprint, Sample};
use std::path::Path;

/// Numbered lines (1-based) with any CR of a CRLF ending removed.
fn numbered(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
}

/// Header value with the line it came from.
struct Entry<'a> {
    line: usize,
    value: &'a str,
}

/// The file being read: its path names every error, its line count places the errors about
/// what is missing at the end.
struct Reader<'a> {
    path: &'a Path,
    total_lines: usize,
}

/// The header's entries in `KEYS` order and the line of `positions_cm` that ends it.
struct Header<'a, 'r> {
    reader: &'r Reader<'r>,
    entries: [Option<Entry<'a>>; KEYS.len()],
    end: usize,
}

pub(super) fn parse(text: &str, path: &Path) -> Result<Sample, SampleError> {
    let reader = Reader {
        path,
        total_lines: text.lines().count(),
    };
    let mut lines = numbered(text);
    reader.magic(lines.next().map(|(_, l)| l))?;
    let header = reader.header(&mut lines)?;
    let radius = header.float("radius_cm", 0.0, true, "0")?;
    let footprint = header.footprint(radius)?;
    let seed = header.integer::<u64>("seed", &format!("a decimal integer in 0..={}", u64::MAX))?;
    let contact_distance = header.float("contact_distance_cm", 0.0, true, "0")?;
    let n = header.integer::<usize>("n", "a non-negative decimal integer")?;
    let positions = reader.positions(lines, n, radius, &footprint, header.end)?;
    Ok(Sample {
        radius,
        footprint,
        seed,
        contact_distance,
        positions,
    })
}

impl Reader<'_> {
    fn err(&self, line: usize, field: &str, value: &str, allowed: String) -> SampleError {
        SampleError::Invalid {
            path: self.path.to_path_buf(),
            line,
            field: field.to_string(),
            value: value.to_string(),
            allowed,
        }
    }

    fn magic(&self, first: Option<&str>) -> Result<(), SampleError> {
        match first {
            Some(MAGIC) => Ok(()),
            Some(first) => {
                let allowed = if first.starts_with("dustdem-sample ") {
                    format!("unsupported format version; this reader knows '{MAGIC}'")
                } else {
                    format!("not a sample file; the first line must be '{MAGIC}'")
                };
                Err(self.err(1, "magic", first, allowed))
            }
            None => Err(self.err(
                1,
                "magic",
                "(missing)",
                format!("empty file; the first line must be '{MAGIC}'"),
            )),
        }
    }

    /// Reads `key = value` lines up to `positions_cm`: known keys, each at most once.
    fn header<'a>(
        &self,
        lines: &mut impl Iterator<Item = (usize, &'a str)>,
    ) -> Result<Header<'a, '_>, SampleError> {
        let mut entries: [Option<Entry>; KEYS.len()] = Default::default();
        for (line, text) in lines.by_ref() {
            if text.trim() == POSITIONS {
                return Ok(Header {
                    reader: self,
                    entries,
                    end: line,
                });
            }
            let Some((key, value)) = text.split_once('=') else {
                let allowed = format!("expected 'key = value' or '{POSITIONS}'");
                return Err(self.err(line, "header", text, allowed));
            };
            let (key, value) = (key.trim(), value.trim());
            let Some(k) = KEYS.iter().position(|&known| known == key) else {
                let allowed = format!("unknown key; known keys are {}", KEYS.join(", "));
                return Err(self.err(line, key, value, allowed));
            };
            if let Some(first) = &entries[k] {
                let allowed = format!(
                    "each key may appear only once; first given on line {}",
                    first.line
                );
                return Err(self.err(line, key, value, allowed));
            }
            entries[k] = Some(Entry { line, value });
        }
        Err(self.err(
            self.total_lines + 1,
            POSITIONS,
            "(missing)",
            format!("the header must end with a line '{POSITIONS}'"),
        ))
    }

    /// Reads exactly `n` monomer lines (blank lines allowed after them), each inside the
    /// footprint and on or above the floor to within `SLACK` radii.
    fn positions<'a>(
        &self,
        lines: impl Iterator<Item = (usize, &'a str)>,
        n: usize,
        radius: f64,
        footprint: &Footprint,
        header_end: usize,
    ) -> Result<Vec<[f64; 3]>, SampleError> {
        let bounds = Bounds::new(footprint, radius);
        // Never trust n for the allocation: a corrupt header must not abort.
        let mut positions = Vec::with_capacity(n.min(self.total_lines - header_end));
        for (line, text) in lines {
            let index = positions.len();
            if index == n {
                if text.trim().is_empty() {
                    continue;
                }
                let allowed = format!("file has more monomer lines than n; extra line '{text}'");
                return Err(self.err(line, "n", &n.to_string(), allowed));
            }
            let p = self.monomer(line, text, index)?;
            bounds.check(self, line, index, p)?;
            positions.push(p);
        }
        if positions.len() != n {
            let allowed = format!(
                "file is truncated: header says {n} monomers but only {} lines follow '{POSITIONS}'",
                positions.len()
            );
            return Err(self.err(self.total_lines + 1, "n", &n.to_string(), allowed));
        }
        Ok(positions)
    }

    /// One monomer line: exactly three finite numbers separated by single spaces.
    fn monomer(&self, line: usize, text: &str, index: usize) -> Result<[f64; 3], SampleError> {
        let mut p = [0.0; 3];
        let mut fields = text.split(' ');
        for (c, axis) in ["x", "y", "z"].iter().enumerate() {
            let field = format!("monomer {index} {axis}");
            let Some(s) = fields.next() else {
                let allowed = format!("each monomer line must be 'x y z'; got '{text}'");
                return Err(self.err(line, &field, "(missing)", allowed));
            };
            p[c] = match s.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                _ => {
                    let allowed = "must be a finite number [cm]".to_string();
                    return Err(self.err(line, &field, s, allowed));
                }
            };
        }
        if let Some(extra) = fields.next() {
            let allowed = format!("each monomer line must be exactly 'x y z'; got '{text}'");
            return Err(self.err(line, &format!("monomer {index}"), extra, allowed));
        }
        Ok(p)
    }
}

impl<'a> Header<'a, '_> {
    fn get(&self, key: &str) -> Result<&Entry<'a>, SampleError> {
        let k = KEYS.iter().position(|&known| known == key).unwrap_or(0);
        self.entries[k].as_ref().ok_or_else(|| {
            let allowed = format!("required header key, due before '{POSITIONS}'");
            self.reader.err(self.end, key, "(missing)", allowed)
        })
    }

    /// A finite number above `min` (exclusive when `strict`, inclusive otherwise).
    fn float(&self, key: &str, min: f64, strict: bool, bound: &str) -> Result<f64, SampleError> {
        let e = self.get(key)?;
        match e.value.parse::<f64>() {
            Ok(v) if v.is_finite() && (v > min || (!strict && v == min)) => Ok(v),
            _ => {
                let relation = if strict { ">" } else { ">=" };
                let allowed = format!("must be a finite number {relation} {bound}");
                Err(self.reader.err(e.line, key, e.value, allowed))
            }
        }
    }

    /// A decimal integer of type `T`; `what` says which.
    fn integer<T: std::str::FromStr>(&self, key: &str, what: &str) -> Result<T, SampleError> {
        let e = self.get(key)?;
        e.value.parse::<T>().map_err(|_| {
            self.reader
                .err(e.line, key, e.value, format!("must be {what}"))
        })
    }

    fn reject_if_present(&self, key: &str, kind: &str) -> Result<(), SampleError> {
        let k = KEYS.iter().position(|&known| known == key).unwrap_or(0);
        match &self.entries[k] {
            Some(e) => {
                let allowed = format!("not allowed with footprint = {kind}");
                Err(self.reader.err(e.line, key, e.value, allowed))
            }
            None => Ok(()),
        }
    }

    /// The footprint and its size key, the other footprint's size key refused.
    fn footprint(&self, radius: f64) -> Result<Footprint, SampleError> {
        let fp = self.get("footprint")?;
        match fp.value {
            "box" => {
                self.reject_if_present("cylinder_radius_cm", "box")?;
                let bound = format!("2 radius_cm = {:e}", 2.0 * radius);
                let side = self.float("side_cm", 2.0 * radius, false, &bound)?;
                Ok(Footprint::Box { side })
            }
            "cylinder" => {
                self.reject_if_present("side_cm", "cylinder")?;
                let bound = format!("radius_cm = {radius:e}");
                let radius = self.float("cylinder_radius_cm", radius, false, &bound)?;
                Ok(Footprint::Cylinder { radius })
            }
            other => Err(self.reader.err(
                fp.line,
                "footprint",
                other,
                "must be 'box' or 'cylinder'".to_string(),
            )),
        }
    }
}

/// Where a monomer's centre may lie: inside the footprint less one radius and at least one
/// radius above the floor, each to within `SLACK` radii.
struct Bounds {
    footprint: Footprint,
    radius: f64,
    limit: f64,
    slack: f64,
}

impl Bounds {
    fn new(footprint: &Footprint, radius: f64) -> Self {
        Bounds {
            footprint: footprint.clone(),
            radius,
            limit: footprint.half_width() - radius,
            slack: SLACK * radius,
        }
    }

    fn check(&self, r: &Reader, line: usize, index: usize, p: [f64; 3]) -> Result<(), SampleError> {
        let (limit, slack) = (self.limit, self.slack);
        let (inside, where_allowed) = match &self.footprint {
            Footprint::Box { .. } => (
                p[0].abs() <= limit + slack && p[1].abs() <= limit + slack,
                format!("|x|, |y| <= side_cm/2 - radius_cm = {limit:e}"),
            ),
            Footprint::Cylinder { .. } => (
                p[0].hypot(p[1]) <= limit + slack,
                format!("sqrt(x^2 + y^2) <= cylinder_radius_cm - radius_cm = {limit:e}"),
            ),
        };
        if !inside {
            let allowed = format!("sphere sticks out of the footprint; allowed {where_allowed}");
            let value = format!("{:e} {:e}", p[0], p[1]);
            return Err(r.err(line, &format!("monomer {index} (x, y)"), &value, allowed));
        }
        if p[2] < self.radius - slack {
            let allowed = format!(
                "sphere goes below the floor; allowed z >= radius_cm = {:e}",
                self.radius
            );
            let value = format!("{:e}", p[2]);
            return Err(r.err(line, &format!("monomer {index} z"), &value, allowed));
        }
        Ok(())
    }
}
