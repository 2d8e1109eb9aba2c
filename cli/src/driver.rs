//! Runs a world for a number of steps or a span of simulated time and accumulates its step
//! statistics and total energy into a [`RunAccumulator`]; the CLI, the benchmark and ρ tuning
//! all run worlds through it.

use crate::summary::RunAccumulator;
use projfluid::stats::StepStats;
use projfluid::{Error, Vec3, World};
use std::fmt;
use std::time::Instant;

/// How long a run lasts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RunLength {
    /// This many CFL-limited steps.
    Steps(u64),
    /// This much simulated time (s); the last step is shortened to land exactly.
    Duration(f64),
    /// Until the world has taken this many steps in total (a resumed run's saved end).
    UntilStep(u64),
    /// Until the world's clock reads this time (s), the last step shortened to land exactly
    /// (a resumed run's saved end).
    UntilTime(f64),
}

/// What the driver tells its caller after every step.
pub struct StepReport<'a> {
    /// The world after the step.
    pub world: &'a World,
    /// The step's statistics.
    pub stats: &'a StepStats,
    /// Wall-clock time of the step alone (s).
    pub wall_seconds: f64,
    /// Processor time of the step alone, all threads of the process (s), where available.
    pub cpu_seconds: Option<f64>,
    /// Steps taken in this run so far, this one included.
    pub steps: u64,
    /// Finished fraction of the run, in [0, 1].
    pub done: f64,
}

/// Why a run stopped early.
#[derive(Debug, PartialEq)]
pub enum RunError<E> {
    /// Step number `step` (1-based within the run) failed.
    Step {
        /// The failing step, counted from 1 within this run.
        step: u64,
        /// Why it failed.
        error: Error,
    },
    /// The per-step callback returned an error.
    Callback(E),
}

impl<E: fmt::Display> fmt::Display for RunError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Step { step, error } => write!(f, "step {step} failed: {error}"),
            RunError::Callback(e) => e.fmt(f),
        }
    }
}

impl From<RunError<std::convert::Infallible>> for Error {
    fn from(e: RunError<std::convert::Infallible>) -> Self {
        match e {
            RunError::Step { step, error } => match error {
                Error::InvalidArgument { field, message } => Error::InvalidArgument {
                    field,
                    message: format!("step {step} failed: {message}"),
                },
                Error::Io(message) => Error::Io(format!("step {step} failed: {message}")),
                Error::OutOfMemory(message) => {
                    Error::OutOfMemory(format!("step {step} failed: {message}"))
                }
            },
            RunError::Callback(never) => match never {},
        }
    }
}

/// A run in progress: the statistics of the steps taken so far, with the total energy (above
/// [`energy_datum`] of the world as it was at the start) recorded before the first step and
/// after each one. [`run`] drives one to its end; several can take turns on their own worlds
/// (the benchmark interleaves its solvers this way). Only the step itself is timed, not the
/// energy.
pub struct Runner {
    length: RunLength,
    /// Rates (1/s) whose multiples of 1/rate seconds the steps land on: frames, probe readings.
    landing: Vec<f64>,
    datum: f64,
    start_time: f64,
    start_steps: u64,
    acc: RunAccumulator,
}

/// How the run's next step is sized.
#[derive(Clone, Copy, Debug)]
enum NextStep {
    /// The CFL-limited size (s).
    Cfl(f64),
    /// Ending exactly at this time (s).
    Until(f64),
}

impl NextStep {
    /// The CFL step, or, where it would pass `end` (s), the step that ends there.
    fn land(world: &World, end: f64) -> Self {
        let dt = world.next_dt();
        if world.time() + dt >= end {
            NextStep::Until(end)
        } else {
            NextStep::Cfl(dt)
        }
    }
}

/// One step taken by [`Runner::step`].
pub struct StepTaken {
    /// The step's statistics.
    pub stats: StepStats,
    /// Wall-clock time of the step alone (s).
    pub wall_seconds: f64,
    /// Processor time of the step alone, all threads of the process (s), where available.
    pub cpu_seconds: Option<f64>,
    /// Finished fraction of the run, in [0, 1].
    pub done: f64,
}

impl Runner {
    /// Starts a run of `world` for `length`; a duration or end time that is negative or not
    /// finite is an error.
    pub fn new(world: &World, length: RunLength) -> Result<Self, Error> {
        if let RunLength::Duration(d) | RunLength::UntilTime(d) = length
            && !(d.is_finite() && d >= 0.0)
        {
            return Err(Error::invalid(
                "duration",
                d,
                "must be a non-negative finite number",
            ));
        }
        let datum = energy_datum(world);
        let mut acc = RunAccumulator::default();
        acc.record_energy(total_energy(world, datum));
        Ok(Self {
            length,
            landing: Vec::new(),
            datum,
            start_time: world.time(),
            start_steps: world.steps(),
            acc,
        })
    }

    /// Lands the run's steps on every multiple of 1/`fps` seconds of simulated time: a step
    /// that would pass one is shortened to end on it ([`frame_index`] tells which). Called
    /// again with another rate, the steps land on the times of both.
    pub fn landing_on(mut self, fps: f64) -> Self {
        self.landing.push(fps);
        self
    }

