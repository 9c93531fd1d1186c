//! The walls: planes moving at constant velocity, each with its own contact constants.

use crate::material::ContactConstants;
use glam::DVec3;

/// A planar wall moving at constant velocity. `normal` points into the domain.
#[derive(Clone, Debug, PartialEq)]
pub struct Wall {
    pub name: String,
    pub point: DVec3,
    pub normal: DVec3,
    pub velocity: DVec3,
    /// Contact constants with this wall's strength factors applied.
    pub constants: ContactConstants,
}
