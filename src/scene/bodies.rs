//! Rigid bodies in a scene: their spec ([`SceneBody`]), its checks (errors name the JSON key,
//! e.g. `bodies[1].density`) and how a world gets them ([`Scene::add_bodies`]).

use super::{ObstacleSpec, Scene};
use crate::body::{BodyKind, BodyMass, BodySpec, Oscillation, Pose, Shape, Velocity};
use crate::boundary::mesh::TriangleMesh;
use crate::{BodyId, Error, Vec3, World};
use serde::{Deserialize, Serialize};

/// A rigid body of a scene (docs/scene-format.md, `bodies[i]`; docs/method.md §11).
#[derive(Clone, Debug, PartialEq)]
pub struct SceneBody {
    /// How it moves.
    pub kind: BodyKind,
    /// Its surface, in the body's own frame.
    pub shape: BodyShape,
    /// Uniform density filling the closed surface (kg/m³): required for dynamic bodies; for
    /// the others it only places the centre of mass that torques are reported about.
    pub density: Option<f64>,
    /// The body frame's origin in the world (m).
    pub position: [f64; 3],
    /// The body frame's orientation as a unit quaternion `[w, x, y, z]`.
    pub rotation: [f64; 4],
    /// Initial velocity of the centre of mass (m/s; ignored for static bodies).
    pub velocity: [f64; 3],
    /// Initial angular velocity about the centre of mass (rad/s, world axes; ignored for
    /// static bodies).
    pub angular_velocity: [f64; 3],
    /// A scripted oscillation about the initial pose (kinematic bodies only).
    pub motion: Option<MotionSpec>,
}

/// A body's surface in its own frame: a primitive centred on the frame's origin, or a mesh.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyShape {
    /// A box with these half-extents along x, y and z (m).
    Box {
        /// Half-extents (m, > 0).
        half_extents: [f64; 3],
    },
    /// A sphere (m).
    Sphere {
        /// Radius (m, > 0).
        radius: f64,
    },
    /// A cylinder along the frame's y axis (m).
    Cylinder {
        /// Radius (m, > 0).
        radius: f64,
        /// Height along y (m, > 0).
        height: f64,
    },
    /// A mesh read or generated as an obstacle's, its transform placing it in the body's
    /// frame.
    Mesh(ObstacleSpec),
}

/// A kinematic body's scripted motion: its pose is the initial pose displaced by
/// `amplitude`·sin(2πt/`period` + `phase`) and turned by the rotation vector
/// `angular_amplitude`·sin(2πt/`period` + `phase`) (see [`Oscillation`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// Translation amplitude (m; default 0).
    #[serde(default)]
    pub amplitude: [f64; 3],
    /// Rotation amplitude as axis times angle (rad; default 0).
    #[serde(default)]
    pub angular_amplitude: [f64; 3],
    /// Period (s, > 0).
    pub period: f64,
    /// Phase (rad; default 0).
    #[serde(default)]
    pub phase: f64,
}

impl From<MotionSpec> for Oscillation {
    fn from(m: MotionSpec) -> Self {
        Oscillation {
            amplitude: Vec3::from(m.amplitude),
            angular_amplitude: Vec3::from(m.angular_amplitude),
            period: m.period,
            phase: m.phase,
        }
    }
}

impl SceneBody {
    /// The surface in the body frame (m); primitives are meshed for particle radius `r`.
    /// Mesh files are read here; errors name the file and line.
    pub fn mesh(&self, r: f64) -> Result<TriangleMesh, Error> {
        match &self.shape {
            BodyShape::Box { half_extents } => Shape::Box {
                half_extents: Vec3::from(*half_extents),
            }
            .mesh(r),
            &BodyShape::Sphere { radius } => Shape::Sphere { radius }.mesh(r),
            &BodyShape::Cylinder { radius, height } => Shape::Cylinder { radius, height }.mesh(r),
            BodyShape::Mesh(source) => source.mesh(r),
        }
    }

    /// The [`BodySpec`] for [`World::add_body`], for particle radius `r`.
    pub fn spec(&self, r: f64) -> Result<BodySpec, Error> {
        Ok(BodySpec {
            kind: self.kind,
            mesh: self.mesh(r)?,
            mass: self.density.map(BodyMass::Density),
            pose: Pose::from_parts(Vec3::from(self.position), self.rotation)?,
            velocity: Velocity {
                linear: Vec3::from(self.velocity),
                angular: Vec3::from(self.angular_velocity),
            },
            motion: self.motion.map(Oscillation::from),
        })
    }
}

