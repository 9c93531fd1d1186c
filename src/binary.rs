//! Little-endian binary encoding for checkpoints: a growing byte buffer on the way out, a
//! bounds-checked cursor with errors that say what was being read on the way in.

use glam::DVec3;
use std::fmt;

#[derive(Default)]
pub struct Encoder {
    pub bytes: Vec<u8>,
}

impl Encoder {
    pub fn u32(&mut self, v: u32) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }
    pub fn u64(&mut self, v: u64) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64(&mut self, v: f64) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }
    pub fn vec3(&mut self, v: DVec3) {
        self.f64(v.x);
        self.f64(v.y);
        self.f64(v.z);
    }
    pub fn bytes_with_len(&mut self, b: &[u8]) {
        self.u64(b.len() as u64);
        self.bytes.extend_from_slice(b);
    }
    pub fn f64s(&mut self, v: &[f64]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|x| self.f64(*x));
    }
    pub fn vec3s(&mut self, v: &[DVec3]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|x| self.vec3(*x));
    }
    pub fn u32s(&mut self, v: &[u32]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|x| self.u32(*x));
    }
}

/// What went wrong reading a binary record.
#[derive(Clone, Debug, PartialEq)]
pub struct DecodeError {
    pub what: String,
    pub offset: usize,
    pub problem: String,
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} at byte {}: {}", self.what, self.offset, self.problem)
    }
}

pub struct Decoder<'a> {
    bytes: &'a [u8],
    pub offset: usize,
}

impl<'a> Decoder<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Decoder { bytes, offset: 0 }
    }

    pub fn remaining(&self) -> usize {
        self.bytes.len() - self.offset
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], DecodeError> {
        if self.remaining() < n {
            return Err(DecodeError {
                what: what.to_string(),
                offset: self.offset,
                problem: format!(
                    "file ends early (needs {n} more bytes, has {}): truncated",
                    self.remaining()
                ),
            });
        }
        let s = &self.bytes[self.offset..self.offset + n];
        self.offset += n;
        Ok(s)
    }

    pub fn u32(&mut self, what: &str) -> Result<u32, DecodeError> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().unwrap()))
    }
    pub fn u64(&mut self, what: &str) -> Result<u64, DecodeError> {
        Ok(u64::from_le_bytes(self.take(8, what)?.try_into().unwrap()))
    }
    pub fn f64(&mut self, what: &str) -> Result<f64, DecodeError> {
        Ok(f64::from_le_bytes(self.take(8, what)?.try_into().unwrap()))
    }
    pub fn vec3(&mut self, what: &str) -> Result<DVec3, DecodeError> {
        Ok(DVec3::new(
            self.f64(what)?,
            self.f64(what)?,
            self.f64(what)?,
        ))
    }

    /// A length prefix, refused when larger than the bytes left (a corrupt length must not
    /// allocate gigabytes).
    fn len(&mut self, what: &str, item_size: usize) -> Result<usize, DecodeError> {
        let at = self.offset;
        let n = self.u64(what)?;
        if n.saturating_mul(item_size as u64) > self.remaining() as u64 {
            return Err(DecodeError {
                what: what.to_string(),
                offset: at,
                problem: format!("length {n} exceeds the rest of the file: truncated or corrupt"),
            });
        }
        Ok(n as usize)
    }

    pub fn bytes_with_len(&mut self, what: &str) -> Result<&'a [u8], DecodeError> {
        let n = self.len(what, 1)?;
        self.take(n, what)
    }
    pub fn f64s(&mut self, what: &str) -> Result<Vec<f64>, DecodeError> {
        let n = self.len(what, 8)?;
        (0..n).map(|_| self.f64(what)).collect()
    }
    pub fn vec3s(&mut self, what: &str) -> Result<Vec<DVec3>, DecodeError> {
        let n = self.len(what, 24)?;
        (0..n).map(|_| self.vec3(what)).collect()
    }
    pub fn u32s(&mut self, what: &str) -> Result<Vec<u32>, DecodeError> {
        let n = self.len(what, 4)?;
        (0..n).map(|_| self.u32(what)).collect()
    }
}

/// FNV-1a, 64 bit: detects corruption of a checkpoint body (not an integrity guarantee).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h = Fnv1a::default();
    h.update(bytes);
    h.0
}

/// FNV-1a fed piece by piece: the hash of a file written line by line, kept up to date as it
/// grows (the value after some pieces equals [`fnv1a64`] of their concatenation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fnv1a(pub u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Fnv1a(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    pub fn update(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 ^= *b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}
