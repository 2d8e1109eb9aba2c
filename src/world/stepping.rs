//! Advancing a world in time: one step, a duration, or a damped relaxation towards rest.
//! The step itself is [`crate::step`]'s; this is where its size is checked, time kept, and
//! fluid emitted before it and removed after it (docs/method.md §12).
//!
//! A call either succeeds or changes nothing: everything that can fail — the sizes, the
//! presence of fluid, the particle limit over the emitters' output, the memory the steps
//! need as far as it can be known — is checked before the first step. What only a step
//! can size (neighbour lists beyond their reservation, a rebuilt grid, kept corrections,
//! the body coupling, the LDLᵀ factorisation) it reserves fallibly; a step that cannot have
//! it is undone, and a run of steps ends there with the steps before it kept.

use super::World;
use crate::Error;
use crate::params::check_step;
use crate::stats::StepStats;
use crate::step::{StepContext, idle_step, take_step};

/// The relative precision to which a duration is kept: steps end within this fraction of
/// the end time (s) of it, so that rounding never leaves a vanishing last step.
const CLOCK_RESOLUTION: f64 = 1e-12;

/// Bytes per boundary particle that sorting the boundary and computing its volumes needs
/// at once (positions, owners, masses, components, order, volumes, cell ranks).
const BOUNDARY_SORT_BYTES: f64 = 128.0;

impl World {
    /// Takes one step with the CFL-limited step size.
    pub fn step(&mut self) -> Result<&StepStats, Error> {
        self.step_with_dt(self.next_dt())
    }

    /// Takes one step of `dt` seconds (positive, finite, at most [`crate::params::MAX_STEP`]).
    /// The CFL rule still sets the size the following [`World::step`] will use.
    ///
    /// Before the step the emitters insert their due layers; after it the particles in a
    /// sink or outside the domain are removed (the step's statistics, and the next Δt, are
    /// those of the step before the removal). A world without fluid particles steps only if
    /// it has emitters or had particles removed: time and bodies then move on and the
    /// statistics are zero; otherwise stepping it is an error.
    ///
    /// Errors, changing nothing: a bad `dt` (or one so short that the clock, at the current
    /// time, would not move), no fluid, emitters that would exceed the particle limit, or
    /// ([`Error::OutOfMemory`]) too little memory for the step — for its buffers, or for
    /// neighbour lists, a grid, corrections, the body coupling or the LDLᵀ factorisation
    /// that grow during it (a fluid compressed far beyond rest, e.g. particles placed on top
    /// of each other, needs many more neighbours).
    pub fn step_with_dt(&mut self, dt: f64) -> Result<&StepStats, Error> {
        check_step("dt", dt)?;
        if self.time + dt == self.time {
            return Err(Error::invalid(
                "dt",
                dt,
                &format!("is too short to move the clock at t = {} s", self.time),
            ));
        }
        self.prepare_steps(0.0)?;
        self.take_prepared_step(dt)
    }

    /// Takes one step that ends at simulated time `end` (s) exactly: a step of
    /// `end` − [`World::time`] seconds (checked as [`World::step_with_dt`] checks its `dt`),
    /// after which the clock reads `end` without the round-off of adding the step's size.
    /// For landing on output times and run ends. Errors, changing nothing: as
    /// [`World::step_with_dt`], and an `end` that is not after the current time.
    pub fn step_until(&mut self, end: f64) -> Result<&StepStats, Error> {
        let dt = end - self.time;
        if dt.is_nan() || dt <= 0.0 {
            return Err(Error::invalid(
                "end",
                end,
                &format!("must be after the current time ({} s)", self.time),
            ));
        }
        self.step_with_dt(dt)?;
        self.time = end;
        Ok(self.last.as_ref().expect("a step was taken"))
    }

