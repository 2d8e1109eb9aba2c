//! One time step (docs/method.md §1.3): predict, search neighbours, iterate local projections and
//! global solves (with Chebyshev extrapolation) until the displacement rule stops, update
//! velocities, apply XSPH, and choose the next step size by the CFL rule (§8).

use crate::constraint::{CHUNK, Corrections, Neighborhood, Projection};
use crate::neighbors::{CellTable, NeighborLists};
use crate::params::SolverKind;
use crate::solver::{Chebyshev, DiagonalSystem};
use crate::stats::{StepStats, StepTimings};
use crate::{Error, Vec3, World, reduce};
use rayon::prelude::*;
use std::time::Instant;

/// Buffers reused by every step, so that a step allocates nothing once sizes are stable.
#[derive(Clone, Debug, Default)]
pub(crate) struct StepBuffers {
    /// X^(k−1), X^(k), X^(k+1) of the outer iteration (m). `current` receives the prediction
    /// s at the start of a step; `next` also serves the reordering and XSPH as scratch.
    previous: Vec<Vec3>,
    current: Vec<Vec3>,
    next: Vec<Vec3>,
    /// Right-hand side b of the global step (kg·m), for the solvers that are not one
    /// Jacobi sweep (the sweep's is formed a chunk at a time).
    rhs: Vec<Vec3>,
    /// Local-step results per constraint.
    projections: Vec<Projection>,
    /// Corrections P_{i,j} − X_j of multi-step projections (m).
    corrections: Corrections,
    order: Vec<u32>,
    table: CellTable,
    fluid_lists: NeighborLists,
    boundary_lists: NeighborLists,
    /// The projection weight w_j of every fluid particle.
    weights: Vec<f64>,
    system: DiagonalSystem,
    /// The volume m/ρ_j of every fluid particle after the step, for XSPH (m³).
    volumes: Vec<f64>,
    scratch_ids: Vec<u32>,
    /// δ_k of every outer iteration of the last step (m).
    pub(crate) displacements: Vec<f64>,
}

impl World {
    /// Takes one step with the CFL-limited step size.
    pub fn step(&mut self) -> Result<&StepStats, Error> {
        self.step_with_dt(self.next_dt)
    }

