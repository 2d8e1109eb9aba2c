//! Rigid bodies that meet the fluid (docs/method.md §11): a triangle mesh sampled once in the
//! body's own frame with boundary particles, placed by a pose, of one of three kinds.
//!
//! - **static** bodies never move; their particles join the walls' (and share their Akinci
//!   volumes), and the fluid's force on them is reported;
//! - **kinematic** bodies move as the embedding program (or a scripted [`Oscillation`]) says:
//!   their pose and velocity are set between steps, and the fluid feels them where they will
//!   be at the end of the step;
//! - **dynamic** bodies are moved by gravity and the fluid's force and torque on them.
//!
//! A body's frame is the frame its mesh is given in; velocities are those of the centre of
//! mass (linear, m/s) and about it (angular, rad/s, in world axes).

mod inset;
mod mass;
mod motion;
mod pose;
mod shape;

pub(crate) use inset::inset;
pub use mass::MassProperties;
pub use motion::Oscillation;
pub use pose::{Pose, Rotation, Velocity};
pub use shape::Shape;

use crate::boundary::Aabb;
use crate::boundary::mesh::TriangleMesh;
use crate::{Error, Vec3};
use nalgebra::Matrix3;

/// How a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BodyKind {
    /// Never moves.
    Static,
    /// Moves as set from outside (or by its scripted motion); the fluid does not move it.
    Kinematic,
    /// Moved by gravity and the fluid.
    Dynamic,
}

/// How a body's mass is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BodyMass {
    /// Uniform density (kg/m³) filling the closed mesh.
    Density(f64),
    /// Explicit mass properties.
    Explicit(MassProperties),
}

/// What [`crate::World::add_body`] needs to make a body.
#[derive(Clone, Debug)]
pub struct BodySpec {
    /// How the body moves.
    pub kind: BodyKind,
    /// The surface in the body's own frame (m).
    pub mesh: TriangleMesh,
    /// The mass: required for dynamic bodies; for the others it only places the centre of
    /// mass about which torques are reported (without it, the centroid of the enclosed volume,
    /// or of the bounding box for an open mesh).
    pub mass: Option<BodyMass>,
    /// The initial pose.
    pub pose: Pose,
    /// The initial velocity (ignored for static bodies).
    pub velocity: Velocity,
    /// A scripted motion about the initial pose (kinematic bodies only).
    pub motion: Option<Oscillation>,
}

/// The part of a body's state that changes during a run: what a checkpoint keeps of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState {
    /// The pose.
    pub pose: Pose,
    /// The velocity.
    pub velocity: Velocity,
    /// A kinematic body's pose at the end of the next step, where one was set.
    pub target: Option<Pose>,
    /// The fluid's force in the last step (N).
    pub force: Vec3,
    /// The fluid's torque in the last step, about the centre of mass (N·m).
    pub torque: Vec3,
}

/// A rigid body in a world.
#[derive(Clone, Debug)]
pub struct Body {
    pub(crate) kind: BodyKind,
    /// The surface, body frame (m).
    pub(crate) mesh: TriangleMesh,
    /// Boundary particles, body frame (m).
    pub(crate) samples: Vec<Vec3>,
    /// Akinci masses ψ of the samples (kg), computed in the body frame over the body's own
    /// samples (moving bodies; static ones share the walls' volumes).
    pub(crate) psi: Vec<f64>,
    /// Mass properties (dynamic bodies, or where given).
    pub(crate) mass: Option<MassProperties>,
    /// The centre of mass in the body frame (m).
    pub(crate) centre: Vec3,
    pub(crate) pose: Pose,
    pub(crate) velocity: Velocity,
    /// The scripted motion with the pose it oscillates about.
    pub(crate) motion: Option<(Oscillation, Pose)>,
    /// Where a kinematic body is to be at the end of the next step.
    pub(crate) target: Option<Pose>,
    /// The largest distance of a sample from the centre of mass (m).
    pub(crate) reach: f64,
    /// The fluid's force on the body in the last step (N) and its torque about the centre
    /// of mass (N·m).
    pub(crate) force: Vec3,
    pub(crate) torque: Vec3,
}

impl Body {
    /// How the body moves.
    pub fn kind(&self) -> BodyKind {
        self.kind
    }

