//! `dustdem bench`: the LAMMPS export (data file and deck) and the tables the command writes.
//! Small and fast; nothing here asserts a timing.

mod common;

use common::printed::{
    k_r_wall, k_s_wall, zeta_crit_wall, A0, F_C, F_C_WALL, G_STAR, K_R, K_S, POISSON, RADIUS,
    XI_CRIT, ZETA_CRIT,
};
use common::Scratch;
use dustdem::bench::prepare::{compressed_engine, gap_filling_factor, state_file};
use dustdem::bench::{benchmark_config, benchmark_engine, lammps};
use std::process::Command;

fn dustdem() -> Command {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
}

/// Every `pair_coeff` / `fix ... granular` number after `keyword`, by position.
fn after(line: &str, keyword: &str, count: usize) -> Vec<f64> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let at = words
        .iter()
        .position(|w| *w == keyword)
        .unwrap_or_else(|| panic!("no `{keyword}` in `{line}`"));
    words[at + 1..at + 1 + count]
        .iter()
        .map(|w| w.parse().unwrap_or_else(|_| panic!("`{w}` in `{line}`")))
        .collect()
}

fn close(a: f64, b: f64, what: &str) {
    // The printed constants carry six significant figures.
    assert!(
        (a - b).abs() <= 2e-5 * b.abs(),
        "{what}: deck {a:e}, expected {b:e}"
    );
}

fn export(n: usize) -> (Scratch, dustdem::sample::Sample) {
    let dir = Scratch::new("bench-export");
    let config = benchmark_config(n).unwrap();
    let (_, sample, walls) = benchmark_engine(&config).unwrap();
    lammps::export(&config, &sample, &walls, &dir).unwrap();
    (dir, sample)
}

#[test]
fn the_data_file_reads_back_the_positions_and_radius() {
    let (dir, sample) = export(200);
    let text = std::fs::read_to_string(dir.join(lammps::DATA)).unwrap();
    let count: usize = text
        .lines()
        .find(|l| l.ends_with(" atoms"))
        .and_then(|l| l.split_whitespace().next())
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(count, 200);
    let start = text.lines().position(|l| l.starts_with("Atoms")).unwrap();
    let atoms: Vec<Vec<f64>> = text
        .lines()
        .skip(start + 1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|w| w.parse().unwrap()).collect())
        .collect();
    assert_eq!(atoms.len(), 200);
    for (i, (atom, p)) in atoms.iter().zip(&sample.positions).enumerate() {
        // atom_style sphere: id type diameter density x y z.
        assert_eq!(atom[0], (i + 1) as f64);
        assert_eq!(atom[1], 1.0);
        assert_eq!(atom[2], 2.0 * RADIUS, "diameter");
        assert_eq!(atom[3], 2.65, "density");
        assert_eq!(
            [atom[4], atom[5], atom[6]],
            *p,
            "monomer {i}: exact round trip"
        );
    }
    // Every monomer inside the box LAMMPS is given.
    let bound = |name: &str| -> (f64, f64) {
        let l = text.lines().find(|l| l.ends_with(name)).unwrap();
        let w: Vec<f64> = l
            .split_whitespace()
            .take(2)
            .map(|w| w.parse().unwrap())
            .collect();
        (w[0], w[1])
    };
    for (axis, name) in ["xlo xhi", "ylo yhi", "zlo zhi"].iter().enumerate() {
        let (lo, hi) = bound(name);
        assert!(sample
            .positions
            .iter()
            .all(|p| p[axis] - RADIUS > lo && p[axis] + RADIUS < hi));
    }
}

