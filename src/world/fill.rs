//! Adding to a world: fluid particles and blocks, boundary particles, container boxes and
//! triangle-mesh obstacles. Every method checks its input first and changes nothing when it
//! rejects it.

use super::placement::Settling;
use super::{MAX_PARTICLES, World, box_wall_sample_count, check_finite};
use crate::boundary::mesh::{TriangleMesh, sample_count_bound, sample_poisson_disk};
use crate::boundary::winding::is_closed_and_oriented;
use crate::boundary::{
    Aabb, ContainerWalls, MAX_WALL_SPACING, MIN_WALL_SPACING, WALL_SPACING, WALLS, WallField,
    sample_box_walls_into, wall_spacing,
};
use crate::{Error, Vec3};

/// Most boundary particles one triangle mesh may need (by [`sample_count_bound`]), which also
/// bounds the sampler's time and memory.
const MAX_MESH_SAMPLES: f64 = 50e6;

/// Working memory of the Poisson-disk sampler per sample of [`sample_count_bound`] (bytes):
/// about ten candidates of 32 bytes each, the accepted samples and their cell table.
pub(super) const MESH_SAMPLING_BYTES: f64 = 400.0;

/// The error of a fluid reservation that failed.
fn fluid_oom(_: std::collections::TryReserveError) -> Error {
    Error::out_of_memory("fluid particles")
}

/// The error of a boundary reservation that failed.
fn boundary_oom(_: std::collections::TryReserveError) -> Error {
    Error::out_of_memory("boundary particles")
}

/// The points `at(i, j, k)` for i < count[0], j < count[1], k < count[2], i running fastest.
fn lattice(
    count: [usize; 3],
    at: impl Fn(usize, usize, usize) -> Vec3,
) -> impl Iterator<Item = Vec3> {
    (0..count[2])
        .flat_map(move |k| (0..count[1]).flat_map(move |j| (0..count[0]).map(move |i| (i, j, k))))
        .map(move |(i, j, k)| at(i, j, k))
}

impl World {
    /// Adds fluid particles at `positions` (m) with `velocities` (m/s; zero when `None`)
    /// where they do not lie inside a solid (outside every container box, or inside a closed
    /// obstacle or body), moving those nearer than r to a wall, a closed obstacle or a body out
    /// to r (they are not projected as [`World::add_fluid_block`]'s are). Returns how
    /// many it added; they get the next ids in the order given (see [`World::ids`]). Rejects
    /// non-finite values, length mismatches, too many particles and
    /// ([`Error::OutOfMemory`]) a shortage of memory without changing the world.
    pub fn add_fluid_particles(
        &mut self,
        positions: &[Vec3],
        velocities: Option<&[Vec3]>,
    ) -> Result<usize, Error> {
        check_finite("positions", positions)?;
        if let Some(v) = velocities {
            if v.len() != positions.len() {
                return Err(Error::invalid(
                    "velocities",
                    v.len(),
                    &format!("must have one entry per position ({})", positions.len()),
                ));
            }
            check_finite("velocities", v)?;
        }
        if self.fluid.len() + positions.len() > MAX_PARTICLES {
            return Err(Error::invalid(
                "positions",
                positions.len(),
                "would exceed the particle limit",
            ));
        }
        self.try_reserve_fluid(positions.len()).map_err(fluid_oom)?;
        let solids = self.solids();
        let outside: Vec<bool> = positions.iter().map(|p| !solids.contain(p)).collect();
        let kept = |k: &usize| outside[*k];
        let first = self.fluid.next_id;
        let added = outside.iter().filter(|&&o| o).count();
        let at = (0..positions.len()).filter(kept).map(|k| positions[k]);
        let material = self.materials.current;
        match velocities {
            Some(v) => self
                .fluid
                .extend(material, at, (0..v.len()).filter(kept).map(|k| v[k])),
            None => self
                .fluid
                .extend(material, at, std::iter::repeat_n(Vec3::zeros(), added)),
        }
        self.settle_new_fluid(first, solids, Settling::Clear);
        self.last_added = added;
        Ok(added)
    }

