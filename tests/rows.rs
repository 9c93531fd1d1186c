//! The row measures' fixed summation order (src/state/rows.rs), held to the measurements it
//! reorders: the projected area of `experiment::measure` (the same pixels, so the same bits),
//! the slab profile of `sample::slab_profile` and the energy report (to rounding: the same
//! terms added in another order).

use dustdem::backend::cpu::CpuEngine;
use dustdem::config::Config;
use dustdem::engine::Engine;
use dustdem::experiment::compression::Compression;
use dustdem::experiment::measure::projected_area;
use dustdem::rng::Rng;
use dustdem::sample::slab_profile;
use dustdem::state::reduction::REDUCE_BLOCK;
use dustdem::state::rows::{
    row_area, row_profile, row_profile_final, row_raster, sphere_volume, Raster, RowRequest, Slabs,
};
use glam::DVec3;

/// The monomer radius [cm]: a radius other than 1 and a box off the origin, so that r² = r,
/// r / r = 1 or x − x0 = x + x0 cannot pass for the right arithmetic.
const R: f64 = 0.6e-4;

/// `n` centres scattered over a box of 20 radii whose corner sits at (3, −5, 7) radii.
fn scattered(n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = Rng::new(seed);
    let corner = DVec3::new(3.0, -5.0, 7.0) * R;
    (0..n)
        .map(|_| corner + DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 20.0 * R)
        .collect()
}

#[test]
fn the_raster_counts_the_projected_area_as_the_measurement_does() {
    let r = R;
    for n in [1, 2, 63, 64, 65, 300] {
        let p = scattered(n, n as u64);
        let lo = p.iter().fold(p[0], |a, b| a.min(*b));
        let hi = p.iter().fold(p[0], |a, b| a.max(*b));
        let grid = Raster::new([lo.x, lo.y], [hi.x, hi.y], r);
        let mut bits = vec![0u32; grid.words()];
        row_raster(&p, r, &grid, &mut bits);
        let area = row_area(&bits) as f64 * grid.pixel * grid.pixel;
        assert_eq!(area, projected_area(&p, r), "{n} monomers");
    }
}

#[test]
fn the_profile_in_blocks_is_the_sequential_profile_to_rounding() {
    let r = R;
    let p = scattered(300, 3);
    let z: Vec<f64> = p.iter().map(|p| p.z).collect();
    // Slabs from 6 radii (one below the lowest centre's bottom) to 29 radii.
    let (bottom, top, area) = (6.0 * r, 29.0 * r, 400.0 * r * r);
    let slabs = Slabs::between(bottom, top, 2.0 * r);
    let blocks = z.len().div_ceil(REDUCE_BLOCK);
    let volumes = row_profile_final(&row_profile(&z, r, &slabs), blocks, slabs.count);
    let ours = slabs.profile(&volumes, area);
    let theirs = slab_profile(z.iter().copied(), r, area, bottom, top, 2.0 * r);
    assert_eq!(ours.len(), theirs.len());
    for (a, b) in ours.iter().zip(&theirs) {
        assert_eq!(a.0, b.0);
        assert!(
            (a.1 - b.1).abs() <= 1e-13 * b.1.abs().max(1e-3),
            "{a:?} {b:?}"
        );
    }
    // Every monomer lies within the slabs: the volumes add up to N spheres.
    let total: f64 = volumes.iter().sum();
    assert!((total / (300.0 * sphere_volume(r)) - 1.0).abs() < 1e-12);
}

/// The state of a 300-monomer uni run (5 m/s) after 2000 steps: monomers moving and spinning,
/// in contact with each other and with both plates.
fn compressed_state() -> dustdem::state::State {
    let text = "[sample]\nmonomers = 300\nfootprint = \"cylinder\"\nseed = 2\n[experiment]\n\
                kind = \"uni\"\nwall_speed_m_s = 5.0\nphi_stop = 0.7\nmax_steps = 2000\n\
                average_steps = 100\n[integration]\ndt_ns = 0.3\n";
    let config = Config::parse(text, "test").unwrap();
    let mut run = Compression::with_engine(&config, CpuEngine::new).unwrap();
    run.run(&mut |_| Ok(())).unwrap();
    run.engine.state().into_owned()
}

#[test]
fn the_row_energies_and_extent_are_the_energy_report_and_the_measured_area() {
    let state = compressed_state();
    assert!(state.contacts.pair_contact_count() > 100 && state.contacts.wall_contact_count() > 10);
    let measures = state.row_measures(&RowRequest {
        slabs: None,
        projected_area: true,
    });
    // The raster spans the extent the blocks reduce (least and greatest x, y of the centres).
    let r = state.law.radius;
    assert_eq!(
        measures.projected_area,
        Some(projected_area(&state.monomers.position, r))
    );
    let row = measures.energy;
    let report = state.energy();
    let pairs = [
        ("kinetic", row.kinetic, report.kinetic),
        ("rotational", row.rotational, report.rotational),
        (
            "normal potential",
            row.normal_potential,
            report.normal_potential,
        ),
        (
            "tangential potential",
            row.tangential_potential,
            report.tangential_potential,
        ),
    ];
    for (what, ours, theirs) in pairs {
        // Each term is nonzero here, so a term dropped or replaced by a constant shows.
        assert!(theirs.abs() > 0.0, "{what} is zero in the report");
        assert!(
            (ours - theirs).abs() <= 1e-12 * theirs.abs(),
            "{what}: row {ours:e}, report {theirs:e}"
        );
    }
    assert_eq!(
        (row.dissipated, row.wall_work),
        (report.dissipated, report.wall_work)
    );
}
