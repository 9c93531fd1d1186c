//! Microseconds per step of each pass of the step script on one thread, on the benchmark's
//! warmed RBD sample: `cargo run --release --example pass_times -- 100000`. Finer than the
//! bench's five groups, for finding which pass a change moved. With a filling factor and a
//! directory, `-- 10000 0.45 bench`, it starts from the sample `dustdem bench --samples 0.45
//! --prepare-speed 0.25 --out bench` compressed (reusing its stored state, else preparing it);
//! a third argument sets the steps timed (default 60), a fourth, `untallied`, stops booking
//! the corrections' dissipation (`[output] tally_corrections = false`). The environment
//! variable `PASS_TIMES_THREADS` sets the threads (default 1); with `PASS_TIMES_WHOLE` set, it
//! times the steps as `run` takes them instead, one figure per step.
use dustdem::backend::script::STEP;
use dustdem::bench::options::{Options, SampleState};
use std::path::PathBuf;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().map(|s| s.parse().unwrap()).unwrap_or(100000);
    let config = dustdem::bench::benchmark_config(n).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(
            std::env::var("PASS_TIMES_THREADS")
                .ok()
                .and_then(|t| t.parse().ok())
                .unwrap_or(1),
        )
        .build()
        .unwrap();
    let mut e = match (args.get(1), args.get(2)) {
        (Some(phi), Some(out)) => {
            let options = Options {
                prepare_speed_m_s: 0.25,
                out: PathBuf::from(out),
                ..Options::default()
            };
            let sample = SampleState::Compressed {
                phi: phi.parse().unwrap(),
            };
            let lammps_dir = PathBuf::from(out).join("lammps");
            let mut notes = vec![];
            dustdem::bench::prepare::starting_engine(
                &config,
                sample,
                &options,
                &pool,
                &lammps_dir,
                &mut notes,
                &|p| eprintln!("{p}"),
            )
            .unwrap()
        }
        _ => dustdem::bench::benchmark_engine(&config).unwrap().0,
    };
    let steps: usize = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(60);
    if args.get(4).map(String::as_str) == Some("untallied") {
        dustdem::engine::Engine::stop_tallying_corrections(&mut e);
    }
    pool.install(|| {
        e.run(100).unwrap();
        if std::env::var("PASS_TIMES_WHOLE").is_ok() {
            // The step as `run` takes it, passes joined: one figure per step.
            let c = Instant::now();
            e.run(steps as u64).unwrap();
            println!(
                "{:24} {:8.0} us",
                "run",
                c.elapsed().as_secs_f64() / steps as f64 * 1e6
            );
            return;
        }
        let mut t = vec![0.0; STEP.len()];
        for _ in 0..steps {
            for (k, &p) in STEP.iter().enumerate() {
                let c = Instant::now();
                e.run_step_pass(p).unwrap();
                t[k] += c.elapsed().as_secs_f64();
            }
        }
        for (k, p) in STEP.iter().enumerate() {
            println!("{:24} {:8.0} us", p.entry(), t[k] / steps as f64 * 1e6);
        }
    });
}
