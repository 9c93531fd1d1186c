//! Measured data: what a laboratory gives — compression curves φ(P) with uncertainties and
//! sticking velocities — with its provenance. TOML, validated once on loading; every problem
//! names the file, the field, the value and what is allowed (as config errors do).
//!
//! Here: the data a calibration works with; `file` is the TOML format and its checks.

mod file;

use serde::{Deserialize, Serialize};

/// Geometry of a compression experiment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Geometry {
    /// Sample in a box, one wall moving (Güttler et al. 2009).
    Omni,
    /// Sample between two plates, free sides (Blum & Schräpler 2004).
    Uni,
}

impl std::str::FromStr for Geometry {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "omni" => Ok(Geometry::Omni),
            "uni" => Ok(Geometry::Uni),
            other => Err(format!("geometry `{other}`: expected omni or uni")),
        }
    }
}

impl Geometry {
    pub fn name(self) -> &'static str {
        match self {
            Geometry::Omni => "omni",
            Geometry::Uni => "uni",
        }
    }
}

/// One compression curve: filling factor against pressure, with a 1σ uncertainty per point.
#[derive(Clone, Debug, PartialEq)]
pub struct CompressionCurve {
    pub name: String,
    pub geometry: Geometry,
    /// Increasing pressures [Pa].
    pub pressure: Vec<f64>,
    pub phi: Vec<f64>,
    pub phi_sigma: Vec<f64>,
    /// Wall speed of the experiment [m/s], when the data say.
    pub wall_speed: Option<f64>,
}

impl CompressionCurve {
    pub fn pressure_range(&self) -> (f64, f64) {
        (self.pressure[0], self.pressure[self.pressure.len() - 1])
    }

    /// Measured φ and σ at pressure `p`, linear in log P between points (inside the range).
    pub fn at(&self, p: f64) -> (f64, f64) {
        let x = p.log10();
        let xs: Vec<f64> = self.pressure.iter().map(|p| p.log10()).collect();
        let k = xs
            .windows(2)
            .position(|w| x <= w[1])
            .unwrap_or(xs.len() - 2);
        let t = ((x - xs[k]) / (xs[k + 1] - xs[k])).clamp(0.0, 1.0);
        let lerp = |v: &[f64]| v[k] + t * (v[k + 1] - v[k]);
        (lerp(&self.phi), lerp(&self.phi_sigma))
    }
}

/// A sticking velocity: the largest head-on speed at which two monomers stick.
#[derive(Clone, Debug, PartialEq)]
pub struct StickingVelocity {
    pub name: String,
    /// [m/s]
    pub velocity: f64,
    /// 1σ [m/s]
    pub sigma: f64,
}

/// Where the numbers come from.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Provenance {
    pub citation: String,
    /// What the numbers are (raw points, a published fit, a synthetic run, ...).
    pub what: String,
    pub notes: String,
}

/// A measured data set: any number of compression curves and sticking velocities, used jointly.
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredSet {
    pub source: Provenance,
    pub compression: Vec<CompressionCurve>,
    pub sticking: Vec<StickingVelocity>,
}

impl MeasuredSet {
    pub fn curve_count(&self) -> usize {
        self.compression.len() + self.sticking.len()
    }

    /// Several data sets as one, to be fitted jointly; provenance entries are joined.
    pub fn merge(sets: Vec<MeasuredSet>) -> MeasuredSet {
        let join = |f: &dyn Fn(&Provenance) -> &str| {
            sets.iter()
                .map(|s| f(&s.source))
                .filter(|t| !t.is_empty())
                .collect::<Vec<_>>()
                .join("; ")
        };
        let source = Provenance {
            citation: join(&|p| &p.citation),
            what: join(&|p| &p.what),
            notes: join(&|p| &p.notes),
        };
        let mut merged = MeasuredSet {
            source,
            compression: Vec::new(),
            sticking: Vec::new(),
        };
        for s in sets {
            merged.compression.extend(s.compression);
            merged.sticking.extend(s.sticking);
        }
        merged
    }
}

/// `n` pressures from `lo` to `hi`, evenly spaced in log P.
pub fn log_spaced(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let (a, b) = (lo.log10(), hi.log10());
    (0..n)
        .map(|k| 10f64.powf(a + (b - a) * k as f64 / (n - 1) as f64))
        .collect()
}
