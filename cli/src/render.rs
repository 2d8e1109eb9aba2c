//! Pictures of a simulation without external tools: fluid particles splatted as shaded
//! spheres (lit, darker with depth), coloured by speed, obstacle particles drawn as a faint
//! translucent grey, container boxes as faint edges, seen by a fixed perspective camera
//! framed on the containers. Written as 8-bit RGB PNG files with the `png` crate.
//!
//! This module holds the renderer and the composition of a frame; the camera and its
//! projection, the drawing of spheres and lines, the colours and the image live in its
//! submodules.

mod camera;
mod colour;
mod image;
mod raster;

pub use camera::Camera;
pub use image::Image;

use camera::View;
use colour::{background, speed_colour};
use projfluid::boundary::Aabb;
use projfluid::{Vec3, World};

/// What to draw and how: image size, camera, particle size and the speed colour scale.
#[derive(Clone, Debug, PartialEq)]
pub struct Renderer {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// The camera.
    pub camera: Camera,
    /// Radius of the drawn spheres (m), usually the particle radius.
    pub particle_radius: f64,
    /// Speed (m/s) drawn with the last colour of the scale; 0 m/s gets the first.
    pub speed_max: f64,
}

/// The scene as seen through the camera: what is needed to draw one frame.
pub struct Frame<'a> {
    /// Fluid particle positions (m).
    pub positions: &'a [Vec3],
    /// Fluid particle velocities (m/s), one per position.
    pub velocities: &'a [Vec3],
    /// Obstacle particles (m), drawn faintly.
    pub obstacle: &'a [Vec3],
    /// Container boxes, drawn as faint edges.
    pub containers: &'a [Aabb],
}

impl Renderer {
    /// A renderer for `world`: camera framed on its containers (or its particles if it has
    /// none), spheres of the particle radius, and a speed scale up to √(2·|g|·height), the
    /// speed of a fall from the top of the box.
    pub fn for_world(world: &World, width: usize, height: usize) -> Renderer {
        let bounds = world
            .containers()
            .iter()
            .copied()
            .reduce(|a, b| a.union(&b))
            .or_else(|| Aabb::around(&world.positions()))
            .unwrap_or(Aabb {
                min: Vec3::zeros(),
                max: Vec3::repeat(1.0),
            });
        let g = Vec3::from(world.params().gravity).norm();
        let drop = (bounds.max - bounds.min).y.max(0.1);
        Renderer {
            width,
            height,
            camera: Camera::framing(&bounds, width as f64 / height.max(1) as f64),
            particle_radius: world.params().particle_radius,
            speed_max: (2.0 * g.max(1.0) * drop).sqrt(),
        }
    }

    /// Draws the world's fluid, its obstacle and body particles (boundary particles farther
    /// than r/2 from every container wall) and its containers.
    pub fn render_world(&self, world: &World) -> Image {
        let r = world.params().particle_radius;
        let containers = world.containers();
        // Wall samples lie on a container's faces or up to two extra layers (2r) outside.
        let on_wall = |p: &Vec3| {
            containers.iter().any(|c| {
                let deep_inside =
                    (0..3).all(|a| p[a] > c.min[a] + 0.5 * r && p[a] < c.max[a] - 0.5 * r);
                c.contains(p, 2.5 * r) && !deep_inside
            })
        };
        let obstacle: Vec<Vec3> = world
            .boundary_particles()
            .into_iter()
            .filter(|p| !on_wall(p))
            .collect();
        self.render(&Frame {
            positions: &world.positions(),
            velocities: &world.velocities(),
            obstacle: &obstacle,
            containers,
        })
    }

    /// Draws one frame: background, container edges, fluid spheres (depth-tested, lit,
    /// darkened with distance, coloured by speed), then obstacle particles blended at 45 %
    /// grey over whatever lies behind them.
    pub fn render(&self, frame: &Frame) -> Image {
        let (w, h) = (self.width, self.height);
        let mut rgb: Vec<[f64; 3]> = (0..w * h).map(|i| background(i / w, h)).collect();
        let mut depth = vec![f64::INFINITY; w * h];
        let view = View::new(self);
        // Depth range for the fading: the distance to the target ± the framed radius.
        let mid = (self.camera.target - self.camera.eye).norm();
        let spread = 0.6 * mid;
        let fade = |z: f64| 1.0 - 0.55 * ((z - (mid - spread)) / (2.0 * spread)).clamp(0.0, 1.0);

        for c in frame.containers {
            self.draw_box_edges(&view, c, &mut rgb);
        }
        let light = Vec3::new(-0.4, 0.6, 0.7).normalize();
        for (p, v) in frame.positions.iter().zip(frame.velocities) {
            let colour = speed_colour(v.norm() / self.speed_max.max(1e-9));
            let shade = |nx: f64, ny: f64, nz: f64, z: f64| {
                let lambert = (nx * light.x + ny * light.y + nz * light.z).max(0.0);
                let shade = (0.3 + 0.7 * lambert) * fade(z);
                colour.map(|c| c * shade)
            };
            self.splat(&view, p, &mut depth, shade, &mut rgb);
        }
        let mut obstacle_depth = vec![f64::INFINITY; w * h];
        let mut grey = vec![[0.0; 3]; w * h];
        for p in frame.obstacle {
            let shade = |_: f64, _: f64, nz: f64, z: f64| [(0.55 + 0.35 * nz) * fade(z); 3];
            self.splat(&view, p, &mut obstacle_depth, shade, &mut grey);
        }
        for i in 0..w * h {
            if obstacle_depth[i] < depth[i] {
                rgb[i] = std::array::from_fn(|k| 0.55 * rgb[i][k] + 0.45 * grey[i][k]);
            }
        }
        Image {
            width: w,
            height: h,
            pixels: rgb
                .iter()
                .map(|c| c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8))
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 160 × 90 renderer framed on a 2 × 1 × 1 m box.
    pub(super) fn renderer() -> Renderer {
        let bounds = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(2.0, 1.0, 1.0),
        };
        Renderer {
            width: 160,
            height: 90,
            camera: Camera::framing(&bounds, 160.0 / 90.0),
            particle_radius: 0.025,
            speed_max: 4.0,
        }
    }

