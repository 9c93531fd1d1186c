//! `[output] tally_corrections = false`: the inelastic corrections' channels (rolling,
//! sliding, twisting, walls) are not booked, so the CPU engine skips their step energies.
//! What must hold: the trajectory and the other channels are the booked run's to the bit,
//! and the unbooked channels and the energy balance read NaN, in the rows a compression
//! writes too.

use dustdem::backend::cpu::CpuEngine;
use dustdem::bench::{benchmark_config, benchmark_engine};
use dustdem::config::Config;
use dustdem::engine::Engine;
use dustdem::experiment::compression::{Compression, Event};

/// The benchmark's fresh 600-monomer sample under walls at 1 m/s, 3000 steps.
fn pushed(tallied: bool) -> CpuEngine {
    let mut e = benchmark_engine(&benchmark_config(600).unwrap()).unwrap().0;
    if !tallied {
        e.stop_tallying_corrections();
    }
    e.run(3000).unwrap();
    e
}

fn bits(v: &[glam::DVec3]) -> Vec<[u64; 3]> {
    v.iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

#[test]
fn unbooked_corrections_leave_the_trajectory_and_the_other_channels_to_the_bit() {
    let (booked, unbooked) = (pushed(true), pushed(false));
    let (a, b) = (&booked.monomers, &unbooked.monomers);
    assert_eq!(bits(&a.position), bits(&b.position));
    assert_eq!(bits(&a.velocity), bits(&b.velocity));
    assert_eq!(bits(&a.angular_velocity), bits(&b.angular_velocity));
    assert_eq!(
        booked.contacts, unbooked.contacts,
        "pointers, twists, anchors"
    );
    let (ta, tb) = (booked.tally, unbooked.tally);
    // The booked run did correct contacts and walls, so the switch had work to skip.
    for (name, channel) in [("rolling", ta.rolling), ("sliding", ta.sliding)] {
        assert!(channel > 0.0, "booked {name} {channel}");
    }
    assert!(ta.walls != 0.0, "booked walls {}", ta.walls);
    for (name, channel) in [
        ("rolling", tb.rolling),
        ("sliding", tb.sliding),
        ("twisting", tb.twisting),
        ("walls", tb.walls),
    ] {
        assert!(channel.is_nan(), "unbooked {name} {channel}");
    }
    for (name, x, y) in [
        ("breaking", ta.breaking, tb.breaking),
        ("forming", ta.forming, tb.forming),
        ("damping", ta.damping, tb.damping),
    ] {
        assert_eq!(x.to_bits(), y.to_bits(), "{name}: {x} and {y}");
    }
    assert!(booked.energy().balance().is_finite());
    assert!(unbooked.energy().balance().is_nan());
}

#[test]
fn a_compression_with_the_key_off_writes_nan_in_the_unbooked_columns_only() {
    let config = Config::parse(
        "[sample]\nmonomers = 300\nseed = 3\n[experiment]\nkind = \"omni\"\n\
         wall_speed_m_s = 1.0\nmax_steps = 600\naverage_steps = 200\n\
         [output]\ntally_corrections = false\n",
        "unbooked",
    )
    .unwrap();
    let mut run = Compression::with_engine(&config, CpuEngine::new).unwrap();
    let mut rows = Vec::new();
    run.run(&mut |e| {
        if let Event::Row(r) = e {
            rows.push(r.values());
        }
        Ok(())
    })
    .unwrap();
    let columns = dustdem::experiment::compression::Row::HEADER;
    let unbooked = [
        "d_rolling_erg",
        "d_sliding_erg",
        "d_twisting_erg",
        "d_walls_erg",
        "energy_balance_erg",
    ];
    assert_eq!(rows.len(), 4, "rows at steps 0, 200, 400, 600");
    for (k, row) in rows.iter().enumerate() {
        for (name, value) in columns.iter().zip(row) {
            if unbooked.contains(name) {
                assert!(value.is_nan(), "row {k}: {name} = {value}");
            } else if k > 0 {
                // (The first row has no averaged pressure yet.)
                assert!(!value.is_nan(), "row {k}: {name} = {value}");
            }
        }
    }
}

/// The device engine still evaluates the corrections' energies, but reports their channels
/// NaN once told, and a CPU state whose channels are NaN resumes on it unbooked.
#[test]
fn the_device_engine_reports_the_unbooked_channels_nan_too() {
    use dustdem::backend::gpu::context::context_for_tests;
    use dustdem::backend::gpu::engine::GpuEngine;
    let Some(ctx) = context_for_tests() else {
        return;
    };
    let mut cpu = benchmark_engine(&benchmark_config(300).unwrap()).unwrap().0;
    cpu.run(300).unwrap();
    let mut gpu = GpuEngine::resume(ctx, &cpu.state).unwrap();
    gpu.advance(300).unwrap();
    let booked = gpu.energy().dissipated;
    assert!(booked.rolling > 0.0, "{booked:?}");
    gpu.stop_tallying_corrections();
    gpu.advance(300).unwrap();
    let unbooked = gpu.energy().dissipated;
    for channel in [
        unbooked.rolling,
        unbooked.sliding,
        unbooked.twisting,
        unbooked.walls,
    ] {
        assert!(channel.is_nan(), "{unbooked:?}");
    }
    assert!(unbooked.damping > booked.damping, "{unbooked:?}");
    let resumed = GpuEngine::resume(context_for_tests().unwrap(), &gpu.state()).unwrap();
    assert!(resumed.energy().dissipated.sliding.is_nan());
}