    /// The run's next step, or `None` once the run has reached its end.
    fn next_step(&self, world: &World) -> Option<NextStep> {
        let now = world.time();
        let until = |end: f64| {
            let left = end - now;
            (left > 1e-12 * end.abs().max(1.0)).then(|| NextStep::land(world, end))
        };
        let step = match self.length {
            RunLength::Steps(n) => (self.acc.steps() < n).then(|| NextStep::Cfl(world.next_dt())),
            RunLength::UntilStep(n) => (world.steps() < n).then(|| NextStep::Cfl(world.next_dt())),
            RunLength::Duration(d) => until(self.start_time + d),
            RunLength::UntilTime(end) => until(end),
        }?;
        let end = match step {
            NextStep::Cfl(dt) => now + dt,
            NextStep::Until(end) => end,
        };
        // The next landing time of every rate, earliest first.
        let mut ahead: Vec<(f64, f64)> = (self.landing.iter())
            .map(|&fps| {
                let next = match frame_index(now, fps) {
                    Some(k) => k + 1,
                    None => (now * fps).ceil() as u64,
                };
                (next as f64 / fps, fps)
            })
            .collect();
        ahead.sort_by(|a, b| a.0.total_cmp(&b.0));
        // The step lands on the first time it would pass; one ending within the frame
        // tolerance before a time lands on it too.
        Some(
            match ahead
                .iter()
                .find(|&&(time, fps)| end > time - FRAME_TOLERANCE / fps)
            {
                Some(&(time, _)) => NextStep::Until(time),
                None => step,
            },
        )
    }

