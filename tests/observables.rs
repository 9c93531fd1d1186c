//! The observables a run writes, checked against quantities computed here from their
//! definitions (Seizinger et al. 2012, Sects. 3.2 and 5.2.1; docs/physics.md, Sect. 5), not
//! from the code that writes them:
//!
//! - the top-wall pressure of curve.csv, integrated over the wall's travel, is the wall work
//!   of the energy tally;
//! - monomers squeezed between the plates at a known overlap report the JKR force, written
//!   again here from the printed constants, over the box base;
//! - the slabs of profiles.csv hold the monomers' volume, and φ in curve.csv is N V / (A h).
//!
//! The files carry pressures in Pa, lengths in µm and energies in erg; the conversions are
//! written out below, independently of the code's.

mod common;

use common::printed::{self, F_C_WALL, PRINTED_REL, RADIUS};
use common::Scratch;
use dustdem::backend::cpu::CpuEngine;
use dustdem::config::Config;
use dustdem::experiment::compression::{Compression, Event, Row};
use dustdem::state::Monomers;
use glam::DVec3;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// 1 Pa = 10 dyn/cm².
const DYN_CM2_PER_PA: f64 = 10.0;
/// 1 µm = 1e-4 cm.
const CM_PER_UM: f64 = 1e-4;
/// Monomer radius [µm] (Table 1).
const R_UM: f64 = RADIUS / CM_PER_UM;

/// Volume of a sphere of radius `r`.
fn sphere(r: f64) -> f64 {
    4.0 / 3.0 * PI * r * r * r
}

/// Volume of the cap of height `h` (0 ≤ h ≤ 2r) cut from a sphere of radius `r`.
fn cap(r: f64, h: f64) -> f64 {
    let h = h.clamp(0.0, 2.0 * r);
    PI * h * h * (3.0 * r - h) / 3.0
}

