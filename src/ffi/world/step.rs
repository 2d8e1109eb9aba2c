//! The functions that advance a `PfWorld` in time: one step, a span of simulated time, and
//! a damped relaxation towards equilibrium.

use super::PfWorld;
use crate::ffi::checked::Args;
use crate::ffi::status::{Failure, PfStatus, status_call};

/// Takes one time step of `dt` seconds (0 < dt ≤ 1), or of the CFL-limited size when
/// `dt` ≤ 0 (the usual choice). The CFL rule sets the size of the next CFL step either way.
///
/// Errors: `PF_ERROR_INVALID_ARGUMENT` (dt NaN, infinite, above 1, or so short that the
/// time would not change, e.g. 1e-300; no fluid particles;
/// emitters that would exceed the particle limit), `PF_ERROR_OUT_OF_MEMORY` (the step's
/// buffers and neighbour lists, reserved before it starts, or what only the step can size
/// and grows during it: neighbour lists of a fluid compressed far beyond rest, a rebuilt
/// neighbour grid, the corrections its projections keep, the coupling of the fluid to
/// bodies, the LDLᵀ factorisation). On any error the world is unchanged. A step does not
/// abort for want of memory, short of the thread pool's own bookkeeping (a few hundred
/// bytes).
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_step(world: *mut PfWorld, dt: f64) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_step", || {
        let mut world = args.world(world)?;
        if !dt.is_finite() {
            return Err(Failure::invalid(format!(
                "dt must be finite (≤ 0 for the CFL step), got {dt}"
            )));
        }
        if dt <= 0.0 {
            world.step()?;
        } else {
            world.step_with_dt(dt)?;
        }
        Ok(())
    })
}

/// Takes CFL-limited steps until `seconds` more simulated time has passed (the last step
/// is shortened to land exactly). 0 takes no step; otherwise `seconds` must be at least
/// `dt_min` (`PfParams.dt_min`, default 1e-4 s), since a shorter span would not move the
/// clock reliably, and the run must end before t = 1e12·dt_min (1e8 s by default), beyond
/// which the clock no longer resolves such a step.
///
/// Errors: `PF_ERROR_INVALID_ARGUMENT` (seconds negative, not finite, between 0 and dt_min,
/// or ending too late; no fluid particles; emitters that could exceed the particle limit within
/// `seconds`), `PF_ERROR_OUT_OF_MEMORY`. Everything is checked, and the storage the steps
/// need (particles the emitters may insert, buffers, neighbour lists for up to 1.25 times
/// the neighbours of fluid at rest) reserved, before the first step: such an error changes
/// nothing. What only a step can size grows during it (`pf_world_step`); a step that cannot
/// have that memory returns `PF_ERROR_OUT_OF_MEMORY` having changed nothing, and ends the
/// call there with the steps before it kept (`pf_world_time` tells how far it got).
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_advance(world: *mut PfWorld, seconds: f64) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_advance", || {
        let mut world = args.world(world)?;
        world.advance(seconds)?;
        Ok(())
    })
}

/// Relaxes the fluid towards its equilibrium: takes CFL-limited steps like
/// `pf_world_advance` for `seconds`, and after every step of Δt scales every fluid velocity
/// by exp(−`damping`·Δt) (`damping` in 1/s; 0 is `pf_world_advance`). A block of particles
/// on a lattice is not at rest under gravity; 10 s at 4/s bring a tank to its equilibrium
/// packing, from which it stays at rest under the calm settings (`pf_params_calm`).
///
/// Errors: those of `pf_world_advance`, and `PF_ERROR_INVALID_ARGUMENT` for a damping that
/// is negative or not finite; on any error no step is taken and the world is unchanged,
/// except that a step that runs out of memory part-way through the call ends it there, as
/// in `pf_world_advance`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_relax(
    world: *mut PfWorld,
    seconds: f64,
    damping: f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_relax", || {
        let mut world = args.world(world)?;
        world.relax(seconds, damping)?;
        Ok(())
    })
}
