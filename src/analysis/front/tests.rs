//! Tests of the compaction front: synthetic profiles with a dense layer whose lower edge moves
//! at a known speed, one diameter thick slabs, noise.

use super::*;
use crate::rng::Rng;

/// Slab thickness: one diameter of a 0.6 µm monomer [m].
const D: f64 = 1.2e-6;
/// Initial sample height [m] (the paper's dynamic samples are ≈ 60 µm high).
const H: f64 = 60e-6;
const SLABS: usize = 50;
const PHI_DENSE: f64 = 0.45;

fn profile(time_s: f64, phi: Vec<f64>, wall_m: Option<f64>) -> Profile {
    Profile {
        step: (time_s * 1e12) as u64,
        time_s,
        phi_mean: f64::NAN,
        z_m: (0..phi.len()).map(|k| (k as f64 + 0.5) * D).collect(),
        phi,
        thickness_m: D,
        wall_m,
    }
}

/// Length of [lo, hi] ∩ [a, b] over the slab thickness.
fn overlap(lo: f64, hi: f64, a: f64, b: f64) -> f64 {
    ((hi.min(b) - lo.max(a)) / D).max(0.0)
}

/// Initial φ per slab: 0.15 with a fixed slab-to-slab structure of sd 0.01.
fn initial(rng: &mut Rng) -> Vec<f64> {
    (0..SLABS).map(|_| 0.15 + 0.01 * rng.normal()).collect()
}

/// The profile at a time when the wall is at `wall`, the dense layer (φ = 0.45) fills
/// [edge, wall], and a weaker precursor (excess `pre_excess`) fills [pre_edge, edge]; the
/// slabs stop at the wall (the topmost is cut by it) and carry measurement noise `noise`.
fn compacted(
    init: &[f64],
    wall: f64,
    edge: f64,
    pre_edge: f64,
    pre_excess: f64,
    noise: f64,
    rng: &mut Rng,
) -> Vec<f64> {
    let n = (wall / D).ceil() as usize;
    (0..n)
        .map(|k| {
            let (lo, hi) = (k as f64 * D, (k + 1) as f64 * D);
            init[k] * overlap(lo, hi, 0.0, edge.min(wall))
                + pre_excess * overlap(lo, hi, pre_edge, edge)
                + PHI_DENSE * overlap(lo, hi, edge, wall)
                + noise * rng.normal()
        })
        .collect()
}

/// Least-squares slope error for errors of at most `d` each: d·Σ|tᵢ − t̄| / Σ(tᵢ − t̄)².
fn slope_error_bound(t: &[f64], d: f64) -> f64 {
    let m = t.iter().sum::<f64>() / t.len() as f64;
    d * t.iter().map(|t| (t - m).abs()).sum::<f64>()
        / t.iter().map(|t| (t - m).powi(2)).sum::<f64>()
}

#[test]
fn interpolates_the_threshold_crossing_between_slab_centres() {
    // Excess rising by 0.1 per slab above z0 = c₁₀ − 0.3d: 0.03 at c₁₀, 0.13 at c₁₁, so
    // the threshold 0.05 is crossed at z0 + 0.5d = c₁₀ + 0.2d.
    let init = vec![0.15; 20];
    let z0 = 10.2 * D;
    let phi = (0..20)
        .map(|k| 0.15 + (0.1 * ((k as f64 + 0.5) * D - z0) / D).max(0.0))
        .collect();
    let p = front_height(
        &profile(0.0, init.clone(), None),
        &profile(1e-6, phi, Some(24e-6)),
        &FrontOptions::default(),
    )
    .unwrap();
    assert!((p.front_m - (z0 + 0.5 * D)).abs() < 1e-9 * D, "{p:?}");
    assert!(!p.reached_bottom);
    assert_eq!((p.time_s, p.wall_m), (1e-6, Some(24e-6)));

    // Compacted all the way down: the front sits at the bottom wall.
    let all = vec![0.5; 20];
    let p = front_height(
        &profile(0.0, init.clone(), None),
        &profile(1e-6, all, None),
        &FrontOptions::default(),
    )
    .unwrap();
    assert!(p.reached_bottom && p.front_m.abs() < 1e-18);

    // Nothing compacted, or compaction only deep below the wall (noise): no front.
    let mut deep = init.clone();
    deep[3] += 0.2;
    for phi in [init.clone(), deep] {
        assert_eq!(
            front_height(
                &profile(0.0, init.clone(), None),
                &profile(1e-6, phi, None),
                &FrontOptions::default()
            ),
            None
        );
    }
    // Slabs that do not line up with the initial ones cannot be compared.
    let mut shifted = profile(1e-6, vec![0.5; 20], None);
    shifted.z_m.iter_mut().for_each(|z| *z += 0.5 * D);
    assert_eq!(
        front_height(
            &profile(0.0, init, None),
            &shifted,
            &FrontOptions::default()
        ),
        None
    );
}