    /// The current pose.
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// The current velocity.
    pub fn velocity(&self) -> Velocity {
        self.velocity
    }

    /// The centre of mass in world coordinates (m).
    pub fn centre_of_mass(&self) -> Vec3 {
        self.pose.apply(&self.centre)
    }

    /// Mass properties, where the body has them.
    pub fn mass_properties(&self) -> Option<&MassProperties> {
        self.mass.as_ref()
    }

    /// The fluid's force on the body during the last step (N).
    pub fn force(&self) -> Vec3 {
        self.force
    }

    /// The fluid's torque on the body during the last step, about its centre of mass (N·m).
    pub fn torque(&self) -> Vec3 {
        self.torque
    }

    /// The surface in the body's own frame (m).
    pub fn mesh(&self) -> &TriangleMesh {
        &self.mesh
    }

    /// The mesh placed at the current pose (m).
    pub fn placed_mesh(&self) -> TriangleMesh {
        let vertices = self.mesh.vertices().iter().map(|v| self.pose.apply(v));
        TriangleMesh::new(vertices.collect(), self.mesh.triangles().to_vec())
            .expect("a rigid motion keeps a valid mesh valid")
    }

    /// Number of boundary particles sampling the body.
    pub fn particle_count(&self) -> usize {
        self.samples.len()
    }

    /// The boundary particles at the current pose (m).
    pub fn particle_positions(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.samples.iter().map(|s| self.pose.apply(s))
    }

    /// What changes during a run.
    pub fn state(&self) -> BodyState {
        BodyState {
            pose: self.pose,
            velocity: self.velocity,
            target: self.target,
            force: self.force,
            torque: self.torque,
        }
    }

    /// Restores what [`Body::state`] returned.
    pub(crate) fn set_state(&mut self, state: &BodyState) {
        self.pose = state.pose;
        self.velocity = state.velocity;
        self.target = state.target;
        self.force = state.force;
        self.torque = state.torque;
    }

    /// Whether the body moves during steps.
    pub(crate) fn moves(&self) -> bool {
        self.kind != BodyKind::Static
    }

    /// The highest speed of any of its particles (m/s).
    pub(crate) fn max_particle_speed(&self) -> f64 {
        self.velocity.linear.norm() + self.velocity.angular.norm() * self.reach
    }

    /// Sets the pose so that the centre of mass is at `centre` (m) and the orientation is
    /// `rotation`.
    fn place_centre(&mut self, centre: Vec3, rotation: Rotation) {
        self.pose = Pose {
            position: centre - rotation * self.centre,
            rotation,
        };
    }

    /// Moves the body to where it is at the end of a step of `dt` seconds that ends at time
    /// `end` (s): by its script, or with its velocity (static bodies stay).
    pub(crate) fn advance_pose(&mut self, dt: f64, end: f64) {
        if self.kind == BodyKind::Static {
            return;
        }
        // A target pose is for bodies without a script (the setters refuse scripted ones).
        if let Some(target) = self.target.take().filter(|_| self.motion.is_none()) {
            let from = self.centre_of_mass();
            let to = target.apply(&self.centre);
            let turn = target.rotation * self.pose.rotation.inverse();
            self.velocity = Velocity {
                linear: (to - from) / dt,
                angular: turn.scaled_axis() / dt,
            };
            self.pose = target;
            return;
        }
        match self.motion {
            Some((script, initial)) => {
                let (pose, velocity) = script.at(&initial, end);
                // The script moves the frame's origin; report the centre of mass's velocity.
                self.pose = pose;
                let arm = pose.rotation * self.centre;
                self.velocity = Velocity {
                    linear: velocity.linear + velocity.angular.cross(&arm),
                    angular: velocity.angular,
                };
            }
            None => {
                let centre = self.centre_of_mass() + self.velocity.linear * dt;
                let rotation =
                    Rotation::from_scaled_axis(self.velocity.angular * dt) * self.pose.rotation;
                self.place_centre(centre, rotation);
            }
        }
    }

