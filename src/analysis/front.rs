//! The compaction front of a dynamic compression: where each filling-factor profile departs
//! from the initial one, and the speed v_p at which that height moves down (Sect. 5.2).
//!
//! Heights are in metres and times in seconds, so speeds come out in m/s (the paper's
//! v_p = 6.98 ± 0.16 m/s). [`super::run_files::read_profiles`] reads them so.

#[cfg(test)]
mod tests;

use super::average::{spread, Spread};
use super::run_files::Profile;
use super::speed_laws::fit_line;

/// How the front is found in a profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontOptions {
    /// A slab counts as compacted when its φ exceeds the initial φ of the same slab by more
    /// than this. Default 0.05: a third of the initial φ ≈ 0.15 of an RBD sample and several
    /// times the slab-to-slab noise of a profile (one diameter thick slabs of a 60 µm box hold
    /// ~10³ monomers, so σ_φ ≈ 0.005), yet far below the dense layer's excess of ~0.3.
    pub threshold: f64,
    /// Slabs right under the wall that may fall short of the threshold before the compacted
    /// run starts. Default 2: the topmost slab is cut by the wall (its φ counts the part above
    /// the wall as empty), and the next may be too while the layer forms.
    pub skip_top: usize,
}

impl Default for FrontOptions {
    fn default() -> Self {
        Self {
            threshold: 0.05,
            skip_top: 2,
        }
    }
}

/// The front in one profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontPoint {
    pub time_s: f64,
    /// Height [m] of the front: scanning down from the wall through the contiguous run of
    /// compacted slabs, the height where the excess over the initial profile falls to the
    /// threshold, interpolated linearly between the centres of the lowest compacted slab and
    /// the one below it.
    pub front_m: f64,
    /// Height of the top wall [m], when the profile carries it.
    pub wall_m: Option<f64>,
    /// The compacted run reaches the bottom slab: the front has arrived at the bottom wall
    /// and `front_m` is that slab's lower edge; such points are left out of the speed.
    pub reached_bottom: bool,
}

/// The front's height in `current`, compared slab by slab with `initial` (slabs of equal
/// index lie at the same height: both start at the bottom wall). `None` if no compacted run
/// starts within the top `skip_top + 1` slabs, or the slabs of the two profiles do not line
/// up.
pub fn front_height(
    initial: &Profile,
    current: &Profile,
    opt: &FrontOptions,
) -> Option<FrontPoint> {
    let d = current.thickness_m;
    let n = current.z_m.len().min(initial.z_m.len());
    if n == 0 || d.is_nan() || d <= 0.0 {
        return None;
    }
    let aligned = (0..n).all(|k| (current.z_m[k] - initial.z_m[k]).abs() <= 1e-3 * d);
    if !aligned {
        return None;
    }
    let excess: Vec<f64> = (0..n).map(|k| current.phi[k] - initial.phi[k]).collect();
    let compacted = |k: usize| excess[k] > opt.threshold;
    let top = (0..n)
        .rev()
        .take(opt.skip_top + 1)
        .find(|&k| compacted(k))?;
    let mut lowest = top;
    while lowest > 0 && compacted(lowest - 1) {
        lowest -= 1;
    }
    let (front_m, reached_bottom) = if lowest == 0 {
        (current.z_m[0] - 0.5 * d, true)
    } else {
        let (below, at) = (excess[lowest - 1], excess[lowest]);
        let t = (opt.threshold - below) / (at - below);
        (current.z_m[lowest - 1] + t * d, false)
    };
    Some(FrontPoint {
        time_s: current.time_s,
        front_m,
        wall_m: current.wall_m,
        reached_bottom,
    })
}

/// Front heights of `profiles` against the first one, the profile before compression; the
/// profiles without a front are left out.
pub fn front_heights(profiles: &[Profile], opt: &FrontOptions) -> Vec<FrontPoint> {
    let Some((initial, rest)) = profiles.split_first() else {
        return Vec::new();
    };
    rest.iter()
        .filter_map(|p| front_height(initial, p, opt))
        .collect()
}

/// A speed from a least-squares line of height against time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Speed {
    /// Downward speed [m/s]: minus the slope of height against time.
    pub v: f64,
    /// Standard error of `v` from the residual scatter about the line.
    pub std_err: f64,
    /// Points used.
    pub points: usize,
}

/// Speeds of the front and (where every point used carries it) of the wall.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontSpeed {
    pub front: Speed,
    pub wall: Option<Speed>,
    /// Mean of (front − wall) height over the points used [m]: negative when the front runs
    /// below the wall, as it must.
    pub mean_lead_m: Option<f64>,
}

fn line_speed(t: &[f64], z: &[f64]) -> Option<Speed> {
    // Times centred for conditioning: they are microseconds after an arbitrary start.
    let t0 = t.iter().sum::<f64>() / t.len() as f64;
    let tc: Vec<f64> = t.iter().map(|t| t - t0).collect();
    let f = fit_line(&tc, z, None).ok()?;
    Some(Speed {
        v: -f.law.b,
        std_err: f.std_err.b,
        points: t.len(),
    })
}

