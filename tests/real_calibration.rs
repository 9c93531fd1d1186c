//! The committed real-data calibrations (docs/calibration/real/) rebuild byte for byte from
//! their committed run cache: `dustdem calibrate --cache-only` reads every run from it (a run
//! it lacks is an error, never simulated), so a change to the search, the fits, the decision
//! or the report that would change a committed answer fails here until the reports are
//! rebuilt (and the runs they need made) on purpose.

mod common;

use common::Scratch;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

const MEASURED: [&str; 3] = [
    "configs/measured/guettler2009_omni.toml",
    "configs/measured/blum_schraepler2004_uni.toml",
    "configs/measured/poppe2000_sticking.toml",
];

/// Each committed calibration: its directory, config, seeds, rounds, whether it is a plan, and
/// the first screen's sample size ("0": none).
const CASES: [(&str, &str, &str, &str, bool, &str); 7] = [
    (
        "n1000_v0p5",
        "configs/real_data_n1000_v0p5.toml",
        "1,2,3,4,5,6",
        "2",
        false,
        "0",
    ),
    (
        "n1000_v0p5",
        "configs/real_data_n1000_v0p5.toml",
        "1,2,3,4,5,6",
        "2",
        true,
        "0",
    ),
    (
        "n1000_v0p25",
        "configs/real_data_n1000_v0p25.toml",
        "1,2,3,4,5,6",
        "2",
        false,
        "0",
    ),
    (
        "n1000_v0p5_paper_fix",
        "configs/real_data_n1000_v0p5_paper_fix.toml",
        "1,2,3",
        "1",
        false,
        "0",
    ),
    (
        "n1000_v0p5_viscoelastic",
        "configs/real_data_n1000_v0p5_viscoelastic.toml",
        "1,2,3",
        "1",
        false,
        "0",
    ),
    (
        "n1000_v0p5_screen500",
        "configs/real_data_n1000_v0p5.toml",
        "1,2,3,4,5,6",
        "2",
        false,
        "500",
    ),
    (
        "n1000_v0p25_screen500",
        "configs/real_data_n1000_v0p25.toml",
        "1,2,3,4,5,6",
        "2",
        false,
        "500",
    ),
];

#[test]
fn the_committed_real_data_reports_rebuild_from_their_run_cache() {
    let scratch = Scratch::new("real-calibration");
    let cache = repo("docs/calibration/real/run_cache");
    for (k, (dir, config, seeds, rounds, plan, screen)) in CASES.into_iter().enumerate() {
        let out = scratch.join(format!("{k}_{dir}"));
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_dustdem"));
        cmd.current_dir(repo("")).arg("calibrate");
        for m in MEASURED {
            cmd.args(["--measured", m]);
        }
        cmd.args(["--config", config, "--seeds", seeds, "--rounds", rounds])
            .args(["--screen-monomers", screen])
            .arg("--out")
            .arg(&out)
            .arg("--cache")
            .arg(&cache)
            .arg("--cache-only")
            // The search these reports were made with: one range end screened, single
            // effects only (docs/calibration/real/README.md).
            .args(["--screen-upper-end-only", "--single-effects-only"]);
        if plan {
            cmd.arg("--plan");
        }
        let result = cmd.output().unwrap();
        assert!(
            result.status.success(),
            "{dir}: {}",
            String::from_utf8_lossy(&result.stderr)
        );
        let committed = repo("docs/calibration/real").join(dir);
        let compared = common::assert_rebuilt_as_committed(&out, &committed, dir);
        let expected = if plan { 1 } else { 5 };
        assert!(compared >= expected, "{dir}: {compared} files");
    }
}