#[test]
fn the_deck_has_the_coefficients_derived_by_hand() {
    let (dir, _) = export(200);
    let deck = std::fs::read_to_string(dir.join(lammps::DECK)).unwrap();
    let line = |start: &str| {
        deck.lines()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| panic!("no `{start}` line"))
            .to_string()
    };
    assert_eq!(line("pair_style"), "pair_style granular");
    assert_eq!(line("units"), "units cgs");
    assert_eq!(line("atom_style"), "atom_style sphere");
    assert_eq!(line("timestep"), "timestep 3.000000000e-10");
    // Skin 0.2 r.
    close(
        after(&line("neighbor"), "neighbor", 1)[0],
        0.2 * RADIUS,
        "skin",
    );

    // Monomer pairs: jkr E η ν γ with Table 1's E = 54 GPa, κ = 1e-6 g/s, ν, γ = 20 erg/cm².
    let pair = line("pair_coeff * *");
    assert!(pair.contains(" damping velocity "), "{pair}");
    assert!(pair.ends_with(" twisting marshall"), "{pair}");
    let jkr = after(&pair, "jkr", 4);
    close(jkr[0], 5.4e11, "E");
    close(jkr[1], 1e-6, "damping");
    close(jkr[2], POISSON, "nu");
    close(jkr[3], 20.0, "gamma");
    // mindlin k_t a = k_s at a = a₀: k_t = k_s/a₀ = 8 G*; μ_s = k_s ζ_crit / (2 F_c).
    let t = after(&pair, "mindlin", 3);
    close(t[0], 8.0 * G_STAR, "k_t");
    close(K_S / A0, 8.0 * G_STAR, "printed k_s / a0");
    assert_eq!(t[1], 0.0, "no tangential damping");
    close(t[2], K_S * ZETA_CRIT / (2.0 * F_C), "mu_s");
    // rolling sds: k_roll = k_r, μ_roll = k_r ξ_crit / (2 F_c).
    let r = after(&pair, "sds", 3);
    close(r[0], K_R, "k_roll");
    assert_eq!(r[1], 0.0);
    close(r[2], K_R * XI_CRIT / (2.0 * F_C), "mu_roll");

    // Walls: dmt with E/(1 + ν) (LAMMPS mixes E/(2(1 − ν)) there), caps over 2 × 4πγr =
    // 8/3 F_c,wall; the side walls weakened 1000×.
    let bottom = line("fix bottom");
    assert!(bottom.contains("wall/gran granular dmt "), "{bottom}");
    close(
        after(&bottom, "dmt", 1)[0],
        5.4e11 / (1.0 + POISSON),
        "wall E",
    );
    let cap = 8.0 / 3.0 * F_C_WALL;
    for (start, factor) in [("fix bottom", 1.0), ("fix top", 1.0), ("fix side_x", 1e-3)] {
        let wall = line(start);
        let t = after(&wall, "mindlin", 3);
        close(t[0], factor * k_s_wall() / common::printed::A0_WALL, start);
        close(t[2], factor * k_s_wall() * zeta_crit_wall() / cap, start);
        let r = after(&wall, "sds", 3);
        close(r[0], factor * k_r_wall(), start);
        close(r[2], factor * k_r_wall() * XI_CRIT / cap, start);
    }
    assert!(line("fix top").contains("wall/gran/region"));
    // The top wall moves at 1 m/s: 100 cm/s × 0.3 ns per step.
    let dz = line("variable top_dz");
    assert!(
        dz.starts_with("variable top_dz equal -3.000000000e-8*step"),
        "{dz}"
    );
    assert!(line("region top").contains("move NULL NULL v_top_dz units box"));
}

fn csv_header(path: &std::path::Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    header.split(',').map(str::to_string).collect()
}

