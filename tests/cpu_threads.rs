//! The parallel CPU engine gives the same bits for any thread count, and the same bits as the
//! GPU engine's exact float mode: a compression with contact events, inelastic corrections and
//! wall contacts, 2000 steps in pools of 1, 2 and 3 threads and on the device.

use dustdem::backend::cpu::chunking::SERIAL_BELOW;
use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::backend::gpu::shader::FloatMode;
use dustdem::binary::Encoder;
use dustdem::config::Config;
use dustdem::engine::Engine;
use dustdem::experiment::compression::Compression;
use dustdem::state::{ContactTable, State};

const STEPS: u64 = 2000;

/// 5000 monomers (ten chunks of the CPU passes, above the size below which the passes stay on
/// one thread), a fast wall so that contacts form, break and slide within 2000 steps. Stored
/// in the sample's order, where contact events spread over all chunks rather than the few
/// under the wall, so that more per-chunk sums are non-zero (a thread-dependent sum of the
/// damping work fails this test; checked by making it one).
fn config() -> Config {
    Config::parse(
        "[sample]\nmonomers = 5000\nseed = 11\n[integration]\nspace_filling_order = false\n[experiment]\nkind = \"omni\"\nwall_speed_m_s = 10.0\n",
        "thread test",
    )
    .unwrap()
}

/// `f` on the engine of [`config`], in a pool of `threads`.
fn in_pool<R: Send>(threads: usize, f: impl FnOnce(CpuEngine) -> R + Send) -> R {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        f(Compression::with_engine(&config(), CpuEngine::new)
            .unwrap()
            .engine)
    })
}

fn run_in_pool(threads: usize) -> CpuEngine {
    in_pool(threads, |mut engine| {
        engine.run(STEPS).unwrap();
        engine
    })
}

/// The contacts slot for slot up to each count. A slot above its count holds what a broken
/// contact's swap left there, which the CPU step's corrections (in `integrate_pairs`, before
/// the events) and the device's (in `contacts`, after them) leave different: no state.
fn same_contacts(a: &ContactTable, b: &ContactTable) -> bool {
    let n = a.pair_count.len();
    a.pair_count == b.pair_count
        && a.wall_count == b.wall_count
        && (0..n).all(|i| a.pairs_of(i) == b.pairs_of(i) && a.walls_of(i) == b.walls_of(i))
}

fn encoded(state: &State) -> Vec<u8> {
    let mut e = Encoder::default();
    state.encode(&mut e);
    e.bytes
}

#[test]
fn one_two_and_three_threads_give_the_same_bits() {
    assert!(config().sample.monomers > SERIAL_BELOW);
    let one = run_in_pool(1);
    let t = one.tally;
    eprintln!(
        "after {STEPS} steps: {} pair and {} wall contacts; tally {t:?}",
        one.contacts.pair_contact_count(),
        one.contacts.wall_contact_count()
    );
    // The run exercises what could depend on the order of work: contact events, inelastic
    // corrections (booked in the tally) and wall contacts.
    assert!(t.forming != 0.0 && t.rolling != 0.0 && t.sliding != 0.0);
    assert!(one.contacts.wall_contact_count() > 0);
    let reference = encoded(&one.state);
    for threads in [2, 3] {
        let other = run_in_pool(threads);
        assert!(
            encoded(&other.state) == reference,
            "{threads} threads: the state differs from one thread's"
        );
        // Fields the encoding may not carry, compared by their bits too.
        assert_eq!(other.wall_force, one.wall_force, "{threads} threads");
        assert_eq!(other.tally, one.tally, "{threads} threads");
        assert_eq!(other.wall_work.to_bits(), one.wall_work.to_bits());
    }
}

#[test]
fn the_gpu_exact_mode_gives_the_cpu_bits() {
    let Some(ctx) = context_for_tests() else {
        return;
    };
    if ctx.float_mode != FloatMode::Exact {
        eprintln!("notice: the adapter has no exact float mode; nothing to compare to the bit");
        return;
    }
    let cpu = run_in_pool(3);
    let mut gpu = Compression::with_engine(&config(), |law, dt, m, w, ps, ws| {
        GpuEngine::new(ctx, law, dt, m, w, ps, ws).map_err(Into::into)
    })
    .unwrap();
    gpu.engine.advance(STEPS).unwrap();
    let g = gpu.engine.state().into_owned();
    let (a, b) = (&cpu.monomers, &g.monomers);
    assert_eq!(a.position, b.position);
    assert_eq!(a.velocity, b.velocity);
    assert_eq!(a.angular_velocity, b.angular_velocity);
    assert_eq!(a.force, b.force);
    assert_eq!(a.torque, b.torque);
    assert!(same_contacts(&cpu.contacts, &g.contacts), "contact tables");
    assert_eq!(cpu.walls, g.walls);
    // Both sum the per-slot wall forces in `reduce_walls`'s blocks.
    assert_eq!(cpu.wall_force, g.wall_force);
}

/// A run that fails (a monomer's position made NaN: it touches every wall, more than its wall
/// slots hold) returns its error in a pool of two, whose other thread the run keeps awake, as
/// in a pool of one (a keeper left spinning would hang it).
#[test]
fn a_failing_run_returns_its_error_with_the_pool_kept_awake() {
    for threads in [1, 2] {
        in_pool(threads, |mut engine| {
            engine.run(10).unwrap();
            let last = engine.monomers.len() - 1;
            engine.monomers.position[last].x = f64::NAN;
            let error = engine.run(100).unwrap_err();
            let named = format!("monomer {last} ");
            assert!(format!("{error}").contains(&named), "{threads}: {error}");
        });
    }
}
