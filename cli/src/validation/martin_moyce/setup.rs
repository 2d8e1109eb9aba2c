//! The collapse's setup: column ratio, resolution, slab thickness, duration and solver, and
//! the world they build.

use crate::validation::reference::COLUMN_WIDTH;
use projfluid::boundary::Aabb;
use projfluid::scene::ContainerWalls;
use projfluid::{Error, Params, SolverKind, Vec3, World};

/// How the collapse is set up and how long it runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Setup {
    /// Height/width ratio n² of the column: 2 (height 2a) or 1 (square).
    pub n2: u32,
    /// Particles across the column width a; the spacing is d = a/particles_across.
    pub particles_across: usize,
    /// Slab thickness in particles (between the two side walls).
    pub layers: usize,
    /// Dimensionless duration τ = t·√(g/a).
    pub duration: f64,
    /// Global solver.
    pub solver: SolverKind,
    /// Worker threads (0 = one per core).
    pub threads: usize,
    /// What the tank's walls are (default: particles, as in scenes).
    pub walls: ContainerWalls,
    /// Whether the outer iteration starts from the coarse correction (docs/method.md §3.8;
    /// off, as by default).
    pub coarse_correction: bool,
}

impl Setup {
    /// The defaults for ratio `n2`: 20 particles across, 4 layers, and a duration covering
    /// the tabulated front (τ = 3.0 for n² = 2, 3.5 for n² = 1).
    pub fn new(n2: u32) -> Self {
        Self {
            n2,
            particles_across: 20,
            layers: 4,
            duration: if n2 == 1 { 3.5 } else { 3.0 },
            solver: SolverKind::Chebyshev,
            threads: 0,
            walls: ContainerWalls::Particles,
            coarse_correction: false,
        }
    }

    /// Checks every field; the error names the bad one.
    pub fn validate(&self) -> Result<(), Error> {
        if !matches!(self.n2, 1 | 2) {
            return Err(Error::invalid("n2", self.n2, "must be 1 or 2"));
        }
        if !(4..=200).contains(&self.particles_across) {
            let n = self.particles_across;
            return Err(Error::invalid(
                "resolution",
                n,
                "must lie between 4 and 200",
            ));
        }
        if !(1..=20).contains(&self.layers) {
            return Err(Error::invalid(
                "layers",
                self.layers,
                "must lie between 1 and 20",
            ));
        }
        if !(self.duration.is_finite() && self.duration > 0.0 && self.duration <= 20.0) {
            return Err(Error::invalid(
                "duration",
                self.duration,
                "must lie in (0, 20]",
            ));
        }
        Ok(())
    }

    /// n = √(n²).
    pub fn n(&self) -> f64 {
        f64::from(self.n2).sqrt()
    }

    /// Lattice spacing d (m).
    pub fn spacing(&self) -> f64 {
        COLUMN_WIDTH / self.particles_across as f64
    }

    /// Tank length in units of a: the front cannot reach the far wall within the duration
    /// even at the shallow-water (Ritter) speed bound dZ/dT = 2.
    pub fn tank_length(&self) -> f64 {
        (1.0 + 2.0 * self.n() * self.duration).ceil() + 1.0
    }

    /// The world at t = 0 and the tank it stands in. At the default mass factor the
    /// column starts at rest density and does not first settle.
    pub fn build(&self) -> Result<(World, Aabb), Error> {
        self.validate()?;
        let a = COLUMN_WIDTH;
        let d = self.spacing();
        let params = Params {
            solver: self.solver,
            threads: self.threads,
            coarse_correction: self.coarse_correction,
            ..Params::with_radius(0.5 * d)
        };
        let r = params.particle_radius;
        let mut world = World::new(params)?;
        // First centres one spacing (plus r/4, so that no corner starts compressed) from the walls.
        let gap = d + 0.25 * r;
        let count = [
            self.particles_across,
            self.n2 as usize * self.particles_across,
            self.layers,
        ];
        let tank = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(
                self.tank_length() * a,
                (self.n2 as f64 + 1.0) * a,
                2.0 * gap + (self.layers - 1) as f64 * d,
            ),
        };
        world.add_container_with(tank, self.walls)?;
        world.add_fluid_block(Vec3::repeat(gap), count, Vec3::zeros())?;
        Ok((world, tank))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::validation::martin_moyce::{column_height, front_position};

    #[test]
    fn setup_is_validated_and_builds_the_column() {
        let mut s = Setup::new(2);
        s.particles_across = 6;
        let (world, tank) = s.build().unwrap();
        assert_eq!(world.fluid_count(), 6 * 12 * 4);
        assert!(tank.max.x >= s.tank_length() * COLUMN_WIDTH * 0.999);
        let positions = world.positions();
        let (a, d) = (COLUMN_WIDTH, s.spacing());
        let z = front_position(&positions, 0.0, 0.0, d).unwrap();
        let h = column_height(&positions, 0.0, 0.0, d).unwrap();
        // Centres start one spacing plus r/4 from the walls: extents a + r/4 and 2a + r/4.
        assert!((z - (a + 0.125 * d)).abs() < 1e-9, "z = {z}");
        assert!((h - (2.0 * a + 0.125 * d)).abs() < 1e-9, "h = {h}");
        assert!(!world.params().coarse_correction);
        let corrected = Setup {
            coarse_correction: true,
            ..s.clone()
        };
        assert!(corrected.build().unwrap().0.params().coarse_correction);
        for bad in [
            Setup {
                n2: 3,
                ..Setup::new(2)
            },
            Setup {
                particles_across: 2,
                ..Setup::new(2)
            },
            Setup {
                layers: 0,
                ..Setup::new(2)
            },
            Setup {
                duration: f64::NAN,
                ..Setup::new(2)
            },
        ] {
            assert!(bad.build().is_err());
        }
    }
}
