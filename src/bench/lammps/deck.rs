//! The LAMMPS input deck that runs the benchmark's compression: the sample's data file, the
//! granular pair style, the box's walls and the top wall moving down at the wall speed.
//!
//! Walls: the bottom and the four side walls are static planes (`fix wall/gran ... zplane`,
//! `xplane`, `yplane`); the top wall is a plane region whose position follows an equal-style
//! variable (`region ... move`), the one way LAMMPS 29 Sep 2021 moves a granular wall at
//! constant speed (`fix wall/gran` itself only wiggles or shears). `fix wall/gran/region`
//! takes the wall's velocity from the region's motion, so damping and sliding see it.

use super::coeffs::{num, GranularCoeffs};
use crate::config::Config;
use crate::engine::SKIN_RADII;
use crate::material::{ContactConstants, Material};
use crate::model::ContactLaw;
use std::fmt::Write;

/// Everything the deck states, in CGS.
#[derive(Clone, Debug, PartialEq)]
pub struct DeckSpec {
    pub monomers: usize,
    pub seed: u64,
    /// Half the box side: the side walls' planes are at ±half_side in x and y [cm].
    pub half_side: f64,
    /// Bottom wall plane [cm].
    pub bottom_z: f64,
    /// Top wall plane at step 0 [cm].
    pub top_z: f64,
    /// Top wall speed, downward [cm/s].
    pub speed: f64,
    pub dt: f64,
    /// Neighbour skin [cm]: dustdem's [`SKIN_RADII`] monomer radii.
    pub skin: f64,
    pub pair: GranularCoeffs,
    /// Top and bottom walls.
    pub end_walls: GranularCoeffs,
    pub side_walls: GranularCoeffs,
    /// Comment lines on where LAMMPS's model differs from dustdem's.
    pub differences: Vec<String>,
}

impl DeckSpec {
    pub fn new(config: &Config, half_side: f64, bottom_z: f64, top_z: f64) -> DeckSpec {
        let material = config.material();
        let law = config.contact_law();
        DeckSpec {
            monomers: config.sample.monomers,
            seed: config.sample.seed,
            half_side,
            bottom_z,
            top_z,
            speed: config.experiment.wall_speed_m_s * 100.0,
            dt: config.dt(),
            skin: SKIN_RADII * law.radius,
            pair: GranularCoeffs::pair(&material, &law),
            end_walls: GranularCoeffs::wall(&material, &law, config.walls.top_bottom),
            side_walls: GranularCoeffs::wall(&material, &law, config.walls.side),
            differences: differences(&material, &law, config),
        }
    }

    /// The deck's text. `warm` and `steps` are index variables: `-var warm W -var steps S` on
    /// the command line overrides them.
    pub fn text(&self) -> String {
        let mut s = String::new();
        let mut line = |text: &str| {
            let _ = writeln!(s, "{text}");
        };
        line(&format!(
            "# dustdem benchmark: {} RBD monomers (seed {}) compressed omnidirectionally, the top \
             wall moving down at {} m/s.",
            self.monomers,
            self.seed,
            self.speed / 100.0
        ));
        line("# Written by `dustdem bench --lammps` from the same sample (sample.data) and");
        line("# material as the dustdem run; LAMMPS 29 Sep 2021 (Debian 20220106) syntax.");
        line("# Run: mpirun -np 2 lmp -in in.compress -var warm 100 -var steps 1000");
        line("#");
        line("# Where this model differs from dustdem's (Seizinger et al. 2012):");
        for d in &self.differences {
            line(&format!("# - {d}"));
        }
        line("");
        line("variable warm index 100");
        line("variable steps index 1000");
        line("units cgs");
        line("atom_style sphere");
        // Per-atom variables by ID (fz[1] and the like) need the map; cheap.
        line("atom_modify map array");
        line("boundary f f f");
        line("newton on");
        line("comm_modify vel yes");
        line("read_data sample.data");
        // The skin is explicit: cgs's default skin is 0.1 cm, a thousand monomer diameters.
        line(&format!("neighbor {} bin", num(self.skin)));
        line("neigh_modify delay 0 every 1 check yes");
        line("pair_style granular");
        line(&format!("pair_coeff * * {}", self.pair.args()));
        line(&format!("timestep {}", num(self.dt)));
        line("fix integrate all nve/sphere");
        line(&format!(
            "fix bottom all wall/gran granular {} zplane {} NULL",
            self.end_walls.args(),
            num(self.bottom_z)
        ));
        for axis in ["x", "y"] {
            line(&format!(
                "fix side_{axis} all wall/gran granular {} {axis}plane {} {}",
                self.side_walls.args(),
                num(-self.half_side),
                num(self.half_side)
            ));
        }
        // The top wall's displacement at a step; `step` counts on over both runs.
        line(&format!(
            "variable top_dz equal {}*step",
            num(-self.speed * self.dt)
        ));
        line(&format!(
            "region top plane 0 0 {} 0 0 -1 side in move NULL NULL v_top_dz units box",
            num(self.top_z)
        ));
        line(&format!(
            "fix top all wall/gran/region granular {} region top",
            self.end_walls.args()
        ));
        line(&format!(
            "variable top_z equal {}+v_top_dz",
            num(self.top_z)
        ));
        // Overlapping pairs, each counted at both monomers (LAMMPS does not count JKR contacts
        // stretched beyond touching).
        line("compute contacts all contact/atom");
        line("compute contact_sum all reduce sum c_contacts");
        line("thermo_style custom step atoms c_contact_sum v_top_z cpu");
        line("thermo_modify lost error");
        // Only the first and last step of each run: thermo output costs a neighbour search.
        line("thermo 1000000000");
        line("run ${warm}");
        line("run ${steps}");
        s
    }
}

