//! Bad sweep files and out-of-range command-line values are refused (exit 2) naming the field,
//! and nothing is written.

use super::*;

/// Each bad sweep file is refused (exit 2) with a message naming the file's field, and
/// nothing is written.
#[test]
fn bad_sweep_files_are_refused_naming_the_field() {
    let dir = Scratch::new("sweep-bad");
    std::fs::write(dir.join("base.toml"), BASE).unwrap();
    let good_axes = "[axes]\nseed = [1]\n";
    let cases: &[(&str, &str)] = &[
        ("[axes]\nseed = [1]\n", "base = (missing) is not allowed"),
        (
            "base = \"nope.toml\"\n",
            "base = \"nope.toml\" is not allowed: no config file",
        ),
        ("base = 3\n", "base = 3 is not allowed"),
        (
            "base = \"base.toml\"\nspeed = 1\n",
            "speed = 1 is not allowed: unknown key",
        ),
        (
            "base = \"base.toml\"\n[axes]\nwall_speed_m_s = [1.0, 0.0]\n",
            "[axes] wall_speed_m_s = 0.0 is not allowed: each speed must be > 0",
        ),
        (
            "base = \"base.toml\"\n[axes]\nwall_speed_m_s = [1, 1.0]\n",
            "[axes] wall_speed_m_s = 1.0 is not allowed: appears twice",
        ),
        (
            "base = \"base.toml\"\n[axes]\nseed = [-1]\n",
            "[axes] seed = -1 is not allowed: each seed must be an integer ≥ 0",
        ),
        (
            "base = \"base.toml\"\n[axes]\nmonomers = [0]\n",
            "[axes] monomers = 0 is not allowed",
        ),
        (
            "base = \"base.toml\"\n[axes]\nmonomers = []\n",
            "[axes] monomers = [] is not allowed: must list at least one value",
        ),
        (
            "base = \"base.toml\"\n[axes]\ntemperature = [10]\n",
            "[axes] temperature = [10] is not allowed: unknown axis",
        ),
        (
            "base = \"base.toml\"\n[variants]\nmodified = { rolling_modifer = 8 }\n",
            "[variants] modified.rolling_modifer = 8 is not allowed: unknown config key",
        ),
        (
            "base = \"base.toml\"\n[variants]\nmodified = { model = { rolling = 8 } }\n",
            "[variants] modified.model.rolling = 8 is not allowed: unknown key of [model]",
        ),
        (
            "base = \"base.toml\"\n[variants]\nreseeded = { seed = 3 }\n",
            "[variants] reseeded.seed = 3 is not allowed: [sample] seed is set by [axes] seed",
        ),
        (
            "base = \"base.toml\"\n[variants]\n\"a b\" = {}\n",
            "[variants] a b = {} is not allowed: a variant's name",
        ),
        (
            "base = \"base.toml\"\n[variants]\nsoft = 3\n",
            "[variants] soft = 3 is not allowed: must be a table",
        ),
        (
            "base = \"base.toml\"\n[variants]\nnegative = { rolling_modifier = -1 }\n",
            "[model] rolling_modifier = -1 is not allowed",
        ),
        (
            "base = \"base.toml\"\n[variants]\nstiff = { sliding_modifier = 20 }\n",
            "(case v3.0_seed1_stiff_n200: base",
        ),
        (
            "base = \"base.toml\"\n[slurm]\ntime = \"1h\"\n",
            "[slurm] time = \"1h\" is not allowed",
        ),
        (
            "base = \"base.toml\"\n[slurm]\nnodes = 2\n",
            "[slurm] nodes = 2 is not allowed: unknown key",
        ),
        (
            "base = \"base.toml\"\n[slurm]\nsignal_lead_s = 5\n",
            "[slurm] signal_lead_s = 5 is not allowed: must be an integer between 10 and 65535",
        ),
        (
            "base = \"base.toml\"\n[slurm]\nrequeue = \"yes\"\n",
            "[slurm] requeue = \"yes\" is not allowed: must be true or false",
        ),
        ("base = \"base.toml\"\n[axes\n", "invalid sweep file"),
    ];
    for (k, (body, expected)) in cases.iter().enumerate() {
        let file = dir.join(format!("bad{k}.toml"));
        std::fs::write(&file, body).unwrap();
        let out = dir.join(format!("out{k}"));
        let result = run(&[
            "sweep",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--backend",
            "cpu",
        ]);
        let stderr = text(&result.stderr);
        assert_eq!(result.status.code(), Some(2), "{body}: {stderr}");
        assert!(
            stderr.contains(expected),
            "{body}\nexpected: {expected}\ngot: {stderr}"
        );
        assert!(
            stderr.contains(&format!("bad{k}.toml")),
            "names the file: {stderr}"
        );
        assert!(!out.exists(), "{body}: nothing is written");
    }
    // Command-line values out of range.
    let good = dir.join("good.toml");
    std::fs::write(&good, format!("base = \"base.toml\"\n{good_axes}")).unwrap();
    let out = dir.join("out-good");
    for (args, expected) in [
        (
            &["--case", "1"][..],
            "--case 1: out of range; this sweep has 1 cases, 0 to 0",
        ),
        (&["--jobs", "0"][..], "--jobs 0: out of range"),
        (
            &["--slurm", "--time", "1h"][..],
            "--time 1h: not a Slurm time limit",
        ),
    ] {
        let result = run(&[
            &[
                "sweep",
                good.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ][..],
            args,
        ]
        .concat());
        assert_eq!(result.status.code(), Some(2));
        assert!(
            text(&result.stderr).contains(expected),
            "{}",
            text(&result.stderr)
        );
        assert!(!out.exists());
    }
    let missing = run(&["sweep", "collect", dir.join("nowhere").to_str().unwrap()]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(text(&missing.stderr).contains("cases.csv"));
}