    /// Takes one step of `dt` seconds (positive, finite). The CFL rule still sets the size
    /// the following [`World::step`] will use.
    pub fn step_with_dt(&mut self, dt: f64) -> Result<&StepStats, Error> {
        if !(dt.is_finite() && dt > 0.0 && dt <= 1.0) {
            return Err(Error::invalid(
                "dt",
                dt,
                "must be a positive finite number of seconds (at most 1)",
            ));
        }
        if self.fluid_count() == 0 {
            return Err(Error::invalid(
                "fluid particles",
                0,
                "must be present before stepping",
            ));
        }
        let stats = self.advance_one(dt);
        self.time += dt;
        self.steps += 1;
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

    fn advance_one(&mut self, dt: f64) -> StepStats {
        let started = Instant::now();
        let gravity = Vec3::from(self.params.gravity);
        let mut buffers = std::mem::take(&mut self.buffers);
        // 1. Inertial prediction s = x + Δt v + Δt² g, into the buffer of X^(k) (it is
        // X^(0)); the search keeps a copy by component, which serves where s is read later.
        let fluid = &self.fluid;
        self.pool.install(|| {
            buffers.current.resize(fluid.positions.len(), Vec3::zeros());
            buffers
                .current
                .par_iter_mut()
                .zip(fluid.positions.par_iter().zip(fluid.velocities.par_iter()))
                .for_each(|(s, (x, v))| *s = x + v * dt + gravity * (dt * dt));
        });
        // 2. Sort into Z-order; the sort's pass also tells whether the grid still covers s.
        self.prepare_grid(&buffers.current, false);
        let sort = |world: &World, b: &mut StepBuffers| {
            let grid = world.grid.as_ref().expect("prepare_grid builds the grid");
            world
                .pool
                .install(|| grid.sort(&b.current, &mut b.order, &mut b.table))
        };
        if !sort(self, &mut buffers) && !self.grid_capped {
            self.prepare_grid(&buffers.current, true);
            sort(self, &mut buffers);
        }
        let mut timings = StepTimings::default();
        let World {
            params,
            constraint,
            pool,
            fluid,
            boundary,
            grid,
            solver,
            chebyshev,
            ..
        } = self;
        let grid = grid.as_ref().expect("prepare_grid builds the grid");
        let stats = pool.install(|| {
            let b = &mut buffers;
            // Reorder all per-particle arrays, then search on s.
            permute(&b.order, &mut fluid.positions, &mut b.next);
            permute(&b.order, &mut fluid.velocities, &mut b.next);
            permute(&b.order, &mut b.current, &mut b.next);
            permute(&b.order, &mut fluid.ids, &mut b.scratch_ids);
            let h = params.support_radius();
            grid.search(
                &b.table,
                &b.current,
                &b.current,
                h,
                true,
                &mut b.fluid_lists,
            );
            grid.search_in(
                &boundary.table,
                &boundary.by_component,
                &b.current,
                h,
                false,
                &mut b.boundary_lists,
            );
            timings.neighbors = started.elapsed().as_secs_f64();

            // 3. The system matrix of formulation F1, frozen for the step.
            let mass = constraint.mass;
            let dt2k = dt * dt * params.stiffness;
            let lists = &b.fluid_lists;
            b.system.diagonal.resize(lists.len(), 0.0);
            b.system
                .diagonal
                .par_iter_mut()
                .enumerate()
                .for_each(|(j, a)| *a = mass + dt2k * constraint.membership(lists, j));
            solver.prepare(&b.system);

            // 4. Outer local/global iterations from X^(0) = X^(−1) = s.
            b.previous.clone_from(&b.current);
            b.next.resize(b.current.len(), Vec3::zeros());
            constraint.weights(&b.fluid_lists, &mut b.weights);
            let nb = Neighborhood {
                fluid: &b.fluid_lists,
                boundary: &b.boundary_lists,
                boundary_positions: &boundary.positions,
                boundary_psi: &boundary.psi,
                weights: &b.weights,
            };
            chebyshev.reset();
            let accelerate = params.solver == SolverKind::Chebyshev;
            let single_sweep = solver.single_diagonal_sweep();
            let (mut outer, mut inner, mut displacement) = (0, 0, f64::INFINITY);
            b.displacements.clear();
            while outer < params.max_outer_iterations {
                let t = Instant::now();
                constraint.project(&b.current, &nb, &mut b.projections, &mut b.corrections);
                let t_local = t.elapsed().as_secs_f64();
                let (projections, corrections) = (&b.projections, &b.corrections);
                let (current, predicted) = (&b.current, b.fluid_lists.searched_points());
                // b_j = m s_j + Δt²k Σ_{i: j∈N̄_i} P_{i,j}, with P_{i,j} = X_j + correction,
                // for the particles of chunk `chunk`.
                let fill_rhs = |chunk: usize, rhs: &mut [Vec3]| {
                    let first = chunk * CHUNK;
                    constraint.gathered_corrections(
                        first,
                        current,
                        &nb,
                        projections,
                        corrections,
                        rhs,
                    );
                    for (j, rhs) in (first..).zip(rhs) {
                        let members = constraint.membership(lists, j);
                        *rhs = predicted.at(j) * mass + (current[j] * members + *rhs) * dt2k;
                    }
                };
                if single_sweep {
                    let omega = if accelerate {
                        chebyshev.next_weight(outer)
                    } else {
                        1.0
                    };
                    let sweep = Sweep {
                        diagonal: &b.system.diagonal,
                        current,
                        previous: &b.previous,
                        chebyshev: (accelerate && chebyshev.changes(omega))
                            .then_some((&*chebyshev, omega)),
                    };
                    // The right-hand side lives only as long as its chunk's sweep.
                    displacement = b
                        .next
                        .par_chunks_mut(CHUNK)
                        .enumerate()
                        .map(|(chunk, next)| {
                            let mut rhs = [Vec3::zeros(); CHUNK];
                            let rhs = &mut rhs[..next.len()];
                            fill_rhs(chunk, rhs);
                            sweep.apply(chunk * CHUNK, rhs, next)
                        })
                        .reduce(|| f64::NEG_INFINITY, reduce::nan_max);
                    inner += 1;
                } else {
                    b.rhs.resize(b.current.len(), Vec3::zeros());
                    b.rhs
                        .par_chunks_mut(CHUNK)
                        .enumerate()
                        .for_each(|(chunk, rhs)| fill_rhs(chunk, rhs));
                    b.next.copy_from_slice(&b.current);
                    inner += solver.solve(&b.system, &b.rhs, &mut b.next);
                    if accelerate {
                        let omega = chebyshev.next_weight(outer);
                        chebyshev.extrapolate(omega, &mut b.next, &b.current, &b.previous);
                    }
                    displacement = max_distance(&b.next, &b.current);
                }
                b.displacements.push(displacement);

                // Rotate: X^(k−1) ← X^(k) ← X^(k+1).
                std::mem::swap(&mut b.previous, &mut b.current);
                std::mem::swap(&mut b.current, &mut b.next);
                outer += 1;
                timings.local += t_local;
                timings.global += t.elapsed().as_secs_f64() - t_local;
                if outer >= params.min_outer_iterations
                    && displacement < params.displacement_tolerance
                {
                    break;
                }
            }

            let rho = if accelerate { chebyshev.rho() } else { 0.0 };
            if accelerate {
                chebyshev.finish_step(&b.displacements);
            }
            // 5. Velocity update v = (x^{n+1} − x^n)/Δt, then the new positions.
            let t = Instant::now();
            fluid
                .velocities
                .par_iter_mut()
                .zip(b.current.par_iter().zip(fluid.positions.par_iter()))
                .for_each(|(v, (new, old))| *v = (new - old) / dt);
            std::mem::swap(&mut fluid.positions, &mut b.current);

            // 6. Densities at the new positions (step's neighbour lists), 7. XSPH.
            constraint.densities(&fluid.positions, &nb, &mut fluid.densities);
            if params.viscosity > 0.0 {
                let buffers = (&mut b.volumes, &mut b.next);
                xsph(params.viscosity, constraint, &nb, fluid, buffers);
            }
            let rest = constraint.rest_density;
            let errors = |rho: &f64| (rho / rest - 1.0).max(0.0);
            let n = fluid.densities.len() as f64;
            let density_error_avg = reduce::sum(&fluid.densities, errors) / n;
            let density_error_max = reduce::max(&fluid.densities, errors);
            timings.rest = t.elapsed().as_secs_f64();
            StepStats {
                dt,
                outer_iterations: outer,
                inner_iterations: inner,
                hit_max_iterations: displacement >= params.displacement_tolerance,
                rho,
                last_displacement: displacement,
                density_error_avg,
                density_error_max,
                timings,
            }
        });
        // 8. CFL: Δt = λ·0.4·2r / max|v + Δt g|, clamped.
        let v_max = self.pool.install(|| {
            reduce::max(&self.fluid.velocities, |v| {
                (v + gravity * dt).norm_squared()
            })
        });
        let v_max = v_max.max(1e-9).sqrt();
        let p = &self.params;
        let cfl = p.cfl_factor * 0.4 * p.spacing() / v_max;
        self.next_dt = if cfl.is_finite() {
            cfl.clamp(p.dt_min, p.dt_max)
        } else {
            p.dt_min
        };
        self.buffers = buffers;
        stats
    }
}

/// Reorders `data` so that slot k holds the old `data[order[k]]`.
fn permute<T: Copy + Send + Sync + Default>(
    order: &[u32],
    data: &mut Vec<T>,
    scratch: &mut Vec<T>,
) {
    scratch.resize(data.len(), T::default());
    scratch
        .par_iter_mut()
        .zip(order.par_iter())
        .for_each(|(s, &o)| *s = data[o as usize]);
    std::mem::swap(data, scratch);
}

/// The global step of a solver that is one Jacobi sweep on the diagonal system, fused with
/// Chebyshev's extrapolation and the displacement, for the particles of one chunk.
struct Sweep<'a> {
    /// Â_jj (kg).
    diagonal: &'a [f64],
    /// X^(k) and X^(k−1) (m).
    current: &'a [Vec3],
    previous: &'a [Vec3],
    /// The recurrence and its weight ω, when the extrapolation changes the iterate.
    chebyshev: Option<(&'a Chebyshev, f64)>,
}

impl Sweep<'_> {
    /// Writes X^(k+1)_j for the particles `first..` of the right-hand sides `rhs` (kg·m) into
    /// `next` (m): the sweep X_j + (b_j − Â_jj·X_j)/Â_jj, bitwise as [`crate::solver::Jacobi`]
    /// computes it, then extrapolated. Returns max_j |X^(k+1)_j − X^(k)_j| (m) over the chunk.
    fn apply(&self, first: usize, rhs: &[Vec3], next: &mut [Vec3]) -> f64 {
        let mut largest = f64::NEG_INFINITY;
        for (j, (b, next)) in (first..).zip(rhs.iter().zip(next)) {
            let (x, d) = (self.current[j], self.diagonal[j]);
            let mut plain = x + (b - x * d) / d;
            if let Some((chebyshev, omega)) = self.chebyshev {
                plain = chebyshev.extrapolated(omega, plain, x, self.previous[j]);
            }
            *next = plain;
            largest = reduce::nan_max(largest, (plain - x).norm());
        }
        largest
    }
}