    /// Adds a cubic lattice of fluid particles with spacing 2r: centres at
    /// `start + 2r·(i, j, k)` for i < count[0], j < count[1], k < count[2], all moving with
    /// `velocity`, except those inside a solid (outside every container box, or inside a
    /// closed obstacle or body), which are not created. Returns how many it added; they get
    /// the next ids with i running fastest, then j, then k.
    ///
    /// The new particles start calm wherever they are put (docs/method.md §2.7): those nearer
    /// than r to a container wall are moved out to r, and what they compress against walls,
    /// obstacles, bodies or fluid already there is projected away on their positions, not
    /// turned into velocity. Errors, changing nothing, on a zero or absurd count, a non-finite
    /// lattice, or ([`Error::OutOfMemory`]) a shortage of memory.
    pub fn add_fluid_block(
        &mut self,
        start: Vec3,
        count: [usize; 3],
        velocity: Vec3,
    ) -> Result<usize, Error> {
        let total = count.iter().try_fold(1usize, |acc, &c| acc.checked_mul(c));
        match total {
            Some(n) if n > 0 && n <= MAX_PARTICLES => {}
            _ => {
                return Err(Error::invalid(
                    "count",
                    format!("{count:?}"),
                    "must be positive and not absurdly large",
                ));
            }
        }
        let n = total.unwrap_or(0);
        check_finite("start", &[start, velocity])?;
        let d = self.params.spacing();
        let at =
            move |i: usize, j: usize, k: usize| start + Vec3::new(i as f64, j as f64, k as f64) * d;
        // The lattice is monotone along each axis: its far corner is finite only if all are.
        check_finite("positions", &[at(count[0] - 1, count[1] - 1, count[2] - 1)])?;
        if self.fluid.len() + n > MAX_PARTICLES {
            return Err(Error::invalid(
                "count",
                format!("{count:?}"),
                "would exceed the particle limit",
            ));
        }
        self.try_reserve_fluid(n).map_err(fluid_oom)?;
        let solids = self.solids();
        let added = lattice(count, at).filter(|p| !solids.contain(p)).count();
        let first = self.fluid.next_id;
        let kept = lattice(count, at).filter(|p| !solids.contain(p));
        self.fluid.extend(
            self.materials.current,
            kept,
            std::iter::repeat_n(velocity, added),
        );
        self.settle_new_fluid(first, solids, Settling::Block);
        self.last_added = added;
        Ok(added)
    }

    /// Adds static boundary particles at `positions` (m). Rejects non-finite values, too many
    /// particles and ([`Error::OutOfMemory`]) a shortage of memory without changing the world.
    pub fn add_boundary_particles(&mut self, positions: &[Vec3]) -> Result<(), Error> {
        check_finite("positions", positions)?;
        if self.boundary.len() + positions.len() > MAX_PARTICLES {
            return Err(Error::invalid(
                "positions",
                positions.len(),
                "would exceed the boundary particle limit",
            ));
        }
        self.try_reserve_boundary(positions.len())
            .map_err(boundary_oom)?;
        self.boundary.add_static(positions, WALLS);
        Ok(())
    }

    /// Adds a closed container box: its six walls sampled with boundary particles of the
    /// default spacing [`WALL_SPACING`]·r = r, `layers` layers thick (1–3). Fluid outside
    /// every container counts as escaped. Errors, changing nothing, on a bad box or layer
    /// count, too many particles, or a shortage of memory. See
    /// [`add_container_spaced`](Self::add_container_spaced) for other spacings.
    pub fn add_container(&mut self, container: Aabb, layers: usize) -> Result<(), Error> {
        let spacing = WALL_SPACING * self.params.particle_radius;
        self.add_container_spaced(container, layers, spacing)
    }

