//! Writing a state to the device: parameters, walls, monomers, the contact table, and the lists
//! of a finished step (empty event lists, the pair-contact list of every contact).

use super::{groups, GpuEngine};
use crate::backend::gpu::buffers::{PAIR_N1, PAIR_N2};
use crate::backend::gpu::interface::{Binding, Kernel};
use crate::backend::gpu::layout::SLOT_CHUNKS;
use crate::backend::gpu::layout::{self, vec4, GpuConstants, GpuMonomerAux, GpuWall};
use crate::backend::gpu::shader::Precision;
use crate::mixed::split::SplitPosition;
use crate::state::interaction::wall_interaction;
use crate::state::{ContactTable, Monomers};
use glam::DVec3;

impl GpuEngine {
    /// Writes a per-slot vector array to its chunk bindings.
    fn write_slots(&self, chunks: [Binding; SLOT_CHUNKS], data: &[[f64; 4]]) {
        for (chunk, part) in chunks.into_iter().zip(data.chunks(self.sizes.slot_chunk())) {
            self.write(chunk, part);
        }
    }

    /// Writes the whole state to the device; tallies, flags and the diagnostics block start
    /// from zero (flags from "none").
    pub fn upload(&mut self, m: &Monomers, table: &ContactTable) {
        let n = m.len();
        let v4 = |v: &[DVec3]| v.iter().map(|x| vec4(*x)).collect::<Vec<_>>();
        self.write(Binding::Params, &[self.params()]);
        let walls: Vec<GpuWall> = self
            .walls
            .iter()
            .map(|w| GpuWall {
                point: vec4(w.point),
                normal: vec4(w.normal),
                velocity: vec4(w.velocity),
                k: GpuConstants::from(w.constants),
                point_lo: match self.precision {
                    Precision::Exact => [0.0; 4],
                    // What the f32 nearest to each coordinate leaves out.
                    Precision::Mixed => vec4(w.point - w.point.as_vec3().as_dvec3()),
                },
            })
            .collect();
        self.write(Binding::Walls, &walls);
        self.write_positions(&m.position);
        self.write(Binding::Velocity, &v4(&m.velocity));
        self.write(Binding::AngularVelocity, &v4(&m.angular_velocity));
        self.write(Binding::Force, &v4(&m.force));
        self.write(Binding::Torque, &v4(&m.torque));
        self.write(Binding::DampingForce, &v4(&m.damping_force));
        // The previous step's wall powers of each monomer (Σ_w F·v_w dt and its damping part).
        let mut aux = Vec::with_capacity(n);
        for i in 0..n {
            let (mut p, mut q) = (0.0, 0.0);
            for c in table.walls_of(i) {
                let w = &self.walls[c.wall as usize];
                let (f, fd, _) = wall_interaction(&self.law, m.position[i], m.velocity[i], w, c);
                p += f.dot(w.velocity * self.dt);
                q += fd.dot(w.velocity * self.dt);
            }
            aux.push(GpuMonomerAux {
                inverse_mass_scale: m.inverse_mass_scale[i],
                inverse_inertia_scale: m.inverse_inertia_scale[i],
                wall_power: p,
                damping_power: q,
            });
        }
        self.write(Binding::Aux, &aux);
        self.write(Binding::Tally, &vec![0.0f64; n * layout::TALLY_STRIDE]);
        let n1: Vec<[f64; 4]> = table
            .pair
            .iter()
            .map(|c| [c.n1.x, c.n1.y, c.n1.z, c.twist])
            .collect();
        let n2: Vec<[f64; 4]> = table.pair.iter().map(|c| vec4(c.n2)).collect();
        let partner: Vec<u32> = table.pair.iter().map(|c| c.partner).collect();
        self.write_slots(PAIR_N1, &n1);
        self.write_slots(PAIR_N2, &n2);
        self.write(Binding::PairPartner, &partner);
        self.write(Binding::PairCount, &table.pair_count);
        let wn1: Vec<[f64; 4]> = table
            .wall
            .iter()
            .map(|c| [c.n1.x, c.n1.y, c.n1.z, c.twist])
            .collect();
        let anchor: Vec<[f64; 4]> = table.wall.iter().map(|c| vec4(c.anchor)).collect();
        let wall_id: Vec<u32> = table.wall.iter().map(|c| c.wall).collect();
        self.write(Binding::WallN1, &wn1);
        self.write(Binding::WallAnchor, &anchor);
        self.write(Binding::WallId, &wall_id);
        self.write(Binding::WallCount, &table.wall_count);
        self.write(Binding::IncomingCount, &vec![0u32; n]);
        // The candidate lists are built at the first neighbour passes.
        let mut flags = [layout::NO_MONOMER; layout::FLAG_COUNT];
        flags[layout::FLAG_REBUILD] = 0;
        self.write(Binding::Flags, &flags);
        self.write(Binding::NeighbourCount, &vec![0u32; n]);
        self.write(Binding::ReferencePosition, &v4(&m.position));
        self.write(Binding::Diag, &[0.0f64; layout::DIAG_SIZE]);
        // The lists of a finished step: event lists empty (no entries, dispatches of no
        // workgroups), the pair-contact list holding every contact of the table.
        let contact_list: Vec<u32> = (0..n)
            .flat_map(|i| {
                let first = (i * table.pair_slots) as u32;
                first..first + table.pair_count[i]
            })
            .collect();
        let pair_groups =
            (contact_list.len().div_ceil(layout::PAIR_GROUP) as u32).min(self.work_groups_max);
        self.write(Binding::ContactList, &contact_list);
        let mut work = [0u32; layout::WORK_LISTS];
        work[layout::WORK_PAIRS] = contact_list.len() as u32;
        self.write(Binding::Work, &work);
        let mut args = [0u32, 1, 1].repeat(layout::ARGS_REBUILD + 1);
        args[3 * layout::WORK_PAIRS] = pair_groups;
        // The candidate lists are built at the first neighbour passes (FLAG_REBUILD above).
        args[3 * layout::ARGS_REBUILD] = groups(n);
        self.write(Binding::WorkArgs, &args);
        // The pair contacts' tests for a first contacts_scan, which no integrate_pairs precedes.
        self.write(Binding::PairTests, &vec![0u32; n]);
        self.dispatch(&[Kernel::ContactsPairTests]);
    }

