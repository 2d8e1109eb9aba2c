//! Advancing a world in time: one step, a duration, or a damped relaxation towards rest.
//! The step itself is [`crate::step`]'s; this is where its size is checked, time kept, and
//! fluid emitted before it and removed after it (docs/method.md §12).

use super::World;
use crate::Error;
use crate::stats::StepStats;
use crate::step::{StepContext, idle_step, take_step};

impl World {
    /// Takes one step with the CFL-limited step size.
    pub fn step(&mut self) -> Result<&StepStats, Error> {
        self.step_with_dt(self.next_dt)
    }

    /// Takes one step of `dt` seconds (positive, finite). The CFL rule still sets the size
    /// the following [`World::step`] will use.
    ///
    /// Before the step the emitters insert their due layers; after it the particles in a
    /// sink or outside the domain are removed (the step's statistics, and the next Δt, are
    /// those of the step before the removal). A world without fluid particles steps only if
    /// it has emitters or had particles removed: time and bodies then move on and the
    /// statistics are zero; otherwise stepping it is an error.
    pub fn step_with_dt(&mut self, dt: f64) -> Result<&StepStats, Error> {
        if !(dt.is_finite() && dt > 0.0 && dt <= 1.0) {
            return Err(Error::invalid(
                "dt",
                dt,
                "must be a positive finite number of seconds (at most 1)",
            ));
        }
        if self.fluid_count() == 0 && self.emitters.is_empty() && self.fluid.removed == 0 {
            return Err(Error::invalid(
                "fluid particles",
                0,
                "must be present before stepping",
            ));
        }
        self.emit()?;
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
            time: *time,
            inflow_speed,
        };
        let (stats, next_dt) = if idle {
            idle_step(context, dt)
        } else {
            take_step(context, dt)
        };
        self.next_dt = next_dt;
        self.time += dt;
        self.steps += 1;
        self.advance_emitters(dt);
        self.drain();
        Ok(self.last.insert(stats))
    }

    /// Steps until `seconds` more simulated time has passed; the last step is shortened to
    /// land exactly. Returns the number of steps taken.
    pub fn advance(&mut self, seconds: f64) -> Result<usize, Error> {
        self.advance_with(seconds, |_| Ok(()))
    }

    /// [`World::advance`], calling `each` with the world after every step; an error from
    /// `each` ends the run there and is returned.
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
    /// Returns the number of steps taken.
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

    /// Takes CFL-limited steps until `seconds` (≥ 0, finite) more simulated time has passed,
    /// the last one shortened to land exactly, calling `after(world, Δt)` after every step.
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
        let end = self.time + seconds;
        let mut steps = 0;
        while end - self.time > 1e-12 * end.abs().max(1.0) {
            let dt = self.next_dt.min(end - self.time);
            self.step_with_dt(dt)?;
            after(self, dt)?;
            steps += 1;
        }
        Ok(steps)
    }
}
