//! The CPU engine's executor of the step script (`backend::script`): each pass is the CPU
//! function of its entry point's name, on the engine's state and workspace. The match covers
//! every [`Kernel`], so an entry point added to the WGSL has no CPU engine until it has a twin.

use super::partner_index::RowChange;
use super::passes::contacts::{contacts, contacts_scanned};
use super::passes::forces::{forces, forces_corrections, forces_of_changed_rows};
use super::passes::integrate::{
    integrate_clear_work, integrate_drift, integrate_kick, integrate_pairs, integrate_pairs_step,
    integrate_start, NextKick,
};
use super::passes::neighbours::{mark_partners_of, neighbours, neighbours_list};
use super::passes::scan::{contacts_clear_tally, contacts_pair_tests, contacts_scan};
use super::passes::walls::{reduce_walls_final, wall_contacts, wall_forces};
use super::CpuEngine;
use crate::backend::script::Kernel;
use crate::engine::EngineError;

impl CpuEngine {
    /// Runs one pass of the script on the engine's state.
    ///
    /// The read passes (`reduce_diagnostics`, `row_*`) change nothing: the device runs them to
    /// fill the small block it reads back, the CPU reads its state directly through their
    /// twins in `state::reduction` and `state::rows`, so here they are no-ops.
    pub fn run_pass(&mut self, pass: Kernel) -> Result<(), EngineError> {
        if pass == Kernel::IntegrateKickWithWallSums {
            return self.integrate_kick_with_wall_sums();
        }
        let (im, ii) = (1.0 / self.law.mass, 1.0 / self.law.moment_of_inertia);
        let s = &mut self.state;
        let w = &mut self.workspace;
        let list = &mut self.neighbours;
        let (law, dt) = (s.law, s.dt);
        match pass {
            Kernel::IntegrateKick => integrate_kick(
                dt,
                im,
                ii,
                &mut s.monomers,
                &mut s.contacts,
                &s.walls,
                &mut w.pair_tests,
            ),
            Kernel::IntegrateKickWithWallSums => unreachable!("handled above"),
            Kernel::IntegratePairs => {
                integrate_pairs(&law, dt, &s.monomers, &mut s.contacts, &mut w.pair_tests)
            }
            Kernel::IntegrateDrift => integrate_drift(dt, &mut s.monomers, &mut s.walls, list),
            Kernel::IntegrateStart => integrate_start(dt, im, ii, &mut s.monomers),
            Kernel::IntegrateClearWork => integrate_clear_work(&mut s.tally, &mut s.wall_work),
            Kernel::Neighbours => neighbours(&s.monomers.position, list),
            Kernel::NeighboursList => neighbours_list(&s.monomers.position, list),
            Kernel::ContactsScan => contacts_scan(
                &law,
                &s.monomers,
                &s.walls,
                list,
                &s.contacts,
                &w.pair_tests,
                &mut w.work,
            ),
            Kernel::Contacts => return self.contacts_of_the_listed_owners(),
            Kernel::ContactsClearTally => contacts_clear_tally(&mut s.tally),
            Kernel::ContactsPairTests => {
                contacts_pair_tests(&law, &s.monomers, &s.contacts, &mut w.pair_tests)
            }
            Kernel::ForcesCorrections => {
                let d = forces_corrections(&law, dt, &s.monomers, &mut s.contacts, &w.work);
                s.tally.add(&d);
            }
            Kernel::Forces => {
                forces(&law, &s.monomers, &s.contacts, w);
                w.results_of_step = false;
            }
            Kernel::WallContacts => {
                let work = std::mem::take(&mut w.work);
                let d = wall_contacts(&law, dt, &s.walls, &s.monomers, &mut s.contacts, &work, w);
                w.work = work;
                s.tally.add(&d);
            }
            Kernel::WallForces => {
                wall_forces(dt, &s.walls, &mut s.monomers, &mut s.contacts, w, None)
            }
            Kernel::ReduceWallsFinal => reduce_walls_final(
                dt,
                &s.walls,
                w,
                &mut s.wall_force,
                &mut s.wall_damping,
                &mut s.tally,
                &mut s.wall_work,
            ),
            Kernel::ReduceDiagnostics
            | Kernel::RowSums
            | Kernel::RowSumsFinal
            | Kernel::RowProfile
            | Kernel::RowProfileFinal
            | Kernel::RowRaster
            | Kernel::RowArea => {}
        }
        Ok(())
    }

    /// One pass as the step runs it: `integrate_pairs` in its step form
    /// (`integrate_pairs_step`: the pair contacts' inelastic corrections applied, and their
    /// forces evaluated, where their pointers are advanced), `contacts_scan` and `contacts`
    /// in one sweep (`contacts_scanned`, run at `contacts_scan`), `forces` then only for the
    /// rows the contact events changed (`forces_of_changed_rows`), every other pass as
    /// [`Self::run_pass`]. The state after a whole step is the same to the bit either way;
    /// `run_pass` keeps each pass the device's twin, for comparing them pass by pass.
    pub fn run_step_pass(&mut self, pass: Kernel) -> Result<(), EngineError> {
        let s = &mut self.state;
        let w = &mut self.workspace;
        let (law, dt) = (s.law, s.dt);
        match pass {
            Kernel::IntegratePairs => {
                integrate_pairs_step(&law, dt, &s.monomers, &mut s.contacts, w, &mut s.tally)
            }
            Kernel::ContactsScan => return self.contacts_scanned_step(),
            // Done by the step's form of `contacts_scan`.
            Kernel::Contacts => {}
            Kernel::Forces if w.results_of_step && w.partner_index_current => {
                forces_of_changed_rows(&law, &s.monomers, &s.contacts, w);
                w.results_of_step = false;
            }
            _ => return self.run_pass(pass),
        }
        Ok(())
    }

