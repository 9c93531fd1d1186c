//! Contact maintenance pass: breaks stretched contacts (δ < −δ_c) and forms new ones (δ ≥ 0),
//! keeping the history (pointers, twist, wall anchor) of every contact that persists.

use crate::engine::EngineError;
use crate::model::{wall as wall_law, ContactLaw};
use crate::state::interaction::{pair_step_energy, wall_step_energy};
use crate::state::{ContactTable, Dissipation, Monomers, PairContact, Wall, WallContact};

/// Removes broken contacts and adds new ones; `candidates` are the neighbour-list pairs.
pub fn contacts(
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