#[test]
fn a_small_run_writes_both_tables() {
    let dir = Scratch::new("bench-run");
    let out = dir.join("tmp");
    let result = dustdem()
        .args([
            "bench",
            "--sizes",
            "200",
            "--seconds",
            "1",
            "--backends",
            "cpu",
            "--untallied",
        ])
        .args(["--rounds", "1", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(result.status.success(), "{stderr}");
    let md = std::fs::read_to_string(out.join("bench.md")).unwrap();
    assert!(
        md.contains("| N | sample | φ | contacts/monomer | cpu, 1 thread | cpu, all"),
        "{md}"
    );
    assert!(md.contains("| 200 |"), "{md}");
    assert!(md.contains("threads, corrections untallied |"), "{md}");
    assert!(md.contains("Cost per step"), "{md}");
    let header = csv_header(&out.join("bench.csv"));
    for column in [
        "n",
        "contacts_per_monomer",
        "cpu_t1_steps",
        "cpu_t1_rate",
        "cpu_all_rate",
        "cpu_all_untallied_rate",
        "peak_rss_mib",
        "cpu_t1_us_forces",
    ] {
        assert!(header.iter().any(|h| h == column), "{column}: {header:?}");
    }
    let text = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    let row: Vec<&str> = text.lines().last().unwrap().split(',').collect();
    assert_eq!(row.len(), header.len());
    for side in ["cpu_t1_rate", "cpu_all_untallied_rate"] {
        let rate: f64 = row[header.iter().position(|h| h == side).unwrap()]
            .parse()
            .unwrap();
        assert!(rate > 0.0, "{side} {rate}");
    }
}

#[test]
fn bad_arguments_name_the_argument_and_the_range() {
    let result = dustdem()
        .args(["bench", "--sizes", "200,3", "--out", "/nonexistent/never"])
        .output()
        .unwrap();
    assert_eq!(result.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("--sizes 200,3") && stderr.contains("10 to 10000000"),
        "{stderr}"
    );
}

#[test]
fn lammps_runs_the_deck_where_it_is_installed() {
    if lammps::run::on_path("lmp").is_none() {
        eprintln!("notice: LAMMPS test not run: `lmp` is not on PATH (apt-get install lammps)");
        return;
    }
    let dir = Scratch::new("bench-lammps");
    let out = dir.join("out");
    // `--out` relative to the working directory, as users type it: LAMMPS runs in the deck's
    // folder, so every path handed to it must be right from there.
    let result = dustdem()
        .args([
            "bench",
            "--sizes",
            "200",
            "--seconds",
            "0.5",
            "--backends",
            "cpu",
        ])
        .args([
            "--threads",
            "1",
            "--rounds",
            "1",
            "--lammps",
            "--out",
            "out",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(result.status.success(), "{stderr}");
    let header = csv_header(&out.join("bench.csv"));
    let text = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    let row: Vec<&str> = text.lines().last().unwrap().split(',').collect();
    let rate = row[header.iter().position(|h| h == "lammps_r1_rate").unwrap()];
    let rate: f64 = rate
        .parse()
        .unwrap_or_else(|_| panic!("no LAMMPS rate `{rate}`: {stderr}"));
    assert!(rate > 0.0);
    // The timed run's log: every atom still there, contacts present.
    let log = std::fs::read_to_string(out.join("lammps/n200/log.round1.r1.lammps")).unwrap();
    let run = lammps::parse_log(&log).unwrap();
    assert_eq!(run.atoms, 200);
    assert!(run.contacts_per_monomer.unwrap() > 0.5, "{run:?}");
    whole_runs_are_made(&out, &header, &row);
}

/// `bench --lammps`'s whole runs: both processes ran the same steps, whole rows of 100 and at
/// least the warm-up plus the CPU engine's measurement, and their rates are in bench.csv.
fn whole_runs_are_made(out: &std::path::Path, header: &[String], row: &[&str]) {
    let cell = |name: &str| row[header.iter().position(|h| h == name).unwrap()];
    let steps: u64 = cell("whole_run_steps").parse().unwrap();
    let measured: u64 =
        cell("warmup_steps").parse::<u64>().unwrap() + cell("cpu_t1_steps").parse::<u64>().unwrap();
    assert!(steps.is_multiple_of(100) && steps >= measured && steps < measured + 100);
    for name in ["whole_run_dustdem_rate", "whole_run_lammps_rate"] {
        assert!(cell(name).parse::<f64>().unwrap() > 0.0, "{name}");
    }
    let curve = std::fs::read_to_string(out.join("whole_run/n200/run/curve.csv")).unwrap();
    let last = curve.lines().last().unwrap();
    assert_eq!(last.split(',').next().unwrap(), steps.to_string());
    let logs: Vec<_> = std::fs::read_dir(out.join("lammps/n200"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().contains("log.whole1."))
        .collect();
    assert_eq!(logs.len(), 1, "{logs:?}");
    let run = lammps::parse_log(&std::fs::read_to_string(&logs[0]).unwrap()).unwrap();
    assert_eq!((run.steps, run.atoms), (steps, 200));
}

fn pool() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
}

#[test]
fn a_compressed_sample_reaches_its_filling_factor_and_is_stored_and_reused() {
    let dir = Scratch::new("bench-prepare");
    let config = benchmark_config(200).unwrap();
    let fresh = gap_filling_factor(&benchmark_engine(&config).unwrap().0);
    let quiet = |_: &str| {};
    let first = compressed_engine(&config, 0.2, 2.0, &pool(), &dir, &quiet).unwrap();
    let phi = gap_filling_factor(&first.engine);
    // One check every 200 steps of 3 nm wall travel: the target is passed by less than 0.005.
    assert!(
        fresh < 0.16 && (0.2..0.205).contains(&phi),
        "fresh {fresh}, prepared {phi}"
    );
    assert!(first.steps > 0 && !first.reused);
    assert_eq!(first.file, state_file(&dir, 200, 0.2, 2.0));
    // The measurement's wall goes on at the preparation's speed, 2 m/s.
    assert_eq!(first.engine.walls[1].velocity.z, -200.0);
    let again = compressed_engine(&config, 0.2, 2.0, &pool(), &dir, &quiet).unwrap();
    assert!(again.reused && again.steps == 0);
    assert_eq!(again.engine.walls[1].velocity.z, -200.0);
    assert_eq!(
        again.engine.monomers.position,
        first.engine.monomers.position
    );
    assert_eq!(again.engine.step, first.engine.step);
}

#[test]
fn a_denser_target_continues_from_a_stored_one_to_the_same_bits() {
    let (direct, chained) = (Scratch::new("bench-direct"), Scratch::new("bench-chained"));
    let config = benchmark_config(200).unwrap();
    let quiet = |_: &str| {};
    let a = compressed_engine(&config, 0.21, 2.0, &pool(), &direct, &quiet).unwrap();
    let low = compressed_engine(&config, 0.18, 2.0, &pool(), &chained, &quiet).unwrap();
    let b = compressed_engine(&config, 0.21, 2.0, &pool(), &chained, &quiet).unwrap();
    assert_eq!(
        b.steps,
        a.steps - low.steps,
        "the second target starts where the first ended"
    );
    assert_eq!(b.engine.step, a.engine.step);
    assert_eq!(b.engine.monomers.position, a.engine.monomers.position);
    assert_eq!(b.engine.monomers.velocity, a.engine.monomers.velocity);
    // A state prepared at another speed is not taken.
    let other = compressed_engine(&config, 0.21, 1.0, &pool(), &chained, &quiet).unwrap();
    assert!(!other.reused && other.steps > b.steps);
}

#[test]
fn a_compressed_state_exports_its_positions_velocities_and_walls() {
    let dir = Scratch::new("bench-export-state");
    let config = benchmark_config(200).unwrap();
    let quiet = |_: &str| {};
    let p = compressed_engine(&config, 0.2, 1.0, &pool(), &dir.join("states"), &quiet).unwrap();
    lammps::export_state(&config, &p.engine.state, &dir).unwrap();
    let text = std::fs::read_to_string(dir.join(lammps::DATA)).unwrap();
    let section = |name: &str| -> Vec<Vec<f64>> {
        let start = text.lines().position(|l| l.starts_with(name)).unwrap();
        text.lines()
            .skip(start + 2)
            .take_while(|l| !l.is_empty())
            .map(|l| l.split_whitespace().map(|w| w.parse().unwrap()).collect())
            .collect()
    };
    let (atoms, velocities) = (section("Atoms"), section("Velocities"));
    assert_eq!((atoms.len(), velocities.len()), (200, 200));
    let s = &p.engine.state;
    for i in [0, 77, 199] {
        assert_eq!(atoms[i][4..7], s.monomers.position[i].to_array());
        assert_eq!(velocities[i][0], (i + 1) as f64);
        assert_eq!(velocities[i][1..4], s.synchronized_velocity(i).to_array());
        assert_eq!(
            velocities[i][4..7],
            s.synchronized_angular_velocity(i).to_array()
        );
    }
    // The deck's top wall starts where the compressed state's is.
    let deck = std::fs::read_to_string(dir.join(lammps::DECK)).unwrap();
    let region = deck.lines().find(|l| l.starts_with("region top")).unwrap();
    let top: f64 = region.split_whitespace().nth(5).unwrap().parse().unwrap();
    // The deck writes ten significant digits.
    let z = s.walls[1].point.z;
    assert!((top - z).abs() <= 1e-9 * z, "{region}: {z}");
}
