//! Rows without full readbacks: the row kernels (shaders/passes/rows.wgsl) against their CPU
//! twins (src/state/rows.rs), both backends' rows and profiles to the bit, and the bytes one
//! row reads back from the device, which must not grow with N.

use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::backend::gpu::layout::{ROW_PARTIALS, ROW_RESULTS, ROW_SUMS};
use dustdem::backend::gpu::shader::FloatMode;
use dustdem::config::Config;
use dustdem::engine::Engine;
use dustdem::experiment::compression::{Compression, Event, Row};
use dustdem::state::rows::{row_sums, row_sums_final, RowRequest, Slabs};
use dustdem::state::{EnergyReport, State};

/// A uni compression of `n` monomers (a cylinder between plates: wall contacts on two plates,
/// a projected area that changes), stopped after `steps`.
fn uni(n: usize, steps: u64, profile_every: u64) -> Config {
    let text = format!(
        "[sample]\nmonomers = {n}\nfootprint = \"cylinder\"\nseed = 2\n[experiment]\n\
         kind = \"uni\"\nwall_speed_m_s = 5.0\nphi_stop = 0.7\nmax_steps = {steps}\n\
         average_steps = 100\nprofile_every_rows = {profile_every}\n\
         [integration]\ndt_ns = 0.3\n"
    );
    Config::parse(&text, "test").unwrap()
}

/// The state of a uni run of `n` monomers after `steps` steps on the CPU: contacts between
/// monomers and with both plates, monomers moving and spinning.
fn compressed(n: usize, steps: u64) -> State {
    let mut run = Compression::with_engine(&uni(n, steps, 0), CpuEngine::new).unwrap();
    run.run(&mut |_| Ok(())).unwrap();
    run.engine.state().into_owned()
}

#[test]
fn row_kernels_match_their_cpu_twins_to_the_bit() {
    let Some(ctx) = context_for_tests() else {
        return;
    };
    let exact = ctx.float_mode == FloatMode::Exact;
    // 300 monomers: five blocks, the last one partial.
    let state = compressed(300, 2000);
    let (pairs, walls) = (
        state.contacts.pair_contact_count(),
        state.contacts.wall_contact_count(),
    );
    assert!(
        pairs > 100 && walls > 10,
        "{pairs} pair, {walls} wall contacts"
    );
    let r = state.law.radius;
    let top = state.walls[1].point.z;
    let request = RowRequest {
        slabs: Some(Slabs::between(state.walls[0].point.z, top, 2.0 * r)),
        projected_area: true,
    };
    let cpu = state.row_measures(&request);
    let mut gpu = GpuEngine::resume(ctx, &state).unwrap();
    let device = gpu.row_measures(&request).unwrap();
    // The blocks of row_sums, then row_sums_final.
    let blocks = row_sums(&state);
    let data = gpu.row_data();
    let device_blocks: Vec<f64> = data[ROW_PARTIALS..].to_vec();
    let twin_blocks: Vec<f64> = blocks.iter().flatten().copied().collect();
    let final_twin = row_sums_final(&blocks);
    let final_device = &data[ROW_RESULTS..ROW_RESULTS + ROW_SUMS];
    eprintln!(
        "energies cpu {:?} gpu {:?}; area {:?} {:?}; {} slabs",
        &final_twin[..4],
        &final_device[..4],
        cpu.projected_area,
        device.projected_area,
        cpu.slab_volumes.len()
    );
    assert!(cpu.slab_volumes.len() > 5);
    assert!(
        final_twin.iter().take(4).all(|&e| e != 0.0),
        "motion, spin and contacts all hold energy"
    );
    if exact {
        assert_eq!(device_blocks, twin_blocks, "row_sums");
        assert_eq!(final_device, &final_twin[..], "row_sums_final");
        assert_eq!(
            device, cpu,
            "row_profile, row_profile_final, row_raster, row_area"
        );
    } else {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()) + 1e-30;
        for (a, b) in final_device.iter().zip(&final_twin) {
            assert!(close(*a, *b), "{a} {b}");
        }
        for (a, b) in device.slab_volumes.iter().zip(&cpu.slab_volumes) {
            assert!(close(*a, *b), "{a} {b}");
        }
    }
    // The reordered sums are the energy report's to rounding.
    let reference = state.energy();
    for (a, b) in [
        (cpu.energy.kinetic, reference.kinetic),
        (cpu.energy.rotational, reference.rotational),
        (cpu.energy.normal_potential, reference.normal_potential),
        (
            cpu.energy.tangential_potential,
            reference.tangential_potential,
        ),
    ] {
        assert!((a - b).abs() <= 1e-12 * b.abs(), "{a} {b}");
    }
}