/// v_p: minus the least-squares slope of the front height against time, over the points
/// whose front has not reached the bottom; `None` with fewer than three such points (a
/// line and its error need three) or all at one time.
pub fn front_speed(points: &[FrontPoint]) -> Option<FrontSpeed> {
    let used: Vec<&FrontPoint> = points.iter().filter(|p| !p.reached_bottom).collect();
    let t: Vec<f64> = used.iter().map(|p| p.time_s).collect();
    let z: Vec<f64> = used.iter().map(|p| p.front_m).collect();
    let front = line_speed(&t, &z)?;
    let walls: Option<Vec<f64>> = used.iter().map(|p| p.wall_m).collect();
    let (wall, mean_lead_m) = match walls {
        Some(w) => (
            line_speed(&t, &w),
            Some(z.iter().zip(&w).map(|(z, w)| z - w).sum::<f64>() / z.len() as f64),
        ),
        None => (None, None),
    };
    Some(FrontSpeed {
        front,
        wall,
        mean_lead_m,
    })
}

/// v_p of one run from its profiles (the first one before compression).
pub fn run_front_speed(profiles: &[Profile], opt: &FrontOptions) -> Option<FrontSpeed> {
    front_speed(&front_heights(profiles, opt))
}

/// Per-seed front speeds combined: mean ± standard error (sd/√n) over the seeds, the way
/// the paper quotes v_p over six samples.
pub fn combine_seeds(v_p: &[f64]) -> Option<Spread> {
    spread(v_p)
}

/// The front read as Seizinger et al. (2012, Sect. 5.2) describe it: "the height where the
/// initial and current filling factor profile deviate from each other", its distance below
/// the wall's starting height, over "the time that has passed since the start". One value
/// per profile whose front lies in the middle half of the sample (away from the layer's
/// formation under the wall and from the bottom); their mean, with the number of profiles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElapsedFront {
    pub v: f64,
    pub profiles: usize,
}

/// [`ElapsedFront`] of one run; `deviation` is the excess over the initial slab that counts
/// as a deviation. `None` without the initial wall height or a profile in the middle half.
pub fn elapsed_front_speed(profiles: &[Profile], deviation: f64) -> Option<ElapsedFront> {
    let (initial, rest) = profiles.split_first()?;
    let top = initial.wall_m?;
    let bottom = initial.bottom_m();
    let opt = FrontOptions {
        threshold: deviation,
        ..FrontOptions::default()
    };
    let middle = |z: f64| {
        let x = (z - bottom) / (top - bottom);
        (0.25..=0.75).contains(&x)
    };
    let speeds: Vec<f64> = rest
        .iter()
        .filter(|p| p.time_s > initial.time_s)
        .filter_map(|p| front_height(initial, p, &opt))
        .filter(|f| !f.reached_bottom && middle(f.front_m))
        .map(|f| (top - f.front_m) / (f.time_s - initial.time_s))
        .collect();
    let s = spread(&speeds)?;
    Some(ElapsedFront {
        v: s.mean,
        profiles: s.count,
    })
}

/// The dense layer's mean φ between the front (found with `opt`) and the wall, over the
/// profiles whose front lies in the middle half of the sample, and the front speed that mass
/// conservation then requires: the wall sweeps up φ₀ and leaves φ_layer, so
/// v_p = v_wall / (1 − φ₀/φ_layer). Returns (φ_layer, v_p) for the wall speed `v_wall`.
pub fn mass_balance_front(
    profiles: &[Profile],
    opt: &FrontOptions,
    v_wall: f64,
) -> Option<(f64, f64)> {
    let (initial, rest) = profiles.split_first()?;
    let top = initial.wall_m?;
    let bottom = initial.bottom_m();
    let phi0 = initial.phi_mean;
    let mut layers = Vec::new();
    for p in rest {
        let (Some(f), Some(wall)) = (front_height(initial, p, opt), p.wall_m) else {
            continue;
        };
        let x = (f.front_m - bottom) / (top - bottom);
        if f.reached_bottom || !(0.25..=0.75).contains(&x) {
            continue;
        }
        // Whole slabs between the front and the wall; the one the wall cuts is left out.
        let half = 0.5 * p.thickness_m;
        let inside: Vec<f64> = (0..p.z_m.len())
            .filter(|&k| p.z_m[k] - half >= f.front_m && p.z_m[k] + half <= wall)
            .map(|k| p.phi[k])
            .collect();
        if let Some(s) = spread(&inside) {
            layers.push(s.mean);
        }
    }
    let layer = spread(&layers)?.mean;
    (layer > phi0).then(|| (layer, v_wall / (1.0 - phi0 / layer)))
}
