//! Two monomers colliding head-on: the sticking experiment.

use crate::engine::{Engine, EngineError};
use crate::material::normal_period_of;
use crate::model::normal::{jkr_potential, X_MIN};
use crate::model::ContactLaw;
use crate::state::{Monomers, Wall, DEFAULT_PAIR_SLOTS, DEFAULT_WALL_SLOTS};
use glam::DVec3;

/// Energy the JKR loop takes from a head-on collision without damping: the work to stretch the
/// contact from δ = 0 (where it formed) to the break at −δ_c, U(x_min) − U(x₀) [erg].
pub fn jkr_loop_energy(law: &ContactLaw) -> f64 {
    jkr_potential(X_MIN, law.pair.f_c, law.pair.delta0)
}

/// Relative speed below which two free monomers stick without damping: ½ (m/2) v² = E_loop.
pub fn analytic_sticking_speed(law: &ContactLaw) -> f64 {
    (4.0 * jkr_loop_energy(law) / law.mass).sqrt()
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome {
    Stuck,
    /// The contact broke; relative speed when it did.
    Separated {
        rebound_speed: f64,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollisionResult {
    pub outcome: Outcome,
    /// Largest overlap reached [cm].
    pub max_overlap: f64,
    /// Steps simulated.
    pub steps: u64,
}

/// Collides two monomers head-on at relative speed `speed` [cm/s] on the engine `build` makes
/// (the same arguments as a compression's). They start 0.05 δ₀ apart and count as stuck when the
/// contact survives `periods` normal periods after forming.
pub fn head_on_collision<E: Engine>(
    law: &ContactLaw,
    speed: f64,
    dt: f64,
    periods: f64,
    build: impl FnOnce(ContactLaw, f64, Monomers, Vec<Wall>, usize, usize) -> Result<E, EngineError>
        + Send,
) -> Result<CollisionResult, EngineError> {
    on_one_thread(|| collide(law, speed, dt, periods, build))
}

/// Runs `f` on a private one-thread rayon pool. A collision advances one step at a time (it
/// watches the contact form and break), and two monomers give a parallel pass nothing to share:
/// handing every step to the global pool costs a thread wake-up per step, more than ten times
/// the step itself (one sticking threshold of the calibration test system, measured on 2
/// cores: 2.4 s from the global pool, 0.14 s on one thread). The bits are the same.
fn on_one_thread<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    match rayon::ThreadPoolBuilder::new().num_threads(1).build() {
        Ok(pool) => pool.install(f),
        // No thread to be had: the caller's pool gives the same result, only slower.
        Err(_) => f(),
    }
}

fn collide<E: Engine>(
    law: &ContactLaw,
    speed: f64,
    dt: f64,
    periods: f64,
    build: impl FnOnce(ContactLaw, f64, Monomers, Vec<Wall>, usize, usize) -> Result<E, EngineError>,
) -> Result<CollisionResult, EngineError> {
    let r = law.radius;
    let gap = 0.05 * law.pair.delta0;
    let half = r + 0.5 * gap;
    let mut monomers = Monomers::new(vec![
        DVec3::new(-half, 0.0, 0.0),
        DVec3::new(half, 0.0, 0.0),
    ]);
    monomers.velocity = vec![
        DVec3::new(0.5 * speed, 0.0, 0.0),
        DVec3::new(-0.5 * speed, 0.0, 0.0),
    ];
    let mut engine = build(
        *law,
        dt,
        monomers,
        Vec::new(),
        DEFAULT_PAIR_SLOTS,
        DEFAULT_WALL_SLOTS,
    )?;
    let period = normal_period_of(law.mass, &law.pair);
    let approach = gap / speed;
    let limit = ((approach + periods * period) / dt).ceil() as u64 + 10;
    let mut formed_at = None;
    let mut max_overlap = f64::NEG_INFINITY;
    while engine.step_count() < limit {
        engine.advance(1)?;
        let p = engine.positions();
        let overlap = 2.0 * r - (p[1] - p[0]).length();
        max_overlap = max_overlap.max(overlap);
        let touching = engine.contact_counts().0 > 0;
        match (formed_at, touching) {
            (None, true) => formed_at = Some(engine.step_count()),
            (Some(_), false) => {
                let state = engine.state();
                let rel = state.synchronized_velocity(1) - state.synchronized_velocity(0);
                return Ok(CollisionResult {
                    outcome: Outcome::Separated {
                        rebound_speed: rel.x,
                    },
                    max_overlap,
                    steps: engine.step_count(),
                });
            }
            _ => {}
        }
    }
    Ok(CollisionResult {
        outcome: Outcome::Stuck,
        max_overlap,
        steps: engine.step_count(),
    })
}

/// Sticking threshold by bisection between a speed that sticks and one that does not, to a
/// relative width `tolerance` [cm/s], each collision on the engine `build` makes.
pub fn sticking_threshold<E: Engine>(
    law: &ContactLaw,
    dt: f64,
    mut sticks: f64,
    mut bounces: f64,
    tolerance: f64,
    build: impl Fn(ContactLaw, f64, Monomers, Vec<Wall>, usize, usize) -> Result<E, EngineError> + Sync,
) -> Result<f64, EngineError> {
    for _ in 0..60 {
        if bounces - sticks <= tolerance * sticks {
            break;
        }
        let mid = 0.5 * (sticks + bounces);
        match head_on_collision(law, mid, dt, 5.0, &build)?.outcome {
            Outcome::Stuck => sticks = mid,
            Outcome::Separated { .. } => bounces = mid,
        }
    }
    Ok(0.5 * (sticks + bounces))
}