    /// Rigid contact with a container's walls (docs/method.md §11.4): moves a dynamic body
    /// back so that none of its particles lies closer than `clearance` (m) to a wall of
    /// `container`, and stops its motion into any wall it touches. Other kinds are unchanged.
    pub(crate) fn keep_inside(&mut self, container: &Aabb, clearance: f64) {
        if self.kind != BodyKind::Dynamic {
            return;
        }
        let (lo, hi) = (
            container.min + Vec3::repeat(clearance),
            container.max - Vec3::repeat(clearance),
        );
        let (mut below, mut above) = (Vec3::zeros(), Vec3::zeros());
        for p in self.particle_positions() {
            below = below.sup(&(lo - p));
            above = above.sup(&(p - hi));
        }
        let mut shift = Vec3::zeros();
        for a in 0..3 {
            if below[a] > 0.0 {
                shift[a] = below[a];
                self.velocity.linear[a] = self.velocity.linear[a].max(0.0);
            } else if above[a] > 0.0 {
                shift[a] = -above[a];
                self.velocity.linear[a] = self.velocity.linear[a].min(0.0);
            }
        }
        if shift != Vec3::zeros() {
            self.pose.position += shift;
        }
    }

    /// A dynamic body's velocity change over a step of `dt` seconds under `gravity` (m/s²)
    /// and the fluid's force and torque of that step (symplectic Euler: the pose of the step
    /// was set with the old velocity). Other kinds are unchanged.
    pub(crate) fn accelerate(&mut self, dt: f64, gravity: Vec3) {
        let (BodyKind::Dynamic, Some(mass)) = (self.kind, self.mass) else {
            return;
        };
        self.velocity.linear += (gravity + self.force / mass.mass) * dt;
        let r: Matrix3<f64> = self.pose.rotation.to_rotation_matrix().into_inner();
        let inertia = r * mass.inertia * r.transpose();
        let omega = self.velocity.angular;
        let gyroscopic = omega.cross(&(inertia * omega));
        let inverse = inertia
            .try_inverse()
            .expect("inertia tensors are checked positive definite");
        self.velocity.angular += inverse * (self.torque - gyroscopic) * dt;
    }
}

/// The centre of mass (body frame, m) a body without mass properties reports torques about.
fn centroid(mesh: &TriangleMesh) -> Vec3 {
    match MassProperties::of_mesh(mesh, 1.0) {
        Ok(p) => p.centre,
        Err(_) => {
            let b = mesh.bounds();
            (b.min + b.max) / 2.0
        }
    }
}

impl BodySpec {
    /// Checks the spec and makes the body with its samples (body frame, m) and their Akinci
    /// masses ψ (kg). Errors name the field.
    pub(crate) fn build(self, samples: Vec<Vec3>, psi: Vec<f64>) -> Result<Body, Error> {
        self.velocity.validate()?;
        if let Some(script) = &self.motion {
            if self.kind != BodyKind::Kinematic {
                return Err(Error::invalid(
                    "motion",
                    format!("{:?}", self.kind),
                    "is for kinematic bodies only",
                ));
            }
            script.validate()?;
        }
        let mass = match self.mass {
            Some(BodyMass::Density(density)) => Some(MassProperties::of_mesh(&self.mesh, density)?),
            Some(BodyMass::Explicit(p)) => Some(MassProperties::new(p.mass, p.centre, p.inertia)?),
            None if self.kind == BodyKind::Dynamic => {
                return Err(Error::invalid(
                    "mass",
                    "none",
                    "must be given for a dynamic body (a density or explicit properties)",
                ));
            }
            None => None,
        };
        if samples.is_empty() {
            return Err(Error::invalid(
                "mesh",
                format!("area {:.3e} m²", self.mesh.area()),
                "gives no boundary particles",
            ));
        }
        let centre = mass.map_or_else(|| centroid(&self.mesh), |p| p.centre);
        let reach = samples
            .iter()
            .map(|s| (s - centre).norm())
            .fold(0.0, f64::max);
        let velocity = if self.kind == BodyKind::Static {
            Velocity::default()
        } else {
            self.velocity
        };
        Ok(Body {
            kind: self.kind,
            mesh: self.mesh,
            samples,
            psi,
            mass,
            centre,
            pose: self.pose,
            velocity,
            motion: self.motion.map(|m| (m, self.pose)),
            target: None,
            reach,
            force: Vec3::zeros(),
            torque: Vec3::zeros(),
        })
    }
}