/// max_i |a_i − b_i| (m).
fn max_distance(a: &[Vec3], b: &[Vec3]) -> f64 {
    reduce::max_over(a.len(), |i| (a[i] - b[i]).norm())
}

/// XSPH filter v_i ← v_i + c Σ_j (m/ρ_j)(v_j − v_i) W_ij (docs/method.md §1.3), with the
/// buffers for the volumes m/ρ_j and the new velocities.
fn xsph(
    c: f64,
    constraint: &crate::constraint::DensityConstraint,
    nb: &Neighborhood,
    fluid: &mut crate::world::Fluid,
    (volumes, scratch): (&mut Vec<f64>, &mut Vec<Vec3>),
) {
    let mass = constraint.mass;
    volumes.clear();
    volumes.par_extend(fluid.densities.par_iter().map(|rho| mass / rho));
    let state = (&fluid.positions[..], &fluid.velocities[..], &volumes[..]);
    scratch.resize(fluid.velocities.len(), Vec3::zeros());
    scratch
        .par_iter_mut()
        .enumerate()
        .for_each(|(i, out)| *out = constraint.xsph_velocity(c, i, state, nb));
    std::mem::swap(&mut fluid.velocities, scratch);
}

#[cfg(test)]
mod tests {
    use crate::boundary::Aabb;
    use crate::solver::{GlobalSolver, Jacobi, SystemMatrix};
    use crate::{Params, Vec3, World};

