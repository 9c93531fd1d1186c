//! The force pass's contact law four contacts at a time gives the bits of the scalar code, on
//! every lane choice the processor runs: contacts from far beyond the JKR branch end (no Newton
//! iteration) through pulled-apart and squeezed ones (few to many iterations, so lanes of one
//! batch stop after different iterations), owners with 0 to 12 contacts (batches that span
//! owners, a last batch of fewer than four), and each damping law.

use dustdem::backend::cpu::lanes::ContactLanes;
use dustdem::backend::cpu::law::corrections_lanes::{chunk_corrections, Noted};
use dustdem::backend::cpu::law::forces_lanes::{chunk_forces, radius_ratios};
use dustdem::backend::cpu::law::integrate_lanes::{chunk_pairs, PairChunk, StepForm};
use dustdem::backend::cpu::law::results::PairResult;
use dustdem::backend::cpu::law::results::{OwnerChunk, ResultPlaces};
use dustdem::backend::cpu::prefetch::Prefetching;
use dustdem::material::Material;
use dustdem::model::normal::{jkr_contact_radius_ratio, D_MIN};
use dustdem::model::{ContactLaw, Damping, ModelOptions};
use dustdem::rng::Rng;
use dustdem::state::{Dissipation, Monomers, PairContact};
use glam::DVec3;

const SLOTS: usize = 12;
/// Time step of the contact tests: large enough that pointers turn measurably and some
/// contacts cross their limits.
const DT: f64 = 3e-10;

fn law(damping: Damping) -> ContactLaw {
    let options = ModelOptions {
        damping,
        ..ModelOptions::default()
    };
    ContactLaw::new(&Material::silicate(), &options)
}

fn unit(rng: &mut Rng) -> DVec3 {
    DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize()
}

/// `n` owners around the origin, each with 0 to 12 contacts to partners of its own (appended
/// after the owners, so no contact moves another), placed at a separation 2r − dδ₀ with d
/// spread from below the branch end to deep overlap; pointers `spread` (log-uniform up to it)
/// away from their equilibrium directions.
fn contacts(
    law: &ContactLaw,
    n: usize,
    seed: u64,
    spread: f64,
) -> (Monomers, Vec<PairContact>, Vec<u32>) {
    let mut rng = Rng::new(seed);
    let r = law.radius;
    let delta0 = law.pair.delta0;
    let mut positions: Vec<DVec3> = (0..n).map(|_| unit(&mut rng) * (1e3 * r)).collect();
    let mut contacts = vec![];
    let mut counts = vec![];
    for i in 0..n {
        let count = (rng.uniform() * (SLOTS + 1) as f64) as usize % (SLOTS + 1);
        counts.push(count as u32);
        for _ in 0..count {
            let d = rng.uniform_range(D_MIN - 2.0, 40.0);
            let nc = unit(&mut rng);
            positions.push(positions[i] - nc * (2.0 * r - d * delta0));
            let mut tilt = || unit(&mut rng) * (spread * 10f64.powf(-3.0 * rng.uniform()));
            let (n1, n2) = ((-nc + tilt()).normalize(), (nc + tilt()).normalize());
            contacts.push(PairContact {
                partner: positions.len() as u32 - 1,
                n1,
                n2,
                // φ_crit = 1/(16π) = 0.0199: a few contacts beyond it.
                twist: rng.uniform_range(-0.022, 0.022),
            });
        }
    }
    let total = positions.len();
    let empty = PairContact {
        partner: 0,
        n1: DVec3::X,
        n2: DVec3::X,
        twist: 0.0,
    };
    let mut rows = vec![empty; total * SLOTS];
    let mut next = contacts.into_iter();
    for (i, &count) in counts.iter().enumerate() {
        for s in 0..count as usize {
            rows[i * SLOTS + s] = next.next().unwrap();
        }
    }
    counts.resize(total, 0);
    let mut monomers = Monomers::new(positions);
    for v in monomers.velocity.iter_mut() {
        *v = DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 10.0;
    }
    (monomers, rows, counts)
}

fn evaluate(
    lanes: ContactLanes,
    law: &ContactLaw,
    m: &Monomers,
    rows: &[PairContact],
    counts: &[u32],
) -> Vec<PairResult> {
    let total = counts.iter().sum::<u32>() as usize;
    let mut results = vec![PairResult::default(); total];
    let chunk = OwnerChunk {
        rows,
        slots: SLOTS,
        counts,
        first: 0,
        prefetching: Prefetching::RowsAndPartners,
    };
    chunk_forces(lanes, law, m, chunk, one_after_another(&mut results));
    results
}

fn bits(results: &[PairResult]) -> Vec<u64> {
    results
        .iter()
        .flat_map(|r| [r.force, r.damping, r.torque_owner, r.torque_partner])
        .flat_map(|v| v.to_array())
        .map(f64::to_bits)
        .collect()
}

