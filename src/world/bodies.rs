//! Rigid bodies in a world (docs/method.md §11): adding them, moving kinematic ones between
//! steps, and reading their poses and the fluid's loads on them and on the walls.

use super::{MAX_PARTICLES, World};
use crate::body::{Body, BodyKind, BodySpec, Pose, Velocity, inset};
use crate::boundary::mesh::{sample_count_bound, sample_poisson_disk};
use crate::boundary::own_masses;
use crate::boundary::winding::is_closed_and_oriented;
use crate::{Error, Vec3};

/// Most boundary particles one body may have.
const MAX_BODY_SAMPLES: f64 = 5e6;

/// A body's handle within its world: the order in which it was added, from 0.
pub type BodyId = usize;

impl World {
    /// Adds a rigid body: its mesh is sampled in the body frame by Poisson disk with a
    /// minimum distance of one particle radius r, like an obstacle, and for a closed mesh the
    /// samples are set back r into the body (half way through parts thinner than 2r), so that
    /// the fluid, which keeps about r from boundary particles, meets the mesh itself. A static body's particles
    /// join the walls' (their Akinci volumes are computed with the walls'); a moving body's
    /// volumes are computed once over its own particles. Returns the body's id. Errors,
    /// leaving the world unchanged, on a bad spec (named field), a mesh that is far larger
    /// than r or gives no particles, the particle limit, or a world on the GPU backend,
    /// which does not step bodies yet.
    ///
    /// A closed body makes room for itself (docs/method.md §2.7): fluid whose centre lies
    /// inside it is removed (see [`World::removed_count`]), and the fluid next to it is
    /// moved out of it and settled.
    pub fn add_body(&mut self, spec: BodySpec) -> Result<BodyId, Error> {
        self.refuse_on_gpu("bodies")?;
        let r = self.params.particle_radius;
        let bounds = spec.mesh.bounds();
        let size = bounds.max - bounds.min;
        let bound = sample_count_bound(&spec.mesh, r);
        let total = self.boundary.len() as f64
            + self
                .bodies
                .iter()
                .map(|b| b.samples.len() as f64)
                .sum::<f64>();
        if size.iter().any(|&s| s / r > 1e5)
            || !(bound <= MAX_BODY_SAMPLES && total + bound <= MAX_PARTICLES as f64)
        {
            return Err(Error::invalid(
                "mesh",
                format!(
                    "extent {:?} m needing up to {bound:.3e} particles",
                    size.as_slice()
                ),
                &format!(
                    "is too large for the particle radius {r} m (at most {MAX_BODY_SAMPLES:.0e} \
                     particles a body)"
                ),
            ));
        }
        crate::reserve::probe(bound * super::fill::MESH_SAMPLING_BYTES)
            .map_err(|_| Error::out_of_memory("body particles"))?;
        let on_surface = sample_poisson_disk(&spec.mesh, r);
        let samples = self.pool.install(|| inset(&spec.mesh, &on_surface, r));
        let id = self.bodies.len();
        let owner = u32::try_from(id)
            .ok()
            .filter(|&o| o < crate::boundary::WALLS)
            .ok_or_else(|| Error::invalid("bodies", id, "too many bodies"))?;
        let kind = spec.kind;
        let psi = if kind == BodyKind::Static {
            Vec::new()
        } else {
            // On the world's own pool: rayon's global pool would start threads that outlive
            // the world (and that the C API's pf_world_destroy could not join).
            let (kernel, rest_density) = (&self.constraint.kernel, self.params.rest_density);
            self.pool
                .install(|| own_masses(&samples, kernel, rest_density))
                .map_err(|_| Error::out_of_memory("body particles"))?
        };
        let body = spec.build(samples, psi)?;
        if kind == BodyKind::Static {
            let placed: Vec<Vec3> = body.particle_positions().collect();
            self.boundary.add_static(&placed, owner);
        }
        self.boundary.set_moving(owner, body.moves());
        let closed = is_closed_and_oriented(&body.mesh).then(|| body.placed_mesh());
        self.bodies.push(body);
        if let Some(placed) = closed {
            self.displace_fluid(&placed);
        }
        Ok(id)
    }

    /// The bodies, in the order they were added (index = [`BodyId`]).
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// Body `id`, or an error naming it.
    pub fn body(&self, id: BodyId) -> Result<&Body, Error> {
        self.bodies.get(id).ok_or_else(|| no_body(id))
    }

    /// A moving (kinematic or dynamic) body for a change of its pose or velocity.
    fn moving_body(&mut self, id: BodyId) -> Result<&mut Body, Error> {
        let body = self.bodies.get_mut(id).ok_or_else(|| no_body(id))?;
        if body.kind == BodyKind::Static {
            return Err(Error::invalid(
                "body",
                id,
                "is static: its pose and velocity cannot change",
            ));
        }
        Ok(body)
    }

    /// Sets a kinematic or dynamic body's pose now (it is teleported; the next step moves it
    /// on with its velocity). Errors for a static body or a scripted one, changing nothing.
    pub fn set_body_pose(&mut self, id: BodyId, pose: Pose) -> Result<(), Error> {
        let pose = Pose::from_parts(pose.position, pose.wxyz())?;
        let body = self.moving_body(id)?;
        refuse_scripted(body, id)?;
        body.pose = pose;
        body.target = None;
        Ok(())
    }

    /// Sets a kinematic or dynamic body's velocity: of its centre of mass (m/s) and about it
    /// (rad/s, world axes). The next step moves the body with it. Errors for a static or
    /// scripted body or non-finite values, changing nothing.
    pub fn set_body_velocity(&mut self, id: BodyId, velocity: Velocity) -> Result<(), Error> {
        velocity.validate()?;
        let body = self.moving_body(id)?;
        refuse_scripted(body, id)?;
        body.velocity = velocity;
        body.target = None;
        Ok(())
    }

    /// Sets where a kinematic body is to be at the end of the next step: the step moves it
    /// there, and its velocity follows from the two poses and the step's size. Errors for
    /// other kinds, scripted bodies or a bad pose, changing nothing.
    pub fn set_body_target_pose(&mut self, id: BodyId, pose: Pose) -> Result<(), Error> {
        let pose = Pose::from_parts(pose.position, pose.wxyz())?;
        let body = self.moving_body(id)?;
        refuse_scripted(body, id)?;
        if body.kind != BodyKind::Kinematic {
            return Err(Error::invalid(
                "body",
                id,
                "is dynamic: only kinematic bodies follow a target pose",
            ));
        }
        body.target = Some(pose);
        Ok(())
    }

    /// The fluid's force on the container walls and static obstacles together during the last
    /// step (N); static bodies report theirs separately. Measured only in worlds with bodies
    /// (zero otherwise), where the loads are computed every step.
    pub fn wall_force(&self) -> Vec3 {
        self.wall_load.force
    }
}

fn no_body(id: BodyId) -> Error {
    Error::invalid("body", id, "is not a body of this world")
}

fn refuse_scripted(body: &Body, id: BodyId) -> Result<(), Error> {
    if body.motion.is_some() {
        return Err(Error::invalid(
            "body",
            id,
            "follows a scripted motion: its pose and velocity are the script's",
        ));
    }
    Ok(())
}
