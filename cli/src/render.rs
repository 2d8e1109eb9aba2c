//! Pictures of a simulation without external tools: fluid particles splatted as shaded
//! spheres (lit, darker with depth), coloured by speed, obstacle particles drawn as a faint
//! translucent grey, container boxes as faint edges, seen by a fixed perspective camera
//! framed on the containers. Written as 8-bit RGB PNG files with the `png` crate.

use projfluid::boundary::Aabb;
use projfluid::{Error, Vec3, World};
use std::path::Path;

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

/// An 8-bit RGB image, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width·height` pixels, row by row from the top.
    pub pixels: Vec<[u8; 3]>,
}

impl Image {
    /// The pixel in column `x` and row `y` (from the top).
    pub fn pixel(&self, x: usize, y: usize) -> [u8; 3] {
        self.pixels[y * self.width + x]
    }

    /// Writes the image as an 8-bit RGB PNG file; errors name the path.
    pub fn write_png(&self, path: &Path) -> Result<(), Error> {
        let fail = |e: String| Error::Io(format!("cannot write {}: {e}", path.display()));
        let file = std::fs::File::create(path).map_err(|e| fail(e.to_string()))?;
        let mut encoder = png::Encoder::new(
            std::io::BufWriter::new(file),
            self.width as u32,
            self.height as u32,
        );
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| fail(e.to_string()))?;
        let data: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        writer
            .write_image_data(&data)
            .map_err(|e| fail(e.to_string()))?;
        writer.finish().map_err(|e| fail(e.to_string()))
    }
}

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

/// Camera coordinates of a point: right, up, and depth along the view direction (m).
struct View {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    focal: f64,
    centre: (f64, f64),
}

impl View {
    fn new(r: &Renderer) -> Self {
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
    fn project(&self, p: &Vec3) -> Option<(f64, f64, f64)> {
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

/// Background: a vertical gradient from dark slate (top) to near black (bottom).
fn background(y: usize, height: usize) -> [f64; 3] {
    let t = y as f64 / height.max(2) as f64;
    let top = [0.16, 0.18, 0.22];
    let bottom = [0.05, 0.05, 0.07];
    std::array::from_fn(|k| top[k] + (bottom[k] - top[k]) * t)
}

/// Speed colour scale: deep blue, light blue, white, orange, red at t = 0, ¼, ½, ¾, 1.
fn speed_colour(t: f64) -> [f64; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [0.05, 0.25, 0.75],
        [0.25, 0.65, 0.95],
        [0.92, 0.95, 0.97],
        [1.0, 0.65, 0.2],
        [0.85, 0.15, 0.1],
    ];
    let x = t.clamp(0.0, 1.0) * 4.0;
    let i = (x.floor() as usize).min(3);
    let f = x - i as f64;
    std::array::from_fn(|k| STOPS[i][k] + (STOPS[i + 1][k] - STOPS[i][k]) * f)
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

    /// Draws the world's fluid, its obstacle particles (boundary particles farther than r/2
    /// from every container wall) and its containers.
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
            .boundary_positions()
            .iter()
            .filter(|p| !on_wall(p))
            .copied()
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

    /// Draws a sphere of the particle radius at `p` into the pixels whose centres it covers
    /// and where it is nearer than `depth`; `shade(nx, ny, nz, z)` gives the colour from the
    /// sphere's normal in camera space (x right, y up, z towards the eye) and the depth.
    fn splat(
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
    fn draw_box_edges(&self, view: &View, b: &Aabb, rgb: &mut [[f64; 3]]) {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn renderer() -> Renderer {
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

    fn background_pixel(y: usize, h: usize) -> [u8; 3] {
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

    #[test]
    fn png_files_read_back() {
        let r = renderer();
        let image = r.render(&Frame {
            positions: &[r.camera.target],
            velocities: &[Vec3::zeros()],
            obstacle: &[],
            containers: &[],
        });
        let path =
            std::env::temp_dir().join(format!("projfluid-render-{}.png", std::process::id()));
        image.write_png(&path).unwrap();
        let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!((info.width, info.height), (160, 90));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        let back: Vec<u8> = image.pixels.iter().flatten().copied().collect();
        assert_eq!(&buf[..info.buffer_size()], &back[..]);
        let err = image
            .write_png(Path::new("/nonexistent/x.png"))
            .unwrap_err();
        assert!(err.to_string().contains("/nonexistent/x.png"), "{err}");
    }
}
