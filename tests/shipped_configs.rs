//! Every run config shipped in configs/ loads and passes validation, and so does every sweep
//! file there (`sweep*.toml`, with every case's config); the measured-data files in
//! configs/measured/ are checked by tests/calibrate/.

use dustdem::config::Config;
use dustdem::sweep::Sweep;
use std::path::Path;

#[test]
fn every_shipped_config_loads() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let mut loaded = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with("sweep") {
                let sweep =
                    Sweep::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                // Builds and checks every case's config; writes nothing.
                let cases = sweep
                    .cases(Path::new("runs/shipped"))
                    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                assert_eq!(cases.len(), sweep.case_count());
            } else {
                Config::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            }
            loaded.push(name);
        }
    }
    loaded.sort();
    assert!(
        loaded.iter().any(|n| n == "guettler_benchmark.toml")
            && loaded.iter().any(|n| n == "sweep_example.toml")
            && loaded.len() >= 6,
        "{loaded:?}"
    );
}
