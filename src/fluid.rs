//! Fluid particle storage: a structure of arrays in the order the last step sorted it.

use crate::Vec3;

/// Fluid particles in their current storage order (Z-order after the first step).
#[derive(Clone, Debug, Default)]
pub(crate) struct Fluid {
    /// Positions (m).
    pub positions: Vec<Vec3>,
    /// Velocities (m/s).
    pub velocities: Vec<Vec3>,
    /// Densities after the last step (kg/m³; zero before the first step).
    pub densities: Vec<f64>,
    /// The order in which each particle was added; outputs are reported in this order.
    pub ids: Vec<u32>,
}

impl Fluid {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.positions.len()
    }
}