/// What differs, with the numbers of this material: each line is one comment of the deck.
fn differences(material: &Material, law: &ContactLaw, config: &Config) -> Vec<String> {
    let p: &ContactConstants = &law.pair;
    // LAMMPS's JKR pull-off: the contact radius a = (9πγR²/(4E*))^(1/3) = a₀/4^(1/3), where
    // δ/δ₀ = 3(a/a₀)² − 2(a/a₀)^(1/2).
    let y = 0.25f64.cbrt();
    let lammps_break = 3.0 * y * y - 2.0 * y.sqrt();
    let twist_k = 0.5 * p.k_s * p.a0 * p.a0;
    let twist_cap = 2.0 / 3.0 * p.a0 * p.k_s * p.zeta_crit;
    let side = config.walls.side;
    vec![
        format!(
            "normal: the same JKR force (E* = {:.6e} dyn/cm2, gamma = {} erg/cm2, R = r/2); \
             contacts form at overlap >= 0 in both, but LAMMPS breaks them at {lammps_break:.2} \
             delta0 (its own pull-off criterion) where dustdem breaks at -delta_c = {:.3} delta0",
            law.e_star,
            material.surface_energy,
            -p.delta_c / p.delta0
        ),
        "sliding: LAMMPS's Mindlin spring is k_t a (dustdem's k_s = 8 a0 G* at a = a0 only), on \
         an integrated tangential displacement rotated into the contact plane, capped at \
         mu_s |F_ne + 2 F_c| (equal to dustdem's k_s zeta_crit where F_ne = 0); dustdem uses \
         contact pointers and a fixed zeta_crit"
            .into(),
        "rolling: a plain spring (k_roll = dustdem's k_r) with a Coulomb-like limit \
         mu_roll |F_ne + 2 F_c| (equal to dustdem's k_r xi_crit where F_ne = 0), not the \
         Dominik-Tielens pointers with a fixed xi_crit"
            .into(),
        format!(
            "twisting (marshall): a plain spring 0.5 k_t a^3 ({twist_k:.4e} erg at a = a0; \
             dustdem's k_t = {:.4e} erg) with the limit (2/3) a mu_s |F_ne + 2 F_c| \
             ({twist_cap:.4e} dyn cm at a = a0, F_ne = 0; dustdem's k_t phi_crit = {:.4e})",
            p.k_t,
            p.k_t * p.phi_crit
        ),
        "damping: the same normal damping; no tangential, rolling or twisting damping in \
         either (x_gamma,t = 0, gamma_roll = 0)"
            .into(),
        "walls: DMT instead of JKR (Hertz repulsion minus a constant pull-off 4 pi gamma r, \
         contact ends at zero overlap, equilibrium overlap 3^(1/3) times JKR's), because fix \
         wall/gran of this LAMMPS version returns NaN forces once a JKR wall contact is \
         stretched below zero overlap; the friction limits use 2 F_pulloff = 8 pi gamma r"
            .into(),
        format!(
            "walls: R = r as in dustdem; fix wall/gran of this LAMMPS version mixes E_eff = \
             E/(2(1-nu)), so the walls are given E/(1+nu) to get dustdem's E*; wall twisting \
             follows the wall's sliding coefficients (dustdem: k_t,wall = k_t); the side walls \
             are weakened by {} (sliding), {} (rolling) and twisting through sliding (dustdem: {})",
            side.sliding, side.rolling, side.twisting
        ),
        "integration: velocity Verlet (fix nve/sphere) against dustdem's leap-frog, the same \
         time step; the same neighbour skin (0.2 r, rebuilt when a monomer moved half of it), \
         LAMMPS's cutoff adds its pull-off distance"
            .into(),
    ]
}
