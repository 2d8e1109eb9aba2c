//! Rasterising: particles splatted as depth-tested spheres, box edges drawn as lines.

use super::Renderer;
use super::camera::View;
use projfluid::Vec3;
use projfluid::boundary::Aabb;

impl Renderer {
    /// Draws a sphere of the particle radius at `p` into the pixels whose centres it covers
    /// and where it is nearer than `depth`; `shade(nx, ny, nz, z)` gives the colour from the
    /// sphere's normal in camera space (x right, y up, z towards the eye) and the depth.
    pub(super) fn splat(
        &self,
        view: &View,
        p: &Vec3,
        depth: &mut [f64],
        shade: impl Fn(f64, f64, f64, f64) -> [f64; 3],
        rgb: &mut [[f64; 3]],
    ) {
        let Some((sx, sy, z)) = view.project(p) else {
            return;
        };
        let radius = (self.particle_radius * view.focal / z).max(0.75);
        let (w, h) = (self.width as isize, self.height as isize);
        let x0 = ((sx - radius).floor() as isize).max(0);
        let x1 = ((sx + radius).ceil() as isize).min(w - 1);
        let y0 = ((sy - radius).floor() as isize).max(0);
        let y1 = ((sy + radius).ceil() as isize).min(h - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let dx = (x as f64 + 0.5 - sx) / radius;
                let dy = (y as f64 + 0.5 - sy) / radius;
                let d2 = dx * dx + dy * dy;
                if d2 > 1.0 {
                    continue;
                }
                let nz = (1.0 - d2).sqrt();
                let surface = z - nz * self.particle_radius;
                let i = (y * w + x) as usize;
                if surface < depth[i] {
                    depth[i] = surface;
                    rgb[i] = shade(dx, -dy, nz, z);
                }
            }
        }
    }

    /// The twelve edges of `b`, blended at 25 % white.
    pub(super) fn draw_box_edges(&self, view: &View, b: &Aabb, rgb: &mut [[f64; 3]]) {
        let corner = |i: usize| {
            Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            )
        };
        for i in 0..8 {
            for bit in [1, 2, 4] {
                if i & bit == 0 {
                    self.draw_line(view, &corner(i), &corner(i | bit), rgb);
                }
            }
        }
    }

    fn draw_line(&self, view: &View, a: &Vec3, b: &Vec3, rgb: &mut [[f64; 3]]) {
        let (Some(p), Some(q)) = (view.project(a), view.project(b)) else {
            return;
        };
        let steps = ((q.0 - p.0).abs().max((q.1 - p.1).abs()).ceil() as usize).clamp(1, 1 << 16);
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let (x, y) = (p.0 + (q.0 - p.0) * t, p.1 + (q.1 - p.1) * t);
            if x >= 0.0 && y >= 0.0 && (x as usize) < self.width && (y as usize) < self.height {
                let i = y as usize * self.width + x as usize;
                rgb[i] = rgb[i].map(|c| 0.75 * c + 0.25);
            }
        }
    }
}
