//! The state as bytes, for checkpoints: everything a step reads, so that a restored engine of
//! either backend continues bit for bit. An engine's own search structures (the CPU's neighbour
//! list, the device's candidate lists) are not stored: they are rebuilt, and contact formation
//! visits candidates in sorted order, so when they were built does not matter.

use super::{ContactTable, Dissipation, Monomers, PairContact, State, Wall, WallContact};
use crate::binary::{DecodeError, Decoder, Encoder};
use crate::material::ContactConstants;
use crate::model::ContactLaw;

fn constants(e: &mut Encoder, c: &ContactConstants) {
    for v in [
        c.reduced_radius,
        c.a0,
        c.delta0,
        c.f_c,
        c.delta_c,
        c.k_r,
        c.k_s,
        c.k_t,
        c.xi_crit,
        c.zeta_crit,
        c.phi_crit,
    ] {
        e.f64(v);
    }
}

fn read_constants(d: &mut Decoder) -> Result<ContactConstants, DecodeError> {
    let w = "wall constants";
    Ok(ContactConstants {
        reduced_radius: d.f64(w)?,
        a0: d.f64(w)?,
        delta0: d.f64(w)?,
        f_c: d.f64(w)?,
        delta_c: d.f64(w)?,
        k_r: d.f64(w)?,
        k_s: d.f64(w)?,
        k_t: d.f64(w)?,
        xi_crit: d.f64(w)?,
        zeta_crit: d.f64(w)?,
        phi_crit: d.f64(w)?,
    })
}

fn invalid(d: &Decoder, what: &str, problem: String) -> DecodeError {
    DecodeError {
        what: what.to_string(),
        offset: d.offset,
        problem,
    }
}

impl State {
    pub fn encode(&self, e: &mut Encoder) {
        e.f64(self.dt);
        e.u64(self.step);
        e.f64(self.time);
        e.f64(self.wall_work);
        for v in self.tally.channels() {
            e.f64(v);
        }
        let m = &self.monomers;
        for v in [
            &m.position,
            &m.velocity,
            &m.angular_velocity,
            &m.force,
            &m.torque,
            &m.damping_force,
        ] {
            e.vec3s(v);
        }
        e.f64s(&m.inverse_mass_scale);
        e.f64s(&m.inverse_inertia_scale);
        e.u32s(&m.id);
        let c = &self.contacts;
        e.u64(c.pair_slots as u64);
        e.u64(c.wall_slots as u64);
        e.u32s(&c.pair_count);
        e.u32s(&c.wall_count);
        for i in 0..m.len() {
            for p in c.pairs_of(i) {
                e.u32(p.partner);
                e.vec3(p.n1);
                e.vec3(p.n2);
                e.f64(p.twist);
            }
            for w in c.walls_of(i) {
                e.u32(w.wall);
                e.vec3(w.n1);
                e.vec3(w.anchor);
                e.f64(w.twist);
            }
        }
        e.u64(self.walls.len() as u64);
        for w in &self.walls {
            e.bytes_with_len(w.name.as_bytes());
            e.vec3(w.point);
            e.vec3(w.normal);
            e.vec3(w.velocity);
            constants(e, &w.constants);
        }
        e.vec3s(&self.wall_force);
        e.vec3s(&self.wall_damping);
    }

