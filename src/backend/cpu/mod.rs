//! CPU reference backend (f64): the same passes, in the same order, as the GPU step script.
//!
//! One step: `integrate` (kick, pointers, twist, drift) → `neighbours` (refresh when stale) →
//! `contacts` (break, form) → `forces` (monomer pairs) → `walls` → work bookkeeping.

pub mod contacts;
pub mod forces;
pub mod integrate;
pub mod neighbours;
pub mod walls;

use crate::model::ContactLaw;
use glam::DVec3;
use crate::state::{ContactTable, Dissipation, Monomers, Wall};
use neighbours::NeighbourList;
use std::fmt;

/// Contact slots per monomer for partners of higher index (equal spheres touch at most 12).
pub const DEFAULT_PAIR_SLOTS: usize = 12;
/// Wall contact slots per monomer (a box corner touches 3 walls).
pub const DEFAULT_WALL_SLOTS: usize = 3;

#[derive(Clone, Debug, PartialEq)]
pub enum EngineError {
    SlotOverflow {
        kind: &'static str,
        step: u64,
        monomer: usize,
        limit: usize,
    },
    NonFinite {
        step: u64,
        monomer: usize,
    },
    /// Two monomers (or a monomer and a wall) overlap by more than half a radius: the time
    /// step is far too large or the state is corrupt.
    RunawayOverlap {
        step: u64,
        monomer: usize,
        partner: String,
        overlap: f64,
    },
}

impl fmt::Display for EngineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EngineError::SlotOverflow {
                kind,
                step,
                monomer,
                limit,
            } => write!(
                f,
                "at step {step}, monomer {monomer} needs more than {limit} {kind} contact slots; raise \
                 [integration] {} in the config",
                if *kind == "monomer-wall" {
                    "wall_slots"
                } else {
                    "pair_slots"
                }
            ),
            EngineError::NonFinite { step, monomer } => write!(
                f,
                "non-finite position or velocity of monomer {monomer} at step {step} \
                 (time step too large or overlapping monomers?)"
            ),
            EngineError::RunawayOverlap {
                step,
                monomer,
                partner,
                overlap,
            } => write!(
                f,
                "runaway overlap at step {step}: monomer {monomer} and {partner} overlap by \
                 {overlap:.3e} cm, more than half a radius (time step too large?)"
            ),
        }
    }
}

impl std::error::Error for EngineError {}

/// Mechanical energy at the current (synchronised) time, plus what has left it [erg].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyReport {
    pub kinetic: f64,
    pub rotational: f64,
    /// JKR potentials of all contacts (monomer–monomer and monomer–wall).
    pub normal_potential: f64,
    /// Rolling + sliding + twisting potentials of all contacts.
    pub tangential_potential: f64,
    pub dissipated: Dissipation,
    /// Work done on the monomers by moving walls.
    pub wall_work: f64,
}

impl EnergyReport {
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.rotational + self.normal_potential + self.tangential_potential
    }

    /// Conserved: mechanical + dissipated − wall work.
    pub fn balance(&self) -> f64 {
        self.mechanical() + self.dissipated.total() - self.wall_work
    }
}

/// The whole simulation state of the CPU backend.
#[derive(Clone, Debug)]
pub struct CpuEngine {
    pub law: ContactLaw,
    pub dt: f64,
    pub monomers: Monomers,
    pub contacts: ContactTable,
    pub walls: Vec<Wall>,
    pub neighbours: NeighbourList,
    pub tally: Dissipation,
    pub wall_work: f64,
    /// Total force each wall exerts on the monomers, at the current time.
    pub wall_force: Vec<DVec3>,
    wall_damping: Vec<DVec3>,
    pub step: u64,
    pub time: f64,
    /// Wall-clock seconds spent in each pass, in [`PASS_NAMES`] order.
    pub pass_seconds: [f64; 5],
}

/// The passes of one step, in order.
pub const PASS_NAMES: [&str; 5] = ["integrate", "neighbours", "contacts", "forces", "walls"];

