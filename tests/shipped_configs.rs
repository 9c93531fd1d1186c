//! Every run config shipped in configs/ loads and passes validation (the measured-data files in
//! configs/measured/ are checked by tests/calibrate.rs).

use dustdem::config::Config;
use std::path::Path;

#[test]
fn every_shipped_config_loads() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let mut loaded = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            Config::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            loaded.push(path.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    loaded.sort();
    assert!(
        loaded.iter().any(|n| n == "guettler_benchmark.toml") && loaded.len() >= 5,
        "{loaded:?}"
    );
}