#[test]
fn recovers_a_front_moving_at_7_m_s_ahead_of_a_5_m_s_wall() {
    const V_P: f64 = 7.0;
    const V_WALL: f64 = 5.0;
    let mut rng = Rng::new(21);
    let init = initial(&mut rng);
    let mut profiles = vec![profile(0.0, init.clone(), Some(H))];
    // 40 profiles over 0.3–5.8 µs: the front runs from 58 to 19 µm, the wall to 31 µm.
    let times: Vec<f64> = (0..40).map(|i| 0.3e-6 + i as f64 * 0.141e-6).collect();
    for &t in &times {
        let wall = H - V_WALL * t;
        let edge = H - V_P * t;
        // A precursor below the front, excess 0.03 (under the threshold), growing with the
        // distance run: its lower edge moves at 1.3 v_p, so a front read without the
        // threshold would move at ~9 m/s.
        let pre_edge = edge - 0.3 * V_P * t;
        let phi = compacted(&init, wall, edge, pre_edge, 0.03, 0.005, &mut rng);
        profiles.push(profile(t, phi, Some(wall)));
    }
    let points = front_heights(&profiles, &FrontOptions::default());
    assert_eq!(points.len(), times.len(), "a front in every profile");
    for p in &points {
        let truth = H - V_P * p.time_s;
        // The compacted run ends in the slab holding the edge or the one below it.
        assert!((p.front_m - truth).abs() <= D, "{p:?}: truth {truth}");
    }
    let s = front_speed(&points).unwrap();
    let bound = slope_error_bound(&times, D);
    println!("{s:?}; bound from |error| <= d: {bound}");
    assert!((s.front.v - V_P).abs() <= bound, "{s:?}");
    // Quantisation to slabs scatters the front by about d/√12 about the line.
    let sxx: f64 = {
        let m = times.iter().sum::<f64>() / times.len() as f64;
        times.iter().map(|t| (t - m).powi(2)).sum()
    };
    let expected_se = D / 12f64.sqrt() / sxx.sqrt();
    assert!(
        s.front.std_err > 0.2 * expected_se && s.front.std_err < 3.0 * expected_se,
        "{s:?} vs {expected_se}"
    );
    assert!((s.front.v - V_P).abs() <= 4.0 * s.front.std_err, "{s:?}");
    assert_eq!(s.front.points, 40);
    let wall = s.wall.unwrap();
    assert!((wall.v - V_WALL).abs() < 1e-6, "{wall:?}");
    assert!(
        s.mean_lead_m.unwrap() < -5e-6,
        "the front runs ahead of the wall"
    );
    assert_eq!(
        run_front_speed(&profiles, &FrontOptions::default()),
        Some(s)
    );
}

