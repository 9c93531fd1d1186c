//! Microseconds per step of each pass of the step script on one thread, on the benchmark's
//! warmed RBD sample: `cargo run --release --example pass_times -- 100000`. Finer than the
//! bench's five groups, for finding which pass a change moved.
use dustdem::backend::script::STEP;
use std::time::Instant;
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(100000);
    let config = dustdem::bench::benchmark_config(n).unwrap();
    let (mut e, _, _) = dustdem::bench::benchmark_engine(&config).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(|| {
        e.run(300).unwrap();
        let mut t = vec![0.0; STEP.len()];
        let steps = 60;
        for _ in 0..steps {
            for (k, &p) in STEP.iter().enumerate() {
                let c = Instant::now();
                e.run_pass(p).unwrap();
                t[k] += c.elapsed().as_secs_f64();
            }
        }
        for (k, p) in STEP.iter().enumerate() {
            println!("{:24} {:8.0} us", p.entry(), t[k] / steps as f64 * 1e6);
        }
    });
}
