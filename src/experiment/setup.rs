//! Builds the initial state of an experiment from a config: sample, monomers, walls.

use crate::config::{Config, ExperimentKind, FootprintKind, SampleSource, SampleTop};
use crate::model::ContactLaw;
use crate::sample::{
    generate_rbd, generate_rbd_below, side_for_cube, Footprint, RbdParams, Sample,
};
use crate::state::order::space_filling_order;
use crate::state::{Monomers, Wall};
use glam::DVec3;
use std::fmt;

#[derive(Debug)]
pub enum SetupError {
    Sample(crate::sample::SampleError),
    Invalid(String),
}

impl fmt::Display for SetupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SetupError::Sample(e) => write!(f, "{e}"),
            SetupError::Invalid(s) => write!(f, "{s}"),
        }
    }
}

impl std::error::Error for SetupError {}

/// Filling factor an RBD sample approaches; used to size an automatic footprint.
const RBD_FILLING_FACTOR: f64 = 0.15;

/// The sample the config asks for: an RBD sample generated with contacts at the equilibrium
/// distance 2r − δ₀ (so they start at rest), or one read from a file.
pub fn build_sample(config: &Config, law: &ContactLaw) -> Result<Sample, SetupError> {
    let s = &config.sample;
    let r = law.radius;
    match s.source {
        SampleSource::File => {
            let path = s.file.as_ref().expect("validated: file is set");
            let sample = Sample::load(path).map_err(SetupError::Sample)?;
            if (sample.radius / r - 1.0).abs() > 1e-9 {
                return Err(SetupError::Invalid(format!(
                    "{}: monomer radius {} cm differs from [material] radius_um = {} ({} cm)",
                    path.display(),
                    sample.radius,
                    config.material.radius_um,
                    r
                )));
            }
            Ok(sample)
        }
        SampleSource::Rbd => {
            let cube_side = side_for_cube(s.monomers, r, RBD_FILLING_FACTOR);
            let box_side = if s.side_um > 0.0 {
                s.side_um * 1e-4
            } else {
                cube_side
            };
            let footprint = match s.footprint {
                FootprintKind::Box => Footprint::Box { side: box_side },
                FootprintKind::Cylinder => Footprint::Cylinder {
                    radius: if s.cylinder_radius_um > 0.0 {
                        s.cylinder_radius_um * 1e-4
                    } else {
                        cube_side / std::f64::consts::PI.sqrt()
                    },
                },
            };
            // A cylinder's "side" is that of the square of the same base area.
            let side = match footprint {
                Footprint::Box { side } => side,
                Footprint::Cylinder { radius } => radius * std::f64::consts::PI.sqrt(),
            };
            let params = RbdParams {
                n: s.monomers,
                radius: r,
                footprint,
                seed: s.seed,
                contact_distance: 2.0 * r - law.pair.delta0,
            };
            match s.top {
                SampleTop::Rough => Ok(generate_rbd(&params)),
                SampleTop::Cut => generate_rbd_below(&params, side).map_err(|e| {
                    SetupError::Invalid(format!(
                        "[sample] top = \"cut\" with monomers = {} and a side of {:.2} µm: {e}; \
                         use fewer monomers, a larger side_um, or top = \"rough\"",
                        s.monomers,
                        side * 1e4
                    ))
                }),
            }
        }
    }
}

/// Index of the top wall in [`build_walls`]' list; the bottom wall is 0.
pub const TOP_WALL: usize = 1;

/// Walls for the experiment: bottom (index 0) at the height where the monomers resting on the
/// floor sit at the wall's equilibrium overlap, top (index 1) touching the highest monomer and
/// moving down, and for the omnidirectional box the four side walls.
pub fn build_walls(
    config: &Config,
    law: &ContactLaw,
    sample: &Sample,
) -> Result<Vec<Wall>, SetupError> {
    let r = law.radius;
    let end = law.wall_constants(config.walls.top_bottom);
    let side = law.wall_constants(config.walls.side);
    let speed = config.experiment.wall_speed_m_s * 100.0;
    let z_max = sample.z_max();
    let mut walls = vec![
        Wall {
            name: "bottom".into(),
            point: DVec3::new(0.0, 0.0, end.delta0),
            normal: DVec3::Z,
            velocity: DVec3::ZERO,
            constants: end,
        },
        Wall {
            name: "top".into(),
            point: DVec3::new(0.0, 0.0, z_max + r),
            normal: -DVec3::Z,
            velocity: DVec3::new(0.0, 0.0, -speed),
            constants: end,
        },
    ];
    if config.experiment.kind == ExperimentKind::Omni {
        let half =
            match sample.footprint {
                Footprint::Box { side } => 0.5 * side,
                Footprint::Cylinder { .. } => return Err(SetupError::Invalid(
                    "[sample] footprint = \"cylinder\" is not allowed for kind = \"omni\": the \
                     omnidirectional box needs footprint = \"box\""
                        .into(),
                )),
            };
        for (name, normal) in [
            ("x-", DVec3::X),
            ("x+", -DVec3::X),
            ("y-", DVec3::Y),
            ("y+", -DVec3::Y),
        ] {
            walls.push(Wall {
                name: format!("side {name}"),
                point: -normal * half,
                normal,
                velocity: DVec3::ZERO,
                constants: side,
            });
        }
    }
    Ok(walls)
}

/// The monomers an engine starts from: the sample's, in the storage order the config asks for
/// (`[integration] space_filling_order`), each keeping its sample number as its id.
pub fn stored_monomers(config: &Config, sample: &Sample) -> Monomers {
    let monomers = monomers_of(sample);
    if config.integration.space_filling_order {
        let order = space_filling_order(&monomers.position, 2.0 * sample.radius);
        monomers.permuted(&order)
    } else {
        monomers
    }
}

pub fn monomers_of(sample: &Sample) -> Monomers {
    Monomers::new(
        sample
            .positions
            .iter()
            .map(|p| DVec3::new(p[0], p[1], p[2]))
            .collect(),
    )
}
