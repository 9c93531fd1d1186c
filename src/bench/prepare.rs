//! Compressed benchmark samples: the benchmark's fresh RBD sample compressed by the engine
//! itself (the top wall at the preparation speed) until the wall gap's filling factor reaches
//! the target, then handed to the measurement with the top wall still at that speed. Most
//! of a quasi-static run's steps are spent at φ 0.3–0.5 with four to six contacts per monomer,
//! not at the fresh sample's φ ≈ 0.13 with two; this is the state those steps start from.
//!
//! A prepared state is stored (`<out>/states/n<N>_phi<φ>_v<speed>.state`, the checkpoint
//! container with a key naming how it was made), so later benchmarks reuse it; a file whose key
//! differs is prepared again.

use super::options::{Options, SampleState};
use super::{benchmark_engine, lammps};
use crate::backend::cpu::CpuEngine;
use crate::binary::{Decoder, Encoder};
use crate::config::Config;
use crate::output::checkpoint::{read_checkpoint, write_checkpoint};
use crate::state::State;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Index of the top wall in the benchmark's walls (bottom, top, then the four side walls).
const TOP: usize = 1;
/// Steps between two checks of the filling factor.
const CHUNK: u64 = 200;
/// Stored in every prepared file: a change of this module's procedure changes it.
const FORMAT: &str = "dustdem bench prepared state 1";

/// The engine a measurement starts from (before its warm-up), with the LAMMPS export of the
/// same state where asked for; a compressed state's preparation is noted in `notes`.
pub fn starting_engine(
    config: &Config,
    sample: SampleState,
    options: &Options,
    pool: &rayon::ThreadPool,
    lammps_dir: &std::path::Path,
    notes: &mut Vec<String>,
    progress: &dyn Fn(&str),
) -> Result<CpuEngine, String> {
    if options.lammps {
        std::fs::create_dir_all(lammps_dir)
            .map_err(|e| format!("{}: {e}", lammps_dir.display()))?;
    }
    match sample {
        SampleState::Fresh => {
            let (engine, sample, walls) = benchmark_engine(config)?;
            if options.lammps {
                lammps::export(config, &sample, &walls, lammps_dir)?;
            }
            Ok(engine)
        }
        SampleState::Compressed { phi } => {
            let speed = options.prepare_speed_m_s;
            let states = options.out.join("states");
            let p = compressed_engine(config, phi, speed, pool, &states, progress)?;
            let n = config.sample.monomers;
            notes.push(if p.reused {
                format!(
                    "N = {n}, φ {phi}: the compressed state stored in {}",
                    p.file.display()
                )
            } else {
                format!(
                    "N = {n}, φ {phi}: compressed at {speed} m/s in {} steps ({:.0} s), stored \
                     in {}",
                    p.steps,
                    p.seconds,
                    p.file.display()
                )
            });
            if options.lammps {
                let mut at_speed = config.clone();
                at_speed.experiment.wall_speed_m_s = speed;
                lammps::export_state(&at_speed, &p.engine.state, lammps_dir)?;
            }
            Ok(p.engine)
        }
    }
}

/// A compressed starting state and how it was reached.
pub struct Prepared {
    pub engine: CpuEngine,
    /// Steps the preparation ran (0 where the stored state was reused).
    pub steps: u64,
    pub seconds: f64,
    pub file: PathBuf,
    pub reused: bool,
}

/// Filling factor by the wall gap: N monomer volumes over the box between the bottom and top
/// walls and the side walls (x- and x+, y- and y+ are walls 2–5).
pub fn gap_filling_factor(state: &State) -> f64 {
    let w = &state.walls;
    assert!(w.len() == 6, "the benchmark's omni box has six walls");
    let gap = (w[TOP].point - w[0].point).dot(w[0].normal);
    let side_x = (w[3].point - w[2].point).dot(w[2].normal);
    let side_y = (w[5].point - w[4].point).dot(w[4].normal);
    let r = state.law.radius;
    let volume = 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    state.monomers.len() as f64 * volume / (gap * side_x * side_y)
}

