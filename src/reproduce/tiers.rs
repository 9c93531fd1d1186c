//! What each tier runs: sizes, speeds, seeds and models of the three studies.
//!
//! The paper's sizes (Seizinger et al. 2012, Sect. 5): about 11 000 monomers for the
//! quasi-static omnidirectional curves at 1–5 cm/s, 40 000 for the dynamic ones at 1–25 m/s,
//! 18 000 in the unidirectional cylinder at 5 cm/s, six samples each. The quick tier scales
//! them down to finish in about an hour on two CPU cores; the full tier uses them.

use std::fmt;

/// How much to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Tier {
    /// A minute: tiny samples, for testing the pipeline, not the physics.
    Smoke,
    /// About an hour on two CPU cores: scaled-down samples, three seeds.
    Quick,
    /// The paper's sizes and six seeds: for a GPU or a cluster (`--slurm`).
    Full,
}

impl fmt::Display for Tier {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self {
            Tier::Smoke => "smoke",
            Tier::Quick => "quick",
            Tier::Full => "full",
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StudyKind {
    QuasiStatic,
    Dynamic,
    Uni,
}

/// One sweep of a tier.
#[derive(Clone, Debug)]
pub struct Study {
    pub kind: StudyKind,
    pub name: &'static str,
    pub title: &'static str,
    pub monomers: usize,
    pub speeds: Vec<f64>,
    pub seeds: Vec<u64>,
    /// Also the modified model (m_r = 8, m_s = 2.5) beside the unmodified one.
    pub modified_too: bool,
    pub pressure_stop_pa: f64,
    pub phi_stop: f64,
    /// Profiles every this many rows (rows are 100 steps): dynamic runs are short.
    pub profile_every_rows: u64,
}

impl Tier {
    pub fn studies(self) -> Vec<Study> {
        let (qs, dynamic, uni, seeds): (usize, usize, usize, u64) = match self {
            Tier::Smoke => (150, 300, 150, 2),
            Tier::Quick => (1000, 4000, 1000, 3),
            Tier::Full => (11_000, 40_000, 18_000, 6),
        };
        let seeds: Vec<u64> = (1..=seeds).collect();
        let (slow, dynamic_speeds, uni_speed) = match self {
            Tier::Smoke => (vec![1.0], vec![2.0, 5.0], 1.0),
            // 5 cm/s is the slowest that two cores finish in the hour with the rest.
            Tier::Quick => (vec![0.05], vec![1.0, 2.5, 5.0, 10.0, 15.0], 0.1),
            Tier::Full => (
                vec![0.01, 0.05],
                vec![1.0, 2.5, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0],
                0.05,
            ),
        };
        vec![
            Study {
                kind: StudyKind::QuasiStatic,
                name: "quasi_static",
                title: "Quasi-static omnidirectional compression",
                monomers: qs,
                speeds: slow,
                seeds: seeds.clone(),
                modified_too: true,
                pressure_stop_pa: 1e6,
                phi_stop: 0.7,
                profile_every_rows: 100,
            },
            Study {
                kind: StudyKind::Dynamic,
                name: "dynamic",
                title: "Dynamic omnidirectional compression",
                monomers: dynamic,
                speeds: dynamic_speeds,
                seeds: seeds.clone(),
                modified_too: false,
                pressure_stop_pa: 1e7,
                phi_stop: 0.65,
                profile_every_rows: 2,
            },
            Study {
                kind: StudyKind::Uni,
                name: "uni",
                title: "Unidirectional compression",
                monomers: uni,
                speeds: vec![uni_speed],
                seeds,
                modified_too: true,
                pressure_stop_pa: 1e5,
                phi_stop: 0.5,
                profile_every_rows: 100,
            },
        ]
    }
}

fn list<T: fmt::Display>(items: &[T]) -> String {
    let items: Vec<String> = items.iter().map(|x| x.to_string()).collect();
    format!("[{}]", items.join(", "))
}

impl Study {
    /// The base config (everything the sweep's axes leave alone).
    pub fn base_config(&self) -> String {
        let (kind, footprint) = match self.kind {
            StudyKind::Uni => ("uni", "cylinder"),
            _ => ("omni", "box"),
        };
        format!(
            "# {title} (written by dustdem reproduce).\n\
             [sample]\nsource = \"rbd\"\nmonomers = {n}\nfootprint = \"{footprint}\"\nseed = 1\n\n\
             [experiment]\nkind = \"{kind}\"\nwall_speed_m_s = 1.0\nphi_stop = {phi}\n\
             pressure_stop_pa = {p:e}\nprofile_every_rows = {profiles}\n\n\
             [integration]\ndt_ns = 0.3\n\n\
             [output]\ndir = \"runs\"\nsnapshot_format = \"none\"\ncheckpoint_minutes = 5.0\n",
            title = self.title,
            n = self.monomers,
            phi = self.phi_stop,
            p = self.pressure_stop_pa,
            profiles = self.profile_every_rows,
        )
    }

    /// The sweep file (its base config beside it).
    pub fn sweep_file(&self) -> String {
        let mut text = format!(
            "# {} (written by dustdem reproduce).\nbase = \"base.toml\"\n\n[axes]\n\
             wall_speed_m_s = {}\nseed = {}\nmonomers = [{}]\n\n[variants]\nunmodified = {{}}\n",
            self.title,
            list(&self.speeds),
            list(&self.seeds),
            self.monomers
        );
        if self.modified_too {
            text += "modified = { rolling_modifier = 8, sliding_modifier = 2.5 }\n";
        }
        text
    }
}
