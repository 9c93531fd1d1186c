//! Bad sample files and checkpoints: each is refused with exit code 2, no panic, and a message
//! naming the file, the field or place, the value and what is allowed. (Bad configs are in
//! tests/cli.rs; the files live in tests/bad_inputs/.)

mod common;

use common::Scratch;
use std::path::Path;
use std::process::{Command, Output};

fn dustdem(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .args(args)
        .output()
        .unwrap()
}

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("bad-{name}"))
}

fn assert_refused(out: &Output, case: &str, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{case}: {stderr}");
    assert!(!stderr.contains("panicked"), "{case}: {stderr}");
    for n in needles {
        assert!(stderr.contains(n), "{case}: expected {n:?} in: {stderr}");
    }
}

#[test]
fn bad_sample_files_are_refused() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_inputs");
    let out = scratch("samples");
    let cases: &[(&str, &[&str])] = &[
        (
            "sample_wrong_version",
            &["line 1", "dustdem-sample 9", "dustdem-sample 1"],
        ),
        ("sample_truncated", &["truncated", "20 monomers"]),
        ("sample_nan", &["line 12", "NaN", "finite"]),
        (
            "sample_unknown_key",
            &["colour", "unknown key", "radius_cm"],
        ),
        ("sample_negative_radius", &["radius_cm", "-6e-5", "> 0"]),
        (
            "sample_outside_footprint",
            &["line 15", "footprint", "side_cm/2 - radius_cm"],
        ),
    ];
    for (name, needles) in cases {
        let config = dir.join(format!("{name}.toml"));
        let result = dustdem(&[
            "run",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ]);
        assert_refused(
            &result,
            name,
            &[&[&format!("{name}.txt")[..]][..], needles].concat(),
        );
    }
}

/// A valid checkpoint to spoil: a tiny run that checkpoints every row.
fn valid_checkpoint(dir: &Path) -> Vec<u8> {
    let config = dir.join("run.toml");
    std::fs::write(
        &config,
        "[sample]\nmonomers = 50\n[experiment]\nmax_steps = 300\n[output]\ncheckpoint_every_rows = 1\nsnapshot_format = \"none\"\n",
    )
    .unwrap();
    let out = dir.join("run");
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
    std::fs::read(out.join("checkpoint.bin")).unwrap()
}

#[test]
fn bad_checkpoints_are_refused() {
    let dir = scratch("checkpoints");
    let good = valid_checkpoint(&dir);
    let spoil = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = good.clone();
        f(&mut b);
        b
    };
    let cases: Vec<(&str, Vec<u8>, &[&str])> = vec![
        ("empty", Vec::new(), &["only 0 bytes", "truncated"]),
        (
            "not_a_checkpoint",
            b"[sample]\nmonomers = 3\n".repeat(4),
            &["wrong magic"],
        ),
        ("truncated", good[..good.len() / 2].to_vec(), &["truncated"]),
        (
            "wrong_version",
            spoil(&|b| b[16] = 7),
            &["version 7", "version 3", "newer"],
        ),
        (
            "old_version",
            spoil(&|b| b[16] = 2),
            &[
                "version 2",
                "older dustdem",
                "version 3",
                "re-run",
                "dustdem run",
            ],
        ),
        (
            "big_endian",
            spoil(&|b| b[12..16].reverse()),
            &["big-endian"],
        ),
        (
            "corrupt_body",
            spoil(&|b| {
                let k = b.len() - 100;
                b[k] ^= 0x40;
            }),
            &["checksum", "corrupt"],
        ),
    ];
    for (name, bytes, needles) in cases {
        let path = dir.join(format!("{name}.bin"));
        std::fs::write(&path, bytes).unwrap();
        let out = dustdem(&["resume", path.to_str().unwrap(), "--quiet"]);
        assert_refused(
            &out,
            name,
            &[&[&format!("{name}.bin")[..]][..], needles].concat(),
        );
    }
    let missing = dustdem(&["resume", dir.join("missing.bin").to_str().unwrap()]);
    assert_refused(&missing, "missing", &["missing.bin", "cannot read"]);
}

#[test]
fn a_blown_up_run_stops_naming_step_and_monomer_and_keeps_its_state() {
    let dir = scratch("blowup");
    let config = dir.join("unstable.toml");
    // Ten times the stability limit.
    std::fs::write(
        &config,
        "[sample]\nmonomers = 200\n[experiment]\nwall_speed_m_s = 20.0\nmax_steps = 200000\n[integration]\ndt_ns = 8.0\nallow_unstable_dt = true\n",
    )
    .unwrap();
    let out_dir = dir.join("out");
    let out = dustdem(&[
        "run",
        config.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_refused(
        &out,
        "blow-up",
        &["at step", "monomer", "checkpoint-failed.bin"],
    );
    assert!(!stderr.contains("no snapshot"), "{stderr}");
    assert!(out_dir.join("checkpoint-failed.bin").is_file(), "{stderr}");
    // The failed state as a VTU, named in the message, that a reader independent of ours
    // (vtkio) parses: 200 points, every point array complete, NaN and inf kept as they are.
    let failed: Vec<_> = std::fs::read_dir(out_dir.join("snapshots"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with("_failed.vtu"))
        .collect();
    assert_eq!(failed.len(), 1, "{failed:?}");
    assert!(stderr.contains(failed[0].to_str().unwrap()), "{stderr}");
    let vtk = vtkio::Vtk::import(&failed[0]).expect("the failed-state VTU parses");
    let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid");
    };
    let vtkio::model::Piece::Inline(piece) = &pieces[0] else {
        panic!("piece not inline");
    };
    assert_eq!(piece.points.len(), 3 * 200);
    for a in &piece.data.point {
        let vtkio::model::Attribute::DataArray(a) = a else {
            panic!("unexpected field attribute");
        };
        let per_point = a.data.len() / 200;
        assert!(per_point == 1 || per_point == 3, "{}", a.name);
        assert_eq!(a.data.len() % 200, 0, "{}", a.name);
    }
    // This blow-up leaves non-finite values behind, so the file shows how they are kept.
    let finite = piece.data.point.iter().find_map(|a| match a {
        vtkio::model::Attribute::DataArray(a) if a.name == "finite" => Some(&a.data),
        _ => None,
    });
    let Some(vtkio::model::IOBuffer::U8(finite)) = finite else {
        panic!("no UInt8 array `finite`: the blown-up state had no non-finite value?");
    };
    assert!(finite.contains(&0), "{finite:?}");
}

#[test]
fn snapshots_form_a_series_paraview_can_open() {
    let dir = scratch("snapshots");
    let config = dir.join("snap.toml");
    std::fs::write(
        &config,
        "[sample]\nmonomers = 100\n[experiment]\nmax_steps = 1000\n[output]\nsnapshot_format = \"both\"\nsnapshot_every_rows = 4\n",
    )
    .unwrap();
    let out_dir = dir.join("out");
    let out = dustdem(&[
        "run",
        config.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let snaps = out_dir.join("snapshots");
    let vtu: Vec<_> = std::fs::read_dir(&snaps)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.ends_with(".vtu"))
        .collect();
    // Start, rows 4 and 8, end (row 10).
    assert_eq!(vtu.len(), 4, "{vtu:?}");
    let pvd = std::fs::read_to_string(snaps.join("run.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 4);
    assert!(snaps.join("snap_0000001000.dump").is_file());
    let dump = std::fs::read_to_string(snaps.join("snap_0000001000.dump")).unwrap();
    assert!(dump.contains("ITEM: NUMBER OF ATOMS\n100\n"));
}