impl CpuEngine {
    /// Builds the engine with synchronised initial velocities `monomers.velocity` (time 0):
    /// finds the initial contacts, computes the forces at time 0 and shifts the velocities back
    /// half a step, as the leap-frog stores them.
    pub fn new(
        law: ContactLaw,
        dt: f64,
        monomers: Monomers,
        walls: Vec<Wall>,
        pair_slots: usize,
        wall_slots: usize,
    ) -> Result<Self, EngineError> {
        let n = monomers.len();
        let nw = walls.len();
        let mut engine = CpuEngine {
            law,
            dt,
            contacts: ContactTable::new(n, pair_slots, wall_slots),
            neighbours: NeighbourList::new(
                2.0 * law.radius,
                crate::backend::cpu::neighbours::SKIN_RADII * law.radius,
            ),
            monomers,
            walls,
            tally: Dissipation::default(),
            wall_work: 0.0,
            wall_force: vec![DVec3::ZERO; nw],
            wall_damping: vec![DVec3::ZERO; nw],
            step: 0,
            time: 0.0,
            pass_seconds: [0.0; 5],
        };
        engine.neighbours.refresh(&engine.monomers.position);
        contacts::update_contacts(
            &engine.law,
            dt,
            &engine.monomers,
            &engine.walls,
            &engine.neighbours.pairs,
            &mut engine.contacts,
            &mut engine.tally,
        )?;
        // Contacts present at the start are part of the initial state, not a dissipation.
        engine.tally = Dissipation::default();
        engine.compute_forces();
        let half = 0.5 * dt;
        let (im, ii) = engine.inverse_mass_inertia();
        for i in 0..n {
            let m = &mut engine.monomers;
            m.velocity[i] -= m.force[i] * (half * im * m.inverse_mass_scale[i]);
            m.angular_velocity[i] -= m.torque[i] * (half * ii * m.inverse_inertia_scale[i]);
        }
        Ok(engine)
    }

    /// An engine holding exactly the given state, nothing recomputed: for reports (energy,
    /// momenta) and tests on a state that another backend computed. `wall_force` is the force
    /// each wall exerts now; the damping part of it is not kept, so a step taken from here books
    /// the first step's wall damping work from zero.
    #[allow(clippy::too_many_arguments)]
    pub fn from_state(
        law: ContactLaw,
        dt: f64,
        monomers: Monomers,
        contacts: ContactTable,
        walls: Vec<Wall>,
        tally: Dissipation,
        wall_work: f64,
        wall_force: Vec<DVec3>,
        step: u64,
        time: f64,
    ) -> Self {
        let nw = walls.len();
        CpuEngine {
            law,
            dt,
            neighbours: NeighbourList::new(
                2.0 * law.radius,
                crate::backend::cpu::neighbours::SKIN_RADII * law.radius,
            ),
            monomers,
            contacts,
            walls,
            tally,
            wall_work,
            wall_force,
            wall_damping: vec![DVec3::ZERO; nw],
            step,
            time,
            pass_seconds: [0.0; 5],
        }
    }

    fn inverse_mass_inertia(&self) -> (f64, f64) {
        (1.0 / self.law.mass, 1.0 / self.law.moment_of_inertia)
    }

    fn compute_forces(&mut self) {
        let clock = std::time::Instant::now();
        forces::pair_forces(
            &self.law,
            self.dt,
            &mut self.monomers,
            &mut self.contacts,
            &mut self.tally,
        );
        self.pass_seconds[3] += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        walls::wall_forces(
            &self.law,
            self.dt,
            &self.walls,
            &mut self.monomers,
            &mut self.contacts,
            &mut self.tally,
            &mut self.wall_force,
            &mut self.wall_damping,
        );
        self.pass_seconds[4] += clock.elapsed().as_secs_f64();
    }

