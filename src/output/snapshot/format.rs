//! The atomic write every snapshot goes through, and the number, vector and XML formatting
//! every snapshot format shares.

use std::fmt;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use super::{Snapshot, WallPlane, CM_PER_S_PER_M_PER_S, CM_TO_UM};
use crate::output::atomic::write_atomic_with;

/// [`write_atomic_with`], with the target named in every error: file-system errors carry no
/// path, and a run's log should say which file failed.
pub(super) fn write_atomically<F>(path: &Path, body: F) -> io::Result<()>
where
    F: FnOnce(&mut BufWriter<&mut File>) -> io::Result<()>,
{
    write_atomic_with(path, body)
        .map_err(|e| io::Error::new(e.kind(), format!("writing {}: {e}", path.display())))
}

/// An `f64` in the shortest form that parses back to the same bits (`1.5e-3`, `0e0`).
/// Scientific notation keeps tiny and huge values short, and every VTK, OVITO and C
/// `strtod` parser accepts it.
pub(super) struct F(pub(super) f64);

impl fmt::Display for F {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:e}", self.0)
    }
}

/// Three values separated by spaces.
pub(super) struct V3(pub(super) [f64; 3]);

impl fmt::Display for V3 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} {}", F(self.0[0]), F(self.0[1]), F(self.0[2]))
    }
}

/// Text escaped for an XML attribute value.
pub(super) struct XmlAttr<'a>(pub(super) &'a str);

impl fmt::Display for XmlAttr<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for c in self.0.chars() {
            match c {
                '&' => f.write_str("&amp;")?,
                '<' => f.write_str("&lt;")?,
                '>' => f.write_str("&gt;")?,
                '"' => f.write_str("&quot;")?,
                '\'' => f.write_str("&apos;")?,
                // Parsers normalise literal line breaks and tabs in attributes to spaces.
                '\n' => f.write_str("&#10;")?,
                '\r' => f.write_str("&#13;")?,
                '\t' => f.write_str("&#9;")?,
                _ => write!(f, "{c}")?,
            }
        }
        Ok(())
    }
}

/// Text that is safe inside an XML comment, which may not contain `--`. Only used for wall
/// names, which are for people to read, so bending a doubled hyphen is harmless.
pub(super) struct XmlComment<'a>(pub(super) &'a str);

impl fmt::Display for XmlComment<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut prev_hyphen = false;
        for c in self.0.chars() {
            if c == '-' && prev_hyphen {
                f.write_str("~")?;
                prev_hyphen = false;
            } else {
                write!(f, "{c}")?;
                prev_hyphen = c == '-';
            }
        }
        Ok(())
    }
}

pub(super) fn scale(v: [f64; 3], k: f64) -> [f64; 3] {
    [v[0] * k, v[1] * k, v[2] * k]
}

pub(super) fn to_m_per_s(v: [f64; 3]) -> [f64; 3] {
    [
        v[0] / CM_PER_S_PER_M_PER_S,
        v[1] / CM_PER_S_PER_M_PER_S,
        v[2] / CM_PER_S_PER_M_PER_S,
    ]
}

pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `v / |v|`; non-finite for a zero or non-finite `v`, which validation turns into an error.
pub(super) fn unit(v: [f64; 3]) -> [f64; 3] {
    // hypot avoids overflow/underflow for normals given with extreme magnitudes.
    let len = v[0].hypot(v[1]).hypot(v[2]);
    if len > 0.0 {
        scale(v, 1.0 / len)
    } else {
        [f64::NAN; 3]
    }
}

/// Writes a `DataArray` of vectors, one tuple per line; in binary if any value is not finite
/// (only a failed-state snapshot has such values, see [`super::write_failed_vtu`]).
pub(super) fn vector_array<W: Write>(
    w: &mut W,
    name: &str,
    values: impl Iterator<Item = [f64; 3]>,
) -> io::Result<()> {
    let values: Vec<[f64; 3]> = values.collect();
    if !values.iter().flatten().all(|x| x.is_finite()) {
        return binary_vector_array(w, name, &values);
    }
    writeln!(
        w,
        r#"        <DataArray type="Float64" Name="{name}" NumberOfComponents="3" format="ascii">"#
    )?;
    for v in values {
        writeln!(w, "          {}", V3(v))?;
    }
    writeln!(w, "        </DataArray>")
}

/// A `DataArray` of vectors as VTK's inline binary data: base64 of the byte count (UInt64,
/// the file's `header_type`) followed by the values, little-endian, in one base64 stream.
fn binary_vector_array<W: Write>(w: &mut W, name: &str, values: &[[f64; 3]]) -> io::Result<()> {
    let mut bytes = Vec::with_capacity(8 + 24 * values.len());
    bytes.extend_from_slice(&(24 * values.len() as u64).to_le_bytes());
    for x in values.iter().flatten() {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    writeln!(
        w,
        r#"        <DataArray type="Float64" Name="{name}" NumberOfComponents="3" format="binary">"#
    )?;
    writeln!(w, "          {}", base64(&bytes))?;
    writeln!(w, "        </DataArray>")
}

/// Standard base64 (RFC 4648, with padding), as VTK's XML readers decode it.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let v = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(v >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Whether monomer `i` of `s` has only finite position, velocity and angular velocity.
pub(super) fn monomer_is_finite(s: &Snapshot, i: usize) -> bool {
    [s.positions[i], s.velocities[i], s.angular_velocities[i]]
        .iter()
        .flatten()
        .all(|x| x.is_finite())
}

/// Writes a single-component `DataArray`, a handful of values per line.
pub(super) fn scalar_array<W: Write, T: fmt::Display>(
    w: &mut W,
    ty: &str,
    name: &str,
    values: impl Iterator<Item = T>,
) -> io::Result<()> {
    writeln!(
        w,
        r#"        <DataArray type="{ty}" Name="{name}" format="ascii">"#
    )?;
    for (i, v) in values.enumerate() {
        if i % 8 == 0 {
            if i > 0 {
                writeln!(w)?;
            }
            write!(w, "         ")?;
        }
        write!(w, " {v}")?;
    }
    writeln!(w)?;
    writeln!(w, "        </DataArray>")
}

pub(super) fn wall_comment<W: Write>(
    w: &mut W,
    walls: &[WallPlane],
    indent: &str,
) -> io::Result<()> {
    if walls.is_empty() {
        return writeln!(w, "{indent}walls: none");
    }
    writeln!(
        w,
        "{indent}walls (point in um, unit normal into the domain):"
    )?;
    for (i, wall) in walls.iter().enumerate() {
        writeln!(
            w,
            "{indent}  {i} {}: point {} normal {}",
            XmlComment(&wall.name),
            V3(scale(wall.point, CM_TO_UM)),
            V3(unit(wall.normal))
        )?;
    }
    Ok(())
}
