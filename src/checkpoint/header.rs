//! A checkpoint's JSON header: the scene, the world's counters and boxes, the bodies' and
//! the emitters' changing state. Every number is exact (serde_json round-trips f64).

use super::RunEnd;
use crate::body::{BodyState, Pose, Velocity};
use crate::boundary::Aabb;
use crate::emitter::{EmitterShape, EmitterSpec, EmitterState};
use crate::solver::OnlineRho;
use crate::{Error, GridParts, Vec3};
use serde::{Deserialize, Serialize};

/// The JSON header.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Header {
    pub scene: String,
    pub time: f64,
    pub steps: u64,
    pub next_dt: f64,
    pub containers: Vec<SavedBox>,
    /// The containers whose walls are fields (absent in checkpoints from before them).
    #[serde(default)]
    pub field_walls: Vec<SavedBox>,
    pub grid: Option<GridParts>,
    pub grid_capped: bool,
    pub boundary_dirty: bool,
    pub fluid_count: usize,
    pub boundary_count: usize,
    pub run_end: Option<RunEnd>,
    pub chebyshev: OnlineRho,
    pub bodies: Vec<SavedBody>,
    /// The id the next added fluid particle gets.
    pub next_id: u64,
    /// Fluid particles removed so far.
    pub removed_count: u64,
    pub sinks: Vec<SavedBox>,
    pub domain: Option<SavedBox>,
    pub emitters: Vec<SavedEmitter>,
    /// The rest densities (kg/m³) of the materials added to the world (docs/method.md §14),
    /// in the order they were added, and the material of the fluid added next.
    pub materials: Vec<f64>,
    pub fluid_material: u16,
    /// Every material's kinematic viscosity ν (m²/s), the world's own fluid's first; absent
    /// in checkpoints written before materials had their own viscosity, whose materials had
    /// none beyond the parameters' (`kinematic_viscosity`) for the world's own fluid.
    #[serde(default)]
    pub viscosities: Vec<f64>,
    /// Every material's surface tension σ (N/m), the world's own fluid's first; absent in
    /// checkpoints written before surface tension, whose materials had none.
    #[serde(default)]
    pub tensions: Vec<f64>,
    /// Whether the particle data holds the pressures the last step carried (absent, and no
    /// pressures, in checkpoints written before they were saved).
    #[serde(default)]
    pub pressures: bool,
}

/// A box as its lower and upper corners (m).
pub(super) type SavedBox = [[f64; 3]; 2];

/// The corners of `b`.
pub(super) fn saved_box(b: &Aabb) -> SavedBox {
    [b.min.into(), b.max.into()]
}

/// The box with corners `b`.
pub(super) fn aabb([min, max]: &SavedBox) -> Aabb {
    Aabb {
        min: Vec3::from(*min),
        max: Vec3::from(*max),
    }
}

/// A body's changing state in the header, every number exact (serde_json round-trips f64).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SavedBody {
    /// Position (m) and quaternion [w, x, y, z].
    pose: ([f64; 3], [f64; 4]),
    /// Linear (m/s) and angular (rad/s) velocity.
    velocity: [[f64; 3]; 2],
    target: Option<([f64; 3], [f64; 4])>,
    /// Force (N) and torque (N·m).
    load: [[f64; 3]; 2],
}

impl SavedBody {
    pub fn of(b: &BodyState) -> Self {
        let pose = |p: &Pose| (p.position.into(), p.wxyz());
        Self {
            pose: pose(&b.pose),
            velocity: [b.velocity.linear.into(), b.velocity.angular.into()],
            target: b.target.as_ref().map(pose),
            load: [b.force.into(), b.torque.into()],
        }
    }

    /// The state, or an error naming what is not a valid pose.
    pub fn state(&self) -> Result<BodyState, Error> {
        let pose = |(x, q): &([f64; 3], [f64; 4])| {
            // Stored quaternions are unit to round-off; keep them exactly as saved.
            Pose::from_parts(Vec3::from(*x), *q).map(|_| Pose {
                position: Vec3::from(*x),
                rotation: crate::body::Rotation::new_unchecked(nalgebra::Quaternion::new(
                    q[0], q[1], q[2], q[3],
                )),
            })
        };
        Ok(BodyState {
            pose: pose(&self.pose)?,
            velocity: Velocity {
                linear: Vec3::from(self.velocity[0]),
                angular: Vec3::from(self.velocity[1]),
            },
            target: self.target.as_ref().map(pose).transpose()?,
            force: Vec3::from(self.load[0]),
            torque: Vec3::from(self.load[1]),
        })
    }
}

/// An emitter's spec and progress in the header.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SavedEmitter {
    shape: SavedShape,
    /// Centre (m).
    position: [f64; 3],
    /// Direction as given.
    direction: [f64; 3],
    /// Speed (m/s).
    speed: f64,
    /// End time (s).
    end_time: Option<f64>,
    /// The last layer's travel (m).
    travelled: f64,
    emitted: u64,
    /// The material it emits (docs/method.md §14).
    material: u16,
}

/// An emitter's opening: a disc's radius or a rectangle's half-extents (m).
#[derive(Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
enum SavedShape {
    Disc(f64),
    Rectangle([f64; 2]),
}

impl SavedEmitter {
    pub fn of(e: &EmitterState) -> Self {
        let s = &e.spec;
        Self {
            shape: match s.shape {
                EmitterShape::Disc { radius } => SavedShape::Disc(radius),
                EmitterShape::Rectangle { half_extents } => SavedShape::Rectangle(half_extents),
            },
            position: s.position.into(),
            direction: s.direction.into(),
            speed: s.speed,
            end_time: s.end_time,
            travelled: e.travelled,
            emitted: e.emitted,
            material: e.material,
        }
    }

    /// The state (checked when the world imports it).
    pub fn state(&self) -> EmitterState {
        EmitterState {
            spec: EmitterSpec {
                shape: match self.shape {
                    SavedShape::Disc(radius) => EmitterShape::Disc { radius },
                    SavedShape::Rectangle(half_extents) => EmitterShape::Rectangle { half_extents },
                },
                position: Vec3::from(self.position),
                direction: Vec3::from(self.direction),
                speed: self.speed,
                end_time: self.end_time,
            },
            travelled: self.travelled,
            emitted: self.emitted,
            material: self.material,
        }
    }
}
