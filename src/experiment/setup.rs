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
        SampleSource::Rbd => build_rbd(config, law),
    }
}

/// Widening steps tried for an automatic footprint under a cut top: 1% each, up to ×1.49.
const CUT_WIDENING_STEPS: i32 = 40;

/// An RBD sample. Under a cut top with an automatic footprint, the footprint widens in 1%
/// steps until `monomers` fit below a height equal to its width: a small sample's wall
/// layers hold less than the bulk's φ = 0.15, so the cube of that φ cannot hold them all.
/// A footprint the config sets is never changed.
fn build_rbd(config: &Config, law: &ContactLaw) -> Result<Sample, SetupError> {
    let s = &config.sample;
    let automatic = match s.footprint {
        FootprintKind::Box => s.side_um <= 0.0,
        FootprintKind::Cylinder => s.cylinder_radius_um <= 0.0,
    };
    let steps = match (s.top, automatic) {
        (SampleTop::Cut, true) => CUT_WIDENING_STEPS,
        _ => 0,
    };
    let mut first_error = None;
    for step in 0..=steps {
        let params = rbd_params(config, law, 1.01f64.powi(step));
        let side = square_side(&params.footprint);
        let built = match s.top {
            SampleTop::Rough => return Ok(generate_rbd(&params)),
            SampleTop::Cut => generate_rbd_below(&params, side),
        };
        match built {
            Ok(sample) => return Ok(sample),
            Err(e) => {
                first_error.get_or_insert(format!(
                    "[sample] top = \"cut\" with monomers = {} and a side of {:.2} µm: {e}",
                    s.monomers,
                    side * 1e4
                ));
            }
        }
    }
    let widened = if steps > 0 {
        format!(" (widened up to ×{:.2} without room)", 1.01f64.powi(steps))
    } else {
        String::new()
    };
    Err(SetupError::Invalid(format!(
        "{}{widened}; use fewer monomers, a larger side_um, or top = \"rough\"",
        first_error.expect("at least one attempt")
    )))
}

/// RBD parameters with the automatic footprint scaled by `widen` (a set footprint is kept).
fn rbd_params(config: &Config, law: &ContactLaw, widen: f64) -> RbdParams {
    let s = &config.sample;
    let r = law.radius;
    let cube_side = side_for_cube(s.monomers, r, RBD_FILLING_FACTOR) * widen;
    let footprint = match s.footprint {
        FootprintKind::Box => Footprint::Box {
            side: if s.side_um > 0.0 {
                s.side_um * 1e-4
            } else {
                cube_side
            },
        },
        FootprintKind::Cylinder => Footprint::Cylinder {
            radius: if s.cylinder_radius_um > 0.0 {
                s.cylinder_radius_um * 1e-4
            } else {
                cube_side / std::f64::consts::PI.sqrt()
            },
        },
    };
    RbdParams {
        n: s.monomers,
        radius: r,
        footprint,
        seed: s.seed,
        contact_distance: 2.0 * r - law.pair.delta0,
    }
}

/// The side of the square with the footprint's base area (a box's own side).
fn square_side(footprint: &Footprint) -> f64 {
    match footprint {
        Footprint::Box { side } => *side,
        Footprint::Cylinder { radius } => radius * std::f64::consts::PI.sqrt(),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn cut_config(monomers: usize, side_um: f64) -> Config {
        let mut config = Config::default();
        config.sample.source = SampleSource::Rbd;
        config.sample.monomers = monomers;
        config.sample.footprint = FootprintKind::Box;
        config.sample.top = SampleTop::Cut;
        config.sample.side_um = side_um;
        config.sample.seed = 1;
        config
    }

    /// 1000 monomers do not fit below a cube of the bulk's φ = 0.15 (18.2 µm): the automatic
    /// footprint widens until they do, and the sample is still as tall as it is wide.
    #[test]
    fn a_small_cut_sample_widens_its_automatic_footprint() {
        let config = cut_config(1000, 0.0);
        let law = config.contact_law();
        let sample = build_sample(&config, &law).expect("the widened footprint holds them");
        let Footprint::Box { side } = sample.footprint else {
            panic!("box footprint expected");
        };
        // Cube of φ = 0.15 for 1000 monomers of 0.6 µm: (1000 · 0.9048 µm³ / 0.15)^(1/3).
        let cube_um = 18.20;
        assert!(
            side * 1e4 > cube_um + 0.1,
            "side {} µm not widened",
            side * 1e4
        );
        assert!(
            side * 1e4 < cube_um * 1.5,
            "side {} µm widened too far",
            side * 1e4
        );
        assert_eq!(sample.positions.len(), 1000);
        let top = sample
            .positions
            .iter()
            .map(|p| p[2])
            .fold(f64::MIN, f64::max);
        assert!(
            top + sample.radius <= side * (1.0 + 1e-12),
            "top {top} above side {side}"
        );
        assert!(
            top + sample.radius > 0.9 * side,
            "top {top} far below the cut at {side}"
        );
    }

    /// A footprint the config sets is never widened: the error names it.
    #[test]
    fn a_set_side_too_small_for_a_cut_top_is_refused() {
        let config = cut_config(1000, 18.2);
        let law = config.contact_law();
        let err = build_sample(&config, &law).expect_err("18.2 µm cannot hold 1000 under a cut");
        let text = err.to_string();
        assert!(
            text.contains("top = \"cut\"") && text.contains("18.20 µm"),
            "{text}"
        );
        assert!(!text.contains("widened"), "{text}");
    }
}
