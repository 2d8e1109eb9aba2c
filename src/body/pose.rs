//! Where a body is and how fast it moves: its pose (position and unit quaternion) and its
//! linear and angular velocity.

use crate::{Error, Vec3};

/// An orientation: a unit quaternion (body frame → world).
pub type Rotation = nalgebra::UnitQuaternion<f64>;

/// Where a body's frame is: the position of its origin (m) and its orientation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The frame's origin in world coordinates (m).
    pub position: Vec3,
    /// The frame's orientation (body → world).
    pub rotation: Rotation,
}

impl Default for Pose {
    /// The identity: the body frame is the world frame.
    fn default() -> Self {
        Self {
            position: Vec3::zeros(),
            rotation: Rotation::identity(),
        }
    }
}

impl Pose {
    /// A body-frame point in world coordinates (m).
    pub fn apply(&self, local: &Vec3) -> Vec3 {
        self.position + self.rotation * local
    }

    /// The pose from a position and a quaternion given as `[w, x, y, z]`, which must be
    /// finite and of unit length within 10⁻⁶ (it is then normalised). Errors name the field.
    pub fn from_parts(position: Vec3, wxyz: [f64; 4]) -> Result<Self, Error> {
        if !position.iter().all(|c| c.is_finite()) {
            return Err(Error::invalid(
                "position",
                format!("{:?}", position.as_slice()),
                "must be finite",
            ));
        }
        let q = nalgebra::Quaternion::new(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
        if !(wxyz.iter().all(|c| c.is_finite()) && (q.norm() - 1.0).abs() <= 1e-6) {
            return Err(Error::invalid(
                "rotation",
                format!("{wxyz:?}"),
                "must be a finite unit quaternion [w, x, y, z] (length 1 within 1e-6)",
            ));
        }
        Ok(Self {
            position,
            rotation: Rotation::from_quaternion(q),
        })
    }

    /// The quaternion as `[w, x, y, z]`.
    pub fn wxyz(&self) -> [f64; 4] {
        let q = self.rotation.quaternion();
        [q.w, q.i, q.j, q.k]
    }
}

/// A body's velocity: of its centre of mass (m/s) and its angular velocity about it (rad/s,
/// world axes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Velocity {
    /// Velocity of the centre of mass (m/s).
    pub linear: Vec3,
    /// Angular velocity (rad/s, world axes).
    pub angular: Vec3,
}

impl Velocity {
    /// Checks that both vectors are finite.
    pub fn validate(&self) -> Result<(), Error> {
        if self
            .linear
            .iter()
            .chain(self.angular.iter())
            .all(|c| c.is_finite())
        {
            Ok(())
        } else {
            Err(Error::invalid(
                "velocity",
                format!(
                    "{:?}, {:?}",
                    self.linear.as_slice(),
                    self.angular.as_slice()
                ),
                "must be finite",
            ))
        }
    }
}