/// Steps in which the top wall travels `share` of the gap between bottom and top (at least
/// one).
pub fn steps_to_travel(state: &State, share: f64) -> u64 {
    let w = &state.walls;
    let gap = (w[TOP].point - w[0].point).dot(w[0].normal);
    let per_step = w[TOP].velocity.length() * state.dt;
    ((share * gap / per_step.max(f64::MIN_POSITIVE)) as u64).max(1)
}

/// The file a prepared state is stored in.
pub fn state_file(dir: &Path, n: usize, phi: f64, speed_m_s: f64) -> PathBuf {
    dir.join(format!("n{n}_phi{phi:.3}_v{speed_m_s}.state"))
}

/// The file a preparation stores its progress in (every [`SAVE_EVERY`]).
fn progress_file(dir: &Path, n: usize, speed_m_s: f64) -> PathBuf {
    dir.join(format!("n{n}_progress_v{speed_m_s}.state"))
}

/// Wall-clock interval between two saves of a preparation's progress.
const SAVE_EVERY: std::time::Duration = std::time::Duration::from_secs(600);

/// What a stored state must have been made from: the format and the benchmark config with the
/// preparation speed as its wall speed.
fn key(at_speed: &Config) -> Result<String, String> {
    let text = toml::to_string(at_speed).map_err(|e| e.to_string())?;
    Ok(format!("{FORMAT}\n{text}"))
}

/// The densest stored state of this preparation below `phi` (a lower target or a saved
/// progress), so a higher target continues from it instead of starting again.
fn densest_below(
    dir: &Path,
    n: usize,
    speed_m_s: f64,
    phi: f64,
    key: &str,
    config: &Config,
) -> Option<State> {
    let prefix = format!("n{n}_");
    let suffix = format!("_v{speed_m_s}.state");
    let names = std::fs::read_dir(dir).ok()?;
    names
        .filter_map(|e| e.ok())
        .filter(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            name.starts_with(&prefix) && name.ends_with(&suffix)
        })
        .filter_map(|e| load(&e.path(), key, config).ok())
        .filter(|s| gap_filling_factor(s) <= phi)
        .max_by(|a, b| a.step.cmp(&b.step))
}

