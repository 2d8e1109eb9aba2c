//! Emitters in a world (docs/method.md §12.2): adding them, and inserting their due layers
//! at the start of a step.

use super::{MAX_PARTICLES, World};
use crate::Error;
use crate::emitter::{Emitter, EmitterSpec, EmitterState};
use crate::reserve::reserve_total;
use std::collections::TryReserveError;

/// An emitter's handle within its world: the order in which it was added, from 0.
pub type EmitterId = usize;

impl World {
    /// Adds an emitter (docs/method.md §12.2): from the start of the next step on it inserts
    /// a layer of fluid particles on a square lattice of spacing d = 2r over its opening,
    /// moving with its speed along its direction, each time the layer before has travelled
    /// d, until its end time. Lattice points closer than 0.9·d to fluid are skipped. Returns
    /// the emitter's index. Errors, changing nothing, on a non-finite position, a zero or
    /// non-finite direction, a speed that is not positive and finite, a non-finite end time,
    /// or an opening that holds no lattice point ("zero area") or far too many. It emits
    /// fluid of the material [`World::set_fluid_material`] last chose.
    pub fn add_emitter(&mut self, spec: EmitterSpec) -> Result<EmitterId, Error> {
        let state = EmitterState {
            spec,
            travelled: self.params.spacing(),
            emitted: 0,
            material: self.materials.current,
        };
        let emitter = Emitter::new(state, self.params.spacing())?;
        self.emitters.push(emitter);
        Ok(self.emitters.len() - 1)
    }

    /// The emitters, in the order they were added (index = [`EmitterId`]).
    pub fn emitters(&self) -> &[Emitter] {
        &self.emitters
    }

    /// Particles inserted by emitters so far.
    pub fn emitted_count(&self) -> u64 {
        self.emitters.iter().map(|e| e.emitted()).sum()
    }

    /// An upper bound on the particles the emitters insert over steps spanning the next
    /// `seconds` (s; 0 for one step): every layer due now or after travelling on for that
    /// long, up to each emitter's end time.
    pub(super) fn emission_bound(&self, seconds: f64) -> f64 {
        self.emitters
            .iter()
            .map(|e| {
                let spec = &e.state().spec;
                let span = spec
                    .end_time
                    .map_or(seconds, |end| (end - self.time).clamp(0.0, seconds));
                let travelled = e.state().travelled + spec.speed * span;
                (travelled / self.params.spacing()).floor() * e.layer_len() as f64
            })
            .sum()
    }

    /// Checks that steps spanning the next `seconds` (s; 0 for one step) cannot emit more
    /// fluid than the particle limit allows, and returns how many particles the world may
    /// then hold at most.
    pub(super) fn check_emission(&self, seconds: f64) -> Result<usize, Error> {
        let due = self.emission_bound(seconds);
        if self.fluid.len() as f64 + due > MAX_PARTICLES as f64 {
            return Err(Error::invalid(
                "emitters",
                format!("{due:.3e} particles due"),
                "would exceed the particle limit",
            ));
        }
        Ok(self.fluid.len() + due as usize)
    }

    /// Inserts every emitter's due layers at the start of a step (emitters in order, each
    /// layer's free lattice points in lattice order), so that they get the next ids. Points
    /// inside a solid (outside every container, inside a closed obstacle or body) are not
    /// inserted, and the new particles are settled as placed fluid is (docs/method.md §2.7).
    /// The caller checked the particle limit ([`World::check_emission`]) and reserved the
    /// fluid's storage; errors when memory for the layers' scratch cannot be had, with the
    /// emitters part-way (the caller puts them back).
    pub(super) fn emit(&mut self) -> Result<(), TryReserveError> {
        if self.emitters.is_empty() {
            return Ok(());
        }
        let first = self.fluid.len();
        let mut solids = None;
        let (mut offsets, mut blocked, mut points) = (Vec::new(), Vec::new(), Vec::new());
        for e in 0..self.emitters.len() {
            self.emitters[e].take_due(self.time, &mut offsets);
            if offsets.is_empty() {
                continue;
            }
            let solids = match &mut solids {
                Some(solids) => solids,
                None => solids.insert(self.solids()),
            };
            let emitter = &mut self.emitters[e];
            let lattice = offsets.len() * emitter.layer_len();
            reserve_total(&mut blocked, lattice)?;
            reserve_total(&mut points, lattice)?;
            // Against the fluid as it is, including the layers other emitters just inserted.
            emitter.mark_blocked(&offsets, &self.fluid.positions, &mut blocked);
            emitter.mark_solid(&offsets, |p| solids.contain(p), &mut blocked);
            let (velocity, material) = (emitter.velocity(), emitter.state().material);
            points.clear();
            points.extend(emitter.free_points(&offsets, &blocked));
            self.fluid.push(
                material,
                &points,
                std::iter::repeat_n(velocity, points.len()),
            );
        }
        match solids.filter(|_| self.fluid.len() > first) {
            Some(solids) => self.settle_emitted(first, &solids),
            None => Ok(()),
        }
    }

    /// Adds a step of `dt` seconds to every emitter's travel.
    pub(super) fn advance_emitters(&mut self, dt: f64) {
        for emitter in &mut self.emitters {
            emitter.advance(dt);
        }
    }

    /// The fastest speed (m/s) of the emitters still emitting at `time` (s), 0 without any:
    /// the CFL rule counts it like a fluid particle's.
    pub(super) fn inflow_speed(&self, time: f64) -> f64 {
        self.emitters
            .iter()
            .filter(|e| e.active_at(time))
            .map(|e| e.state().spec.speed)
            .fold(0.0, f64::max)
    }
}