    /// Checks that steps spanning the next `seconds` (s; 0 for one step) can be taken and
    /// reserves the storage they need, changing nothing observable.
    fn prepare_steps(&mut self, seconds: f64) -> Result<(), Error> {
        if self.fluid_count() == 0 && self.emitters.is_empty() && self.fluid.removed == 0 {
            return Err(Error::invalid(
                "fluid particles",
                0,
                "must be present before stepping",
            ));
        }
        let most = self.check_emission(seconds)?;
        let oom = |_| Error::out_of_memory("the storage of the time steps");
        self.try_reserve_fluid(most - self.fluid_count())
            .map_err(oom)?;
        let iterations = self.params.max_outer_iterations;
        let (bodies, emitters) = (self.bodies.len(), self.emitters.len());
        self.buffers
            .try_reserve(most, iterations, bodies, emitters)
            .map_err(oom)?;
        self.solver.try_reserve(most).map_err(oom)?;
        for force in &mut self.forces {
            force.try_reserve(most).map_err(oom)?;
        }
        if self.boundary.dirty {
            crate::reserve::probe(self.boundary_count() as f64 * BOUNDARY_SORT_BYTES)
                .map_err(oom)?;
        }
        Ok(())
    }

    /// One step of `dt` seconds, after [`World::prepare_steps`] checked everything it can.
    /// Errors ([`Error::OutOfMemory`]) when the step needs more memory than can be had,
    /// having changed nothing.
    fn take_prepared_step(&mut self, dt: f64) -> Result<&StepStats, Error> {
        #[cfg(feature = "gpu")]
        if self.gpu.is_some() {
            return self.take_gpu_step(dt);
        }
        let oom = |_| Error::out_of_memory("the working storage of a time step");
        self.start_step().map_err(oom)?;
        let inflow_speed = self.inflow_speed(self.time + dt);
        let idle = self.fluid_count() == 0;
        let World {
            params,
            constraint,
            pool,
            fluid,
            boundary,
            grid,
            solver,
            chebyshev,
            forces,
            buffers,
            bodies,
            wall_load,
            time,
            containers,
            materials,
            ..
        } = self;
        let context = StepContext {
            params,
            constraint,
            pool,
            fluid,
            boundary,
            grid,
            solver: solver.as_mut(),
            chebyshev,
            forces,
            buffers,
            bodies,
            containers,
            wall_load,
            materials,
            time: *time,
            inflow_speed,
        };
        let taken = if idle {
            Ok(idle_step(context, dt))
        } else {
            take_step(context, dt).map_err(oom)
        };
        self.end_step(taken, dt)
    }

    /// Starts a step: the emitters insert their due layers, remembered so that
    /// [`World::end_step`] can undo them. Errors, the emission undone, when it needs more
    /// memory than can be had.
    pub(super) fn start_step(&mut self) -> Result<(), std::collections::TryReserveError> {
        self.buffers
            .undo
            .before_emission(&mut self.fluid, &self.emitters);
        let emitted = self.emit();
        if emitted.is_err() {
            self.buffers
                .undo
                .undo_emission(&mut self.fluid, &mut self.emitters);
        }
        emitted
    }

    /// Ends a step of `dt` seconds that was `taken` (its statistics and the next step's
    /// size, s) after the emitters inserted their due layers: moves the clock and the
    /// emitters on and lets sinks and the domain remove what left; or, where the step
    /// failed, undoes the emission and returns the error, the world as it was.
    pub(super) fn end_step(
        &mut self,
        taken: Result<(StepStats, f64), Error>,
        dt: f64,
    ) -> Result<&StepStats, Error> {
        let (stats, next_dt) = match taken {
            Ok(taken) => taken,
            Err(e) => {
                self.buffers
                    .undo
                    .undo_emission(&mut self.fluid, &mut self.emitters);
                return Err(e);
            }
        };
        self.next_dt = next_dt;
        self.time += dt;
        self.steps += 1;
        self.advance_emitters(dt);
        self.drain();
        Ok(self.last.insert(stats))
    }

