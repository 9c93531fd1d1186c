//! Readers for what a compression run writes: the φ–P curve (`curve.csv`) and the
//! filling-factor profiles (`profiles.csv`), in the units the analysis uses (s, m, Pa).

use crate::output::csv::read_csv;
use std::path::Path;

/// The rows of a `curve.csv` the analysis needs, one entry per row in time order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CurveTable {
    pub step: Vec<u64>,
    pub time_s: Vec<f64>,
    /// Distance between the bottom and the top wall [m].
    pub wall_gap_m: Vec<f64>,
    /// Pressure on the top wall [Pa]; NaN in the row written before the first step.
    pub p_top_pa: Vec<f64>,
    pub phi: Vec<f64>,
}

/// One filling-factor profile: slabs one monomer diameter thick between the walls.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    pub step: u64,
    pub time_s: f64,
    /// Filling factor of the whole sample at that row.
    pub phi_mean: f64,
    /// Slab centres [m], bottom first.
    pub z_m: Vec<f64>,
    pub phi: Vec<f64>,
    /// Slab thickness [m] (the spacing of the centres; NaN if no profile of the file has two
    /// slabs).
    pub thickness_m: f64,
    /// Height of the top wall [m] when known ([`attach_wall_heights`]).
    pub wall_m: Option<f64>,
}

impl Profile {
    /// Height of the bottom wall [m]: the lower edge of the first slab.
    pub fn bottom_m(&self) -> f64 {
        self.z_m
            .first()
            .map_or(f64::NAN, |z| z - 0.5 * self.thickness_m)
    }
}

fn columns(path: &Path, header: &[String], names: &[&str]) -> Result<Vec<usize>, String> {
    names
        .iter()
        .map(|&name| {
            header.iter().position(|h| h == name).ok_or_else(|| {
                format!(
                    "{}: no column '{name}' (have: {})",
                    path.display(),
                    header.join(", ")
                )
            })
        })
        .collect()
}

/// All rows of a `curve.csv`.
pub fn read_curve_table(path: impl AsRef<Path>) -> Result<CurveTable, String> {
    let path = path.as_ref();
    let (header, rows) = read_csv(path)?;
    let c = columns(
        path,
        &header,
        &["step", "time_s", "wall_gap_um", "p_top_pa", "phi"],
    )?;
    let mut t = CurveTable::default();
    for r in &rows {
        t.step.push(r[c[0]] as u64);
        t.time_s.push(r[c[1]]);
        t.wall_gap_m.push(r[c[2]] * 1e-6);
        t.p_top_pa.push(r[c[3]]);
        t.phi.push(r[c[4]]);
    }
    Ok(t)
}

/// The φ–P curve of a `curve.csv` as (P [Pa], φ) in time order, keeping the rows whose
/// top-wall pressure is finite and positive (as the run's own plot does).
pub fn read_curve(path: impl AsRef<Path>) -> Result<Vec<(f64, f64)>, String> {
    let t = read_curve_table(path)?;
    Ok(t.p_top_pa
        .iter()
        .zip(&t.phi)
        .filter(|(p, _)| p.is_finite() && **p > 0.0)
        .map(|(&p, &phi)| (p, phi))
        .collect())
}

/// The profiles of a `profiles.csv` in the order written (the first is the one before the
/// first step), each gathered from its consecutive rows of one step.
pub fn read_profiles(path: impl AsRef<Path>) -> Result<Vec<Profile>, String> {
    let path = path.as_ref();
    let (header, rows) = read_csv(path)?;
    let c = columns(
        path,
        &header,
        &["step", "time_s", "phi_mean", "z_um", "phi"],
    )?;
    let mut out: Vec<Profile> = Vec::new();
    for r in &rows {
        let step = r[c[0]] as u64;
        if out.last().is_none_or(|p| p.step != step) {
            out.push(Profile {
                step,
                time_s: r[c[1]],
                phi_mean: r[c[2]],
                z_m: Vec::new(),
                phi: Vec::new(),
                thickness_m: f64::NAN,
                wall_m: None,
            });
        }
        let p = out.last_mut().expect("pushed above");
        p.z_m.push(r[c[3]] * 1e-6);
        p.phi.push(r[c[4]]);
    }
    let thickness = out.iter().find(|p| p.z_m.len() >= 2).map_or(f64::NAN, |p| {
        (p.z_m[p.z_m.len() - 1] - p.z_m[0]) / (p.z_m.len() - 1) as f64
    });
    for p in &mut out {
        p.thickness_m = thickness;
    }
    Ok(out)
}

/// Sets each profile's top-wall height from the curve row of the same step: the bottom wall
/// (lower edge of the first slab) plus the wall gap. Profiles without a matching row keep
/// `None`.
pub fn attach_wall_heights(profiles: &mut [Profile], curve: &CurveTable) {
    for p in profiles {
        p.wall_m = curve
            .step
            .iter()
            .position(|&s| s == p.step)
            .map(|i| p.bottom_m() + curve.wall_gap_m[i])
            .filter(|w| w.is_finite());
    }
}

/// A run directory's `profiles.csv` with the top-wall heights from its `curve.csv` where that
/// reads (without it the profiles keep `None`): what the front readings need.
pub fn read_run_profiles(run_dir: &Path) -> Result<Vec<Profile>, String> {
    let mut profiles = read_profiles(run_dir.join("profiles.csv"))?;
    if let Ok(table) = read_curve_table(run_dir.join("curve.csv")) {
        attach_wall_heights(&mut profiles, &table);
    }
    Ok(profiles)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn reads_curve_and_profiles_as_the_run_writes_them() {
        let dir = std::env::temp_dir().join(format!("dustdem-run-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let curve = write(
            &dir,
            "curve.csv",
            "# omni\nstep,time_s,wall_gap_um,area_um2,phi,p_top_pa,p_bottom_pa\n\
             0,0,60,3600,0.15,NaN,NaN\n100,2e-8,59.5,3600,0.1513,-3,0\n\
             200,4e-8,59,3600,0.1525,1200,5\n",
        );
        let profiles = write(
            &dir,
            "profiles.csv",
            "step,time_s,phi_mean,z_um,phi\n0,0,0.15,0.6,0.14\n0,0,0.15,1.8,0.16\n\
             0,0,0.15,3.0,0.15\n200,4e-8,0.1525,0.6,0.14\n200,4e-8,0.1525,1.8,0.3\n",
        );
        assert_eq!(read_curve(&curve).unwrap(), vec![(1200.0, 0.1525)]);
        let t = read_curve_table(&curve).unwrap();
        assert_eq!(t.step, [0, 100, 200]);
        assert!((t.wall_gap_m[2] - 59e-6).abs() < 1e-18);
        assert!(t.p_top_pa[0].is_nan());

        let mut p = read_profiles(&profiles).unwrap();
        assert_eq!(p.len(), 2);
        assert_eq!((p[0].step, p[1].step), (0, 200));
        assert_eq!(p[0].phi, [0.14, 0.16, 0.15]);
        assert_eq!(p[1].phi, [0.14, 0.3]);
        for q in &p {
            assert!((q.thickness_m - 1.2e-6).abs() < 1e-15);
            assert!(q.bottom_m().abs() < 1e-15);
        }
        attach_wall_heights(&mut p, &t);
        assert!((p[0].wall_m.unwrap() - 60e-6).abs() < 1e-15);
        assert!((p[1].wall_m.unwrap() - 59e-6).abs() < 1e-15);

        let bad = write(&dir, "bad.csv", "step,time_s\n0,0\n");
        assert!(read_profiles(&bad)
            .unwrap_err()
            .contains("no column 'phi_mean'"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