#[test]
fn every_lane_choice_gives_the_scalar_bits_for_each_damping_law() {
    let mut choices = vec![ContactLanes::Portable];
    if ContactLanes::detected() == ContactLanes::Avx2 {
        choices.push(ContactLanes::Avx2);
    }
    eprintln!("lanes tested: {choices:?} against scalar");
    let laws = [
        Damping::None,
        Damping::Viscous { kappa: 1e-6 },
        Damping::Viscoelastic { t_vis: 5e-12 },
    ];
    for (seed, damping) in laws.into_iter().enumerate() {
        let law = law(damping);
        let (m, rows, counts) = contacts(&law, 97, seed as u64 + 1, 1.0);
        let reference = evaluate(ContactLanes::Scalar, &law, &m, &rows, &counts);
        assert!(reference.len() > 400, "{} contacts", reference.len());
        assert!(reference.iter().all(|r| r.force.is_finite()));
        for &lanes in &choices {
            let got = evaluate(lanes, &law, &m, &rows, &counts);
            assert_eq!(got.len(), reference.len());
            assert!(bits(&got) == bits(&reference), "{lanes:?}, {damping:?}");
        }
    }
}

#[test]
fn the_masked_newton_iteration_stops_each_lane_where_the_scalar_loop_stops() {
    // Lanes that need different numbers of iterations side by side, including one below the
    // branch end (none), one at it, one at equilibrium (d = 1) and deep overlaps (many).
    let cases = [
        [D_MIN - 1.0, 1.0, 1e4, 0.3],
        [D_MIN, -0.5, 3.0, 1e8],
        [0.999_999, 1e-9, -0.825, 250.0],
    ];
    // Four at a time: one batch, all of it in the lanes.
    let mut choices = vec![ContactLanes::Portable];
    if ContactLanes::detected() == ContactLanes::Avx2 {
        choices.push(ContactLanes::Avx2);
    }
    for d in cases {
        for &isa in &choices {
            let mut lanes = d;
            radius_ratios(isa, &mut lanes);
            for (k, &dk) in d.iter().enumerate() {
                let scalar = jkr_contact_radius_ratio(dk);
                assert_eq!(lanes[k].to_bits(), scalar.to_bits(), "{isa:?}, d = {dk}");
            }
        }
    }
    // The wall contacts' ratios found in place, a last batch of fewer than four included.
    let all: Vec<f64> = cases.iter().flatten().copied().chain([7.5, 0.5]).collect();
    for lanes in [
        ContactLanes::Scalar,
        ContactLanes::Portable,
        ContactLanes::detected(),
    ] {
        let mut found = all.clone();
        radius_ratios(lanes, &mut found);
        for (x, &d) in found.iter().zip(&all) {
            let scalar = jkr_contact_radius_ratio(d);
            assert_eq!(x.to_bits(), scalar.to_bits(), "{lanes:?}, d = {d}");
        }
    }
}

/// Every pointer component and twist of `rows`, as bits.
fn row_bits(rows: &[PairContact]) -> Vec<u64> {
    rows.iter()
        .flat_map(|c| [c.n1.to_array(), c.n2.to_array(), [c.twist; 3]])
        .flatten()
        .map(f64::to_bits)
        .collect()
}

fn advanced(
    lanes: ContactLanes,
    law: &ContactLaw,
    m: &Monomers,
    rows: &[PairContact],
    counts: &[u32],
) -> (Vec<u64>, Vec<u32>) {
    let mut rows = rows.to_vec();
    let mut tests = vec![u32::MAX; counts.len()];
    let chunk = PairChunk {
        rows: &mut rows,
        slots: SLOTS,
        counts,
        first: 0,
        prefetching: Prefetching::RowsAndPartners,
    };
    // dt large enough that pointers turn measurably and some contacts cross their limits.
    chunk_pairs(lanes, law, DT, m, chunk, &mut tests, None);
    (row_bits(&rows), tests)
}

#[test]
fn the_pair_half_of_the_leap_frog_gives_the_scalar_bits_in_lanes() {
    let law = law(Damping::Viscous { kappa: 1e-6 });
    let (mut m, rows, counts) = contacts(&law, 131, 7, 1e-3);
    let mut rng = Rng::new(99);
    for (k, w) in m.angular_velocity.iter_mut().enumerate() {
        // Some monomers do not spin: their pointers must come back unchanged.
        *w = match k % 5 {
            0 => DVec3::ZERO,
            _ => DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 1e5,
        };
    }
    let (reference, reference_tests) = advanced(ContactLanes::Scalar, &law, &m, &rows, &counts);
    // The tests see both outcomes, so a wrong comparison shows.
    let beyond = reference_tests.iter().filter(|t| *t & 2 != 0).count();
    let breaks = reference_tests.iter().filter(|t| *t & 1 != 0).count();
    let owners = counts.iter().filter(|&&c| c > 0).count();
    eprintln!("{owners} owners with contacts: {beyond} beyond a limit, {breaks} breaking");
    assert!(beyond > 10 && beyond + 10 < owners, "{beyond} of {owners}");
    assert!(breaks > 10 && breaks + 10 < owners, "{breaks} of {owners}");
    assert!(reference_tests.iter().all(|&t| t <= 3));
    for lanes in [ContactLanes::Portable, ContactLanes::detected()] {
        let (bits, tests) = advanced(lanes, &law, &m, &rows, &counts);
        assert!(bits == reference, "{lanes:?}: pointers and twist");
        assert_eq!(tests, reference_tests, "{lanes:?}: tests");
    }
}

