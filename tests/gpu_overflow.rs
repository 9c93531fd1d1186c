//! Device failures are detected and reported, never dropped or panicked on: overflows of contact
//! slots, cell-table buckets and candidate lists (with the monomer, the limit and the config key
//! to change), and a lost device.

use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::engine::{GpuEngine, GpuError};
use dustdem::backend::gpu::layout::{INCOMING_CAPACITY, NEIGHBOUR_CAPACITY};
use dustdem::config::Config;
use dustdem::experiment::compression::{Compression, RunError};
use dustdem::state::{Monomers, Wall};
use glam::DVec3;

/// `count` points on a sphere of radius `radius` around the origin (Fibonacci lattice).
fn shell(count: usize, radius: f64) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / count as f64;
            let s = (1.0 - z * z).sqrt();
            let a = golden * k as f64;
            DVec3::new(s * a.cos(), s * a.sin(), z) * radius
        })
        .collect()
}

fn gpu_error(positions: Vec<DVec3>, pair_slots: usize) -> Option<GpuError> {
    let ctx = context_for_tests()?;
    let law = Config::default().contact_law();
    let result = GpuEngine::new(
        ctx,
        law,
        1e-10,
        Monomers::new(positions),
        Vec::new(),
        pair_slots,
        3,
    );
    Some(result.expect_err("the overflow must stop the engine"))
}

#[test]
fn pair_slot_overflow_on_the_gpu_names_the_setting() {
    let config = Config::parse(
        "[sample]\nmonomers = 400\n[integration]\npair_slots = 1\n",
        "overflow test",
    )
    .unwrap();
    let Some(ctx) = context_for_tests() else {
        return;
    };
    let result = Compression::with_engine(&config, |law, dt, m, w, ps, ws| {
        Ok(GpuEngine::new(ctx, law, dt, m, w, ps, ws)?)
    });
    // The device's flag becomes the CPU engine's error, so both backends say the same.
    let text = match result {
        Err(RunError::Engine(e)) => e.to_string(),
        Err(other) => panic!("wrong error: {other}"),
        Ok(_) => panic!("an RBD sample has monomers with two partners of higher index"),
    };
    assert!(
        text.contains("more than 1 monomer-monomer contact slots")
            && text.contains("[integration] pair_slots"),
        "{text}"
    );
}

#[test]
fn wall_slot_overflow_on_the_gpu_names_the_setting() {
    // One monomer in the corner of two walls, overlapping each by δ₀/2, with one wall slot.
    let Some(ctx) = context_for_tests() else {
        return;
    };
    let law = Config::default().contact_law();
    let d = law.radius - 0.5 * law.wall.delta0;
    let wall = |name: &str, normal: DVec3| Wall {
        name: name.into(),
        point: DVec3::ZERO,
        normal,
        velocity: DVec3::ZERO,
        constants: law.wall,
    };
    let result = GpuEngine::new(
        ctx,
        law,
        1e-10,
        Monomers::new(vec![DVec3::new(d, 5.0 * law.radius, d)]),
        vec![wall("bottom", DVec3::Z), wall("side", DVec3::X)],
        4,
        1,
    );
    let text = result
        .expect_err("two wall contacts in one slot")
        .to_string();
    assert!(
        text.contains("more than 1 monomer-wall contact slots")
            && text.contains("[integration] wall_slots"),
        "{text}"
    );
}

/// The lists without a config key of their own name the keys that keep a state from filling
/// them, and no source constant.
fn assert_names_what_to_change(error: &GpuError) {
    let text = error.to_string();
    for key in [
        "[integration] dt_ns",
        "[experiment] wall_speed_m_s",
        "[sample] file",
    ] {
        assert!(text.contains(key), "{key} not named: {text}");
    }
    assert!(!text.contains("::") && !text.contains("CAPACITY"), "{text}");
}

#[test]
fn a_full_candidate_list_is_reported() {
    // Monomer 0 with NEIGHBOUR_CAPACITY + 1 partners of higher index within 2r + skin (none
    // touching it): its list cannot hold them.
    let r = Config::default().contact_law().radius;
    let mut positions = vec![DVec3::ZERO];
    positions.extend(shell(NEIGHBOUR_CAPACITY + 1, 2.1 * r));
    let Some(error) = gpu_error(positions, 32) else {
        return;
    };
    match &error {
        GpuError::NeighbourOverflow { monomer, capacity } => {
            assert_eq!((*monomer, *capacity), (0, NEIGHBOUR_CAPACITY));
        }
        other => panic!("wrong error: {other}"),
    }
    assert_names_what_to_change(&error);
}

#[test]
fn a_full_incoming_list_is_reported() {
    // The last monomer touched by INCOMING_CAPACITY + 1 monomers of lower index (more than
    // equal spheres can touch one without overlapping each other).
    let law = Config::default().contact_law();
    let mut positions = shell(
        INCOMING_CAPACITY + 1,
        2.0 * law.radius - 0.5 * law.pair.delta0,
    );
    positions.push(DVec3::ZERO);
    let Some(error) = gpu_error(positions, 32) else {
        return;
    };
    match &error {
        GpuError::IncomingOverflow { monomer, capacity } => {
            assert_eq!(
                (*monomer, *capacity),
                (INCOMING_CAPACITY + 1, INCOMING_CAPACITY)
            );
        }
        other => panic!("wrong error: {other}"),
    }
    assert_names_what_to_change(&error);
}

#[test]
fn a_full_cell_bucket_is_reported() {
    // 20 monomers crushed into one cell: more than a bucket holds.
    let r = Config::default().contact_law().radius;
    let positions = shell(20, 0.5 * r)
        .into_iter()
        .map(|p| p + DVec3::splat(1.1 * r))
        .collect();
    let Some(error) = gpu_error(positions, 32) else {
        return;
    };
    assert!(
        matches!(error, GpuError::BucketOverflow { .. }),
        "wrong error: {error}"
    );
    assert_names_what_to_change(&error);
}

#[test]
fn a_lost_device_is_an_error_not_a_panic() {
    let config = Config::parse("[sample]\nmonomers = 200\n", "device loss test").unwrap();
    let Some(ctx) = context_for_tests() else {
        return;
    };
    let mut run = Compression::with_engine(&config, |law, dt, m, w, ps, ws| {
        Ok(GpuEngine::new(ctx, law, dt, m, w, ps, ws)?)
    })
    .unwrap();
    run.engine.run(200).unwrap();
    run.engine.ctx.device.destroy();
    match run.engine.run(200) {
        Err(GpuError::DeviceLost(why)) => eprintln!("reported: {why}"),
        Err(other) => panic!("wrong error: {other}"),
        Ok(()) => panic!("a destroyed device cannot run"),
    }
}
