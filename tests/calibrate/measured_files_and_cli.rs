//! Measured files: bad ones exit 2 naming file, field and value; the literature files load;
//! `dustdem synth` and `dustdem calibrate` end to end on the command line.

use super::*;
use std::process::Command;

fn dustdem(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .args(args)
        .output()
        .expect("dustdem runs")
}

/// `dustdem calibrate` on one measured file and a config, with `extra` arguments.
fn calibrate_cli(
    measured: &Path,
    config: &Path,
    out: &Path,
    extra: &[&str],
) -> std::process::Output {
    let mut args = vec![
        "calibrate",
        "--measured",
        measured.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    dustdem(&args)
}

#[test]
fn bad_measured_files_exit_2_naming_file_field_and_value() {
    let dir = Scratch::new("calibrate-bad");
    let good = "[[compression]]\ngeometry = \"omni\"\npressure_pa = [1e2, 1e3]\nphi = [0.15, 0.2]\nphi_sigma = 0.01\n";
    let cases = [
        (
            "missing",
            good.replace("phi = [0.15, 0.2]\n", ""),
            "phi",
            "(missing)",
        ),
        (
            "negative",
            good.replace("1e2, 1e3", "-1e2, 1e3"),
            "pressure_pa[0]",
            "-100",
        ),
        (
            "nan",
            good.replace("0.15, 0.2", "nan, 0.2"),
            "phi[0]",
            "NaN",
        ),
        ("unknown", format!("{good}colour = 3\n"), "colour", "colour"),
    ];
    let config = repo("configs/calibrate_quick.toml");
    for (name, text, field, value) in cases {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let out = calibrate_cli(&path, &config, &dir.join("out"), &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(path.to_str().unwrap()), "{name}: {err}");
        assert!(err.contains(field) && err.contains(value), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
    // A screen larger than the fit's samples is refused before anything runs.
    let path = dir.join("good.toml");
    std::fs::write(&path, good).unwrap();
    let out = calibrate_cli(
        &path,
        &config,
        &dir.join("out"),
        &["--screen-monomers", "500"],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("screen monomers: 500") && err.contains("(120)") && err.contains("0 (the"),
        "{err}"
    );
    assert!(
        !err.contains("panicked") && !err.contains("baseline"),
        "{err}"
    );
}

#[test]
fn synth_and_calibrate_from_the_command_line() {
    // Sticking only (cheap): synth writes data with stronger damping, calibrate finds it,
    // reports progress on stderr and writes the report, the PNG and the corrected config. The
    // same seeds give the same file.
    let dir = Scratch::new("calibrate-cli");
    let config = repo("configs/calibrate_quick.toml");
    let data = dir.join("data.toml");
    let synth = |out: &Path| {
        dustdem(&[
            "synth",
            "--config",
            config.to_str().unwrap(),
            "--effect",
            "normal_damping=1.5",
            "--geometry",
            "omni",
            "--seeds",
            "101",
            "--p-max",
            "1e3",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let out = synth(&data);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let again = dir.join("again.toml");
    assert!(synth(&again).status.success());
    let text = std::fs::read_to_string(&data).unwrap();
    assert_eq!(text, std::fs::read_to_string(&again).unwrap());
    assert!(!text.contains("damping"), "{text}");
    // Keep only the sticking velocity for the calibration.
    let mut m = MeasuredSet::load(&data).unwrap();
    m.compression.clear();
    let sticking = dir.join("sticking.toml");
    std::fs::write(&sticking, m.to_toml()).unwrap();
    let report = dir.join("report");
    // The same file twice: curves of several files are fitted jointly.
    let out = dustdem(&[
        "calibrate",
        "--measured",
        sticking.to_str().unwrap(),
        "--measured",
        sticking.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "--out",
        report.to_str().unwrap(),
        "--threads",
        "2",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("round 1: screen"), "{stderr}");
    // One sticking velocity ties damping with surface energy (see hidden_effects.rs,
    // one_sticking_velocity_cannot_tell_damping_from_surface_energy); either way the damping is
    // among the explanations and the corrected config changes the model.
    assert!(stdout.contains("normal_damping"), "{stdout}");
    for f in ["report.md", "calibration.png", "corrected.toml"] {
        assert!(report.join(f).is_file(), "{f}");
    }
    // A panel per sticking velocity (the file was given twice), no SVG without a compression
    // curve.
    let png = std::fs::read(report.join("calibration.png")).unwrap();
    let reader = png::Decoder::new(png.as_slice()).read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (2 * 560, 420));
    assert!(!report.join("curve_1.svg").exists());
    // The nominal best of the tie is applied: the corrected config differs from the base.
    let corrected = Config::load(&report.join("corrected.toml")).unwrap();
    assert_ne!(corrected, base(), "{stdout}");
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(
        md.contains("## Round 1") && md.contains("calibration.png"),
        "{md}"
    );
}

#[test]
fn literature_files_load_and_match_physics_md() {
    // The Eq. 13 fits sampled by the loader reproduce the tabulated values at both ends.
    for (file, lo, hi) in [
        ("configs/measured/guettler2009_omni.toml", 0.1581, 0.5626),
        (
            "configs/measured/blum_schraepler2004_uni.toml",
            0.1509,
            0.3298,
        ),
    ] {
        let m = MeasuredSet::load(&repo(file)).unwrap();
        let c = &m.compression[0];
        let (p_lo, p_hi) = c.pressure_range();
        assert!((p_lo / 1e2 - 1.0).abs() < 1e-12 && (p_hi / 1e6 - 1.0).abs() < 1e-12);
        let n = c.phi.len();
        assert!(
            (c.phi[0] - lo).abs() < 1e-4 && (c.phi[n - 1] - hi).abs() < 1e-4,
            "{file}"
        );
        assert!(!m.source.citation.is_empty() && !m.source.what.is_empty());
    }
    let poppe = MeasuredSet::load(&repo("configs/measured/poppe2000_sticking.toml")).unwrap();
    assert_eq!(poppe.sticking[0].velocity, 1.2);
}
