//! Inside and outside of closed triangle meshes: the generalised winding number (Jacobson et
//! al. 2013), and a check that a mesh is closed and consistently oriented.

use super::mesh::TriangleMesh;
use crate::Vec3;
use std::collections::HashMap;

/// The winding number of the mesh's surface around point `p` (m): the signed solid angle
/// of every triangle seen from `p` (Van Oosterom and Strackee 1983), summed and divided by
/// 4π. For a closed, outward-oriented shell it is 1 inside and 0 outside (k inside k
/// overlapping shells); near the surface it passes through fractional values, so compare
/// with ½. Costs one pass over the triangles.
pub fn winding_number(mesh: &TriangleMesh, p: &Vec3) -> f64 {
    let vertices = mesh.vertices();
    let total: f64 = mesh
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize] - p);
            let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
            let numerator = a.dot(&b.cross(&c));
            let denominator = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
            2.0 * numerator.atan2(denominator)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

/// True when `p` lies inside the closed mesh (winding number above ½).
pub fn is_inside(mesh: &TriangleMesh, p: &Vec3) -> bool {
    winding_number(mesh, p) > 0.5
}

/// True when every edge of the mesh is shared by exactly two triangles that traverse it in
/// opposite directions: the surface is closed (watertight) and consistently oriented.
pub fn is_closed_and_oriented(mesh: &TriangleMesh) -> bool {
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for t in mesh.triangles() {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    directed
        .iter()
        .all(|(&(a, b), &count)| count == 1 && directed.get(&(b, a)) == Some(&1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::shapes::Shapes;

    #[test]
    fn winding_numbers_of_a_box_and_two_overlapping_shells() {
        let mut shapes = Shapes::new();
        shapes.add_box(Vec3::zeros(), Vec3::new(1.0, 2.0, 1.0));
        let mesh = shapes.clone().into_mesh().unwrap();
        assert!(is_closed_and_oriented(&mesh));
        assert!((winding_number(&mesh, &Vec3::new(0.5, 1.0, 0.5)) - 1.0).abs() < 1e-12);
        assert!(winding_number(&mesh, &Vec3::new(1.5, 1.0, 0.5)).abs() < 1e-12);
        assert!(is_inside(&mesh, &Vec3::new(0.99, 1.99, 0.01)));
        assert!(!is_inside(&mesh, &Vec3::new(1.01, 1.0, 0.5)));
        shapes.add_sphere(Vec3::new(0.5, 2.0, 0.5), 0.4, 2);
        let two = shapes.into_mesh().unwrap();
        assert!(is_closed_and_oriented(&two));
        assert!((winding_number(&two, &Vec3::new(0.5, 1.9, 0.5)) - 2.0).abs() < 1e-9);
        assert!((winding_number(&two, &Vec3::new(0.5, 2.3, 0.5)) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn an_open_or_inconsistent_mesh_is_detected() {
        let mut shapes = Shapes::new();
        shapes.add_box(Vec3::zeros(), Vec3::repeat(1.0));
        let mesh = shapes.into_mesh().unwrap();
        let mut open = mesh.triangles().to_vec();
        open.pop();
        let open = TriangleMesh::new(mesh.vertices().to_vec(), open).unwrap();
        assert!(!is_closed_and_oriented(&open));
        let mut flipped = mesh.triangles().to_vec();
        flipped[0].swap(1, 2);
        let flipped = TriangleMesh::new(mesh.vertices().to_vec(), flipped).unwrap();
        assert!(!is_closed_and_oriented(&flipped));
    }
}
