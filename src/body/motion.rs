//! Scripted motion of a kinematic body: a sinusoidal oscillation of position and orientation
//! about its initial pose, such as a wave paddle's stroke.

use super::{Pose, Rotation, Velocity};
use crate::{Error, Vec3};
use std::f64::consts::TAU;

/// Pose(t) = initial pose displaced by `amplitude`·sin(2πt/T + φ) and turned by the rotation
/// vector `angular_amplitude`·sin(2πt/T + φ) (applied before the initial rotation, about the
/// body's reference point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Oscillation {
    /// Translation amplitude (m).
    pub amplitude: Vec3,
    /// Rotation amplitude as a rotation vector: axis times angle (rad).
    pub angular_amplitude: Vec3,
    /// Period T (s, > 0).
    pub period: f64,
    /// Phase φ (rad).
    pub phase: f64,
}

impl Oscillation {
    /// Checks that every value is finite and the period positive.
    pub fn validate(&self) -> Result<(), Error> {
        let finite = |v: &Vec3| v.iter().all(|c| c.is_finite());
        if !finite(&self.amplitude) || !finite(&self.angular_amplitude) {
            return Err(Error::invalid(
                "motion",
                format!(
                    "{:?}, {:?}",
                    self.amplitude.as_slice(),
                    self.angular_amplitude.as_slice()
                ),
                "amplitudes must be finite",
            ));
        }
        if !(self.period.is_finite() && self.period > 0.0) {
            return Err(Error::invalid(
                "motion.period",
                self.period,
                "must be a positive finite number of seconds",
            ));
        }
        if !self.phase.is_finite() {
            return Err(Error::invalid("motion.phase", self.phase, "must be finite"));
        }
        Ok(())
    }

    /// The pose at time `t` (s) of a body whose pose at rest is `initial`, and its velocity
    /// then (m/s, rad/s; the angular velocity in world axes).
    pub fn at(&self, initial: &Pose, t: f64) -> (Pose, Velocity) {
        let omega = TAU / self.period;
        let arg = omega * t + self.phase;
        let (s, c) = arg.sin_cos();
        let turn = Rotation::from_scaled_axis(self.angular_amplitude * s);
        let pose = Pose {
            position: initial.position + self.amplitude * s,
            rotation: turn * initial.rotation,
        };
        let velocity = Velocity {
            linear: self.amplitude * (omega * c),
            // The rotation vector's axis is fixed, so its rate is the angular velocity.
            angular: self.angular_amplitude * (omega * c),
        };
        (pose, velocity)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_velocity_is_the_derivative_of_the_pose() {
        let motion = Oscillation {
            amplitude: Vec3::new(0.1, 0.0, 0.02),
            angular_amplitude: Vec3::new(0.0, 0.0, 0.3),
            period: 1.5,
            phase: 0.4,
        };
        let initial = Pose {
            position: Vec3::new(1.0, 0.5, 0.2),
            rotation: Rotation::from_scaled_axis(Vec3::new(0.2, 0.1, 0.0)),
        };
        let (t, h) = (0.37, 1e-6);
        let (p0, v) = motion.at(&initial, t);
        let (p1, _) = motion.at(&initial, t + h);
        let linear = (p1.position - p0.position) / h;
        assert!((linear - v.linear).norm() < 1e-5, "{linear} {}", v.linear);
        let turn = (p1.rotation * p0.rotation.inverse()).scaled_axis() / h;
        assert!((turn - v.angular).norm() < 1e-5, "{turn} {}", v.angular);
        let (start, _) = motion.at(&initial, -0.4 / (TAU / 1.5));
        assert!((start.position - initial.position).norm() < 1e-12);
    }

    #[test]
    fn non_positive_periods_and_nan_amplitudes_are_rejected() {
        let good = Oscillation {
            amplitude: Vec3::x(),
            angular_amplitude: Vec3::zeros(),
            period: 1.0,
            phase: 0.0,
        };
        assert!(good.validate().is_ok());
        for bad in [
            Oscillation {
                period: 0.0,
                ..good
            },
            Oscillation {
                period: f64::INFINITY,
                ..good
            },
            Oscillation {
                amplitude: Vec3::new(f64::NAN, 0.0, 0.0),
                ..good
            },
            Oscillation {
                phase: f64::NAN,
                ..good
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
    }
}