#[test]
fn a_front_that_stops_gives_zero_and_the_bottom_is_left_out() {
    let mut rng = Rng::new(22);
    let init = initial(&mut rng);
    let mut profiles = vec![profile(0.0, init.clone(), None)];
    let times: Vec<f64> = (0..30).map(|i| 1e-6 + i as f64 * 0.2e-6).collect();
    for &t in &times {
        // The edge sits at 30 µm; the wall does not move.
        let phi = compacted(&init, H, 30.3e-6, 30.3e-6, 0.0, 0.005, &mut rng);
        profiles.push(profile(t, phi, None));
    }
    // Later profiles compacted to the bottom must not pull the line down.
    for i in 0..5 {
        let phi = compacted(&init, H, 0.0, 0.0, 0.0, 0.005, &mut rng);
        profiles.push(profile(8e-6 + i as f64 * 0.2e-6, phi, None));
    }
    let points = front_heights(&profiles, &FrontOptions::default());
    assert_eq!(points.iter().filter(|p| p.reached_bottom).count(), 5);
    let s = front_speed(&points).unwrap();
    assert_eq!(s.front.points, 30);
    assert!(s.front.v.abs() <= slope_error_bound(&times, D), "{s:?}");
    assert!(s.front.v.abs() < 0.1, "{s:?}");
    assert_eq!((s.wall, s.mean_lead_m), (None, None));

    // No compaction at all: no front, no speed.
    let flat: Vec<Profile> = (0..5)
        .map(|i| profile(i as f64 * 1e-6, init.clone(), None))
        .collect();
    assert!(front_heights(&flat, &FrontOptions::default()).is_empty());
    assert_eq!(run_front_speed(&flat, &FrontOptions::default()), None);
    assert_eq!(run_front_speed(&[], &FrontOptions::default()), None);
}

#[test]
fn seeds_combine_to_mean_and_standard_error() {
    // By hand: mean 41.9/6, Σ(v − mean)² = 0.108333…, sd = √(0.108333…/5), sem = sd/√6.
    let s = combine_seeds(&[6.8, 7.0, 7.2, 6.9, 7.1, 6.9]).unwrap();
    assert!((s.mean - 6.983_333_333_333_333).abs() < 1e-12);
    assert!((s.sd - 0.147_196_014_438_797_6).abs() < 1e-12, "{s:?}");
    assert!((s.sem - 0.060_092_521_257_733_15).abs() < 1e-12, "{s:?}");
    assert_eq!(s.count, 6);
    assert_eq!(combine_seeds(&[]), None);
}

/// Profiles of a run whose wall moves at `v_wall` from `H`, whose dense layer's lower edge moves
/// at the mass-balance speed for φ₀ = 0.15 and PHI_DENSE, led by a precursor `lead` ahead.
fn layered_run(v_wall: f64, lead: f64) -> (Vec<Profile>, f64) {
    delayed_run(v_wall, lead, 0.0)
}

/// [`layered_run`] whose wall and layer only start to move `delay` seconds after the start.
fn delayed_run(v_wall: f64, lead: f64, delay: f64) -> (Vec<Profile>, f64) {
    let v_p = v_wall / (1.0 - 0.15 / PHI_DENSE);
    let init = vec![0.15; SLABS];
    let mut first = profile(0.0, init.clone(), Some(H));
    first.phi_mean = 0.15;
    let mut out = vec![first];
    let mut rng = Rng::new(3);
    for k in 1..=40 {
        let t = k as f64 * 0.02 * H / v_p;
        let moving = (t - delay).max(0.0);
        let (wall, edge) = (H - v_wall * moving, H - v_p * moving);
        let phi = compacted(&init, wall, edge, edge - lead, 0.03, 0.0, &mut rng);
        out.push(profile(t, phi, Some(wall)));
    }
    (out, v_p)
}

#[test]
fn elapsed_front_reads_the_first_deviation_and_mass_balance_the_layer() {
    let v_wall = 5.0;
    // No precursor: the first deviation is the layer's edge, moving at the mass-balance speed.
    let (run, v_p) = layered_run(v_wall, 0.0);
    assert!((v_p - 7.5).abs() < 1e-12);
    let e = elapsed_front_speed(&run, 0.01).unwrap();
    // Slab-interpolated edges are off by at most a slab, at least 15 µm below the start.
    let tol = v_p * D / 15e-6;
    assert!((e.v - v_p).abs() < tol, "{e:?} vs {v_p}");
    assert!(e.profiles >= 15, "{e:?}");
    let (layer, v_mb) = mass_balance_front(&run, &FrontOptions::default(), v_wall).unwrap();
    assert!((layer - PHI_DENSE).abs() < 1e-9, "{layer}");
    assert!((v_mb - v_p).abs() < 1e-6, "{v_mb}");

    // A precursor of excess 0.03 running 6 µm ahead: the first deviation (0.01) follows it,
    // its distance from the start over the elapsed time comes out faster by lead / t.
    let lead = 6e-6;
    let (run, _) = layered_run(v_wall, lead);
    let first = elapsed_front_speed(&run, 0.01).unwrap();
    assert!(first.v > v_p + 0.5 * tol, "{first:?}");
    // The robust reading (excess 0.05) does not see it.
    let robust = elapsed_front_speed(&run, 0.05).unwrap();
    assert!((robust.v - v_p).abs() < tol, "{robust:?}");
}

