//! Contact maintenance pass: breaks stretched contacts (δ < −δ_c) and forms new ones (δ ≥ 0),
//! keeping the history (pointers, twist, wall anchor) of every contact that persists.

use super::forces::pair_step_energy;
use crate::state::{ContactTable, Dissipation, Monomers, PairContact, Wall, WallContact};
use super::walls::wall_step_energy;
use super::EngineError;
use crate::model::normal::jkr_potential_at_overlap;
use crate::model::{rolling, sliding, twisting, wall as wall_law, ContactLaw};
use glam::DVec3;

/// Potential energy held by a monomer–monomer contact (normal + tangential) [erg].
pub fn pair_contact_potential(law: &ContactLaw, x1: DVec3, x2: DVec3, c: &PairContact) -> f64 {
    let k = &law.pair;
    let d = x1 - x2;
    let distance = d.length();
    let nc = d / distance;
    let delta = 2.0 * law.radius - distance;
    let xi = rolling::rolling_displacement(c.n1, c.n2, k.reduced_radius);
    let zeta = sliding::sliding_displacement(c.n1, c.n2, nc, law.radius, law.radius);
    jkr_potential_at_overlap(delta / k.delta0, k.f_c, k.delta0)
        + rolling::rolling_potential(xi, k.k_r)
        + sliding::sliding_potential(zeta, k.k_s)
        + twisting::twisting_potential(c.twist, k.k_t)
}

/// Potential energy held by a monomer–wall contact [erg].
pub fn wall_contact_potential(radius: f64, x: DVec3, wall: &Wall, c: &WallContact) -> f64 {
    let k = &wall.constants;
    let delta = wall_law::wall_overlap(x, wall.point, wall.normal, radius);
    let xi = wall_law::wall_rolling_displacement(c.n1, wall.normal, radius);
    let zeta = wall_law::wall_sliding_displacement(x, c.n1, radius, c.anchor, wall.normal);
    jkr_potential_at_overlap(delta / k.delta0, k.f_c, k.delta0)
        + rolling::rolling_potential(xi, k.k_r)
        + sliding::sliding_potential(zeta, k.k_s)
        + twisting::twisting_potential(c.twist, k.k_t)
}

/// Removes broken contacts and adds new ones; `candidates` are the neighbour-list pairs.
pub fn update_contacts(
    law: &ContactLaw,
    dt: f64,
    monomers: &Monomers,
    walls: &[Wall],
    candidates: &[(u32, u32)],
    table: &mut ContactTable,
    tally: &mut Dissipation,
) -> Result<(), EngineError> {
    let r = law.radius;
    let pos = &monomers.position;
    let n = monomers.len();
    // Break.
    for i in 0..n {
        let mut slot = 0;
        while slot < table.pair_count[i] as usize {
            let idx = i * table.pair_slots + slot;
            let c = table.pair[idx];
            let delta = 2.0 * r - (pos[i] - pos[c.partner as usize]).length();
            if delta < -law.pair.delta_c {
                tally.breaking += pair_step_energy(law, monomers, dt, i, &c);
                let last = i * table.pair_slots + table.pair_count[i] as usize - 1;
                table.pair[idx] = table.pair[last];
                table.pair_count[i] -= 1;
            } else {
                slot += 1;
            }
        }
        let mut slot = 0;
        while slot < table.wall_count[i] as usize {
            let idx = i * table.wall_slots + slot;
            let c = table.wall[idx];
            let w = &walls[c.wall as usize];
            let delta = wall_law::wall_overlap(pos[i], w.point, w.normal, r);
            if delta < -w.constants.delta_c {
                tally.walls += wall_step_energy(law, monomers, dt, i, w, &c);
                let last = i * table.wall_slots + table.wall_count[i] as usize - 1;
                table.wall[idx] = table.wall[last];
                table.wall_count[i] -= 1;
            } else {
                slot += 1;
            }
        }
    }
    // Form.
    for &(i, j) in candidates {
        let (iu, ju) = (i as usize, j as usize);
        let d = pos[iu] - pos[ju];
        let distance = d.length();
        if 2.0 * r - distance < 0.0 || table.has_pair(iu, j) {
            continue;
        }
        if table.pair_count[iu] as usize >= table.pair_slots {
            return Err(EngineError::SlotOverflow {
                kind: "monomer-monomer",
                step: 0,
                monomer: iu,
                limit: table.pair_slots,
            });
        }
        let nc = d / distance;
        let c = PairContact {
            partner: j,
            n1: -nc,
            n2: nc,
            twist: 0.0,
        };
        tally.forming -= pair_step_energy(law, monomers, dt, iu, &c);
        table.pair[iu * table.pair_slots + table.pair_count[iu] as usize] = c;
        table.pair_count[iu] += 1;
    }
    for i in 0..n {
        for (w_idx, w) in walls.iter().enumerate() {
            let w_id = w_idx as u32;
            if wall_law::wall_overlap(pos[i], w.point, w.normal, r) < 0.0 || table.has_wall(i, w_id)
            {
                continue;
            }
            if table.wall_count[i] as usize >= table.wall_slots {
                return Err(EngineError::SlotOverflow {
                    kind: "monomer-wall",
                    step: 0,
                    monomer: i,
                    limit: table.wall_slots,
                });
            }
            let c = WallContact {
                wall: w_id,
                n1: -w.normal,
                anchor: pos[i] - w.normal * r,
                twist: 0.0,
            };
            tally.walls -= wall_step_energy(law, monomers, dt, i, w, &c);
            table.wall[i * table.wall_slots + table.wall_count[i] as usize] = c;
            table.wall_count[i] += 1;
        }
    }
    Ok(())
}