impl Scene {
    /// Adds the scene's bodies to `world`, in order (body `i` gets id `i` in a world without
    /// bodies). Errors start with `bodies[i]: `. [`Scene::build_world`] calls it; a restored
    /// checkpoint calls it on an empty world, whose particles then come from the saved state.
    pub fn add_bodies(&self, world: &mut World) -> Result<Vec<BodyId>, Error> {
        let r = world.params().particle_radius;
        self.bodies
            .iter()
            .enumerate()
            .map(|(i, b)| {
                b.spec(r)
                    .and_then(|spec| world.add_body(spec))
                    .map_err(|e| super::prefixed(e, &format!("bodies[{i}]: ")))
            })
            .collect()
    }
}

/// An error whose field is `prefix.FIELD` and whose message starts with it.
fn named(prefix: &str, e: Error) -> Error {
    match e {
        Error::InvalidArgument { field, message } => Error::InvalidArgument {
            message: format!("{prefix}.{message}"),
            field: format!("{prefix}.{field}"),
        },
        other => other,
    }
}

/// Checks the sizes of the shape at JSON key `key` (a body or an obstacle): positive and
/// finite lengths (m), or a valid mesh source.
pub(super) fn check_shape(key: &str, shape: &BodyShape) -> Result<(), Error> {
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(Error::invalid(
                format!("{key}.{name}"),
                v,
                "must be a positive finite length (m)",
            ))
        }
    };
    match shape {
        BodyShape::Box { half_extents } => {
            for (a, &v) in half_extents.iter().enumerate() {
                positive(&format!("box.half_extents[{a}]"), v)?;
            }
            Ok(())
        }
        &BodyShape::Sphere { radius } => positive("sphere.radius", radius),
        &BodyShape::Cylinder { radius, height } => {
            positive("cylinder.radius", radius)?;
            positive("cylinder.height", height)
        }
        BodyShape::Mesh(source) => {
            super::validate::check_mesh_source(&format!("{key}.mesh"), source)
        }
    }
}

/// Checks body `i`'s values (not its mesh file, read when the world is built).
pub(super) fn check_body(i: usize, b: &SceneBody) -> Result<(), Error> {
    let key = format!("bodies[{i}]");
    check_shape(&key, &b.shape)?;
    match b.density {
        None if b.kind == BodyKind::Dynamic => {
            return Err(Error::invalid(
                format!("{key}.density"),
                "none",
                "must be given for a dynamic body (kg/m³)",
            ));
        }
        Some(d) if !(d.is_finite() && d > 0.0) => {
            return Err(Error::invalid(
                format!("{key}.density"),
                d,
                "must be a positive finite number of kg/m³",
            ));
        }
        _ => {}
    }
    Pose::from_parts(Vec3::from(b.position), b.rotation).map_err(|e| named(&key, e))?;
    for (name, v) in [
        ("velocity", b.velocity),
        ("angular_velocity", b.angular_velocity),
    ] {
        if v.iter().any(|c| !c.is_finite()) {
            return Err(Error::invalid(
                format!("{key}.{name}"),
                format!("{v:?}"),
                "must be finite",
            ));
        }
    }
    if let Some(m) = b.motion {
        if b.kind != BodyKind::Kinematic {
            return Err(Error::invalid(
                format!("{key}.motion"),
                format!("a {} body", kind_name(b.kind)),
                "is for kinematic bodies only",
            ));
        }
        for (name, v) in [
            ("amplitude", m.amplitude),
            ("angular_amplitude", m.angular_amplitude),
        ] {
            if v.iter().any(|c| !c.is_finite()) {
                return Err(Error::invalid(
                    format!("{key}.motion.{name}"),
                    format!("{v:?}"),
                    "must be finite",
                ));
            }
        }
        Oscillation::from(m)
            .validate()
            .map_err(|e| named(&key, e))?;
    }
    Ok(())
}

/// The scene-file name of a kind.
pub(super) fn kind_name(kind: BodyKind) -> &'static str {
    match kind {
        BodyKind::Static => "static",
        BodyKind::Kinematic => "kinematic",
        BodyKind::Dynamic => "dynamic",
    }
}
