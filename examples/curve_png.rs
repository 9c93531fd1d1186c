//! Renders a run's compression curve as PNG, the bitmap twin of the run's `curve.svg` (same
//! chart, same code): `cargo run --release --example curve_png -- RUN_DIR [OUT.png]`.

use dustdem::config::Config;
use dustdem::job::curve_plot;
use dustdem::output::csv::read_csv;
use dustdem::output::plot::panels_png;
use dustdem::output::run_dir::{CONFIG_FILE, CURVE_FILE};
use std::path::PathBuf;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args.first().map(PathBuf::from) else {
        return Err("usage: curve_png RUN_DIR [OUT.png]".into());
    };
    let out = args
        .get(1)
        .map_or_else(|| dir.join("curve.png"), PathBuf::from);
    let config = Config::load(&dir.join(CONFIG_FILE)).map_err(|e| e.to_string())?;
    let (header, rows) = read_csv(dir.join(CURVE_FILE))?;
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or(name.to_string())
    };
    let (p, phi) = (column("p_top_pa")?, column("phi")?);
    // Every row in time order, as the run's own curve.svg is drawn from.
    let points: Vec<(f64, f64)> = rows.iter().map(|r| (r[p], r[phi])).collect();
    let png = panels_png(&[curve_plot(config.experiment.kind, &points)])?;
    std::fs::write(&out, png).map_err(|e| format!("{}: {e}", out.display()))?;
    println!("{}", out.display());
    Ok(())
}
