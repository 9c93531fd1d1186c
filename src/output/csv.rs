//! Plain CSV tables of floating-point columns: one header line, `#` comment
//! lines anywhere, numbers in shortest round-trip form so a file reads back
//! bit for bit.

use crate::binary::Fnv1a;
use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// Streams rows to a CSV file, flushing each one so that the rows of a run
/// that dies mid-way are still on disk. Keeps the length and FNV-1a hash of
/// everything the file holds, so a checkpoint can record which bytes it expects.
pub struct CsvWriter {
    out: BufWriter<File>,
    path: PathBuf,
    columns: usize,
    length: u64,
    hash: Fnv1a,
}

impl CsvWriter {
    /// Creates (truncates) `path` and writes the header line. Names
    /// containing commas or quotes are quoted; line breaks are refused.
    pub fn create(path: impl AsRef<Path>, header: &[&str]) -> io::Result<Self> {
        let path = path.as_ref();
        if let Some(bad) = header.iter().find(|h| h.contains(['\n', '\r'])) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("column name {bad:?} contains a line break"),
            ));
        }
        let line = header
            .iter()
            .map(|h| quote(h))
            .collect::<Vec<_>>()
            .join(",");
        let mut writer = Self {
            out: BufWriter::new(File::create(path)?),
            path: path.to_path_buf(),
            columns: header.len(),
            length: 0,
            hash: Fnv1a::default(),
        };
        writer.emit(&format!("{line}\n"))?;
        Ok(writer)
    }

    /// Reopens a table written by [`CsvWriter::create`] to append to it, first cutting it back
    /// to `length` bytes (its size when a checkpoint was taken), so rows written after that
    /// checkpoint are not duplicated when a resumed run writes them again. The first `length`
    /// bytes must hash to `hash` (what [`CsvWriter::extent`] reported then); otherwise the file
    /// is another one and is left untouched.
    pub fn reopen(
        path: impl AsRef<Path>,
        columns: usize,
        length: u64,
        hash: u64,
    ) -> io::Result<Self> {
        let path = path.as_ref();
        check_prefix(path, length, hash)?;
        let mut file = std::fs::OpenOptions::new().write(true).open(path)?;
        file.set_len(length)?;
        io::Seek::seek(&mut file, io::SeekFrom::End(0))?;
        Ok(Self {
            out: BufWriter::new(file),
            path: path.to_path_buf(),
            columns,
            length,
            hash: Fnv1a(hash),
        })
    }

    /// Length in bytes and FNV-1a 64 hash of everything the file holds.
    pub fn extent(&self) -> (u64, u64) {
        (self.length, self.hash.0)
    }

    /// Writes `text` as `#` comment lines, e.g. run parameters.
    pub fn comment(&mut self, text: &str) -> io::Result<()> {
        let lines: String = text.lines().map(|line| format!("# {line}\n")).collect();
        self.emit(&lines)
    }

    pub fn write_row(&mut self, row: &[f64]) -> io::Result<()> {
        if row.len() != self.columns {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "{}: row has {} values, header has {} columns",
                    self.path.display(),
                    row.len(),
                    self.columns
                ),
            ));
        }
        let mut line = String::new();
        for (i, &v) in row.iter().enumerate() {
            if i > 0 {
                line.push(',');
            }
            line.push_str(&format_number(v));
        }
        line.push('\n');
        self.emit(&line)
    }

    /// Appends `text` to the file, flushed, and to the length and hash.
    fn emit(&mut self, text: &str) -> io::Result<()> {
        self.out.write_all(text.as_bytes())?;
        self.out.flush()?;
        self.length += text.len() as u64;
        self.hash.update(text.as_bytes());
        Ok(())
    }
}

/// Checks that the file at `path` is at least `length` bytes long and that its first `length`
/// bytes hash (FNV-1a 64) to `hash`; reads only, changes nothing.
pub fn check_prefix(path: &Path, length: u64, hash: u64) -> io::Result<()> {
    let bad = |what: String| io::Error::new(io::ErrorKind::InvalidData, what);
    let mut file = File::open(path)?;
    let size = file.metadata()?.len();
    if size < length {
        return Err(bad(format!(
            "has {size} bytes, fewer than the {length} the checkpoint recorded"
        )));
    }
    let mut h = Fnv1a::default();
    let mut left = length;
    let mut buf = vec![0u8; 1 << 16];
    while left > 0 {
        let n = file.read(&mut buf[..left.min(1 << 16) as usize])?;
        if n == 0 {
            return Err(bad(format!(
                "ends before the {length} bytes the checkpoint recorded"
            )));
        }
        h.update(&buf[..n]);
        left -= n as u64;
    }
    if h.0 != hash {
        return Err(bad(format!(
            "its first {length} bytes differ from those the checkpoint recorded: the file was \
             changed or written by another run"
        )));
    }
    Ok(())
}

