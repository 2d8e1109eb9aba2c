//! Placing a mesh in the world: scale, then rotate, then translate.

use super::mesh::TriangleMesh;
use crate::{Error, Vec3};
use nalgebra::Rotation3;

/// A similarity-like placement of a mesh, applied to every vertex p as
/// `translate + R·(scale ∘ p)`: first a per-axis scale about the origin, then a rotation,
/// then a translation.
///
/// The rotation is given as Euler angles in degrees, `rotate_deg = [x, y, z]`, applied about
/// the fixed world axes in the order x, then y, then z, i.e. R = R_z(z)·R_y(y)·R_x(x)
/// (right-handed, counter-clockwise when looking down the axis towards the origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Scale factor along x, y and z (positive, dimensionless).
    pub scale: [f64; 3],
    /// Rotation angles about the world x, y and z axes, in degrees, applied in that order.
    pub rotate_deg: [f64; 3],
    /// Translation (m), applied last.
    pub translate: [f64; 3],
}

impl Default for Transform {
    /// The identity: scale 1, no rotation, no translation.
    fn default() -> Self {
        Self {
            scale: [1.0; 3],
            rotate_deg: [0.0; 3],
            translate: [0.0; 3],
        }
    }
}

impl Transform {
    /// Checks that every component is finite and every scale factor positive; errors name
    /// the field (`scale`, `rotate_deg` or `translate`) and its value.
    pub fn validate(&self) -> Result<(), Error> {
        for (name, v) in [
            ("scale", self.scale),
            ("rotate_deg", self.rotate_deg),
            ("translate", self.translate),
        ] {
            if v.iter().any(|c| !c.is_finite()) {
                return Err(Error::invalid(name, format!("{v:?}"), "must be finite"));
            }
        }
        if self.scale.iter().any(|&s| s <= 0.0) {
            return Err(Error::invalid(
                "scale",
                format!("{:?}", self.scale),
                "must be positive along every axis",
            ));
        }
        Ok(())
    }

    /// The rotation R = R_z·R_y·R_x.
    fn rotation(&self) -> Rotation3<f64> {
        let [x, y, z] = self.rotate_deg.map(f64::to_radians);
        Rotation3::from_euler_angles(x, y, z)
    }

    /// The image of point `p` (m).
    pub fn apply_point(&self, p: &Vec3) -> Vec3 {
        let scaled = p.component_mul(&Vec3::from(self.scale));
        self.rotation() * scaled + Vec3::from(self.translate)
    }

    /// `mesh` with every vertex transformed, validated again (a tiny scale can make a
    /// triangle degenerate). Errors from [`Transform::validate`] or [`TriangleMesh::new`].
    pub fn apply(&self, mesh: &TriangleMesh) -> Result<TriangleMesh, Error> {
        self.validate()?;
        let (r, s, t) = (
            self.rotation(),
            Vec3::from(self.scale),
            Vec3::from(self.translate),
        );
        let vertices = mesh
            .vertices()
            .iter()
            .map(|p| r * p.component_mul(&s) + t)
            .collect();
        TriangleMesh::new(vertices, mesh.triangles().to_vec())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle() -> TriangleMesh {
        TriangleMesh::new(
            vec![
                Vec3::zeros(),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2]],
        )
        .unwrap()
    }

    fn close(a: &Vec3, b: &Vec3) -> bool {
        (a - b).norm() < 1e-12
    }

    #[test]
    fn scale_then_rotate_then_translate() {
        let t = Transform {
            scale: [2.0, 3.0, 1.0],
            rotate_deg: [0.0, 0.0, 90.0],
            translate: [10.0, 0.0, -1.0],
        };
        // (1, 0, 0) → scaled (2, 0, 0) → rotated 90° about z (0, 2, 0) → (10, 2, −1).
        assert!(close(
            &t.apply_point(&Vec3::new(1.0, 0.0, 0.0)),
            &Vec3::new(10.0, 2.0, -1.0)
        ));
        let mesh = t.apply(&triangle()).unwrap();
        assert!(close(&mesh.vertices()[2], &Vec3::new(7.0, 0.0, -1.0)));
        assert_eq!(mesh.triangles(), triangle().triangles());
    }

    #[test]
    fn euler_angles_apply_about_x_then_y_then_z() {
        // x by 90° takes y to z; then y by 90° takes z to x.
        let t = Transform {
            rotate_deg: [90.0, 90.0, 0.0],
            ..Transform::default()
        };
        assert!(close(
            &t.apply_point(&Vec3::new(0.0, 1.0, 0.0)),
            &Vec3::new(1.0, 0.0, 0.0)
        ));
        assert_eq!(Transform::default().apply(&triangle()).unwrap(), triangle());
    }

    #[test]
    fn bad_transforms_are_named() {
        let bad = Transform {
            scale: [1.0, 0.0, 1.0],
            ..Transform::default()
        };
        let msg = bad.apply(&triangle()).unwrap_err().to_string();
        assert_eq!(
            msg,
            "scale must be positive along every axis, got [1.0, 0.0, 1.0]"
        );
        let bad = Transform {
            translate: [0.0, f64::NAN, 0.0],
            ..Transform::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .starts_with("translate must be finite")
        );
        let tiny = Transform {
            scale: [1e-300, 1e-300, 1e-300],
            ..Transform::default()
        };
        assert!(tiny.apply(&triangle()).is_err());
    }
}