    /// Advances one time step.
    pub fn step(&mut self) -> Result<(), EngineError> {
        let (im, ii) = self.inverse_mass_inertia();
        let clock = std::time::Instant::now();
        integrate::integrate(
            self.dt,
            im,
            ii,
            &mut self.monomers,
            &mut self.contacts,
            &mut self.walls,
        );
        self.pass_seconds[0] += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        self.neighbours.refresh(&self.monomers.position);
        self.pass_seconds[1] += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        contacts::update_contacts(
            &self.law,
            self.dt,
            &self.monomers,
            &self.walls,
            &self.neighbours.pairs,
            &mut self.contacts,
            &mut self.tally,
        )
        .map_err(|e| match e {
            EngineError::SlotOverflow {
                kind,
                monomer,
                limit,
                ..
            } => EngineError::SlotOverflow {
                kind,
                step: self.step + 1,
                monomer,
                limit,
            },
            other => other,
        })?;
        self.pass_seconds[2] += clock.elapsed().as_secs_f64();
        let damping_before = self.monomers.damping_force.clone();
        let wall_force_before = self.wall_force.clone();
        let wall_damping_before = self.wall_damping.clone();
        self.compute_forces();
        // Work over the step by the trapezoid rule, which matches the leap-frog's kinetic
        // energy change exactly up to a bounded, telescoping term.
        let dt = self.dt;
        let m = &self.monomers;
        let mut damping_work = 0.0;
        for i in 0..m.len() {
            damping_work += 0.5 * (damping_before[i] + m.damping_force[i]).dot(m.velocity[i] * dt);
        }
        for (w, wall) in self.walls.iter().enumerate() {
            let travel = wall.velocity * dt;
            damping_work -= 0.5 * (wall_damping_before[w] + self.wall_damping[w]).dot(travel);
            self.wall_work += 0.5 * (wall_force_before[w] + self.wall_force[w]).dot(travel);
        }
        self.tally.damping -= damping_work;
        self.step += 1;
        self.time += dt;
        if self.step.is_multiple_of(64) {
            self.check_state()?;
        }
        Ok(())
    }

    pub fn run(&mut self, steps: u64) -> Result<(), EngineError> {
        for _ in 0..steps {
            self.step()?;
        }
        Ok(())
    }

    /// Run-time guard: finite positions and velocities, and no overlap above half a radius.
    pub fn check_state(&self) -> Result<(), EngineError> {
        let m = &self.monomers;
        let r = self.law.radius;
        let limit = 0.5 * r;
        for i in 0..m.len() {
            if !(m.position[i].is_finite() && m.velocity[i].is_finite()) {
                return Err(EngineError::NonFinite {
                    step: self.step,
                    monomer: i,
                });
            }
        }
        for i in 0..m.len() {
            for c in self.contacts.pairs_of(i) {
                let overlap = 2.0 * r - (m.position[i] - m.position[c.partner as usize]).length();
                if overlap > limit {
                    return Err(EngineError::RunawayOverlap {
                        step: self.step,
                        monomer: i,
                        partner: format!("monomer {}", c.partner),
                        overlap,
                    });
                }
            }
            for c in self.contacts.walls_of(i) {
                let w = &self.walls[c.wall as usize];
                let overlap = crate::model::wall::wall_overlap(m.position[i], w.point, w.normal, r);
                if overlap > limit {
                    return Err(EngineError::RunawayOverlap {
                        step: self.step,
                        monomer: i,
                        partner: format!("the {} wall", w.name),
                        overlap,
                    });
                }
            }
        }
        Ok(())
    }

    /// Velocity of monomer i at the current time (the stored one is half a step behind).
    pub fn synchronized_velocity(&self, i: usize) -> DVec3 {
        let m = &self.monomers;
        m.velocity[i] + m.force[i] * (0.5 * self.dt / self.law.mass * m.inverse_mass_scale[i])
    }

    pub fn synchronized_angular_velocity(&self, i: usize) -> DVec3 {
        let m = &self.monomers;
        m.angular_velocity[i]
            + m.torque[i]
                * (0.5 * self.dt / self.law.moment_of_inertia * m.inverse_inertia_scale[i])
    }