    fn small_dam_break() -> World {
        small_dam_break_with(Params::default())
    }

    fn small_dam_break_with(params: Params) -> World {
        let mut world = World::new(params).unwrap();
        let container = Aabb {
            min: Vec3::repeat(-0.00625),
            max: Vec3::new(1.00625, 0.80625, 0.40625),
        };
        world.add_container(container, 1).unwrap();
        world
            .add_fluid_block(Vec3::repeat(0.05), [8, 12, 6], Vec3::zeros())
            .unwrap();
        world
    }

    /// The single-step shortcut (λ only, gradients recomputed in the gather) must give the
    /// same trajectory as writing every projection's corrections out.
    #[test]
    fn single_step_shortcut_matches_written_corrections() {
        let mut shortcut = small_dam_break();
        let mut reference = small_dam_break();
        reference.constraint.materialize_all = true;
        let mut active = 0;
        // 25 steps: later, round-off differences grow exponentially in the splashing flow.
        for _ in 0..25 {
            let a = shortcut.step().unwrap().outer_iterations;
            let b = reference.step().unwrap().outer_iterations;
            assert_eq!(a, b);
            active += a;
        }
        assert!(
            active > 60,
            "the scene must exercise the constraint ({active} iterations)"
        );
        for (a, b) in shortcut.positions().iter().zip(reference.positions()) {
            assert!((a - b).norm() <= 1e-12, "{a:?} vs {b:?}");
        }
        assert!(shortcut.last_step().unwrap().density_error_max > 0.0);
    }