    /// Steps until `seconds` more simulated time has passed; the last step is shortened to
    /// land exactly. Returns the number of steps taken. `seconds` is 0 (no step) or at least
    /// `dt_min` ([`crate::Params::dt_min`]): a shorter span would not move the clock
    /// reliably; and the run must end before t = 10¹²·dt_min (10⁸ s by default), beyond
    /// which the clock no longer resolves such a step. Errors, changing nothing: a bad
    /// `seconds`, no fluid, emitters that could
    /// exceed the particle limit within `seconds`, or ([`Error::OutOfMemory`]) too little
    /// memory for the steps. A step that runs out of memory for what grows during it
    /// ([`World::step_with_dt`]) ends the run with [`Error::OutOfMemory`]: that step changes
    /// nothing, the steps before it are kept ([`World::time`] tells how far the run got).
    pub fn advance(&mut self, seconds: f64) -> Result<usize, Error> {
        self.advance_with(seconds, |_| Ok(()))
    }

    /// [`World::advance`], calling `each` with the world after every step; an error from
    /// `each` ends the run there and is returned, the steps taken so far kept.
    pub fn advance_with(
        &mut self,
        seconds: f64,
        mut each: impl FnMut(&World) -> Result<(), Error>,
    ) -> Result<usize, Error> {
        self.step_for(seconds, |world, _| each(world))
    }

    /// Relaxes the fluid towards its equilibrium: steps like [`World::advance`] for `seconds`
    /// (s), and after every step of Δt scales every velocity by exp(−`damping`·Δt), `damping`
    /// being a rate (1/s, ≥ 0; 0 is [`World::advance`]). Meant for a settled start: a lattice
    /// of particles is not at rest under gravity (its layers slide into each other's hollows)
    /// and 10 s at 4/s bring a tank to its equilibrium packing (docs/validation.md, "Tank at rest").
    /// Returns the number of steps taken. Errors as [`World::advance`], and on a bad
    /// `damping`, changing nothing.
    pub fn relax(&mut self, seconds: f64, damping: f64) -> Result<usize, Error> {
        if !(damping.is_finite() && damping >= 0.0) {
            return Err(Error::invalid(
                "damping",
                damping,
                "must be a non-negative finite rate (1/s)",
            ));
        }
        self.step_for(seconds, |world, dt| {
            if damping > 0.0 {
                let factor = (-damping * dt).exp();
                for v in &mut world.fluid.velocities {
                    *v *= factor;
                }
            }
            Ok(())
        })
    }

    /// Takes CFL-limited steps until `seconds` (0, or at least `dt_min`, finite) more
    /// simulated time has passed, the last one shortened to land exactly, calling
    /// `after(world, Δt)` after every step. Everything that can fail is checked first.
    fn step_for(
        &mut self,
        seconds: f64,
        mut after: impl FnMut(&mut World, f64) -> Result<(), Error>,
    ) -> Result<usize, Error> {
        if !(seconds.is_finite() && seconds >= 0.0) {
            return Err(Error::invalid(
                "seconds",
                seconds,
                "must be a non-negative finite number",
            ));
        }
        if seconds == 0.0 {
            return Ok(0);
        }
        let dt_min = self.params.dt_min;
        if seconds < dt_min {
            return Err(Error::invalid(
                "seconds",
                seconds,
                &format!("must be 0 or at least dt_min = {dt_min} s"),
            ));
        }
        let end = self.time + seconds;
        // Steps land within this of `end`; it must stay below the shortest step.
        let landed = |time: f64| end - time <= CLOCK_RESOLUTION * end.abs().max(1.0);
        if CLOCK_RESOLUTION * end.abs() >= dt_min {
            return Err(Error::invalid(
                "seconds",
                seconds,
                &format!(
                    "would end at t = {end} s, where the clock no longer resolves dt_min = \
                     {dt_min} s (it must end before {} s)",
                    dt_min / CLOCK_RESOLUTION
                ),
            ));
        }
        self.prepare_steps(seconds)?;
        let mut steps = 0;
        while !landed(self.time) {
            // next_dt lies in [dt_min, dt_max] (the CFL rule clamps it, the capillary limit
            // is at least dt_min), so dt is valid.
            let dt = self.next_dt().min(end - self.time);
            self.take_prepared_step(dt)?;
            after(self, dt)?;
            steps += 1;
        }
        Ok(steps)
    }
}