/// The contacts of `contacts(law, 131, 11, 1e-2)` with every monomer spinning at random
/// (about 10⁵ rad/s, seeded by `seed`), so that corrections change the step energies.
fn spinning_contacts(law: &ContactLaw, seed: u64) -> (Monomers, Vec<PairContact>, Vec<u32>) {
    let (mut m, rows, counts) = contacts(law, 131, 11, 1e-2);
    let mut rng = Rng::new(seed);
    for w in m.angular_velocity.iter_mut() {
        *w = DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 1e5;
    }
    (m, rows, counts)
}

fn corrected(
    lanes: ContactLanes,
    law: &ContactLaw,
    m: &Monomers,
    rows: &[PairContact],
    counts: &[u32],
    booked: bool,
) -> (Vec<u64>, Dissipation) {
    let mut rows = rows.to_vec();
    let mut tally = Dissipation::default();
    let owners = rows
        .chunks_mut(SLOTS)
        .zip(counts)
        .enumerate()
        .map(|(i, (row, &count))| (i, &mut row[..count as usize]));
    chunk_corrections(lanes, law, DT, m, owners, booked.then_some(&mut tally));
    (row_bits(&rows), tally)
}

#[test]
fn the_corrections_book_the_scalar_dissipation_bits_in_lanes() {
    let law = law(Damping::Viscous { kappa: 1e-6 });
    let (m, rows, counts) = spinning_contacts(&law, 3);
    let (reference, tally) = corrected(ContactLanes::Scalar, &law, &m, &rows, &counts, true);
    eprintln!("scalar tally: {tally:?}");
    // Every channel booked something, so a channel mixed up shows.
    assert!(tally.rolling != 0.0 && tally.sliding != 0.0 && tally.twisting != 0.0);
    for lanes in [ContactLanes::Portable, ContactLanes::detected()] {
        let (bits, got) = corrected(lanes, &law, &m, &rows, &counts, true);
        assert!(bits == reference, "{lanes:?}: corrected pointers and twist");
        for (a, b) in [
            (got.rolling, tally.rolling),
            (got.sliding, tally.sliding),
            (got.twisting, tally.twisting),
        ] {
            assert_eq!(a.to_bits(), b.to_bits(), "{lanes:?}: {got:?}");
        }
        assert_eq!(got, tally, "{lanes:?}: other channels untouched");
    }
}

#[test]
fn corrections_without_a_tally_leave_the_booked_corrections_bits_in_every_lane_choice() {
    let law = law(Damping::Viscous { kappa: 1e-6 });
    let (m, rows, counts) = spinning_contacts(&law, 5);
    let (reference, _) = corrected(ContactLanes::Scalar, &law, &m, &rows, &counts, true);
    assert!(reference != row_bits(&rows), "some contact was corrected");
    for lanes in [
        ContactLanes::Scalar,
        ContactLanes::Portable,
        ContactLanes::detected(),
    ] {
        let (bits, untouched) = corrected(lanes, &law, &m, &rows, &counts, false);
        assert!(bits == reference, "{lanes:?}: corrected pointers and twist");
        assert_eq!(
            untouched,
            Dissipation::default(),
            "{lanes:?}: nothing booked"
        );
    }
}

/// The pair half of the leap-frog in the CPU step's form (corrections applied and forces
/// evaluated as the contacts are advanced): rows, tests, the booked tally and the forces.
fn advanced_and_corrected(
    lanes: ContactLanes,
    law: &ContactLaw,
    m: &Monomers,
    rows: &[PairContact],
    counts: &[u32],
) -> (Vec<u64>, Vec<u32>, Dissipation, Vec<PairResult>) {
    let mut rows = rows.to_vec();
    let mut tests = vec![u32::MAX; counts.len()];
    let chunk = PairChunk {
        rows: &mut rows,
        slots: SLOTS,
        counts,
        first: 0,
        prefetching: Prefetching::RowsAndPartners,
    };
    let mut noted = Noted::with_room_for(rows_len(counts), true);
    let mut results = vec![PairResult::default(); rows_len(counts)];
    // The lanes book as they go (the scalar code ignores it and notes everything); what is
    // noted is booked after.
    let mut tally = Dissipation::default();
    let step = StepForm {
        noted: &mut noted,
        results: Some(one_after_another(&mut results)),
        booked: Some(&mut tally),
    };
    chunk_pairs(lanes, law, DT, m, chunk, &mut tests, Some(step));
    noted.book(lanes, law, DT, m, &mut tally);
    (row_bits(&rows), tests, tally, results)
}

