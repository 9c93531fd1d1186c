//! The command line end to end: a small compression run, the other subcommands, and bad input.

mod common;

use common::Scratch;
use std::path::Path;
use std::process::{Command, Output, Stdio};

fn dustdem(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .args(args)
        .output()
        .expect("dustdem runs")
}

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("cli-{name}"))
}

fn column(header: &[String], rows: &[Vec<f64>], name: &str) -> Vec<f64> {
    let k = header.iter().position(|h| h == name).unwrap();
    rows.iter().map(|r| r[k]).collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[test]
fn small_omnidirectional_run_writes_its_curve() {
    let dir = scratch("omni");
    let config = dir.join("omni.toml");
    std::fs::write(
        &config,
        "[sample]\nmonomers = 1000\nseed = 3\n[experiment]\nkind = \"omni\"\nwall_speed_m_s = 1.0\nphi_stop = 0.5\n",
    )
    .unwrap();
    let out = dir.join("out");
    let run = dustdem(&[
        "run",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains("filling factor reached phi_stop"),
        "{stdout}"
    );
    for f in ["curve.csv", "profiles.csv", "curve.svg", "config.toml"] {
        assert!(out.join(f).is_file(), "{f} written");
    }
    let (header, rows) = dustdem::output::csv::read_csv(out.join("curve.csv")).unwrap();
    assert!(rows.len() > 100);
    let phi = column(&header, &rows, "phi");
    let gap = column(&header, &rows, "wall_gap_um");
    let area = column(&header, &rows, "area_um2");
    let pressure = column(&header, &rows, "p_top_pa");
    // φ = N (4/3)πr³ / (A h) with the box base and the wall gap, exactly.
    let v = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.6f64.powi(3);
    for k in 0..rows.len() {
        assert!((phi[k] - v / (area[k] * gap[k])).abs() < 1e-12 * phi[k]);
    }
    // The wall gap closes at 1 m/s: 100 steps of 0.3 ns = 3e-2 µm per row.
    assert!((gap[1] - gap[2] - 0.03).abs() < 1e-9);
    assert!(*phi.last().unwrap() >= 0.5);
    // Pressure is positive and rises over the run.
    let n = pressure.len();
    let early = median(pressure[1..n / 10].to_vec());
    let late = median(pressure[n - n / 10..].to_vec());
    eprintln!("median P early {early:.3e} Pa, late {late:.3e} Pa");
    assert!(early >= 0.0 && late > 0.0 && late > 10.0 * early.max(1.0));
    let final_rows = &pressure[n - 5..];
    assert!(final_rows.iter().all(|&p| p > 0.0), "{final_rows:?}");
    // Same seed, same run: the sample and hence the first rows are identical.
    let fit = dustdem(&[
        "fit",
        out.join("curve.csv").to_str().unwrap(),
        "--phi1",
        "0.12",
        "--phi2",
        "0.58",
    ]);
    assert!(
        fit.status.success(),
        "{}",
        String::from_utf8_lossy(&fit.stderr)
    );
    assert!(String::from_utf8_lossy(&fit.stdout).contains("p_m"));
}

#[test]
fn generate_writes_a_reproducible_sample_and_info_prints_constants() {
    let dir = scratch("generate");
    let (a, b) = (dir.join("a.txt"), dir.join("b.txt"));
    for path in [&a, &b] {
        let out = dustdem(&["generate", "--out", path.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let info = dustdem(&["info"]);
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(info.status.success());
    for needle in [
        "a0 1.223268e-6",
        "F_c 5.654867e-3",
        "JKR loop 11.0059 cm/s",
        "Chokshi 7.1832 cm/s",
    ] {
        assert!(text.contains(needle), "info lacks {needle}:\n{text}");
    }
}

#[test]
fn built_in_configs_parse_and_the_collision_config_runs() {
    for name in ["omni_quick", "uni_quick", "two_monomers"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("configs")
            .join(format!("{name}.toml"));
        dustdem::config::Config::load(&path).unwrap_or_else(|e| panic!("{e}"));
    }
    let dir = scratch("collision");
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/two_monomers.toml");
    let out = dustdem(&[
        "run",
        config.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("stuck"));
}

/// Each bad config: exit code 2, no panic, a message naming what is wrong and what is allowed.
#[test]
fn bad_configs_are_refused_with_a_clear_message() {
    let cases: &[(&str, &[&str])] = &[
        ("unknown_key", &["unknown field `colour`", "radius_um"]),
        ("wrong_type", &["monomers", "invalid type"]),
        ("negative_radius", &["[material] radius_um = -0.6", "> 0"]),
        (
            "nan_surface_energy",
            &["surface_energy_mj_m2 = NaN", "finite"],
        ),
        (
            "dt_too_large",
            &[
                "[integration] dt_ns = 5",
                "stability limit",
                "allow_unstable_dt",
            ],
        ),
        ("missing_sample_file", &["does_not_exist.sample"]),
        (
            "phi_stop_too_high",
            &["phi_stop = 0.9", "between 0 and 0.75"],
        ),
        ("negative_kappa", &["kappa", "-0.000001", "≥ 0"]),
        (
            "unknown_experiment",
            &["unknown variant `sideways`", "omni"],
        ),
        ("malformed", &["invalid config"]),
        (
            "poisson_out_of_range",
            &["poisson_ratio = 0.7", "between -1 and 0.5"],
        ),
        ("omni_cylinder", &["cylinder", "box"]),
        ("cut_from_file", &["[sample] top", "\"rough\""]),
    ];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_inputs");
    let out_dir = scratch("bad");
    for (name, needles) in cases {
        let path = dir.join(format!("{name}.toml"));
        let out = dustdem(&[
            "run",
            path.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--quiet",
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
        assert!(
            stderr.contains(&format!("{name}.toml")) || *name == "missing_sample_file",
            "{name} names the file: {stderr}"
        );
        for needle in *needles {
            assert!(
                stderr.contains(needle),
                "{name}: expected {needle:?} in: {stderr}"
            );
        }
    }
    let missing = dustdem(&["run", "no/such/config.toml"]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("no/such/config.toml"));
}

/// Nothing on stderr that looks like an error of ours where `XDG_RUNTIME_DIR` is unset: the
/// adapter probe (`run --backend auto`, `info`) keeps the Vulkan libraries quiet, and
/// `run --backend cpu` does not probe at all. Each command runs once with no Wayland display
/// named and once with a name that does not exist (Mesa's device-select layer then tries to
/// connect, which is what prints `error: XDG_RUNTIME_DIR is invalid or not set` otherwise).
/// The private runtime directory the probe used is gone when the process has exited.
#[test]
fn no_stray_error_lines_without_a_runtime_dir() {
    let dir = scratch("quiet");
    let config = dir.join("tiny.toml");
    std::fs::write(
        &config,
        "[sample]\nmonomers = 50\n[experiment]\nmax_steps = 300\n[output]\nsnapshot_format = \"none\"\n",
    )
    .unwrap();
    let mut k = 0;
    for display in [None, Some("dustdem-no-such-display")] {
        for backend in ["cpu", "auto", "info"] {
            k += 1;
            let out = dir.join(format!("out-{k}"));
            let args: Vec<&str> = match backend {
                "info" => vec!["info"],
                b => vec![
                    "run",
                    config.to_str().unwrap(),
                    "--backend",
                    b,
                    "--quiet",
                    "--out",
                    out.to_str().unwrap(),
                ],
            };
            let mut command = Command::new(env!("CARGO_BIN_EXE_dustdem"));
            command
                .args(&args)
                .env_remove("XDG_RUNTIME_DIR")
                .stdout(Stdio::piped())
                .stderr(Stdio::piped());
            match display {
                Some(name) => command.env("WAYLAND_DISPLAY", name),
                None => command.env_remove("WAYLAND_DISPLAY"),
            };
            let child = command.spawn().expect("dustdem runs");
            let pid = child.id();
            let result = child.wait_with_output().unwrap();
            let stderr = String::from_utf8_lossy(&result.stderr);
            let case = format!("{args:?} with WAYLAND_DISPLAY {display:?}");
            assert!(result.status.success(), "{case}: {stderr}");
            let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
            assert!(errors.is_empty(), "{case}: {errors:?}");
            let runtime = std::env::temp_dir().join(format!("dustdem-runtime-{pid}"));
            assert!(
                !runtime.exists(),
                "{case}: {} left behind",
                runtime.display()
            );
        }
    }
}
