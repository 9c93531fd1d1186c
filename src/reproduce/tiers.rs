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
    /// The paper's dynamic study at its size, the slow studies at sizes two cores finish
    /// beside the paper's (for a cluster or a GPU, `--slurm`); cases accumulate over runs.
    #[value(alias = "full")]
    Paper,
}

impl fmt::Display for Tier {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self {
            Tier::Smoke => "smoke",
            Tier::Quick => "quick",
            Tier::Paper => "paper",
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StudyKind {
    QuasiStatic,
    Dynamic,
    Uni,
}

/// A model variant of a study: its sweep name and its config overrides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Variant {
    pub name: &'static str,
    /// What the report calls it.
    pub label: &'static str,
    /// The sweep file's inline table of overrides.
    pub overrides: &'static str,
}

/// Seizinger et al.'s calibrated model (Sect. 5.1): rolling ×8, sliding ×2.5.
pub const CALIBRATED: Variant = Variant {
    name: "modified",
    label: "calibrated (m_r = 8, m_s = 2.5)",
    overrides: "{ rolling_modifier = 8, sliding_modifier = 2.5 }",
};
/// The Dominik–Tielens / Wada model as published.
pub const UNMODIFIED: Variant = Variant {
    name: "unmodified",
    label: "unmodified",
    overrides: "{}",
};

/// One sweep of a tier.
#[derive(Clone, Debug)]
pub struct Study {
    pub kind: StudyKind,
    pub name: &'static str,
    pub title: &'static str,
    /// Sample sizes, smallest first; the largest is the one the verdicts read.
    pub sizes: Vec<usize>,
    /// The sample size Seizinger et al. (2012) used for this study: rows at other sizes are
    /// counted apart from the headline.
    pub paper_monomers: usize,
    pub speeds: Vec<f64>,
    pub seeds: Vec<u64>,
    /// The headline model first.
    pub variants: Vec<Variant>,
    pub pressure_stop_pa: f64,
    pub phi_stop: f64,
    /// Profiles every this many rows (rows are 100 steps): dynamic runs are short.
    pub profile_every_rows: u64,
    /// Time limit of one Slurm array task (one CPU), for the study's largest case.
    pub slurm_time: &'static str,
}

impl Study {
    /// The largest sample size of the study.
    pub fn monomers(&self) -> usize {
        *self.sizes.iter().max().expect("a study has a size")
    }
}

/// What changes between tiers: sizes, speeds and seeds of each study.
struct Scale {
    quasi_static: (Vec<usize>, Vec<f64>),
    dynamic: (Vec<usize>, Vec<f64>),
    slow_dynamic: (Vec<usize>, Vec<f64>),
    uni: (Vec<usize>, f64),
    seeds: u64,
}

impl Tier {
    fn scale(self) -> Scale {
        match self {
            Tier::Smoke => Scale {
                quasi_static: (vec![150], vec![1.0]),
                dynamic: (vec![300], vec![2.0, 5.0]),
                slow_dynamic: (vec![150], vec![0.5]),
                uni: (vec![150], 1.0),
                seeds: 2,
            },
            // 5 cm/s is the slowest that two cores finish in the hour with the rest.
            Tier::Quick => Scale {
                quasi_static: (vec![1000], vec![0.05]),
                dynamic: (vec![2000], vec![1.0, 2.5, 5.0, 10.0, 15.0]),
                slow_dynamic: (vec![1000], vec![0.25, 0.5]),
                uni: (vec![1000], 0.1),
                seeds: 3,
            },
            // The paper's dynamic study at its size; the slow studies at the sizes two cores
            // finish, with the paper's sizes (11 000, 18 000) exported for a cluster or a GPU.
            Tier::Paper => Scale {
                quasi_static: (vec![2000, 4000, 11_000], vec![0.01, 0.05]),
                dynamic: (
                    vec![40_000],
                    vec![1.0, 2.5, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0],
                ),
                slow_dynamic: (vec![2000], vec![0.1, 0.25, 0.5, 0.75, 1.0]),
                uni: (vec![2000, 4000, 18_000], 0.05),
                seeds: 6,
            },
        }
    }