/// Results owner after owner, slot after slot.
fn one_after_another(results: &mut [PairResult]) -> ResultPlaces<'_> {
    ResultPlaces {
        results,
        starts: None,
        base: 0,
    }
}

fn rows_len(counts: &[u32]) -> usize {
    counts.iter().sum::<u32>() as usize
}

/// The device's order on the same contacts: advanced (`chunk_pairs` without corrections), the
/// monomers drifted, then every contact that does not break (δ < −δ_c, a breaking contact
/// leaves the table first) through the contacts pass's corrections, owner by owner in order,
/// then the forces pass (the scalar reference) on every contact.
fn advanced_then_corrected(
    law: &ContactLaw,
    m: &Monomers,
    rows: &[PairContact],
    counts: &[u32],
) -> (Vec<u64>, Dissipation, Vec<PairResult>) {
    let mut rows = rows.to_vec();
    let mut tests = vec![0; counts.len()];
    let chunk = PairChunk {
        rows: &mut rows,
        slots: SLOTS,
        counts,
        first: 0,
        prefetching: Prefetching::RowsAndPartners,
    };
    chunk_pairs(ContactLanes::Scalar, law, DT, m, chunk, &mut tests, None);
    let mut drifted = m.clone();
    for (x, v) in drifted.position.iter_mut().zip(&m.velocity) {
        *x += *v * DT;
    }
    let x = &drifted.position;
    let mut tally = Dissipation::default();
    let staying = rows
        .chunks_mut(SLOTS)
        .zip(counts)
        .enumerate()
        .flat_map(|(i, (row, &count))| row[..count as usize].iter_mut().map(move |c| (i, c)))
        .filter(|(i, c)| {
            let delta = 2.0 * law.radius - (x[*i] - x[c.partner as usize]).length();
            delta >= -law.pair.delta_c
        })
        .map(|(i, c)| (i, std::slice::from_mut(c)));
    chunk_corrections(
        ContactLanes::Scalar,
        law,
        DT,
        &drifted,
        staying,
        Some(&mut tally),
    );
    let mut results = vec![PairResult::default(); rows_len(counts)];
    let chunk = OwnerChunk {
        rows: &rows[..],
        slots: SLOTS,
        counts,
        first: 0,
        prefetching: Prefetching::Off,
    };
    let places = one_after_another(&mut results);
    chunk_forces(ContactLanes::Scalar, law, &drifted, chunk, places);
    (row_bits(&rows), tally, results)
}

#[test]
fn corrections_made_as_the_pairs_advance_are_the_contacts_pass_corrections_in_every_lane_choice() {
    let law = law(Damping::Viscous { kappa: 1e-6 });
    let (m, rows, counts) = spinning_contacts(&law, 21);
    let (reference, tests, tally, forces) =
        advanced_and_corrected(ContactLanes::Scalar, &law, &m, &rows, &counts);
    eprintln!("tally {tally:?}");
    assert!(tally.rolling != 0.0 && tally.sliding != 0.0 && tally.twisting != 0.0);
    // Owners with breaking contacts keep that test; none is listed for corrections any more.
    assert!(tests.iter().filter(|&&t| t == 1).count() > 10);
    assert!(tests.iter().all(|&t| t <= 1), "no test says beyond");
    let (device_order, device_tally, device_forces) =
        advanced_then_corrected(&law, &m, &rows, &counts);
    assert!(reference == device_order, "the contacts pass's corrections");
    assert_eq!(tally, device_tally, "the same drops in the same order");
    let result_bits = |r: &[PairResult]| format!("{r:?}");
    assert_eq!(result_bits(&forces), result_bits(&device_forces), "forces");
    for lanes in [ContactLanes::Portable, ContactLanes::detected()] {
        let (bits, got_tests, got, got_forces) =
            advanced_and_corrected(lanes, &law, &m, &rows, &counts);
        assert!(bits == reference, "{lanes:?}: pointers and twist");
        assert_eq!(result_bits(&got_forces), result_bits(&forces), "{lanes:?}");
        assert_eq!(got_tests, tests, "{lanes:?}: tests");
        let channels = |d: &Dissipation| [d.rolling, d.sliding, d.twisting].map(f64::to_bits);
        assert_eq!(channels(&got), channels(&tally), "{lanes:?}: {got:?}");
    }
}
