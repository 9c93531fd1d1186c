//! Initial agglomerate samples: generation, density analysis and files.
//!
//! A sample is a packing of equal monomers resting on the floor `z = 0`
//! inside a vertical footprint centred on `x = y = 0`. It is built once by
//! random ballistic deposition ([`generate_rbd`]), stored as a text file
//! ([`Sample::save`], [`Sample::load`]) and then handed to the simulation.

mod file;
mod profile;
mod rbd;

pub use file::SampleError;
pub use profile::{
    filling_factor_profile, interior_filling_factor, slab_profile, INTERIOR_MARGIN_CONTACTS,
    INTERIOR_Z_HI_FRACTION, INTERIOR_Z_LO_FRACTION,
};
pub use rbd::{generate_rbd, generate_rbd_below, side_for_cube, RbdParams};

/// Horizontal cross-section of the container, centred on `x = y = 0`.
#[derive(Clone, Debug, PartialEq)]
pub enum Footprint {
    /// Square of edge `side` (cm), edges parallel to the x and y axes.
    Box { side: f64 },
    /// Disc of radius `radius` (cm).
    Cylinder { radius: f64 },
}

impl Footprint {
    /// Cross-section area (cm^2).
    pub fn area(&self) -> f64 {
        match *self {
            Footprint::Box { side } => side * side,
            Footprint::Cylinder { radius } => std::f64::consts::PI * radius * radius,
        }
    }

    /// Largest |x| (box) or sqrt(x^2 + y^2) (cylinder) of the footprint (cm).
    pub fn half_width(&self) -> f64 {
        match *self {
            Footprint::Box { side } => 0.5 * side,
            Footprint::Cylinder { radius } => radius,
        }
    }

    /// Same shape shrunk by `margin` on every side.
    pub fn inset(&self, margin: f64) -> Footprint {
        match *self {
            Footprint::Box { side } => Footprint::Box {
                side: side - 2.0 * margin,
            },
            Footprint::Cylinder { radius } => Footprint::Cylinder {
                radius: radius - margin,
            },
        }
    }

    /// Whether the point `(x, y)` lies in the footprint (boundary included).
    pub fn contains(&self, x: f64, y: f64) -> bool {
        match *self {
            Footprint::Box { side } => {
                let h = 0.5 * side;
                x.abs() <= h && y.abs() <= h
            }
            Footprint::Cylinder { radius } => x * x + y * y <= radius * radius,
        }
    }
}

/// A packing of equal spheres on the floor `z = 0`.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Monomer radius (cm).
    pub radius: f64,
    /// Container cross-section; every monomer sphere lies inside it.
    pub footprint: Footprint,
    /// Seed of the random stream that built the sample.
    pub seed: u64,
    /// Centre distance at which a falling monomer sticks (cm).
    pub contact_distance: f64,
    /// Monomer centres (cm), in deposition order.
    pub positions: Vec<[f64; 3]>,
}

impl Sample {
    /// Volume of one monomer (cm^3).
    pub fn monomer_volume(&self) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * self.radius.powi(3)
    }

    /// Highest centre height (cm); `radius` (a floor monomer) when empty.
    pub fn z_max(&self) -> f64 {
        self.positions
            .iter()
            .map(|p| p[2])
            .fold(self.radius, f64::max)
    }

    /// Solid fraction of the whole column up to the top of the highest
    /// monomer: `N V_mono / (area * (z_max + radius))`.
    ///
    /// Includes the dense floor layer and the rough top, so it is lower than
    /// [`interior_filling_factor`] for RBD samples.
    pub fn filling_factor_bulk(&self) -> f64 {
        let n = self.positions.len() as f64;
        n * self.monomer_volume() / (self.footprint.area() * (self.z_max() + self.radius))
    }
}