/// A CSV table: header, then rows of numbers; `#` lines are comments.
struct Table {
    header: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Table {
    fn read(path: &Path) -> Table {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines().filter(|l| !l.starts_with('#'));
        let header = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        Table { header, rows }
    }

    fn column(&self, name: &str) -> Vec<f64> {
        let k = self.header.iter().position(|h| h == name).unwrap();
        self.rows.iter().map(|r| r[k]).collect()
    }
}

/// One snapshot of a LAMMPS dump: step, monomer centres [µm] and velocities [m/s], wall
/// planes (name, point [µm], inward normal).
struct Snapshot {
    step: u64,
    centres: Vec<[f64; 3]>,
    velocities: Vec<[f64; 3]>,
    walls: Vec<(String, [f64; 3], [f64; 3])>,
}

impl Snapshot {
    fn read(path: &Path) -> Snapshot {
        let text = std::fs::read_to_string(path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let at = |item: &str| lines.iter().position(|l| l.starts_with(item)).unwrap() + 1;
        let numbers = |words: &[&str]| -> Vec<f64> {
            words.iter().map(|v| v.parse::<f64>().unwrap()).collect()
        };
        let n: usize = lines[at("ITEM: NUMBER OF ATOMS")].parse().unwrap();
        let walls = lines[at("ITEM: WALLS")..at("ITEM: BOX BOUNDS") - 1]
            .iter()
            .map(|l| {
                // "<name> px py pz nx ny nz"; a name may contain spaces.
                let words: Vec<&str> = l.split_whitespace().collect();
                let (name, v) = words.split_at(words.len() - 6);
                let v = numbers(v);
                (name.join(" "), [v[0], v[1], v[2]], [v[3], v[4], v[5]])
            })
            .collect();
        let atoms = at("ITEM: ATOMS");
        // "id type x y z vx vy vz ...".
        let values: Vec<Vec<f64>> = lines[atoms..atoms + n]
            .iter()
            .map(|l| numbers(&l.split_whitespace().collect::<Vec<_>>()))
            .collect();
        Snapshot {
            step: lines[at("ITEM: TIMESTEP")].parse().unwrap(),
            centres: values.iter().map(|v| [v[2], v[3], v[4]]).collect(),
            velocities: values.iter().map(|v| [v[5], v[6], v[7]]).collect(),
            walls,
        }
    }

    fn wall(&self, name: &str) -> ([f64; 3], [f64; 3]) {
        let w = self.walls.iter().find(|w| w.0 == name).unwrap();
        (w.1, w.2)
    }

    /// Volume [µm³] of the monomers below the plane z = `bottom` and above z = `top` [µm].
    fn volume_outside(&self, bottom: f64, top: f64) -> f64 {
        self.centres
            .iter()
            .map(|x| cap(R_UM, bottom - (x[2] - R_UM)) + cap(R_UM, x[2] + R_UM - top))
            .sum()
    }

    /// A bound on the normal force [dyn] the top plate, moving down at `speed` [cm/s], exerts
    /// on the monomers now: every monomer within the break distance δ_c,wall of the plane may
    /// hold a contact, pushing with the JKR force F(δ) where δ ≥ 0 and pulling with at most
    /// F_c,wall where it is stretched, plus damping κ |v − v_w| (κ = 1e-6 g/s, the paper's
    /// viscous damping; the dump's velocities are in m/s).
    fn top_force_bound(&self, speed: f64) -> f64 {
        const KAPPA: f64 = 1e-6;
        let (top, normal) = self.wall("top");
        assert_eq!(normal, [0.0, 0.0, -1.0]);
        let delta0 = printed::delta0_wall();
        let delta_c = (9.0f64 / 16.0).powf(1.0 / 3.0) * delta0;
        let mut bound = 0.0;
        for (x, v) in self.centres.iter().zip(&self.velocities) {
            let delta = RADIUS - (top[2] - x[2]) * CM_PER_UM;
            if delta < -delta_c {
                continue;
            }
            bound += if delta >= 0.0 {
                printed::jkr_force(delta, F_C_WALL, delta0).abs()
            } else {
                F_C_WALL
            };
            let relative = [v[0] * 100.0, v[1] * 100.0, v[2] * 100.0 + speed];
            bound += KAPPA * relative.iter().map(|c| c * c).sum::<f64>().sqrt();
        }
        bound
    }
}

/// The files of one small omnidirectional run of the binary on the CPU.
struct OmniRun {
    curve: Table,
    profiles: Table,
    /// Snapshots at the start, every few rows and at the end, in step order.
    snapshots: Vec<Snapshot>,
}

impl OmniRun {
    fn snapshot(&self, step: f64) -> Option<&Snapshot> {
        self.snapshots.iter().find(|s| s.step as f64 == step)
    }
}

const MONOMERS: usize = 300;
const AVERAGE_STEPS: u64 = 100;
const SNAPSHOT_ROWS: u64 = 10;

/// 300 RBD monomers compressed at 2 m/s to φ = 0.3 (180 rows of 100 steps), a profile every
/// row and a snapshot every 10 rows; run once (about a second), shared by the tests that read
/// its files.
fn omni_run() -> &'static OmniRun {
    static RUN: OnceLock<OmniRun> = OnceLock::new();
    RUN.get_or_init(|| {
        let dir = Scratch::new("observables-omni");
        let config = dir.join("omni.toml");
        std::fs::write(
            &config,
            format!(
                "[sample]\nmonomers = {MONOMERS}\nseed = 11\n\
                 [experiment]\nkind = \"omni\"\nwall_speed_m_s = 2.0\nphi_stop = 0.3\n\
                 average_steps = {AVERAGE_STEPS}\nprofile_every_rows = 1\n\
                 [output]\nsnapshot_format = \"lammps\"\nsnapshot_every_rows = {SNAPSHOT_ROWS}\n"
            ),
        )
        .unwrap();
        let out = dir.join("out");
        let run = Command::new(env!("CARGO_BIN_EXE_dustdem"))
            .args(["run", config.to_str().unwrap(), "--out"])
            .arg(&out)
            .args(["--backend", "cpu", "--threads", "1", "--quiet"])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let mut dumps = Vec::new();
        find_dumps(&out, &mut dumps);
        let mut snapshots: Vec<Snapshot> = dumps.iter().map(|p| Snapshot::read(p)).collect();
        snapshots.sort_by_key(|s| s.step);
        OmniRun {
            curve: Table::read(&out.join("curve.csv")),
            profiles: Table::read(&out.join("profiles.csv")),
            snapshots,
        }
    })
}

fn find_dumps(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            find_dumps(&path, out);
        } else if path.extension().is_some_and(|e| e == "dump") {
            out.push(path);
        }
    }
}