    /// Takes the run's next step of `world` (the world it started with), or returns `None`
    /// once the run has reached its end.
    pub fn step(&mut self, world: &mut World) -> Result<Option<StepTaken>, Error> {
        let Some(next) = self.next_step(world) else {
            return Ok(None);
        };
        let (clock, cpu) = (Instant::now(), process_cpu_seconds());
        let stats = match next {
            NextStep::Cfl(dt) => world.step_with_dt(dt)?,
            NextStep::Until(end) => world.step_until(end)?,
        }
        .clone();
        let wall_seconds = clock.elapsed().as_secs_f64();
        let cpu_seconds = cpu.zip(process_cpu_seconds()).map(|(a, b)| b - a);
        let acc = &mut self.acc;
        acc.add(&stats, wall_seconds);
        if let Some(cpu) = cpu_seconds {
            acc.add_cpu_time(cpu);
        }
        acc.record_energy(total_energy(world, self.datum));
        let start = self.start_time;
        let done = match self.length {
            RunLength::Steps(n) => acc.steps() as f64 / n as f64,
            RunLength::UntilStep(n) => {
                let total = n.saturating_sub(self.start_steps).max(1);
                (world.steps() - self.start_steps) as f64 / total as f64
            }
            RunLength::Duration(d) if d > 0.0 => (world.time() - start) / d,
            RunLength::UntilTime(end) if end > start => (world.time() - start) / (end - start),
            RunLength::Duration(_) | RunLength::UntilTime(_) => 1.0,
        };
        Ok(Some(StepTaken {
            stats,
            wall_seconds,
            cpu_seconds,
            done: done.clamp(0.0, 1.0),
        }))
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u64 {
        self.acc.steps()
    }

    /// Ends the run and returns the statistics of its steps.
    pub fn finish(self) -> RunAccumulator {
        self.acc
    }
}

/// How close to a frame's time, in frame intervals, the clock counts as standing on it.
const FRAME_TOLERANCE: f64 = 1e-6;

/// The index k of the frame whose time k/`fps` the clock `time` (s) stands on, if any:
/// within [`FRAME_TOLERANCE`] of a frame interval (a run's steps land on frame times
/// exactly; the tolerance is for clocks set otherwise).
pub fn frame_index(time: f64, fps: f64) -> Option<u64> {
    let k = (time * fps).round();
    ((time * fps - k).abs() <= FRAME_TOLERANCE && k >= 0.0).then_some(k as u64)
}

/// Runs `world` for `length` with a [`Runner`], calling `on_step` after every step, and
/// returns the statistics of the steps taken. Stops at the first failing step or callback
/// error.
pub fn run<E>(
    world: &mut World,
    length: RunLength,
    on_step: impl FnMut(&StepReport<'_>) -> Result<(), E>,
) -> Result<RunAccumulator, RunError<E>> {
    run_landing(world, length, &[], on_step)
}

/// [`run`], its steps landing on every multiple of 1/rate seconds for each of `rates` (1/s;
/// frames per second, probe readings per second; [`Runner::landing_on`]).
pub fn run_landing<E>(
    world: &mut World,
    length: RunLength,
    rates: &[f64],
    mut on_step: impl FnMut(&StepReport<'_>) -> Result<(), E>,
) -> Result<RunAccumulator, RunError<E>> {
    let mut runner =
        Runner::new(world, length).map_err(|error| RunError::Step { step: 1, error })?;
    for &rate in rates {
        runner = runner.landing_on(rate);
    }
    loop {
        let taken = match runner.step(world) {
            Ok(Some(taken)) => taken,
            Ok(None) => break,
            Err(error) => {
                let step = runner.steps() + 1;
                return Err(RunError::Step { step, error });
            }
        };
        let report = StepReport {
            world,
            stats: &taken.stats,
            wall_seconds: taken.wall_seconds,
            cpu_seconds: taken.cpu_seconds,
            steps: runner.steps(),
            done: taken.done,
        };
        on_step(&report).map_err(RunError::Callback)?;
    }
    Ok(runner.finish())
}

/// Processor time (s) used so far by all threads of this process, user plus system.
#[cfg(unix)]
fn process_cpu_seconds() -> Option<f64> {
    // SAFETY: getrusage only writes the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) } != 0 {
        return None;
    }
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    Some(seconds(usage.ru_utime) + seconds(usage.ru_stime))
}

/// Not reported on this platform.
#[cfg(not(unix))]
fn process_cpu_seconds() -> Option<f64> {
    None
}

/// [`run`] without a per-step callback.
pub fn run_quietly(world: &mut World, length: RunLength) -> Result<RunAccumulator, Error> {
    Ok(run(world, length, |_| {
        Ok::<(), std::convert::Infallible>(())
    })?)
}

/// The potential energy (J) the fluid would have if every particle sat as low, along gravity,
/// as the lowest one does now: N·min_i(−m g·x_i). Energies measured above it are positive for
/// a fluid at rest above its floor, so a relative energy rise is meaningful. Zero without
/// fluid or gravity.
pub fn energy_datum(world: &World) -> f64 {
    let g = Vec3::from(world.params().gravity);
    let m = world.particle_mass();
    let positions = world.positions();
    let lowest = positions
        .iter()
        .map(|x| -m * g.dot(x))
        .fold(f64::INFINITY, f64::min);
    if lowest.is_finite() {
        lowest * positions.len() as f64
    } else {
        0.0
    }
}

/// Kinetic plus potential energy of the fluid (J), measured above `datum`
/// (see [`energy_datum`]).
pub fn total_energy(world: &World, datum: f64) -> f64 {
    world.kinetic_energy() + world.potential_energy() - datum
}

#[cfg(test)]
mod tests {
    use super::*;
    use projfluid::scene::Scene;

    fn small_world() -> World {
        let mut scene = Scene::builtin("dam_break_small").unwrap();
        scene.params.threads = 1;
        scene.build_world().unwrap()
    }

    #[test]
    fn runs_exactly_the_requested_steps_and_reports_each() {
        let mut world = small_world();
        let mut seen = Vec::new();
        let acc = run(&mut world, RunLength::Steps(3), |r| {
            seen.push((r.steps, r.done, r.stats.outer_iterations));
            Ok::<(), ()>(())
        })
        .unwrap();
        assert_eq!(acc.steps(), 3);
        assert_eq!(world.steps(), 3);
        assert_eq!(seen.iter().map(|s| s.0).collect::<Vec<_>>(), [1, 2, 3]);
        assert_eq!(seen[2].1, 1.0);
        assert!(seen.iter().all(|s| s.2 >= 1));
        let summary = acc.summary("s", &world);
        if cfg!(unix) {
            assert!(summary.cpu_ms_per_step.unwrap() > 0.0);
        }
        // At rest above its lowest particle the block has positive potential energy; the
        // dissipative step never adds energy in the first steps of the collapse.
        assert!(summary.energy_initial > 0.0);
        assert!(summary.energy_final < summary.energy_initial);
        assert_eq!(summary.energy_rise(), Some(0.0));
    }

    #[test]
    fn duration_lands_exactly_and_callback_errors_stop_the_run() {
        let mut world = small_world();
        let acc = run_quietly(&mut world, RunLength::Duration(0.0025)).unwrap();
        assert!((world.time() - 0.0025).abs() < 1e-12, "{}", world.time());
        assert!(acc.steps() >= 2);
        let stopped = run(&mut world, RunLength::Steps(5), |r| {
            if r.steps == 2 { Err("enough") } else { Ok(()) }
        });
        assert_eq!(stopped.unwrap_err(), RunError::Callback("enough"));
        let bad = run_quietly(&mut world, RunLength::Duration(f64::NAN)).unwrap_err();
        assert!(bad.to_string().contains("duration"), "{bad}");
    }

    /// With two rates a step ends exactly on every multiple of either interval.
    #[test]
    fn steps_land_on_the_times_of_every_rate() {
        let mut world = small_world();
        let mut times = Vec::new();
        run_landing(&mut world, RunLength::Duration(0.1), &[30.0, 100.0], |r| {
            times.push(r.world.time());
            Ok::<(), ()>(())
        })
        .unwrap();
        let on = |rate: f64| {
            (1..)
                .map(move |k| k as f64 / rate)
                .take_while(|&t| t <= 0.1)
        };
        for t in on(30.0).chain(on(100.0)) {
            assert!(times.contains(&t), "no step ends at {t}: {times:?}");
        }
        assert_eq!(times.last(), Some(&0.1));
    }
}
