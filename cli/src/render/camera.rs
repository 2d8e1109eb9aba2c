//! The camera: its framing of a box, and the projection of points to the screen.

use super::Renderer;
use projfluid::Vec3;
use projfluid::boundary::Aabb;

/// A perspective camera (metres, degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Position of the eye (m).
    pub eye: Vec3,
    /// The point seen at the centre of the image (m).
    pub target: Vec3,
    /// Vertical field of view (degrees).
    pub fov_y_deg: f64,
}

impl Camera {
    /// A camera above (+y) the box `bounds`, looking at its centre from as close as lets
    /// the whole box fit in an image of aspect ratio `aspect` (width / height): in front of
    /// (+z) and to the right of (+x) a box longer than deep, from the (+x, −z) corner along
    /// the diagonal a box about as deep as long (whose x = z diagonal then runs across the
    /// picture, so that things in opposite corners do not hide its middle).
    pub fn framing(bounds: &Aabb, aspect: f64) -> Camera {
        let fov_y_deg: f64 = 35.0;
        let centre = (bounds.min + bounds.max) * 0.5;
        let size = bounds.max - bounds.min;
        let back = if size.z > 0.6 * size.x {
            Vec3::new(1.0, 0.9, -1.0).normalize()
        } else {
            Vec3::new(0.45, 0.55, 1.0).normalize()
        };
        let right = Vec3::y().cross(&back).normalize();
        let up = back.cross(&right);
        let tan_y = (fov_y_deg.to_radians() * 0.5).tan();
        let tan_x = tan_y * aspect.max(1e-3);
        // The nearest distance at which every corner projects inside the image.
        let half = (bounds.max - bounds.min) * 0.5;
        let distance = (0..8)
            .map(|i| {
                let o = Vec3::new(
                    if i & 1 == 0 { -half.x } else { half.x },
                    if i & 2 == 0 { -half.y } else { half.y },
                    if i & 4 == 0 { -half.z } else { half.z },
                );
                o.dot(&back) + (o.dot(&right).abs() / tan_x).max(o.dot(&up).abs() / tan_y)
            })
            .fold(1e-6, f64::max);
        Camera {
            eye: centre + back * (1.08 * distance),
            target: centre,
            fov_y_deg,
        }
    }
}

/// Camera coordinates of a point: right, up, and depth along the view direction (m).
pub(super) struct View {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    pub(super) focal: f64,
    centre: (f64, f64),
}

impl View {
    pub(super) fn new(r: &Renderer) -> Self {
        let c = &r.camera;
        let forward = (c.target - c.eye).normalize();
        let right = forward.cross(&Vec3::y()).normalize();
        let up = right.cross(&forward);
        let focal = 0.5 * r.height as f64 / (c.fov_y_deg.to_radians() * 0.5).tan();
        Self {
            eye: c.eye,
            right,
            up,
            forward,
            focal,
            centre: (0.5 * r.width as f64, 0.5 * r.height as f64),
        }
    }

    /// Screen position (pixels, y down) and depth (m) of `p`; `None` behind the eye.
    pub(super) fn project(&self, p: &Vec3) -> Option<(f64, f64, f64)> {
        let q = p - self.eye;
        let z = q.dot(&self.forward);
        (z > 1e-6).then(|| {
            (
                self.centre.0 + q.dot(&self.right) / z * self.focal,
                self.centre.1 - q.dot(&self.up) / z * self.focal,
                z,
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::tests::renderer;

    #[test]
    fn square_tanks_are_seen_from_a_corner_and_fit() {
        let bounds = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(8.0, 5.0, 8.0),
        };
        let r = Renderer {
            camera: Camera::framing(&bounds, 16.0 / 9.0),
            ..renderer()
        };
        let (eye, target) = (r.camera.eye, r.camera.target);
        assert!(
            eye.x > target.x && eye.z < target.z && eye.y > target.y,
            "{eye:?}"
        );
        let view = View::new(&r);
        let mut widest = 0.0f64;
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { 0.0 } else { 8.0 },
                if i & 2 == 0 { 0.0 } else { 5.0 },
                if i & 4 == 0 { 0.0 } else { 8.0 },
            );
            let (x, y, _) = view.project(&corner).unwrap();
            assert!(x > 0.0 && x < r.width as f64 && y > 0.0 && y < r.height as f64);
            widest = widest.max((x - r.width as f64 / 2.0).abs() / (r.width as f64 / 2.0));
            widest = widest.max((y - r.height as f64 / 2.0).abs() / (r.height as f64 / 2.0));
        }
        // Framed closely: some corner comes near the edge of the picture.
        assert!(widest > 0.85, "{widest}");
    }
}