    /// The background of row `y` in an image `h` pixels high, as stored.
    pub(super) fn background_pixel(y: usize, h: usize) -> [u8; 3] {
        background(y, h).map(|x| (x * 255.0).round() as u8)
    }

    #[test]
    fn an_empty_frame_is_background_only() {
        let r = renderer();
        let image = r.render(&Frame {
            positions: &[],
            velocities: &[],
            obstacle: &[],
            containers: &[],
        });
        for y in 0..r.height {
            for x in 0..r.width {
                assert_eq!(
                    image.pixel(x, y),
                    background_pixel(y, r.height),
                    "({x}, {y})"
                );
            }
        }
    }

    #[test]
    fn a_particle_at_the_target_lights_the_centre_only() {
        let r = renderer();
        let target = r.camera.target;
        let image = r.render(&Frame {
            positions: &[target],
            velocities: &[Vec3::zeros()],
            obstacle: &[],
            containers: &[],
        });
        let (cx, cy) = (r.width / 2, r.height / 2);
        let centre = image.pixel(cx, cy);
        assert_ne!(centre, background_pixel(cy, r.height));
        // At rest the particle has the first colour of the scale: blue dominates.
        assert!(centre[2] > centre[0] && centre[2] > centre[1], "{centre:?}");
        // Far from the centre only background.
        let lit = (0..r.height)
            .flat_map(|y| (0..r.width).map(move |x| (x, y)))
            .filter(|&(x, y)| image.pixel(x, y) != background_pixel(y, r.height))
            .collect::<Vec<_>>();
        assert!(
            !lit.is_empty() && lit.len() < 40,
            "{} pixels lit",
            lit.len()
        );
        for (x, y) in lit {
            assert!(x.abs_diff(cx) <= 3 && y.abs_diff(cy) <= 3, "({x}, {y}) lit");
        }
        // A fast particle is red, a nearer one hides a farther one.
        let fast = r.render(&Frame {
            positions: &[target, target + (r.camera.eye - target) * 0.5],
            velocities: &[Vec3::zeros(), Vec3::new(0.0, -10.0, 0.0)],
            obstacle: &[],
            containers: &[],
        });
        let c = fast.pixel(cx, cy);
        assert!(c[0] > c[1] && c[0] > c[2], "{c:?}");
    }

    #[test]
    fn obstacles_are_faint_and_containers_outlined() {
        let r = renderer();
        let target = r.camera.target;
        let obstacle_only = r.render(&Frame {
            positions: &[],
            velocities: &[],
            obstacle: &[target],
            containers: &[],
        });
        let (cx, cy) = (r.width / 2, r.height / 2);
        let g = obstacle_only.pixel(cx, cy);
        let bg = background_pixel(cy, r.height);
        // Greyish and brighter than the background, but faint (far from white).
        assert!(
            (0..3).all(|k| g[k] > bg[k] && g[k] < 160),
            "{g:?} over {bg:?}"
        );
        assert!(
            g.iter().max().unwrap() - g.iter().min().unwrap() <= 12,
            "{g:?}"
        );
        let bounds = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(2.0, 1.0, 1.0),
        };
        let boxed = r.render(&Frame {
            positions: &[],
            velocities: &[],
            obstacle: &[],
            containers: &[bounds],
        });
        let changed = boxed
            .pixels
            .iter()
            .enumerate()
            .filter(|(i, p)| **p != background_pixel(i / r.width, r.height))
            .count();
        assert!(changed > 200 && changed < 5000, "{changed} edge pixels");
        // The whole box is in view: its corners project inside the image.
        let view = View::new(&r);
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { 0.0 } else { 2.0 },
                if i & 2 == 0 { 0.0 } else { 1.0 },
                if i & 4 == 0 { 0.0 } else { 1.0 },
            );
            let (x, y, _) = view.project(&corner).unwrap();
            assert!(x > 0.0 && x < r.width as f64 && y > 0.0 && y < r.height as f64);
        }
    }
}
