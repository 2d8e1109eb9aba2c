//! What a step puts back when it runs out of memory part-way. Before a step moves the fluid
//! (at its end, docs/method.md §1.3) it changes only the fluid its emitters insert, the
//! bodies' poses, the neighbour grid when it rebuilds it, the boundary when it sorts or
//! places it anew, and the record of the outer iterations; each is kept here before it
//! changes, so that a step that cannot have the memory its neighbour lists, grid, local
//! steps, body coupling or factorisation need leaves the world as it was.

use super::SearchGrid;
use crate::body::{Body, BodyState};
use crate::boundary::{Boundary, BoundaryCopy};
use crate::emitter::{Emitter, EmitterState};
use crate::fluid::Fluid;
use crate::reserve::reserve_total;
use std::collections::TryReserveError;

/// The state a step changed before it could still fail, with its storage kept from step
/// to step.
#[derive(Clone, Debug, Default)]
pub(crate) struct Undo {
    /// The grid from before the step, once the step replaced it.
    pub(super) grid: Option<SearchGrid>,
    /// The boundary's arrays from before the step, once the step sorts or places them.
    pub(super) boundary: BoundaryCopy,
    /// Every body's state from before the step.
    bodies: Vec<BodyState>,
    /// δ_k of the outer iterations of the step before (m).
    displacements: Vec<f64>,
    /// The number of fluid particles and the next id before the emitters inserted theirs.
    fluid: (usize, u64),
    /// Every emitter's progress before it inserted its due layers.
    emitters: Vec<EmitterState>,
    /// The pressures the last step carried (docs/method.md §10.1), which the fluid gives up
    /// while the step runs; its own vector holds this one's room meanwhile.
    pressures: Vec<f64>,
}

impl Undo {
    /// Reserves room to keep `bodies` bodies, `iterations` displacements and `emitters`
    /// emitters.
    pub(crate) fn try_reserve(
        &mut self,
        bodies: usize,
        iterations: usize,
        emitters: usize,
    ) -> Result<(), TryReserveError> {
        reserve_total(&mut self.bodies, bodies)?;
        reserve_total(&mut self.displacements, iterations)?;
        reserve_total(&mut self.emitters, emitters)
    }

    /// Keeps the fluid's size, its carried pressures (moved here, the fluid left without
    /// any) and the emitters' progress before the emitters insert the layers due at the
    /// start of a step (in the room reserved).
    pub(crate) fn before_emission(&mut self, fluid: &mut Fluid, emitters: &[Emitter]) {
        self.fluid = (fluid.len(), fluid.next_id);
        std::mem::swap(&mut self.pressures, &mut fluid.pressures);
        fluid.pressures.clear();
        self.emitters.clear();
        self.emitters.extend(emitters.iter().map(|e| *e.state()));
    }

    /// Removes the particles the emitters inserted since [`Undo::before_emission`] and puts
    /// their progress and the fluid's pressures back.
    pub(crate) fn undo_emission(&mut self, fluid: &mut Fluid, emitters: &mut [Emitter]) {
        fluid.truncate(self.fluid.0, self.fluid.1);
        std::mem::swap(&mut self.pressures, &mut fluid.pressures);
        for (emitter, state) in emitters.iter_mut().zip(&self.emitters) {
            emitter.restore(state);
        }
    }

    /// Keeps the bodies' states and the last step's displacements as the step starts (in
    /// the room reserved; the grid and the boundary are kept where they change).
    pub(super) fn start(&mut self, bodies: &[Body], displacements: &[f64]) {
        self.bodies.clear();
        self.bodies.extend(bodies.iter().map(Body::state));
        self.displacements.clear();
        self.displacements.extend_from_slice(displacements);
    }

    /// Puts back everything the step changed: the grid, the boundary, the bodies' states
    /// and the displacements (moved back, not copied: this cannot fail).
    pub(super) fn restore(
        &mut self,
        grid: &mut SearchGrid,
        boundary: &mut Boundary,
        bodies: &mut [Body],
        displacements: &mut Vec<f64>,
    ) {
        if let Some(before) = self.grid.take() {
            *grid = before;
        }
        boundary.restore(&mut self.boundary);
        for (body, state) in bodies.iter_mut().zip(&self.bodies) {
            body.set_state(state);
        }
        std::mem::swap(displacements, &mut self.displacements);
    }

    /// Forgets what was kept, once the step can no longer fail (the replaced grid is freed).
    pub(super) fn discard(&mut self) {
        self.grid = None;
        self.boundary.discard();
    }
}