    /// Adds a closed container box as [`add_container`](Self::add_container) does, its walls
    /// sampled at most `spacing` (m) apart, from r/4 to 2r. Walls sampled at 2r hold a quarter
    /// of the boundary particles of walls at r; what sparser walls gain and cost depends on
    /// the flow (docs/method.md §7). Errors, changing nothing, on a spacing outside that
    /// range, and as `add_container` does.
    pub fn add_container_spaced(
        &mut self,
        container: Aabb,
        layers: usize,
        spacing: f64,
    ) -> Result<(), Error> {
        self.check_container(&container)?;
        let r = self.params.particle_radius;
        let Some(spacing) = wall_spacing(spacing, r) else {
            return Err(Error::invalid(
                "spacing",
                spacing,
                &format!(
                    "must be from r/4 to 2r ({} to {} m)",
                    MIN_WALL_SPACING * r,
                    MAX_WALL_SPACING * r
                ),
            ));
        };
        if !(1..=3).contains(&layers) {
            return Err(Error::invalid("layers", layers, "must be 1, 2 or 3"));
        }
        let size = container.max - container.min;
        let expected = box_wall_sample_count(&container, spacing, layers);
        if expected + self.boundary.len() as f64 > MAX_PARTICLES as f64 {
            return Err(Error::invalid(
                "container",
                format!("{:?}", size.as_slice()),
                &format!("needs about {expected:.3e} boundary particles, more than the limit"),
            ));
        }
        let mut samples = Vec::new();
        samples
            .try_reserve_exact(expected as usize)
            .map_err(boundary_oom)?;
        sample_box_walls_into(&container, spacing, layers, &mut samples);
        self.containers.try_reserve(1).map_err(boundary_oom)?;
        self.add_boundary_particles(&samples)?;
        self.containers.push(container);
        Ok(())
    }

    /// Adds a closed container box whose six walls are fields rather than particles
    /// (docs/method.md §7): each wall adds to a fluid particle's density, smoothly, what a
    /// wall of boundary particles r apart adds on average along it, and costs nothing per
    /// boundary particle. Fluid outside every container counts as escaped. Errors, changing
    /// nothing, on a box that is not finite, narrower than two particle spacings along an
    /// axis or wider than 10⁵·r, on a shortage of memory, or on a world on the GPU backend,
    /// which does not step such walls yet.
    pub fn add_container_field(&mut self, container: Aabb) -> Result<(), Error> {
        self.refuse_on_gpu("container walls built as fields")?;
        self.check_container(&container)?;
        let oom = |_| Error::out_of_memory("the container");
        self.containers.try_reserve(1).map_err(oom)?;
        self.boundary.walls.try_reserve(1).map_err(oom)?;
        self.boundary.walls.push(self.wall_field(container));
        self.containers.push(container);
        Ok(())
    }

    /// Adds a closed container box with walls of the kind asked for: fields
    /// ([`add_container_field`](Self::add_container_field)) or one layer of particles r apart
    /// ([`add_container`](Self::add_container)). Errors, changing nothing, as those do.
    pub fn add_container_with(
        &mut self,
        container: Aabb,
        walls: ContainerWalls,
    ) -> Result<(), Error> {
        match walls {
            ContainerWalls::Field => self.add_container_field(container),
            ContainerWalls::Particles => self.add_container(container, 1),
        }
    }

    /// The walls of `container` (m) as a field for this world's fluid.
    pub(super) fn wall_field(&self, container: Aabb) -> WallField {
        let spacing = WALL_SPACING * self.params.particle_radius;
        WallField::new(
            container,
            spacing,
            &self.constraint.kernel,
            self.params.rest_density,
        )
    }