    /// Restores a state written by [`State::encode`]; `law` comes from the checkpoint's config.
    pub fn decode(law: ContactLaw, d: &mut Decoder) -> Result<State, DecodeError> {
        let dt = d.f64("time step")?;
        let step = d.u64("step")?;
        let time = d.f64("time")?;
        let wall_work = d.f64("wall work")?;
        let t = "dissipation tally";
        let tally = Dissipation {
            breaking: d.f64(t)?,
            forming: d.f64(t)?,
            damping: d.f64(t)?,
            rolling: d.f64(t)?,
            sliding: d.f64(t)?,
            twisting: d.f64(t)?,
            walls: d.f64(t)?,
        };
        let monomers = Monomers {
            position: d.vec3s("positions")?,
            velocity: d.vec3s("velocities")?,
            angular_velocity: d.vec3s("angular velocities")?,
            force: d.vec3s("forces")?,
            torque: d.vec3s("torques")?,
            damping_force: d.vec3s("damping forces")?,
            inverse_mass_scale: d.f64s("inverse mass scales")?,
            inverse_inertia_scale: d.f64s("inverse inertia scales")?,
            id: d.u32s("monomer ids")?,
        };
        let n = monomers.position.len();
        let lengths = [
            monomers.velocity.len(),
            monomers.angular_velocity.len(),
            monomers.force.len(),
            monomers.torque.len(),
            monomers.damping_force.len(),
            monomers.inverse_mass_scale.len(),
            monomers.inverse_inertia_scale.len(),
            monomers.id.len(),
        ];
        if lengths.iter().any(|&l| l != n) {
            return Err(invalid(
                d,
                "monomer arrays",
                format!("lengths {lengths:?} differ from {n} positions"),
            ));
        }
        if monomers.index_of_ids().is_none() {
            return Err(invalid(
                d,
                "monomer ids",
                format!("not a permutation of 0..{n}"),
            ));
        }
        let pair_slots = d.u64("pair slots")? as usize;
        let wall_slots = d.u64("wall slots")? as usize;
        if !(1..=64).contains(&pair_slots) || !(1..=6).contains(&wall_slots) {
            return Err(invalid(
                d,
                "slot counts",
                format!("{pair_slots} pair / {wall_slots} wall slots are out of range"),
            ));
        }
        let mut contacts = ContactTable::new(n, pair_slots, wall_slots);
        let pair_count = d.u32s("pair contact counts")?;
        let wall_count = d.u32s("wall contact counts")?;
        if pair_count.len() != n || wall_count.len() != n {
            return Err(invalid(
                d,
                "contact counts",
                format!("expected {n} entries"),
            ));
        }
        for i in 0..n {
            if pair_count[i] as usize > pair_slots || wall_count[i] as usize > wall_slots {
                return Err(invalid(
                    d,
                    "contact counts",
                    format!("monomer {i} has more contacts than slots"),
                ));
            }
            for s in 0..pair_count[i] as usize {
                let partner = d.u32("pair contact")?;
                if partner as usize >= n || partner as usize <= i {
                    return Err(invalid(
                        d,
                        "pair contact",
                        format!("monomer {i} has partner {partner}"),
                    ));
                }
                contacts.pair[i * pair_slots + s] = PairContact {
                    partner,
                    n1: d.vec3("pair contact")?,
                    n2: d.vec3("pair contact")?,
                    twist: d.f64("pair contact")?,
                };
            }
            for s in 0..wall_count[i] as usize {
                contacts.wall[i * wall_slots + s] = WallContact {
                    wall: d.u32("wall contact")?,
                    n1: d.vec3("wall contact")?,
                    anchor: d.vec3("wall contact")?,
                    twist: d.f64("wall contact")?,
                };
            }
        }
        contacts.pair_count = pair_count;
        contacts.wall_count = wall_count;
        let nw = d.u64("wall count")? as usize;
        if nw > 64 {
            return Err(invalid(d, "wall count", format!("{nw} walls")));
        }
        let mut walls = Vec::with_capacity(nw);
        for _ in 0..nw {
            let name = String::from_utf8_lossy(d.bytes_with_len("wall name")?).into_owned();
            walls.push(Wall {
                name,
                point: d.vec3("wall")?,
                normal: d.vec3("wall")?,
                velocity: d.vec3("wall")?,
                constants: read_constants(d)?,
            });
        }
        for i in 0..n {
            if contacts.walls_of(i).iter().any(|c| c.wall as usize >= nw) {
                return Err(invalid(
                    d,
                    "wall contact",
                    format!("monomer {i} touches a wall that does not exist"),
                ));
            }
        }
        let wall_force = d.vec3s("wall forces")?;
        let wall_damping = d.vec3s("wall damping forces")?;
        if wall_force.len() != nw || wall_damping.len() != nw {
            return Err(invalid(d, "wall forces", format!("expected {nw} entries")));
        }
        Ok(State {
            law,
            dt,
            monomers,
            contacts,
            walls,
            tally,
            wall_work,
            wall_force,
            wall_damping,
            step,
            time,
        })
    }
}