/// The benchmark's sample (`config`, whose wall speed the measurement uses) compressed to
/// filling factor `phi` at `speed_m_s`, from `dir` if stored there, else prepared on `pool`
/// (from the densest stored state of the same preparation below `phi`, if any) and stored.
/// The top wall keeps moving at `speed_m_s`: a compressed sample that a wall suddenly pushes
/// faster than the critical speed (≈ 0.7–0.9 m/s) is shaken apart within a few hundred steps
/// (at 0.05 m/s to φ 0.3 and then 1 m/s, 1000 monomers lost two thirds of their contacts in
/// 500 steps), which is not the state a quasi-static run spends its steps in.
pub fn compressed_engine(
    config: &Config,
    phi: f64,
    speed_m_s: f64,
    pool: &rayon::ThreadPool,
    dir: &Path,
    progress: &dyn Fn(&str),
) -> Result<Prepared, String> {
    let n = config.sample.monomers;
    let file = state_file(dir, n, phi, speed_m_s);
    let mut at_speed = config.clone();
    at_speed.experiment.wall_speed_m_s = speed_m_s;
    let key = key(&at_speed)?;
    if file.exists() {
        match load(&file, &key, config) {
            Ok(state) => {
                return Ok(Prepared {
                    engine: CpuEngine::from_state(state),
                    steps: 0,
                    seconds: 0.0,
                    file,
                    reused: true,
                })
            }
            Err(why) => progress(&format!("{}: prepared again: {why}", file.display())),
        }
    }
    let clock = Instant::now();
    let mut engine = match densest_below(dir, n, speed_m_s, phi, &key, config) {
        Some(state) => CpuEngine::from_state(state),
        None => benchmark_engine(&at_speed)?.0,
    };
    let start = gap_filling_factor(&engine);
    if engine.step == 0 && start >= phi {
        return Err(format!(
            "--samples {phi}: the fresh sample of {n} monomers already has φ = {start:.3} by its \
             wall gap; ask for a higher filling factor"
        ));
    }
    let first_step = engine.step;
    let mut reported = start;
    let mut saved = Instant::now();
    while gap_filling_factor(&engine) < phi {
        pool.install(|| engine.run(CHUNK))
            .map_err(|e| format!("preparing φ = {phi}: {e}"))?;
        let now = gap_filling_factor(&engine);
        if now - reported >= 0.01 {
            let contacts = 2.0 * engine.contacts.pair_contact_count() as f64 / n as f64;
            progress(&format!(
                "N = {n}: compressing to φ {phi} at {speed_m_s} m/s: φ {now:.3}, {contacts:.2} \
                 contacts per monomer at step {}, {:.0} s",
                engine.step,
                clock.elapsed().as_secs_f64()
            ));
            reported = now;
        }
        if saved.elapsed() >= SAVE_EVERY {
            store(&progress_file(dir, n, speed_m_s), &key, &engine.state)?;
            saved = Instant::now();
        }
    }
    store(&file, &key, &engine.state)?;
    Ok(Prepared {
        steps: engine.step - first_step,
        engine,
        seconds: clock.elapsed().as_secs_f64(),
        file,
        reused: false,
    })
}

fn store(file: &Path, key: &str, state: &State) -> Result<(), String> {
    if let Some(dir) = file.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let mut e = Encoder::default();
    e.bytes_with_len(key.as_bytes());
    state.encode(&mut e);
    write_checkpoint(file, &e.bytes).map_err(|e| format!("{}: {e}", file.display()))
}

fn load(file: &Path, key: &str, config: &Config) -> Result<State, String> {
    let body = read_checkpoint(file).map_err(|e| e.to_string())?;
    let mut d = Decoder::new(&body);
    let stored = d.bytes_with_len("key").map_err(|e| e.to_string())?;
    if stored != key.as_bytes() {
        return Err("made from another config or speed".into());
    }
    let state = State::decode(config.contact_law(), &mut d).map_err(|e| e.to_string())?;
    if d.remaining() != 0 {
        return Err(format!(
            "{} unexpected bytes after the state",
            d.remaining()
        ));
    }
    Ok(state)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::benchmark_config;
    use glam::DVec3;

    #[test]
    fn the_gap_filling_factor_is_the_monomer_volume_over_the_box() {
        let config = benchmark_config(200).unwrap();
        let (engine, _, _) = benchmark_engine(&config).unwrap();
        let mut state = engine.state;
        // A box 10 µm a side: bottom at z = 1 µm, top at 11 µm, sides at ±5 µm.
        let um = 1e-4;
        state.walls[0].point = DVec3::new(3.0, -2.0, 1.0 * um);
        state.walls[TOP].point = DVec3::new(0.0, 0.0, 11.0 * um);
        for (w, x) in [(2, -5.0), (3, 5.0)] {
            state.walls[w].point = DVec3::new(x * um, 7.0, 0.0);
        }
        for (w, y) in [(4, -5.0), (5, 5.0)] {
            state.walls[w].point = DVec3::new(-1.0, y * um, 0.0);
        }
        // 200 × (4/3)π (0.6 µm)³ / (10 µm)³, by hand: 200 × 0.904779 / 1000.
        let expected = 0.180_955_7;
        let phi = gap_filling_factor(&state);
        assert!(
            (phi - expected).abs() < 1e-7,
            "φ {phi}, expected {expected}"
        );
    }
}