/// Wall work, Sect. 5.6 of docs/physics.md: W = ∫ F·v_w dt over the moving walls. Only the top
/// plate moves (bottom and side walls stand still, checked on the snapshots), its velocity is
/// along its inward normal and P_top = n_w·F/A, so W = −∫ P_top A dh with h the wall gap.
///
/// Each row's p_top is the mean of F(n) over the `average_steps` steps n since the previous
/// row, while the tally adds ½(F(n − 1) + F(n))·v dt per step. Summed up to row k the two
/// differ by a telescoping term: Σ (row mean × row travel), the rectangle rule on the interval
/// each mean belongs to, equals the tally up to ½ v dt (F(0) − F(row k)), half a step's work at
/// the forces of the first snapshot and of row k. At every row with a snapshot we allow that
/// term, with both forces bounded from the snapshots (`top_force_bound`).
///
/// The trapezoid rule on the rows, which places each mean at the end of its interval, differs
/// from the rectangle sum by Σ ½ A Δh (p_k − p_{k−1}) = ½ A Δh (p_last − p_first) (constant A
/// and Δh): that difference is its quadrature error, and with the telescoping term its
/// tolerance at the end of the run.
#[test]
fn top_wall_pressure_integrates_to_the_wall_work() {
    let run = omni_run();
    let (first, end) = (&run.snapshots[0], run.snapshots.last().unwrap());
    for (name, point, _) in &first.walls {
        let (now, _) = end.wall(name);
        assert_eq!(
            now != *point,
            name == "top",
            "wall {name}: {point:?} -> {now:?}"
        );
    }
    let c = &run.curve;
    let (step, time, gap, area, p) = (
        c.column("step"),
        c.column("time_s"),
        c.column("wall_gap_um"),
        c.column("area_um2"),
        c.column("p_top_pa"),
    );
    let tally = c.column("wall_work_erg");
    let last = p.len() - 1;
    assert!(p[0].is_nan() && tally[0] == 0.0, "row 0 is the start");
    assert_eq!((step[0], step[last]), (first.step as f64, end.step as f64));
    // One step's travel [µm] and the plate's speed [cm/s].
    let step_um = (gap[0] - gap[last]) / step[last];
    let speed = step_um * CM_PER_UM / (time[last] / step[last]);
    let f_first = first.top_force_bound(speed);
    // Force [dyn] of a pressure [Pa] on an area [µm²], and work [erg] of a force over [µm].
    let force = |k: usize| p[k] * DYN_CM2_PER_PA * area[k] * CM_PER_UM * CM_PER_UM;
    let work = |f: f64, um: f64| f * um * CM_PER_UM;
    let (mut rect, mut trap, mut checked, mut worst) = (0.0, 0.0, 0, 0.0_f64);
    let mut ends = 0.0;
    for k in 1..=last {
        let travel = gap[k - 1] - gap[k];
        assert!((travel / AVERAGE_STEPS as f64 - step_um).abs() < 1e-9 * step_um);
        rect += work(force(k), travel);
        // The first interval has no mean before it: the trapezoid starts as the rectangle.
        trap += work(0.5 * (force(k.max(2) - 1) + force(k)), travel);
        if let Some(s) = run.snapshot(step[k]) {
            ends = work(0.5 * (f_first + s.top_force_bound(speed)), step_um) + 1e-12 * rect.abs();
            let error = tally[k] - rect;
            assert!(
                error.abs() <= ends,
                "row {k}: tally {:.9e} erg, Σ p A Δh {rect:.9e} erg (allowed {ends:.3e})",
                tally[k]
            );
            checked += 1;
            worst = worst.max(error.abs() / ends);
        }
    }
    assert!(checked >= 10, "{checked} rows with snapshots");
    let w = tally[last];
    let quadrature = (trap - rect).abs();
    eprintln!(
        "wall work {w:.9e} erg over {last} rows at {speed:.6} cm/s\n  rectangle {rect:.9e} erg, \
         error {:.2e} of W, allowed {:.2e}; at {checked} rows at most {worst:.2} of the allowance\n  \
         trapezoid {trap:.9e} erg, error {:.2e} of W, allowed {:.2e} (quadrature {:.2e})",
        (rect - w) / w,
        ends / w,
        (trap - w) / w,
        (quadrature + ends) / w,
        quadrature / w
    );
    assert!(w > 0.0, "the top plate does work on the sample");
    // The quadrature error must be a small part of the work, or the comparison tests nothing.
    assert!(
        quadrature < 0.05 * w,
        "quadrature error {quadrature:.3e} of {w:.3e}"
    );
    assert!(
        (trap - w).abs() <= quadrature + ends,
        "tally {w:.9e} erg, trapezoid {trap:.9e} erg (allowed {:.3e})",
        quadrature + ends
    );
}