#[test]
fn elapsed_front_needs_the_starting_wall() {
    let (mut run, _) = layered_run(5.0, 0.0);
    run[0].wall_m = None;
    assert!(elapsed_front_speed(&run, 0.01).is_none());
    assert!(mass_balance_front(&run, &FrontOptions::default(), 5.0).is_none());
}

#[test]
fn elapsed_front_reads_only_fronts_in_the_middle_half() {
    // Nothing moves for 2 µs: v = v_p (1 − t₀/t) is lowest early on, so the profiles whose
    // front lies in the top quarter would pull the mean down.
    let (delay, v_wall) = (2e-6, 5.0);
    let (run, v_p) = delayed_run(v_wall, 0.0, delay);
    let (mut middle, mut all) = (Vec::new(), Vec::new());
    for p in &run[1..] {
        let depth = v_p * (p.time_s - delay);
        if depth <= 2.0 * D {
            continue;
        }
        let v = v_p * (1.0 - delay / p.time_s);
        all.push(v);
        if (0.25..=0.75).contains(&(1.0 - depth / H)) {
            middle.push(v);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    // A slab of error in the front over the earliest time in the middle half.
    let tol = D / (delay + 15e-6 / v_p);
    let gap = (mean(&middle) - mean(&all)).abs();
    assert!(
        gap > 2.0 * tol,
        "the test must tell them apart: {gap} vs {tol}"
    );
    let e = elapsed_front_speed(&run, 0.01).unwrap();
    assert_eq!(e.profiles, middle.len());
    assert!(
        (e.v - mean(&middle)).abs() < tol,
        "{e:?} vs {}",
        mean(&middle)
    );
}

#[test]
fn profiles_without_a_slab_thickness_or_slabs_give_no_front() {
    // A compacted profile that would give a front, once with slabs of no or undefined
    // thickness (a zero thickness would make every slab line up and the front land on a
    // slab centre) and once with no slabs.
    let init = profile(0.0, vec![0.15; 20], None);
    let all = profile(1e-6, vec![0.5; 20], None);
    assert!(front_height(&init, &all, &FrontOptions::default()).is_some());
    for thickness_m in [0.0, -D, f64::NAN] {
        let flat = |p: &Profile| Profile {
            thickness_m,
            z_m: vec![0.0; p.z_m.len()],
            ..p.clone()
        };
        assert_eq!(
            front_height(&flat(&init), &flat(&all), &FrontOptions::default()),
            None,
            "thickness {thickness_m}"
        );
    }
    let empty = |p: &Profile| Profile {
        z_m: Vec::new(),
        phi: Vec::new(),
        ..p.clone()
    };
    assert_eq!(
        front_height(&empty(&init), &empty(&all), &FrontOptions::default()),
        None
    );
}

/// `run` with every height raised by `dz` and every time shifted by `dt`: the same physics
/// seen from another origin.
fn moved(run: &[Profile], dz: f64, dt: f64) -> Vec<Profile> {
    run.iter()
        .map(|p| Profile {
            time_s: p.time_s + dt,
            z_m: p.z_m.iter().map(|z| z + dz).collect(),
            wall_m: p.wall_m.map(|w| w + dz),
            ..p.clone()
        })
        .collect()
}

#[test]
fn front_readings_do_not_depend_on_where_heights_and_times_start() {
    // A sample standing 20 µm above z = 0 and a clock started 100 s earlier: heights above the
    // bottom and times since the start are what count, so every reading is the same.
    let (delay, v_wall) = (2e-6, 5.0);
    let (run, _) = delayed_run(v_wall, 0.0, delay);
    let far = moved(&run, 20e-6, 100.0);
    let (near_e, far_e) = (
        elapsed_front_speed(&run, 0.01).unwrap(),
        elapsed_front_speed(&far, 0.01).unwrap(),
    );
    assert_eq!(near_e.profiles, far_e.profiles);
    assert!(
        (near_e.v - far_e.v).abs() < 1e-6 * near_e.v,
        "{near_e:?} {far_e:?}"
    );
    let opt = FrontOptions::default();
    let (near_s, far_s) = (
        run_front_speed(&run, &opt).unwrap(),
        run_front_speed(&far, &opt).unwrap(),
    );
    // Least squares on times 100 s + a few µs: only centred times keep the slope.
    assert!(
        (near_s.front.v - far_s.front.v).abs() < 1e-6 * near_s.front.v,
        "{near_s:?} {far_s:?}"
    );
    let lead = |s: &FrontSpeed| s.mean_lead_m.unwrap();
    assert!(
        (lead(&near_s) - lead(&far_s)).abs() < 1e-12,
        "{near_s:?} {far_s:?}"
    );
}

#[test]
fn the_mean_lead_is_the_mean_height_of_the_front_below_the_wall() {
    // Fronts 3, 4 and 5 µm below the wall at three times: the mean lead is −4 µm.
    let point = |t: f64, front_m: f64, wall_m: f64| FrontPoint {
        time_s: t,
        front_m,
        wall_m: Some(wall_m),
        reached_bottom: false,
    };
    let points = [
        point(1e-6, 50e-6, 53e-6),
        point(2e-6, 40e-6, 44e-6),
        point(3e-6, 30e-6, 35e-6),
    ];
    let s = front_speed(&points).unwrap();
    assert!((s.mean_lead_m.unwrap() + 4e-6).abs() < 1e-18, "{s:?}");
    assert!((s.front.v - 10.0).abs() < 1e-9, "{s:?}");
    assert!((s.wall.unwrap().v - 9.0).abs() < 1e-9, "{s:?}");
}

#[test]
fn mass_balance_reads_the_layer_only_while_the_front_is_in_the_middle_half() {
    // A layer of φ 0.6 while its front is in the top quarter, 0.45 in the middle half and 0.3
    // in the bottom quarter: the middle half alone gives 0.45 and v_p = v_wall / (1 − 0.15 /
    // 0.45) = 1.5 v_wall, also for a sample standing 20 µm above z = 0.
    let (v_wall, v_p) = (5.0, 7.5);
    let init = vec![0.15; SLABS];
    let mut first = profile(0.0, init.clone(), Some(H));
    first.phi_mean = 0.15;
    let mut run = vec![first];
    for k in 1..=45 {
        let t = k as f64 * 0.02 * H / v_p;
        let (wall, edge) = (H - v_wall * t, H - v_p * t);
        let x = edge / (SLABS as f64 * D);
        let layer = if x > 0.75 {
            0.6
        } else if x < 0.25 {
            0.3
        } else {
            0.45
        };
        let n = (wall / D).ceil() as usize;
        let phi = (0..n)
            .map(|j| {
                let (lo, hi) = (j as f64 * D, (j + 1) as f64 * D);
                0.15 * overlap(lo, hi, 0.0, edge) + layer * overlap(lo, hi, edge, wall)
            })
            .collect();
        run.push(profile(t, phi, Some(wall)));
    }
    let opt = FrontOptions::default();
    for r in [run.clone(), moved(&run, 20e-6, 100.0)] {
        let (layer, v) = mass_balance_front(&r, &opt, v_wall).unwrap();
        assert!((layer - 0.45).abs() < 1e-9, "{layer}");
        assert!((v - v_p).abs() < 1e-6, "{v}");
    }
    // A layer no denser than the sample's start gives no speed (v_p would be infinite).
    run[0].phi_mean = mass_balance_front(&run, &opt, v_wall).unwrap().0;
    assert_eq!(mass_balance_front(&run, &opt, v_wall), None);
}