    pub fn energy(&self) -> EnergyReport {
        let mut e = EnergyReport {
            dissipated: self.tally,
            wall_work: self.wall_work,
            ..Default::default()
        };
        let m = &self.monomers;
        for i in 0..m.len() {
            if m.inverse_mass_scale[i] > 0.0 {
                e.kinetic += 0.5 * self.law.mass * self.synchronized_velocity(i).length_squared();
            }
            if m.inverse_inertia_scale[i] > 0.0 {
                e.rotational += 0.5
                    * self.law.moment_of_inertia
                    * self.synchronized_angular_velocity(i).length_squared();
            }
        }
        let k = &self.law.pair;
        for i in 0..m.len() {
            for c in self.contacts.pairs_of(i) {
                let j = c.partner as usize;
                let total =
                    contacts::pair_contact_potential(&self.law, m.position[i], m.position[j], c);
                let d = m.position[i] - m.position[j];
                let normal = crate::model::normal::jkr_potential_at_overlap(
                    (2.0 * self.law.radius - d.length()) / k.delta0,
                    k.f_c,
                    k.delta0,
                );
                e.normal_potential += normal;
                e.tangential_potential += total - normal;
            }
            for c in self.contacts.walls_of(i) {
                let w = &self.walls[c.wall as usize];
                let total = contacts::wall_contact_potential(self.law.radius, m.position[i], w, c);
                let delta = crate::model::wall::wall_overlap(
                    m.position[i],
                    w.point,
                    w.normal,
                    self.law.radius,
                );
                let normal = crate::model::normal::jkr_potential_at_overlap(
                    delta / w.constants.delta0,
                    w.constants.f_c,
                    w.constants.delta0,
                );
                e.normal_potential += normal;
                e.tangential_potential += total - normal;
            }
        }
        e
    }

    /// Total linear momentum (synchronised velocities) of the free monomers.
    pub fn momentum(&self) -> DVec3 {
        (0..self.monomers.len())
            .map(|i| self.synchronized_velocity(i) * self.law.mass)
            .sum()
    }

    /// Total angular momentum about the origin: orbital plus spin.
    pub fn angular_momentum(&self) -> DVec3 {
        (0..self.monomers.len())
            .map(|i| {
                self.monomers.position[i].cross(self.synchronized_velocity(i) * self.law.mass)
                    + self.synchronized_angular_velocity(i) * self.law.moment_of_inertia
            })
            .sum()
    }
}

mod codec {
    //! The engine's full state as bytes, for checkpoints: everything a step reads, so that a
    //! restored engine continues bit for bit. The neighbour list is not stored: it is rebuilt,
    //! and contact formation visits candidates in sorted order, so its timing does not matter.

    use crate::state::{ContactTable, Dissipation, Monomers, PairContact, Wall, WallContact};
    use super::{CpuEngine, NeighbourList};
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

    impl CpuEngine {
        pub fn encode_state(&self, e: &mut Encoder) {
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

        /// Restores an engine written by [`CpuEngine::encode_state`]; `law` comes from the
        /// checkpoint's config.
        pub fn decode_state(law: ContactLaw, d: &mut Decoder) -> Result<CpuEngine, DecodeError> {
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
            ];
            if lengths.iter().any(|&l| l != n) {
                return Err(invalid(
                    d,
                    "monomer arrays",
                    format!("lengths {lengths:?} differ from {n} positions"),
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
            let mut neighbours = NeighbourList::new(
                2.0 * law.radius,
                crate::backend::cpu::neighbours::SKIN_RADII * law.radius,
            );
            neighbours.refresh(&monomers.position);
            Ok(CpuEngine {
                law,
                dt,
                monomers,
                contacts,
                walls,
                neighbours,
                tally,
                wall_work,
                wall_force,
                wall_damping,
                step,
                time,
                pass_seconds: [0.0; 5],
            })
        }
    }
}