    /// `wall_forces` with the next step's kick joined to it (`CpuEngine::run` between two
    /// steps): the same bits as `wall_forces`, `reduce_walls_final`, then `integrate_kick`.
    pub(super) fn wall_forces_then_kick(&mut self) -> Result<(), EngineError> {
        let kick = NextKick {
            dt: self.dt,
            inverse_mass: 1.0 / self.law.mass,
            inverse_inertia: 1.0 / self.law.moment_of_inertia,
        };
        let s = &mut self.state;
        let w = &mut self.workspace;
        wall_forces(
            s.dt,
            &s.walls,
            &mut s.monomers,
            &mut s.contacts,
            w,
            Some(kick),
        );
        Ok(())
    }

    /// The last step's wall sums, then the kick: what the device runs inside a submission of
    /// several steps (a dispatch fewer per step). The CPU's step ends with
    /// `reduce_walls_final` itself, so its script never needs this.
    pub fn integrate_kick_with_wall_sums(&mut self) -> Result<(), EngineError> {
        self.run_pass(Kernel::ReduceWallsFinal)?;
        self.run_pass(Kernel::IntegrateKick)
    }

    /// `contacts` on the work list `contacts_scan` left, then [`Self::after_events`].
    fn contacts_of_the_listed_owners(&mut self) -> Result<(), EngineError> {
        let s = &mut self.state;
        let w = &mut self.workspace;
        let list = &mut self.neighbours;
        let work = std::mem::take(&mut w.work);
        let changed = contacts(
            &s.law,
            s.dt,
            &s.monomers,
            &s.walls,
            &list.pairs,
            &list.starts,
            &mut s.contacts,
            &mut s.tally,
            &work,
            w,
        );
        w.work = work;
        self.after_events(changed?);
        Ok(())
    }

    /// The step's `contacts_scan` and `contacts` in one sweep (`contacts_scanned`), then
    /// [`Self::after_events`].
    fn contacts_scanned_step(&mut self) -> Result<(), EngineError> {
        let s = &mut self.state;
        let changed = contacts_scanned(
            (&s.law, s.dt),
            &s.monomers,
            &s.walls,
            &mut self.neighbours,
            &mut s.contacts,
            &mut s.tally,
            &mut self.workspace,
        )?;
        self.after_events(changed);
        Ok(())
    }

    /// After the contact events: the partner index follows the pair rows a contact forming or
    /// breaking changed (or, where it cannot, is marked stale), and so do the partner marks.
    fn after_events(&mut self, changed: Vec<RowChange>) {
        let s = &mut self.state;
        let w = &mut self.workspace;
        let list = &mut self.neighbours;
        if !changed.is_empty() && w.partner_index_current {
            let results = &mut w.pair_result;
            w.partner_index_current = w.incoming.update(&s.contacts, &changed, results);
        }
        if w.results_of_step {
            w.changed_rows.extend(changed.iter().map(|c| c.owner));
        }
        if list.partners_current {
            for c in &changed {
                mark_partners_of(list, &s.contacts, c.owner as usize);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::script::{OWNER_EVENTS, OWNER_WALLS};
    use crate::material::Material;
    use crate::model::{ContactLaw, ModelOptions, WallFactors};
    use crate::state::{Monomers, Wall};
    use glam::DVec3;

    /// One monomer resting on the bottom wall (a contact at time 0) with a side wall 1 µm away.
    fn corner() -> CpuEngine {
        let law = ContactLaw::new(&Material::silicate(), &ModelOptions::default());
        let r = law.radius;
        let k = law.wall_constants(WallFactors::FULL);
        let wall = |name: &str, point: DVec3, normal: DVec3| Wall {
            name: name.into(),
            point,
            normal,
            velocity: DVec3::ZERO,
            constants: k,
        };
        let walls = vec![
            wall(
                "bottom",
                DVec3::new(0.0, 0.0, -r + 0.5 * k.delta0),
                DVec3::Z,
            ),
            wall("side", DVec3::new(r + 1e-4, 0.0, 0.0), -DVec3::X),
        ];
        let m = Monomers::new(vec![DVec3::ZERO]);
        CpuEngine::new(law, 1e-10, m, walls, 12, 3).unwrap()
    }

    #[test]
    fn a_monomer_touching_a_second_wall_is_listed_for_its_events_and_forms_the_contact() {
        let mut e = corner();
        assert_eq!(
            e.contacts.wall_count[0], 1,
            "the bottom contact from the start"
        );
        e.run_pass(Kernel::ContactsScan).unwrap();
        assert_eq!(
            e.workspace.work,
            [OWNER_WALLS],
            "touching the bottom only: walls, no events"
        );
        // The side wall moves onto the monomer: a second wall contact to form.
        let r = e.law.radius;
        e.state.walls[1].point.x = r - 1e-9;
        e.run_pass(Kernel::ContactsScan).unwrap();
        assert_eq!(e.workspace.work, [OWNER_EVENTS | OWNER_WALLS]);
        e.run_pass(Kernel::Contacts).unwrap();
        assert_eq!(e.contacts.wall_count[0], 2);
    }
}