    /// Steps the small dam break twice for 25 steps, once as is and once changed by
    /// `variant`, and asserts the two trajectories are bitwise the same.
    fn steps_bitwise_alike(variant: impl FnOnce(&mut World)) {
        let mut plain = small_dam_break();
        let mut changed = small_dam_break();
        variant(&mut changed);
        for _ in 0..25 {
            let a = plain.step().unwrap().outer_iterations;
            let b = changed.step().unwrap().outer_iterations;
            assert_eq!(a, b);
        }
        assert!(plain.last_step().unwrap().density_error_max > 0.0);
        assert!(plain.positions() == changed.positions());
        assert!(plain.velocities() == changed.velocities());
    }

    /// The AVX2 builds of the projection, the gather, the densities and the XSPH filter do
    /// the same IEEE operations in the same order as the portable ones, so the two give
    /// bitwise the same trajectory. (On a processor without AVX2 both worlds take the
    /// portable path.)
    #[test]
    fn avx2_builds_match_the_portable_ones() {
        steps_bitwise_alike(|w| w.constraint.portable = true);
    }

    /// Predicted positions that leave the grid make the step rebuild it around them before
    /// the search (read from the sort's pass), so every step's grid covers its prediction.
    #[test]
    fn grid_follows_particles_that_leave_it() {
        let mut world = World::new(Params::default()).unwrap();
        let velocity = Vec3::new(30.0, 0.0, 0.0);
        world
            .add_fluid_block(Vec3::zeros(), [2, 2, 2], velocity)
            .unwrap();
        let mut first = None;
        for _ in 0..40 {
            world.step().unwrap();
            let grid = world.grid.as_ref().unwrap();
            let s = world.buffers.fluid_lists.searched_points();
            let s: Vec<Vec3> = (0..s.len()).map(|i| s.at(i)).collect();
            assert!(grid.covers(&s));
            first.get_or_insert(grid.parts());
        }
        let x = world.positions()[0].x;
        assert!(
            x > 0.3,
            "the block must outrun its first grid (at x = {x} m)"
        );
        assert_ne!(world.grid.as_ref().map(|g| g.parts()), first);
    }

    /// A single Jacobi sweep that does not say so ([`GlobalSolver::single_diagonal_sweep`]
    /// false), so that the step computes the right-hand side, the solve, the extrapolation
    /// and the displacement in separate passes.
    struct SeparateSweep(Jacobi);

    impl GlobalSolver for SeparateSweep {
        fn solve(&mut self, matrix: &dyn SystemMatrix, b: &[Vec3], x: &mut [Vec3]) -> usize {
            self.0.solve(matrix, b, x)
        }
    }

    /// The fused pass of a single-sweep solver (Chebyshev here) must give the trajectory of
    /// the separate passes, bit for bit.
    #[test]
    fn fused_sweep_matches_separate_passes() {
        steps_bitwise_alike(|w| w.solver = Box::new(SeparateSweep(Jacobi::single_sweep())));
    }

    /// Skipping the density evaluation after a first projection step that the Taylor bound
    /// shows relaxing ends the projection exactly where the evaluation would: the
    /// trajectories are bitwise the same.
    #[test]
    fn first_step_bound_changes_no_bit() {
        steps_bitwise_alike(|w| w.constraint.evaluate_first_step = true);
    }