/// Shortest string that parses back to exactly `v`: plain decimals for
/// moderate magnitudes, exponent form otherwise (Display would spell out
/// 1e-300 with 300 zeros). NaN and infinities as `NaN`, `inf`, `-inf`.
pub fn format_number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-4..1e15).contains(&a) || !v.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

fn quote(name: &str) -> String {
    if name.contains([',', '"']) || name.trim() != name {
        format!("\"{}\"", name.replace('"', "\"\""))
    } else {
        name.to_string()
    }
}

/// Reads a table written by [`CsvWriter`] or by hand: blank lines and lines
/// starting with `#` are skipped, the first other line is the header, every
/// following line must hold one number per column.
pub fn read_csv(path: impl AsRef<Path>) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut header: Option<Vec<String>> = None;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let at = |msg: String| format!("{}:{}: {msg}", path.display(), i + 1);
        let Some(header) = &header else {
            header = Some(split_header(line).map_err(at)?);
            continue;
        };
        let row = line
            .split(',')
            .enumerate()
            .map(|(col, field)| {
                let field = field.trim();
                field.parse::<f64>().map_err(|_| {
                    at(format!(
                        "column {} ({}): {field:?} is not a number",
                        col + 1,
                        header.get(col).map_or("?", |h| h.as_str())
                    ))
                })
            })
            .collect::<Result<Vec<f64>, String>>()?;
        if row.len() != header.len() {
            return Err(at(format!(
                "{} values, header has {} columns",
                row.len(),
                header.len()
            )));
        }
        rows.push(row);
    }
    let header = header.ok_or_else(|| format!("{}: no header line", path.display()))?;
    Ok((header, rows))
}

