//! Shared builders for the physics tests, scratch directories for the tests that write files,
//! and (`exe`) runs of the built binary.
#![allow(dead_code)]

pub mod exe;
pub mod printed;
pub mod slurm;

use dustdem::backend::cpu::CpuEngine;
use dustdem::material::Material;
use dustdem::model::{ContactLaw, Damping, ModelOptions};
use dustdem::state::Monomers;
use dustdem::state::{DEFAULT_PAIR_SLOTS, DEFAULT_WALL_SLOTS};
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh directory `dustdem-test-<pid>-<k>-<name>` in the system temp folder, removed with
/// everything in it when dropped. A test that fails keeps it (its path goes to stderr), so
/// what it wrote can be inspected.
pub struct Scratch(PathBuf);

impl Scratch {
    pub fn new(name: &str) -> Scratch {
        // Tests run on parallel threads and may share a name: a counter keeps them apart.
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let k = NEXT.fetch_add(1, Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("dustdem-test-{}-{k}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept for inspection: {}", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

pub fn law_with(damping: Damping) -> ContactLaw {
    let options = ModelOptions {
        damping,
        ..ModelOptions::default()
    };
    ContactLaw::new(&Material::silicate(), &options)
}

pub fn undamped() -> ContactLaw {
    law_with(Damping::None)
}

pub fn engine(law: ContactLaw, dt: f64, monomers: Monomers) -> CpuEngine {
    CpuEngine::new(
        law,
        dt,
        monomers,
        Vec::new(),
        DEFAULT_PAIR_SLOTS,
        DEFAULT_WALL_SLOTS,
    )
    .unwrap()
}

/// Two monomers along x at centre distance 2r − overlap.
pub fn pair_at_overlap(law: &ContactLaw, overlap: f64) -> Monomers {
    let h = law.radius - 0.5 * overlap;
    Monomers::new(vec![DVec3::new(-h, 0.0, 0.0), DVec3::new(h, 0.0, 0.0)])
}

/// Times of upward zero crossings of a sampled signal (linear interpolation).
pub fn upward_crossings(t: &[f64], y: &[f64], mean: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for k in 1..y.len() {
        let (a, b) = (y[k - 1] - mean, y[k] - mean);
        if a < 0.0 && b >= 0.0 {
            out.push(t[k - 1] + (t[k] - t[k - 1]) * (-a / (b - a)));
        }
    }
    out
}

pub fn mean_period(crossings: &[f64]) -> f64 {
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}

/// SplitMix64: a few lines, no dependency, the same sequence on every machine.
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Log-uniform in [lo, hi], both > 0.
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }

    /// Uniformly distributed direction (rejection from the cube).
    pub fn unit_vector(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.unit(), self.unit(), self.unit()) * 2.0 - DVec3::ONE;
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

/// A random tree aggregate: each monomer sits at the equilibrium distance 2r − δ₀ from a random
/// earlier one and at least 2r from all others, so every contact starts at rest.
pub fn tree_aggregate(law: &ContactLaw, n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = SplitMix64(seed);
    let d = 2.0 * law.radius - law.pair.delta0;
    let mut pos = vec![DVec3::ZERO];
    while pos.len() < n {
        let parent = pos[(rng.unit() * pos.len() as f64) as usize];
        let candidate = parent + rng.unit_vector() * d;
        if pos
            .iter()
            .all(|p| *p == parent || (*p - candidate).length() >= 2.0 * law.radius * (1.0 + 1e-6))
        {
            pos.push(candidate);
        }
    }
    pos
}

/// A 50-monomer tree aggregate drifting and spinning as a whole, with random velocities of up
/// to `random_speed` [cm/s] on top (the conservation tests' state, on either backend).
pub fn moving_cluster(law: &ContactLaw, random_speed: f64, seed: u64) -> Monomers {
    let pos = tree_aggregate(law, 50, seed);
    let centre: DVec3 = pos.iter().copied().sum::<DVec3>() / pos.len() as f64;
    let mut m = Monomers::new(pos);
    let mut rng = SplitMix64(seed ^ 0xabcdef);
    let spin = DVec3::new(300.0, -500.0, 800.0); // rad/s
    for i in 0..m.len() {
        m.velocity[i] = DVec3::new(2.0, -1.0, 0.5)
            + spin.cross(m.position[i] - centre)
            + rng.unit_vector() * (random_speed * rng.unit());
        m.angular_velocity[i] = spin + rng.unit_vector() * (random_speed / law.radius * rng.unit());
    }
    m
}

/// Runs `dustdem calibrate ARGS --cache-only --cache CACHE --out OUT` from the repository root
/// (a committed calibration rebuilt from its run cache, never simulating) and asserts that it
/// succeeds and writes at least the report, the figure, the corrected config and one curve,
/// each byte for byte as in `committed`.
pub fn assert_calibration_rebuilds(args: &[&str], cache: &Path, out: &Path, committed: &Path) {
    let label = committed
        .file_name()
        .unwrap()
        .to_string_lossy()
        .into_owned();
    let result = std::process::Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("calibrate")
        .args(args)
        .args(["--cache-only", "--cache"])
        .arg(cache)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(
        result.status.success(),
        "{label}: {}",
        String::from_utf8_lossy(&result.stderr)
    );
    let compared = assert_rebuilt_as_committed(out, committed, &label);
    assert!(compared >= 4, "{label}: {compared} files");
}

/// Asserts that every file `out` holds is byte for byte the one of the same name in
/// `committed` (a rebuild of a committed result); returns how many it compared.
pub fn assert_rebuilt_as_committed(out: &Path, committed: &Path, label: &str) -> usize {
    let mut compared = 0;
    for entry in std::fs::read_dir(out).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let old =
            std::fs::read(committed.join(&name)).unwrap_or_else(|e| panic!("{label}/{name}: {e}"));
        assert!(
            std::fs::read(&path).unwrap() == old,
            "{label}/{name} differs from its rebuild from the run cache"
        );
        compared += 1;
    }
    compared
}