    /// The centres: f64 vectors in the exact precision, split in the mixed one (voxel, offset
    /// and its low part: `mixed::SplitPosition`, exact to 2⁻⁴⁵ cm).
    fn write_positions(&self, position: &[DVec3]) {
        match self.precision {
            Precision::Exact => self.write(
                Binding::Position,
                &position.iter().map(|x| vec4(*x)).collect::<Vec<_>>(),
            ),
            Precision::Mixed => {
                let split: Vec<SplitPosition> = position
                    .iter()
                    .map(|x| SplitPosition::from_f64(*x))
                    .collect();
                let voxel: Vec<[i32; 4]> =
                    split.iter().map(|s| s.voxel.extend(0).to_array()).collect();
                let offset: Vec<[f64; 4]> =
                    split.iter().map(|s| vec4(s.offset.as_dvec3())).collect();
                let lo: Vec<[f64; 4]> =
                    split.iter().map(|s| vec4(s.offset_lo.as_dvec3())).collect();
                self.write(Binding::PositionVoxel, &voxel);
                self.write(Binding::Position, &offset);
                self.write(Binding::PositionLo, &lo);
            }
        }
    }

    /// Empties the work lists, as integrate_drift does before each step's scan (tests that
    /// run contacts_scan on an uploaded state, whose lists are those of a finished step).
    pub fn clear_work_lists(&self) {
        self.write(Binding::Work, &[0u32; layout::WORK_LISTS]);
        self.write(Binding::WorkArgs, &[0u32, 1, 1].repeat(layout::WORK_LISTS));
    }

    /// Lowers the most workgroups a pass over a work list is dispatched with, so that tests
    /// on small systems walk the lists with a stride as the largest systems do.
    pub fn limit_work_groups(&mut self, max: u32) {
        self.work_groups_max = max.clamp(1, self.work_groups_max);
        self.write(Binding::Params, &[self.params()]);
        // The pair-contact list's dispatch as contacts_scan would size it now.
        let pairs = self.read::<u32>(Binding::Work, layout::WORK_LISTS)[layout::WORK_PAIRS];
        let groups = (pairs as usize).div_ceil(layout::PAIR_GROUP) as u32;
        self.write_at(
            Binding::WorkArgs,
            (12 * layout::WORK_PAIRS) as u64,
            &[groups.min(self.work_groups_max)],
        );
    }
}