/// Four monomers held between the plates at the same overlap δ with each, far from each other
/// and from the side walls, at rest: each plate pushes with 4 F(δ), F the JKR force of a
/// monomer on a wall (a sphere of R = r, Sect. 2.2 of Seizinger et al. 2012):
///
///     δ/δ₀,wall = 3x² − 2x^(1/2),   F = 4 F_c,wall (x³ − x^(3/2)),
///
/// with the printed F_c,wall and δ₀,wall = a₀,wall²/(3r) (common::printed, not the library's
/// law). The overlaps with both plates are bit-identical, so nothing moves and every step's
/// force is the same; both rows must report 4F/A with A the box base. (The config's one-monomer
/// sample only sets the box; the engine gets the four monomers and the plates placed here.)
#[test]
fn monomers_squeezed_between_the_plates_report_the_jkr_pressure() {
    const SIDE_UM: f64 = 8.0;
    let config = Config::parse(
        &format!(
            "[sample]\nmonomers = 1\nside_um = {SIDE_UM}\n\
             [experiment]\nkind = \"omni\"\nmax_steps = 200\naverage_steps = 100\n\
             profile_every_rows = 0\n"
        ),
        "squeeze",
    )
    .unwrap();
    let delta0 = printed::delta0_wall();
    let delta = 3.0 * delta0;
    let gap = 2.0 * (RADIUS - delta);
    let centres: Vec<DVec3> = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
        .iter()
        .map(|&(x, y)| DVec3::new(x * 1.5e-4, y * 1.5e-4, 0.5 * gap))
        .collect();
    let count = centres.len() as f64;
    let mut run = Compression::with_engine(&config, |law, dt, _, mut walls, ps, ws| {
        assert_eq!(
            (walls[0].name.as_str(), walls[1].name.as_str()),
            ("bottom", "top")
        );
        walls[0].point = DVec3::ZERO;
        walls[1].point = DVec3::new(0.0, 0.0, gap);
        walls[1].velocity = DVec3::ZERO;
        CpuEngine::new(law, dt, Monomers::new(centres), walls, ps, ws)
    })
    .unwrap();
    let mut rows: Vec<Row> = Vec::new();
    run.run(&mut |e| {
        if let Event::Row(r) = e {
            rows.push(*r);
        }
        Ok(())
    })
    .unwrap();
    assert_eq!(rows.len(), 3);
    assert_eq!(
        run.engine.contacts.wall_contact_count(),
        8,
        "two plates each"
    );

    let area_cm2 = (SIDE_UM * CM_PER_UM).powi(2);
    let expected = |f_c: f64, d0: f64| count * printed::jkr_force(delta, f_c, d0) / area_cm2;
    let p = expected(F_C_WALL, delta0) / DYN_CM2_PER_PA;
    // The printed F_c,wall and a₀,wall carry six figures (5e-6 each; δ₀,wall ∝ a₀,wall²): the
    // tolerance is how far the expected pressure moves across that range.
    let mut spread = 0.0_f64;
    for sf in [-1.0, 1.0] {
        for sd in [-1.0, 1.0] {
            let q = expected(
                F_C_WALL * (1.0 + sf * PRINTED_REL),
                delta0 * (1.0 + sd * 2.0 * PRINTED_REL),
            ) / DYN_CM2_PER_PA;
            spread = spread.max((q - p).abs());
        }
    }
    let tolerance = spread + 1e-12 * p;
    for r in &rows[1..] {
        eprintln!(
            "step {}: p_top {:.9e} Pa, p_bottom {:.9e} Pa, expected {p:.9e} Pa (rel {:.2e}, allowed {:.2e})",
            r.step,
            r.p_top,
            r.p_bottom,
            (r.p_top - p) / p,
            tolerance / p
        );
        assert!((r.p_top - p).abs() <= tolerance, "top {} Pa", r.p_top);
        assert!(
            (r.p_bottom - p).abs() <= tolerance,
            "bottom {} Pa",
            r.p_bottom
        );
        assert!((r.area - area_cm2).abs() <= 1e-12 * area_cm2);
        assert_eq!(r.wall_gap, gap);
    }
}

