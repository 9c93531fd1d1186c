//! The compaction front of one run directory's `profiles.csv`, read as `sweep analyze` reads
//! each dynamic case (Seizinger et al. 2012, Sect. 5.2): the front's speed from a line through
//! its heights (with the wall's), and the speed the mass balance of the dense layer requires.
//! For a single long run that is not part of a sweep, such as a 10⁶-monomer one.
//!
//! Run: `cargo run --release --example front_speed -- RUN_DIR WALL_SPEED_M_S`.

use dustdem::analysis::front::{front_heights, mass_balance_front, run_front_speed, FrontOptions};
use dustdem::analysis::run_files::read_run_profiles;
use std::path::PathBuf;

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let usage = "usage: front_speed RUN_DIR WALL_SPEED_M_S";
    let dir = PathBuf::from(args.next().ok_or(usage)?);
    let v_wall: f64 = args
        .next()
        .ok_or(usage)?
        .parse()
        .map_err(|e| format!("WALL_SPEED_M_S: {e}"))?;
    let profiles = read_run_profiles(&dir)?;
    let opt = FrontOptions::default();
    let points = front_heights(&profiles, &opt);
    println!(
        "profiles: {}, front found in {}",
        profiles.len(),
        points.len()
    );
    if let (Some(first), Some(last)) = (points.first(), points.last()) {
        println!(
            "front: {:.2} um at {:.3e} s -> {:.2} um at {:.3e} s",
            first.front_m * 1e6,
            first.time_s,
            last.front_m * 1e6,
            last.time_s
        );
    }
    match run_front_speed(&profiles, &opt) {
        Some(s) => {
            println!(
                "front speed: {:.3} +- {:.3} m/s ({} points), {:.3} times the wall",
                s.front.v,
                s.front.std_err,
                s.front.points,
                s.front.v / v_wall
            );
            if let Some(w) = s.wall {
                println!(
                    "wall speed read the same way: {:.3} +- {:.3} m/s",
                    w.v, w.std_err
                );
            }
        }
        None => println!("front speed: none (too few profiles with a front)"),
    }
    match mass_balance_front(&profiles, &opt, v_wall) {
        Some((phi_layer, v_p)) => {
            println!("mass balance: dense layer phi {phi_layer:.4}, front speed {v_p:.3} m/s")
        }
        None => println!("mass balance: none (the front is not yet in the middle half)"),
    }
    Ok(())
}