    pub fn studies(self) -> Vec<Study> {
        let scale = self.scale();
        let seeds: Vec<u64> = (1..=scale.seeds).collect();
        let both = vec![CALIBRATED, UNMODIFIED];
        vec![
            Study {
                kind: StudyKind::QuasiStatic,
                name: "quasi_static",
                // Sect. 5.1: "≈ 11 000".
                paper_monomers: 11_000,
                title: "Quasi-static omnidirectional compression",
                sizes: scale.quasi_static.0,
                speeds: scale.quasi_static.1,
                seeds: seeds.clone(),
                variants: both.clone(),
                pressure_stop_pa: 1e6,
                phi_stop: 0.7,
                profile_every_rows: 100,
                // 11 000 monomers at 1 cm/s: about 10¹¹ particle-steps.
                slurm_time: "3-00:00:00",
            },
            Study {
                kind: StudyKind::Dynamic,
                name: "dynamic",
                // Sect. 5.2: "about 40000 particles".
                paper_monomers: 40_000,
                title: "Dynamic omnidirectional compression",
                sizes: scale.dynamic.0,
                speeds: scale.dynamic.1,
                seeds: seeds.clone(),
                variants: both.clone(),
                pressure_stop_pa: 1e7,
                phi_stop: 0.7,
                profile_every_rows: 2,
                slurm_time: "08:00:00",
            },
            Study {
                kind: StudyKind::Dynamic,
                name: "slow_dynamic",
                // not stated; "a higher number of particles" is used only above 1 m/s (Sect. 5.2), so the quasi-static samples.
                paper_monomers: 11_000,
                title: "Omnidirectional compression below 1 m/s",
                sizes: scale.slow_dynamic.0,
                speeds: scale.slow_dynamic.1,
                seeds: seeds.clone(),
                variants: both.clone(),
                pressure_stop_pa: 1e7,
                phi_stop: 0.7,
                profile_every_rows: 20,
                slurm_time: "04:00:00",
            },
            Study {
                kind: StudyKind::Uni,
                name: "uni",
                // Sect. 5.3, Fig. 15: 18 000.
                paper_monomers: 18_000,
                title: "Unidirectional compression",
                sizes: scale.uni.0,
                speeds: vec![scale.uni.1],
                seeds,
                variants: both,
                pressure_stop_pa: 1e5,
                phi_stop: 0.5,
                profile_every_rows: 100,
                slurm_time: "2-00:00:00",
            },
        ]
    }
}

fn list<T: fmt::Display>(items: &[T]) -> String {
    let items: Vec<String> = items.iter().map(|x| x.to_string()).collect();
    format!("[{}]", items.join(", "))
}

impl Study {
    /// The base config (everything the sweep's axes leave alone). Samples are cut flat at a
    /// height equal to their width (`top = "cut"`), as Seizinger et al. (2012) describe theirs.
    pub fn base_config(&self) -> String {
        let (kind, footprint) = match self.kind {
            StudyKind::Uni => ("uni", "cylinder"),
            _ => ("omni", "box"),
        };
        format!(
            "# {title} (written by dustdem reproduce).\n\
             [sample]\nsource = \"rbd\"\nmonomers = {n}\nfootprint = \"{footprint}\"\n\
             top = \"cut\"\nseed = 1\n\n\
             [experiment]\nkind = \"{kind}\"\nwall_speed_m_s = 1.0\nphi_stop = {phi}\n\
             pressure_stop_pa = {p:e}\nprofile_every_rows = {profiles}\n\n\
             [integration]\ndt_ns = 0.3\n\n\
             [output]\ndir = \"runs\"\nsnapshot_format = \"none\"\ncheckpoint_minutes = 5.0\n",
            title = self.title,
            n = self.monomers(),
            phi = self.phi_stop,
            p = self.pressure_stop_pa,
            profiles = self.profile_every_rows,
        )
    }

    /// The sweep file (its base config beside it).
    pub fn sweep_file(&self) -> String {
        let mut text = format!(
            "# {} (written by dustdem reproduce).\nbase = \"base.toml\"\n\n[axes]\n\
             wall_speed_m_s = {}\nseed = {}\nmonomers = {}\n\n[variants]\n",
            self.title,
            list(&self.speeds),
            list(&self.seeds),
            list(&self.sizes),
        );
        for v in &self.variants {
            text += &format!("{} = {}\n", v.name, v.overrides);
        }
        text += &format!("\n[slurm]\ntime = \"{}\"\n", self.slurm_time);
        text
    }
}