/// φ of every row of curve.csv is N (4/3)πr³ / (A h) with the row's own A and h (Sect. 3.2.2
/// of Seizinger et al. 2012), to the rounding of the written numbers; and the slabs of
/// profiles.csv (2r thick from the bottom plane, φ_k = solid volume in slab k / (A · 2r),
/// Sect. 5.2.1) add up to the monomers' volume. Slab edges cut monomers into spherical caps
/// whose parts add up exactly, so the only volume missing from Σ φ_k A 2r is what lies below
/// the bottom plane or above the last slab: caps computed here from the snapshot taken with the
/// profile (about 1e-8 of N V: the monomers on the floor overlap the plate by some δ₀,wall).
///
/// What is left is rounding: shortest round-trip decimals and µm conversions, some 1e-16 per
/// number over a few hundred terms; 1e-12 of N V allows for it.
#[test]
fn filling_factors_and_profiles_hold_the_monomer_volume() {
    let run = omni_run();
    let c = &run.curve;
    let v_total = MONOMERS as f64 * sphere(R_UM);
    let (gap, area, phi) = (
        c.column("wall_gap_um"),
        c.column("area_um2"),
        c.column("phi"),
    );
    let mut worst_phi = 0.0_f64;
    for k in 0..phi.len() {
        let expected = v_total / (area[k] * gap[k]);
        let rel = (phi[k] - expected) / expected;
        assert!(rel.abs() < 1e-12, "row {k}: phi {} vs {expected}", phi[k]);
        worst_phi = worst_phi.max(rel.abs());
    }
    eprintln!("phi = N V / (A h): worst relative error {worst_phi:.2e} (allowed 1e-12)");

    let steps = c.column("step");
    let pr = &run.profiles;
    let (p_step, z, slab_phi) = (pr.column("step"), pr.column("z_um"), pr.column("phi"));
    let thickness = 2.0 * R_UM;
    let rounding = 1e-12 * v_total;
    let mut worst = 0.0_f64;
    assert!(
        run.snapshots.len() >= 10,
        "{} snapshots",
        run.snapshots.len()
    );
    for s in &run.snapshots {
        let step = s.step as f64;
        let slabs: Vec<usize> = (0..p_step.len()).filter(|&i| p_step[i] == step).collect();
        assert!(!slabs.is_empty(), "a profile at step {step}");
        let row = steps.iter().position(|&t| t == step).unwrap();
        let bottom = z[slabs[0]] - 0.5 * thickness;
        for (j, &i) in slabs.iter().enumerate() {
            let centre = bottom + (j as f64 + 0.5) * thickness;
            assert!((z[i] - centre).abs() < 1e-9, "slab {j} at {} µm", z[i]);
        }
        let top = bottom + slabs.len() as f64 * thickness;
        assert!(top >= bottom + gap[row] - 1e-9, "slabs reach the top plate");
        let (b, _) = s.wall("bottom");
        assert!(
            (b[2] - bottom).abs() < 1e-9,
            "profile from the bottom plate"
        );
        let held: f64 = slabs
            .iter()
            .map(|&i| slab_phi[i] * area[row] * thickness)
            .sum();
        let outside = s.volume_outside(bottom, top);
        let error = v_total - outside - held;
        assert!(
            error.abs() <= rounding,
            "step {step}: slabs hold {held:.12e} µm³, N V {v_total:.12e} less caps \
             {outside:.6e} outside the slabs"
        );
        worst = worst.max(error.abs() / v_total);
    }
    eprintln!(
        "{} profiles: Σ φ A 2r + caps outside = N V to {worst:.2e} (allowed 1e-12)",
        run.snapshots.len()
    );
}
