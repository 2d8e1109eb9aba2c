//! Emitters (docs/method.md §12.2): openings in a plane that insert fluid particles with a
//! set velocity, one lattice layer each time the layer before has travelled one particle
//! spacing, so that the inflow is exactly speed × area / d³ particles per second on average.

use crate::{Error, Vec3};

/// The opening of an emitter, in the plane through its position normal to its direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EmitterShape {
    /// A disc of this radius (m).
    Disc {
        /// Radius (m).
        radius: f64,
    },
    /// A rectangle with these half-extents (m) along the plane's first and second axes
    /// (see [`plane_axes`]).
    Rectangle {
        /// Half-extents (m) along the first and the second axis.
        half_extents: [f64; 2],
    },
}

/// What an emitter is: where, its opening, and the velocity it gives the fluid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitterSpec {
    /// The opening's shape.
    pub shape: EmitterShape,
    /// The opening's centre (m).
    pub position: Vec3,
    /// The direction the fluid leaves in, normal to the opening (any non-zero length; the
    /// emitter normalises it).
    pub direction: Vec3,
    /// The speed the fluid leaves with (m/s, > 0).
    pub speed: f64,
    /// The simulated time (s) from which no more layers are emitted; `None` emits forever.
    pub end_time: Option<f64>,
}

/// An emitter's spec and its progress: what a [`crate::WorldState`] carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitterState {
    /// The spec as given.
    pub spec: EmitterSpec,
    /// How far (m) the last emitted layer has travelled since it was emitted (speed × time;
    /// one spacing d for a new emitter, so that it emits at the start of the next step).
    pub travelled: f64,
    /// Particles emitted so far.
    pub emitted: u64,
    /// The material of the particles it emits (docs/method.md §14).
    pub material: crate::material::MaterialId,
}

/// Most lattice points an emitter layer may hold.
const MAX_LAYER: f64 = 1e6;
/// A lattice point closer than this many spacings to a fluid particle is skipped.
const CLEARANCE: f64 = 0.9;
/// Marks a lattice cell outside the disc.
const OUTSIDE: u32 = u32::MAX;

/// The two unit axes (u, w) spanning the plane normal to the unit vector `n`: u is the
/// coordinate axis least aligned with n (the first of equals) projected into the plane and
/// normalised, and w = n × u. For n = −y (pouring down) they are x and z, for n = +y x and −z;
/// for n = +x they are y and z.
pub fn plane_axes(n: Vec3) -> (Vec3, Vec3) {
    let k = (0..3).fold(0, |k, a| if n[a].abs() < n[k].abs() { a } else { k });
    let e = Vec3::ith(k, 1.0);
    let u = (e - n * n.dot(&e)).normalize();
    (u, n.cross(&u))
}

/// An emitter of a world: its state, its unit direction and the lattice of one layer.
#[derive(Clone, Debug)]
pub struct Emitter {
    state: EmitterState,
    /// Unit direction n and the plane axes u, w.
    axes: [Vec3; 3],
    /// Lattice spacing d = 2r (m).
    spacing: f64,
    /// Lattice cells along u and w.
    dims: [usize; 2],
    /// The lattice point of every cell (u fastest), or [`OUTSIDE`].
    cells: Vec<u32>,
    /// Lattice points relative to the position (m), in lattice order (u fastest, then w).
    points: Vec<Vec3>,
}