fn rows_of<E: Engine>(mut run: Compression<E>) -> (Vec<Row>, Vec<Vec<(f64, f64)>>) {
    let (mut rows, mut profiles) = (Vec::new(), Vec::new());
    run.run(&mut |event| {
        match event {
            Event::Row(row) => rows.push(*row),
            Event::Profile(_, p) => profiles.push(p.to_vec()),
            Event::RowDone(_) => {}
        }
        Ok(())
    })
    .unwrap();
    (rows, profiles)
}

#[test]
fn both_backends_write_the_same_rows_and_profiles() {
    let Some(ctx) = context_for_tests() else {
        return;
    };
    if ctx.float_mode != FloatMode::Exact {
        return;
    }
    let config = uni(200, 1500, 4);
    let (cpu_rows, cpu_profiles) =
        rows_of(Compression::with_engine(&config, CpuEngine::new).unwrap());
    let (gpu_rows, gpu_profiles) = rows_of(
        Compression::with_engine(&config, |law, dt, m, w, ps, ws| {
            Ok(GpuEngine::new(ctx, law, dt, m, w, ps, ws)?)
        })
        .unwrap(),
    );
    assert_eq!(cpu_rows.len(), 16);
    assert_eq!(cpu_profiles.len(), 5);
    assert_eq!(gpu_profiles, cpu_profiles);
    for (a, b) in cpu_rows.iter().zip(&gpu_rows) {
        // Pressures and the dissipation tally aside (the wall forces and the per-monomer
        // tallies are summed in another order, see gpu_compression), every column is the same
        // bits.
        let strip = |r: &Row| Row {
            p_top: 0.0,
            p_bottom: 0.0,
            energy: EnergyReport {
                dissipated: Default::default(),
                wall_work: 0.0,
                ..r.energy
            },
            ..*r
        };
        assert_eq!(strip(a), strip(b));
    }
}

/// Bytes the GPU engine reads back for each row of a uni run of `n` monomers (from one
/// `RowDone` to the next: the small block of the row's submission and the row measures),
/// and for the rows that also carry a profile.
fn bytes_per_row(n: usize) -> Option<(Vec<u64>, u64)> {
    let ctx = context_for_tests()?;
    // A profile every third row.
    let config = uni(n, 1000, 3);
    let mut run = Compression::with_engine(&config, |law, dt, m, w, ps, ws| {
        Ok(GpuEngine::new(ctx, law, dt, m, w, ps, ws)?)
    })
    .unwrap();
    let mut at = Vec::new();
    run.run(&mut |event| {
        if let Event::RowDone(c) = event {
            at.push(c.engine.bytes_read_back());
        }
        Ok(())
    })
    .unwrap();
    let per_row: Vec<u64> = at.windows(2).map(|w| w[1] - w[0]).collect();
    Some((per_row, run.engine.bytes_read_back()))
}

#[test]
fn a_row_reads_back_a_few_hundred_bytes_whatever_the_number_of_monomers() {
    let Some((small, _)) = bytes_per_row(200) else {
        return;
    };
    let (large, _) = bytes_per_row(2000).unwrap();
    eprintln!("bytes read back per row: N = 200 {small:?}, N = 2000 {large:?}");
    assert_eq!(small.len(), large.len());
    // Rows 2, 5, 8 (from the second RowDone) carry a profile: 8 bytes per slab, one slab per
    // diameter of height, so it grows with the sample's height (N^⅓), not with N.
    for (k, (a, b)) in small.iter().zip(&large).enumerate() {
        let profile_row = (k + 2) % 3 == 0;
        if !profile_row {
            assert_eq!(a, b, "row {k}: the same bytes for 10× the monomers");
        }
        // Before the rows were reduced on the device, a uni row read the positions (32 B per
        // monomer) and the whole state for the energies (about 3 kB per monomer).
        assert!(*b < 2048, "row {k}: {b} bytes");
    }
}