/// Splits a header line, honouring "quoted, names" with "" for a quote.
fn split_header(line: &str) -> Result<Vec<String>, String> {
    let mut names = Vec::new();
    let mut chars = line.chars().peekable();
    loop {
        while chars.next_if(|c| *c == ' ' || *c == '\t').is_some() {}
        let mut name = String::new();
        if chars.next_if_eq(&'"').is_some() {
            loop {
                match chars.next() {
                    Some('"') if chars.next_if_eq(&'"').is_some() => name.push('"'),
                    Some('"') => break,
                    Some(c) => name.push(c),
                    None => return Err("unterminated quote in header".to_string()),
                }
            }
            while chars.next_if(|c| *c == ' ' || *c == '\t').is_some() {}
            match chars.peek() {
                None | Some(',') => {}
                Some(c) => return Err(format!("unexpected {c:?} after quoted column name")),
            }
        } else {
            while let Some(c) = chars.next_if(|c| *c != ',') {
                name.push(c);
            }
            name.truncate(name.trim_end().len());
        }
        names.push(name);
        if chars.next().is_none() {
            return Ok(names);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::binary::fnv1a64;
    use std::fs;

    fn temp_path(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("dustdem-csv-test-{}-{name}", std::process::id()))
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let path = temp_path("roundtrip.csv");
        let values = [
            0.1,
            1.0 / 3.0,
            -2.5,
            0.0,
            -0.0,
            16667.0,
            1e-4,
            9.99e-5,
            1e15,
            123456789012345.6,
            1e300,
            -1e-300,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let mut w = CsvWriter::create(&path, &["P [Pa]", "phi, fitted", "say \"hi\""]).unwrap();
        w.comment("dustdem compression run\nseed = 7").unwrap();
        for chunk in values.chunks(3) {
            w.write_row(chunk).unwrap();
        }
        drop(w);
        let (header, rows) = read_csv(&path).unwrap();
        assert_eq!(header, ["P [Pa]", "phi, fitted", "say \"hi\""]);
        let back: Vec<f64> = rows.concat();
        assert_eq!(back.len(), values.len());
        for (a, b) in values.iter().zip(&back) {
            assert!(
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                "{a} vs {b}"
            );
        }
        let text = fs::read_to_string(&path).unwrap();
        assert!(text.contains("# seed = 7\n"));
        assert!(text.contains("0.1,0.3333333333333333,-2.5\n"), "{text}");
        assert!(text.contains("1e300"), "{text}");
        fs::remove_file(&path).unwrap();
    }

    #[test]
    fn every_row_is_flushed() {
        let path = temp_path("flush.csv");
        let mut w = CsvWriter::create(&path, &["t", "E"]).unwrap();
        w.write_row(&[1.0, 2.0]).unwrap();
        let (header, rows) = read_csv(&path).unwrap();
        assert_eq!((header.len(), rows), (2, vec![vec![1.0, 2.0]]));
        let e = w.write_row(&[1.0]).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput);
        drop(w);
        assert!(CsvWriter::create(&path, &["a\nb"]).is_err());
        fs::remove_file(&path).unwrap();
    }

    #[test]
    fn reads_hand_written_files() {
        let path = temp_path("hand.csv");
        fs::write(
            &path,
            "\u{feff}# comment before the header\r\n\r\n p , \"phi\" \r\n\
             1e2, 0.15\r\n  # indented comment\n1E3,0.2\n 2000 ,nan\n",
        )
        .unwrap();
        let (header, rows) = read_csv(&path).unwrap();
        assert_eq!(header, ["p", "phi"]);
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[0], [100.0, 0.15]);
        assert_eq!(rows[1], [1000.0, 0.2]);
        assert!(rows[2][1].is_nan());
        fs::remove_file(&path).unwrap();
    }

    #[test]
    fn reports_malformed_lines() {
        let path = temp_path("bad.csv");
        let cases = [
            ("a,b\n1,2\n3,x\n", ":3: column 2 (b): \"x\" is not a number"),
            ("a,b\n1,2,3\n", ":2: 3 values, header has 2 columns"),
            ("a,b\n1,\n", ":2: column 2 (b): \"\" is not a number"),
            ("# only a comment\n", "no header line"),
            ("\"a,b\n", ":1: unterminated quote in header"),
        ];
        for (text, want) in cases {
            fs::write(&path, text).unwrap();
            let e = read_csv(&path).unwrap_err();
            assert!(e.ends_with(want), "{text:?}: {e}");
        }
        fs::remove_file(&path).unwrap();
        assert!(read_csv(&path).unwrap_err().contains("bad.csv"));
    }

    #[test]
    fn extent_is_the_files_length_and_hash_and_reopen_checks_it() {
        let path = temp_path("extent.csv");
        let mut w = CsvWriter::create(&path, &["a", "b"]).unwrap();
        w.comment("run").unwrap();
        w.write_row(&[1.0, 2.0]).unwrap();
        let (length, hash) = w.extent();
        w.write_row(&[3.0, 4.0]).unwrap();
        drop(w);
        let bytes = fs::read(&path).unwrap();
        assert_eq!(fnv1a64(&bytes[..length as usize]), hash);
        // Another file's hash or a longer length: refused, the file untouched.
        for (l, h) in [(length, hash ^ 1), (bytes.len() as u64 + 1, hash)] {
            assert!(CsvWriter::reopen(&path, 2, l, h).is_err());
            assert_eq!(fs::read(&path).unwrap(), bytes);
        }
        let mut w = CsvWriter::reopen(&path, 2, length, hash).unwrap();
        w.write_row(&[5.0, 6.0]).unwrap();
        let (length, hash) = w.extent();
        drop(w);
        let bytes = fs::read(&path).unwrap();
        assert_eq!((bytes.len() as u64, fnv1a64(&bytes)), (length, hash));
        assert!(String::from_utf8_lossy(&bytes).ends_with("1,2\n5,6\n"));
        fs::remove_file(&path).unwrap();
    }

    #[test]
    fn header_only_table_is_empty() {
        let path = temp_path("empty.csv");
        drop(CsvWriter::create(&path, &["x"]).unwrap());
        assert_eq!(read_csv(&path).unwrap(), (vec!["x".to_string()], vec![]));
        fs::remove_file(&path).unwrap();
    }
}