impl Emitter {
    /// Builds the emitter of `state` on a lattice of spacing `spacing` (m), or an error naming
    /// the field (prefixed `emitter.`) that is not finite, not positive, or gives an opening
    /// without a lattice point ("zero area").
    pub(crate) fn new(state: EmitterState, spacing: f64) -> Result<Self, Error> {
        let spec = &state.spec;
        let fmt = |v: &Vec3| format!("{:?}", v.as_slice());
        if !spec.position.iter().all(|c| c.is_finite()) {
            return Err(Error::invalid(
                "emitter.position",
                fmt(&spec.position),
                "must be finite",
            ));
        }
        let length = spec.direction.norm();
        if !(length.is_finite() && length > 0.0) {
            return Err(Error::invalid(
                "emitter.direction",
                fmt(&spec.direction),
                "must be a non-zero finite vector",
            ));
        }
        if !(spec.speed.is_finite() && spec.speed > 0.0) {
            return Err(Error::invalid(
                "emitter.speed",
                spec.speed,
                "must be a positive finite speed (m/s)",
            ));
        }
        if let Some(end) = spec.end_time.filter(|e| !e.is_finite()) {
            return Err(Error::invalid(
                "emitter.end_time",
                end,
                "must be a finite time (s)",
            ));
        }
        if !(state.travelled.is_finite() && state.travelled >= 0.0) {
            return Err(Error::invalid(
                "emitter.travelled",
                state.travelled,
                "must be a non-negative finite distance (m)",
            ));
        }
        let n = spec.direction / length;
        let (u, w) = plane_axes(n);
        // The lattice's cells along u and w, centred on the opening, and for a disc its
        // squared radius (m²).
        let (dims, disc) = match spec.shape {
            EmitterShape::Disc { radius } => {
                check_length("emitter.shape.radius", radius)?;
                // Points at (k + ½)·d from the centre, as many as fit in the radius.
                let side = 2.0 * (radius / spacing + 0.5 + 1e-9).floor();
                ([side; 2], Some(radius * radius))
            }
            EmitterShape::Rectangle {
                half_extents: [a, b],
            } => {
                check_length("emitter.shape.half_extents[0]", a)?;
                check_length("emitter.shape.half_extents[1]", b)?;
                // Whole cells of side d only.
                let cells = |h: f64| (2.0 * h / spacing + 1e-9).floor();
                ([cells(a), cells(b)], None)
            }
        };
        if dims[0] * dims[1] > 4.0 * MAX_LAYER {
            return Err(Error::invalid(
                "emitter.shape",
                format!("{:?}", spec.shape),
                &format!("is too large for the particle spacing {spacing} m"),
            ));
        }
        let dims = dims.map(|c| c as usize);
        let offset = |i: usize, cells: usize| (i as f64 - (cells as f64 - 1.0) / 2.0) * spacing;
        let (mut cells, mut points) = (Vec::new(), Vec::new());
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let (a, b) = (offset(i, dims[0]), offset(j, dims[1]));
                if disc.is_none_or(|r2| a * a + b * b <= r2) {
                    cells.push(points.len() as u32);
                    points.push(u * a + w * b);
                } else {
                    cells.push(OUTSIDE);
                }
            }
        }
        if points.is_empty() {
            return Err(Error::invalid(
                "emitter.shape",
                format!("{:?}", spec.shape),
                &format!("has zero area: it holds no point of the lattice of spacing {spacing} m"),
            ));
        }
        Ok(Self {
            state,
            axes: [n, u, w],
            spacing,
            dims,
            cells,
            points,
        })
    }

    /// The emitter's spec and progress.
    pub fn state(&self) -> &EmitterState {
        &self.state
    }

    /// The unit direction the fluid leaves in.
    pub fn direction(&self) -> Vec3 {
        self.axes[0]
    }

    /// Lattice points of one layer.
    pub fn layer_len(&self) -> usize {
        self.points.len()
    }

    /// The opening's lattice area (m²): lattice points per layer × d². The emitter inserts
    /// speed × area / d³ particles per second on average (fewer where fluid or a solid is in the way).
    pub fn area(&self) -> f64 {
        self.points.len() as f64 * self.spacing * self.spacing
    }

    /// Particles emitted so far.
    pub fn emitted(&self) -> u64 {
        self.state.emitted
    }

    /// Whether the emitter still emits at simulated time `time` (s).
    pub fn active_at(&self, time: f64) -> bool {
        self.state.spec.end_time.is_none_or(|end| time < end)
    }

    /// Takes the layers due at the start of a step at `time` (s): writes their distances
    /// (m) from the opening along the direction into `offsets`, the oldest (farthest) first.
    /// A layer is due once the one before has travelled d; it is born when that happened and
    /// has travelled on since, so layers stay exactly d apart. Layers born at or after the
    /// end time are not emitted.
    pub(crate) fn take_due(&mut self, time: f64, offsets: &mut Vec<f64>) {
        offsets.clear();
        let (d, speed) = (self.spacing, self.state.spec.speed);
        while self.state.travelled >= d {
            let offset = self.state.travelled - d;
            if !self.active_at(time - offset / speed) {
                break;
            }
            offsets.push(offset);
            self.state.travelled = offset;
        }
    }

    /// Puts back the progress `state` (of this emitter, taken before a step that failed).
    pub(crate) fn restore(&mut self, state: &EmitterState) {
        self.state = *state;
    }

    /// Adds a step of `dt` seconds to the last layer's travel.
    pub(crate) fn advance(&mut self, dt: f64) {
        self.state.travelled += self.state.spec.speed * dt;
    }

    /// Marks in `blocked` (one flag per lattice point of each layer at `offsets`, layer after
    /// layer) the points closer than 0.9·d to one of `positions`. Each particle near the
    /// opening is compared with the lattice points of the cells around it only.
    pub(crate) fn mark_blocked(
        &self,
        offsets: &[f64],
        positions: &[Vec3],
        blocked: &mut Vec<bool>,
    ) {
        let len = self.points.len();
        blocked.clear();
        blocked.resize(offsets.len() * len, false);
        let (Some(&far), Some(&near)) = (offsets.first(), offsets.last()) else {
            return;
        };
        let [n, u, w] = self.axes;
        let d = self.spacing;
        let clear = CLEARANCE * d;
        // The cells within 0.9·d of in-plane coordinate `a` (m), clamped to the lattice.
        let range = |a: f64, cells: usize| {
            let centre = a / d + (cells as f64 - 1.0) / 2.0;
            let lo = (centre - CLEARANCE).ceil().max(0.0);
            let hi = (centre + CLEARANCE).floor().min(cells as f64 - 1.0);
            if lo <= hi {
                lo as usize..hi as usize + 1
            } else {
                0..0
            }
        };
        for x in positions {
            let r = x - self.state.spec.position;
            let h = r.dot(&n);
            if !(h > near - clear && h < far + clear) {
                continue;
            }
            let (a, b) = (r.dot(&u), r.dot(&w));
            if !(a.is_finite() && b.is_finite()) {
                continue;
            }
            let (ri, rj) = (range(a, self.dims[0]), range(b, self.dims[1]));
            for (l, &offset) in offsets.iter().enumerate() {
                if (h - offset).abs() >= clear {
                    continue;
                }
                for j in rj.clone() {
                    for i in ri.clone() {
                        let cell = self.cells[j * self.dims[0] + i];
                        if cell != OUTSIDE
                            && (r - self.points[cell as usize] - n * offset).norm_squared()
                                < clear * clear
                        {
                            blocked[l * len + cell as usize] = true;
                        }
                    }
                }
            }
        }
    }

    /// Marks in `blocked` (as [`Emitter::mark_blocked`] filled it) also the points of the
    /// layers at `offsets` that `inside_solid` says lie inside a solid.
    pub(crate) fn mark_solid(
        &self,
        offsets: &[f64],
        inside_solid: impl Fn(&Vec3) -> bool,
        blocked: &mut [bool],
    ) {
        let (centre, n, len) = (self.state.spec.position, self.axes[0], self.points.len());
        for (l, &offset) in offsets.iter().enumerate() {
            for (k, p) in self.points.iter().enumerate() {
                let at = l * len + k;
                blocked[at] = blocked[at] || inside_solid(&(centre + p + n * offset));
            }
        }
    }

    /// The positions (m) of the lattice points of the layers at `offsets` that `blocked`
    /// leaves free, in lattice order, layer after layer; counts them as emitted.
    pub(crate) fn free_points<'a>(
        &'a mut self,
        offsets: &'a [f64],
        blocked: &'a [bool],
    ) -> impl Iterator<Item = Vec3> + 'a {
        let free = blocked.iter().filter(|b| !**b).count();
        self.state.emitted += free as u64;
        let (centre, n, len) = (self.state.spec.position, self.axes[0], self.points.len());
        let points = &self.points;
        offsets.iter().enumerate().flat_map(move |(l, &offset)| {
            points
                .iter()
                .enumerate()
                .filter(move |(k, _)| !blocked[l * len + k])
                .map(move |(_, p)| centre + p + n * offset)
        })
    }

    /// The velocity (m/s) the emitter gives its particles.
    pub fn velocity(&self) -> Vec3 {
        self.axes[0] * self.state.spec.speed
    }
}