    /// Refuses a container box that is not finite, is narrower than two particle spacings
    /// along an axis, or is wider than 10⁵·r.
    pub(super) fn check_container(&self, container: &Aabb) -> Result<(), Error> {
        check_finite("container", &[container.min, container.max])?;
        let size = container.max - container.min;
        if (0..3).any(|a| size[a] < 2.0 * self.params.spacing()) {
            return Err(Error::invalid(
                "container",
                format!(
                    "{:?}..{:?}",
                    container.min.as_slice(),
                    container.max.as_slice()
                ),
                "must be at least two particle spacings wide along every axis",
            ));
        }
        if size.iter().any(|&s| s / self.params.particle_radius > 1e5) {
            return Err(Error::invalid(
                "container",
                format!("{:?}", size.as_slice()),
                "is too large for the particle radius",
            ));
        }
        Ok(())
    }

    /// Reserves room for `additional` more fluid particles in every per-particle array, so that
    /// a following add does not fail to allocate. Changes nothing observable.
    /// Errors when the memory cannot be had; the world stays usable.
    pub fn try_reserve_fluid(
        &mut self,
        additional: usize,
    ) -> Result<(), std::collections::TryReserveError> {
        let f = &mut self.fluid;
        f.positions.try_reserve(additional)?;
        f.velocities.try_reserve(additional)?;
        f.densities.try_reserve(additional)?;
        f.ids.try_reserve(additional)?;
        f.ascending.try_reserve(additional)
    }

    /// Reserves room for `additional` more boundary particles (see [`World::try_reserve_fluid`]).
    pub fn try_reserve_boundary(
        &mut self,
        additional: usize,
    ) -> Result<(), std::collections::TryReserveError> {
        let boundary = &mut self.boundary;
        boundary
            .positions
            .try_reserve(boundary.len() + additional)?;
        boundary.owner.try_reserve(additional)
    }

    /// Adds a static obstacle: the surface of `mesh` (m) sampled by Poisson disk with a
    /// minimum distance of one particle radius r (see [`sample_poisson_disk`]), the samples
    /// added as boundary particles. Their Akinci volumes are computed before the next step.
    /// Winding does not matter and the mesh need not be closed; only the surface is sampled,
    /// one layer thick. A closed mesh is kept, so that fluid added later is not created
    /// inside it, and makes room for itself (docs/method.md §2.7): fluid whose centre lies
    /// inside it is removed (see [`World::removed_count`]), and the fluid next to it is moved
    /// out of it and settled. Errors, leaving the world unchanged, when the mesh is far larger than r
    /// (an extent above 10⁶·r or more than about 5·10⁷ samples), the boundary particle
    /// limit would be exceeded, or ([`Error::OutOfMemory`]) the memory the sampling needs
    /// cannot be had when the call starts.
    pub fn add_boundary_mesh(&mut self, mesh: &TriangleMesh) -> Result<(), Error> {
        let r = self.params.particle_radius;
        let bounds = mesh.bounds();
        let size = bounds.max - bounds.min;
        if size.iter().any(|&s| s / r > 1e6) {
            return Err(Error::invalid(
                "mesh",
                format!("extent {:?} m", size.as_slice()),
                &format!("is too large for the particle radius {r} m (at most 1e6·r per axis)"),
            ));
        }
        let bound = sample_count_bound(mesh, r);
        if !(bound <= MAX_MESH_SAMPLES
            && bound + self.boundary.len() as f64 <= MAX_PARTICLES as f64)
        {
            return Err(Error::invalid(
                "mesh",
                format!("area {:.3e} m² needing up to {bound:.3e}", mesh.area()),
                &format!(
                    "is too large for the particle radius {r} m (at most {MAX_MESH_SAMPLES:.0e} \
                     boundary particles, {MAX_PARTICLES} in all)"
                ),
            ));
        }
        crate::reserve::probe(bound * MESH_SAMPLING_BYTES).map_err(boundary_oom)?;
        let samples = sample_poisson_disk(mesh, r);
        let closed = is_closed_and_oriented(mesh);
        self.obstacles
            .try_reserve(usize::from(closed))
            .map_err(boundary_oom)?;
        self.add_boundary_particles(&samples)?;
        if closed {
            self.obstacles.push(mesh.clone());
            self.displace_fluid(mesh);
        }
        Ok(())
    }
}
