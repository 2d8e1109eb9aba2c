//! Mass properties of a rigid body: mass, centre of mass and inertia tensor, from a closed
//! triangle mesh of uniform density (signed tetrahedra from the origin, docs/method.md §11.2)
//! or given explicitly.

use crate::boundary::mesh::TriangleMesh;
use crate::{Error, Vec3};
use nalgebra::Matrix3;

/// Mass (kg), centre of mass (m, in the body's own frame) and inertia tensor about the
/// centre of mass (kg·m², body frame) of a rigid body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    /// Mass (kg, > 0).
    pub mass: f64,
    /// Centre of mass in the body's own frame (m).
    pub centre: Vec3,
    /// Inertia tensor about the centre of mass, in the body's own frame (kg·m²; symmetric,
    /// positive definite).
    pub inertia: Matrix3<f64>,
}

impl MassProperties {
    /// The mass properties of the solid that the closed, consistently oriented `mesh` (m)
    /// bounds, filled with `density` (kg/m³). Either orientation is accepted. Errors when the
    /// density is not positive and finite or the mesh encloses no volume.
    pub fn of_mesh(mesh: &TriangleMesh, density: f64) -> Result<Self, Error> {
        if !(density.is_finite() && density > 0.0) {
            return Err(Error::invalid(
                "density",
                density,
                "must be a positive finite number of kg/m³",
            ));
        }
        let v = mesh.vertices();
        let (mut volume, mut first) = (0.0, Vec3::zeros());
        let mut second = Matrix3::zeros();
        for t in mesh.triangles() {
            let [a, b, c] = t.map(|i| v[i as usize]);
            // The tetrahedron (0, a, b, c): signed volume, first and second moments.
            let vt = a.dot(&b.cross(&c)) / 6.0;
            let sum = a + b + c;
            volume += vt;
            first += sum * (vt / 4.0);
            second +=
                (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose())
                    * (vt / 20.0);
        }
        let extent = mesh.bounds().max - mesh.bounds().min;
        let enclosed = volume.abs() > 1e-9 * extent.norm().powi(3);
        if !enclosed {
            return Err(Error::invalid(
                "mesh",
                format!("volume {volume:.3e} m³"),
                "must be closed and enclose a volume to give a body mass from a density",
            ));
        }
        let mass = density * volume.abs();
        let centre = first / volume;
        // Second moment about the centre of mass, times the density, then I = tr(C)·1 − C.
        let c = (second / volume - centre * centre.transpose()) * mass;
        let inertia = Matrix3::identity() * c.trace() - c;
        Self::new(mass, centre, inertia)
    }

    /// Explicit mass properties: `mass` (kg, > 0), `centre` of mass in the body frame (m) and
    /// `inertia` about it (kg·m², symmetric positive definite). Errors name what is wrong.
    pub fn new(mass: f64, centre: Vec3, inertia: Matrix3<f64>) -> Result<Self, Error> {
        if !(mass.is_finite() && mass > 0.0) {
            return Err(Error::invalid(
                "mass",
                mass,
                "must be a positive finite number of kg",
            ));
        }
        if !centre.iter().all(|c| c.is_finite()) {
            return Err(Error::invalid(
                "centre of mass",
                format!("{:?}", centre.as_slice()),
                "must be finite",
            ));
        }
        let symmetric = (inertia - inertia.transpose()).norm() <= 1e-9 * inertia.norm();
        let definite =
            inertia.iter().all(|x| x.is_finite()) && symmetric && inertia.cholesky().is_some();
        if !definite {
            return Err(Error::invalid(
                "inertia",
                format!("{:?}", inertia.as_slice()),
                "must be a finite symmetric positive definite matrix of kg·m²",
            ));
        }
        Ok(Self {
            mass,
            centre,
            inertia,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::shapes::Shapes;

    fn cuboid(size: Vec3) -> TriangleMesh {
        let mut shapes = Shapes::new();
        shapes.add_box(Vec3::new(1.0, 2.0, -0.5), Vec3::new(1.0, 2.0, -0.5) + size);
        shapes.into_mesh().unwrap()
    }

    #[test]
    fn a_cuboid_has_the_textbook_mass_centre_and_inertia() {
        let size = Vec3::new(0.4, 0.2, 0.1);
        let p = MassProperties::of_mesh(&cuboid(size), 500.0).unwrap();
        let mass = 500.0 * 0.4 * 0.2 * 0.1;
        assert!((p.mass - mass).abs() < 1e-12, "{}", p.mass);
        let centre = Vec3::new(1.0, 2.0, -0.5) + size / 2.0;
        assert!((p.centre - centre).norm() < 1e-12, "{}", p.centre);
        let (a, b, c) = (size.x, size.y, size.z);
        let expected =
            Matrix3::from_diagonal(&Vec3::new(b * b + c * c, a * a + c * c, a * a + b * b))
                * (mass / 12.0);
        assert!((p.inertia - expected).norm() < 1e-12, "{}", p.inertia);
    }

    #[test]
    fn a_sphere_mesh_approaches_two_fifths_m_r_squared() {
        let mut shapes = Shapes::new();
        shapes.add_sphere(Vec3::new(0.3, 0.0, 0.0), 0.5, 4);
        let p = MassProperties::of_mesh(&shapes.into_mesh().unwrap(), 1000.0).unwrap();
        let exact_mass = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.125;
        assert!((p.mass / exact_mass - 1.0).abs() < 0.02, "{}", p.mass);
        let i = 0.4 * p.mass * 0.25;
        for k in 0..3 {
            assert!((p.inertia[(k, k)] / i - 1.0).abs() < 0.02, "{}", p.inertia);
        }
        assert!((p.centre - Vec3::new(0.3, 0.0, 0.0)).norm() < 1e-9);
    }

    #[test]
    fn open_meshes_and_bad_numbers_are_rejected() {
        let open =
            TriangleMesh::new(vec![Vec3::zeros(), Vec3::x(), Vec3::y()], vec![[0, 1, 2]]).unwrap();
        let e = MassProperties::of_mesh(&open, 1000.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("closed"), "{e}");
        let cube = cuboid(Vec3::repeat(0.1));
        for density in [0.0, -1.0, f64::NAN] {
            assert!(MassProperties::of_mesh(&cube, density).is_err());
        }
        assert!(MassProperties::new(-1.0, Vec3::zeros(), Matrix3::identity()).is_err());
        let skew = Matrix3::new(1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(MassProperties::new(1.0, Vec3::zeros(), skew).is_err());
        assert!(MassProperties::new(1.0, Vec3::zeros(), -Matrix3::identity()).is_err());
    }
}