/// Checks that a length (m) of an emitter's shape is positive and finite.
fn check_length(field: &str, value: f64) -> Result<(), Error> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            field,
            value,
            "must be a positive finite length (m)",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(shape: EmitterShape) -> EmitterState {
        EmitterState {
            spec: EmitterSpec {
                shape,
                position: Vec3::new(1.0, 2.0, 3.0),
                direction: Vec3::new(0.0, -2.0, 0.0),
                speed: 1.5,
                end_time: None,
            },
            travelled: 0.1,
            emitted: 0,
            material: 0,
        }
    }

    /// The plane axes are orthonormal and normal to the direction.
    #[test]
    fn plane_axes_are_orthonormal() {
        for n in [Vec3::x(), -Vec3::y(), Vec3::new(1.0, 2.0, -3.0).normalize()] {
            let (u, w) = plane_axes(n);
            for (a, b) in [(u, n), (w, n), (u, w)] {
                assert!(a.dot(&b).abs() < 1e-15);
            }
            assert!((u.norm() - 1.0).abs() < 1e-15 && (w.norm() - 1.0).abs() < 1e-15);
        }
        assert_eq!(plane_axes(-Vec3::y()), (Vec3::x(), Vec3::z()));
    }

    /// A rectangle of 5 × 3 spacings holds 15 points, a disc of radius 2d the 12 of the
    /// cell-centred lattice inside it, and one smaller than a cell none.
    #[test]
    fn lattices_fill_the_opening() {
        let d = 0.05;
        let rect = EmitterShape::Rectangle {
            half_extents: [2.5 * d, 1.5 * d],
        };
        let e = Emitter::new(spec(rect), d).unwrap();
        assert_eq!(e.layer_len(), 15);
        assert!((e.area() - 15.0 * d * d).abs() < 1e-15);
        assert_eq!(e.direction(), -Vec3::y());
        let disc = Emitter::new(spec(EmitterShape::Disc { radius: 2.0 * d }), d).unwrap();
        assert_eq!(disc.layer_len(), 12);
        for p in &disc.points {
            assert!(p.norm() <= 2.0 * d && p.y == 0.0);
        }
        let tiny = EmitterShape::Disc { radius: 0.7 * d };
        let message = Emitter::new(spec(tiny), d).unwrap_err().to_string();
        assert!(message.contains("zero area"), "{message}");
    }

    /// Layers are due every d of travel, at their exact distances, and not after the end.
    #[test]
    fn layers_are_due_every_spacing() {
        let d = 0.05;
        let mut state = spec(EmitterShape::Disc { radius: d });
        state.travelled = 2.5 * d;
        state.spec.end_time = Some(10.0);
        let mut e = Emitter::new(state, d).unwrap();
        let mut offsets = Vec::new();
        e.take_due(0.0, &mut offsets);
        assert_eq!(offsets.len(), 2);
        assert!((offsets[0] - 1.5 * d).abs() < 1e-15 && (offsets[1] - 0.5 * d).abs() < 1e-15);
        assert!((e.state().travelled - 0.5 * d).abs() < 1e-15);
        e.advance(d / 1.5);
        e.take_due(10.0 + 0.6 * d / 1.5, &mut offsets);
        assert!(offsets.is_empty(), "born after the end");
    }
}