    /// With unit weights the active projections take several steps and keep their
    /// corrections, the inactive ones do not: the compact segments of the ones kept must be
    /// found by the gather exactly as when every projection keeps its corrections.
    #[test]
    fn kept_corrections_of_some_projections_match_keeping_them_all() {
        let params = Params {
            projection_weight: crate::ProjectionWeight::Unit,
            ..Params::default()
        };
        let mut compact = small_dam_break_with(params.clone());
        let mut reference = small_dam_break_with(params);
        reference.constraint.materialize_all = true;
        let (n, mut mixed) = (compact.fluid_count(), 0);
        for _ in 0..25 {
            let a = compact.step().unwrap().outer_iterations;
            let b = reference.step().unwrap().outer_iterations;
            assert_eq!(a, b);
            let kept = compact.buffers.corrections.kept();
            mixed += usize::from(kept > 0 && kept < n);
        }
        assert!(
            mixed > 0,
            "no step had some, but not all, projections keep corrections"
        );
        for (a, b) in compact.positions().iter().zip(reference.positions()) {
            assert!((a - b).norm() <= 1e-12, "{a:?} vs {b:?}");
        }
    }

    /// Relaxation steps exactly as [`World::advance`] does and then scales every velocity by
    /// exp(−damping·Δt): a plain world stepped over the same step sizes, its velocities
    /// scaled by hand after each step, ends bitwise the same; damping 0 is bitwise
    /// [`World::advance`].
    #[test]
    fn relax_scales_the_velocities_of_each_step() {
        let (seconds, damping) = (0.02, 4.0);
        let mut relaxed = small_dam_break();
        let steps = relaxed.relax(seconds, damping).unwrap();
        let mut by_hand = small_dam_break();
        let mut count = 0;
        while seconds - by_hand.time() > 1e-12 {
            let dt = by_hand.next_dt().min(seconds - by_hand.time());
            by_hand.step_with_dt(dt).unwrap();
            let factor = (-damping * dt).exp();
            let damped: Vec<Vec3> = by_hand.velocities().iter().map(|v| v * factor).collect();
            by_hand.set_velocities(&damped).unwrap();
            count += 1;
        }
        assert!(steps > 3 && steps == count);
        assert!(relaxed.positions() == by_hand.positions());
        assert!(relaxed.velocities() == by_hand.velocities());
        let mut advanced = small_dam_break();
        let mut undamped = small_dam_break();
        assert_eq!(
            advanced.advance(seconds).unwrap(),
            undamped.relax(seconds, 0.0).unwrap()
        );
        assert!(advanced.positions() == undamped.positions());
        assert!(advanced.velocities() == undamped.velocities());
        assert!(advanced.velocities() != relaxed.velocities());
    }

    /// A negative, infinite or NaN duration or damping rate is rejected, naming the argument,
    /// and no step is taken.
    #[test]
    fn relax_rejects_bad_arguments_unchanged() {
        let mut world = small_dam_break();
        for (seconds, damping, field) in [
            (-1.0, 1.0, "seconds"),
            (f64::NAN, 1.0, "seconds"),
            (0.1, -1.0, "damping"),
            (0.1, f64::INFINITY, "damping"),
            (0.1, f64::NAN, "damping"),
        ] {
            let message = world.relax(seconds, damping).unwrap_err().to_string();
            assert!(message.contains(field), "{message}");
            assert_eq!(world.steps(), 0);
        }
    }

    /// `advance_with` takes the steps `advance` takes, shows every one to its callback, and
    /// stops at the first error the callback returns, returning it.
    #[test]
    fn advance_with_sees_every_step_and_stops_on_error() {
        let mut advanced = small_dam_break();
        let mut observed = small_dam_break();
        let steps = advanced.advance(0.02).unwrap();
        let mut seen = Vec::new();
        let count = observed
            .advance_with(0.02, |w| {
                seen.push(w.steps());
                Ok(())
            })
            .unwrap();
        assert_eq!(count, steps);
        assert_eq!(seen, (1..=steps as u64).collect::<Vec<_>>());
        assert!(advanced.positions() == observed.positions());
        let mut stopped = small_dam_break();
        let error = stopped
            .advance_with(0.02, |w| {
                if w.steps() == 2 {
                    Err(crate::Error::invalid("probe", 2, "stops the run"))
                } else {
                    Ok(())
                }
            })
            .unwrap_err();
        assert!(error.to_string().contains("probe"));
        assert_eq!(stopped.steps(), 2);
    }
}
