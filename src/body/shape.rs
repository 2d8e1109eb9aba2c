//! Primitive solids for bodies and obstacles: boxes, spheres and cylinders as closed,
//! outward-oriented triangle meshes centred on the origin of their own frame.

use crate::boundary::mesh::TriangleMesh;
use crate::boundary::shapes::{Frame, Shapes, circle};
use crate::{Error, Vec3};

/// A primitive solid, centred on the origin of its own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A box with these half-extents along x, y and z (m).
    Box {
        /// Half-extents (m, > 0).
        half_extents: Vec3,
    },
    /// A sphere of this radius (m).
    Sphere {
        /// Radius (m, > 0).
        radius: f64,
    },
    /// A cylinder along the frame's y axis.
    Cylinder {
        /// Radius (m, > 0).
        radius: f64,
        /// Height along y (m, > 0).
        height: f64,
    },
}

impl Shape {
    /// The surface as a closed triangle mesh whose triangles are no larger than about
    /// `spacing` (m) across on curved surfaces (at least 32 segments around a circle, a
    /// sphere subdivided at least three times). Errors when a size is not positive and finite.
    pub fn mesh(&self, spacing: f64) -> Result<TriangleMesh, Error> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(
                    name,
                    v,
                    "must be a positive finite length (m)",
                ))
            }
        };
        let mut shapes = Shapes::new();
        match *self {
            Shape::Box { half_extents } => {
                for (name, v) in ["half_extents.x", "half_extents.y", "half_extents.z"]
                    .iter()
                    .zip(half_extents.iter())
                {
                    positive(name, *v)?;
                }
                shapes.add_box(-half_extents, half_extents);
            }
            Shape::Sphere { radius } => {
                positive("radius", radius)?;
                let mut levels = 3;
                while levels < 7 && radius * 1.1 / f64::from(1u32 << levels) > spacing {
                    levels += 1;
                }
                shapes.add_sphere(Vec3::zeros(), radius, levels);
            }
            Shape::Cylinder { radius, height } => {
                positive("radius", radius)?;
                positive("height", height)?;
                let around =
                    ((std::f64::consts::TAU * radius / spacing).ceil() as usize).clamp(32, 4096);
                let frame = |y: f64| Frame {
                    centre: Vec3::new(0.0, y, 0.0),
                    u: Vec3::z(),
                    v: Vec3::x(),
                    size: [radius, radius],
                };
                shapes.add_sweep(
                    &circle(around),
                    &[frame(-height / 2.0), frame(height / 2.0)],
                );
            }
        }
        shapes.into_mesh()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::MassProperties;
    use crate::boundary::winding::is_closed_and_oriented;

    #[test]
    fn primitives_are_closed_and_enclose_their_volume() {
        let pi = std::f64::consts::PI;
        for (shape, volume) in [
            (
                Shape::Box {
                    half_extents: Vec3::new(0.1, 0.2, 0.3),
                },
                0.2 * 0.4 * 0.6,
            ),
            (Shape::Sphere { radius: 0.2 }, 4.0 / 3.0 * pi * 0.008),
            (
                Shape::Cylinder {
                    radius: 0.1,
                    height: 0.5,
                },
                pi * 0.01 * 0.5,
            ),
        ] {
            let mesh = shape.mesh(0.025).unwrap();
            assert!(is_closed_and_oriented(&mesh), "{shape:?}");
            let p = MassProperties::of_mesh(&mesh, 1.0).unwrap();
            assert!(
                (p.mass / volume - 1.0).abs() < 0.01,
                "{shape:?}: {}",
                p.mass
            );
            assert!(p.centre.norm() < 1e-9, "{shape:?}: {}", p.centre);
        }
    }

    #[test]
    fn degenerate_sizes_are_rejected() {
        for shape in [
            Shape::Box {
                half_extents: Vec3::new(0.1, 0.0, 0.1),
            },
            Shape::Sphere { radius: f64::NAN },
            Shape::Cylinder {
                radius: 0.1,
                height: -1.0,
            },
        ] {
            assert!(shape.mesh(0.025).is_err(), "{shape:?}");
        }
    }
}
