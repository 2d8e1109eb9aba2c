use super::*;
use crate::boundary::Aabb;

/// Twelve particles in a half-metre box, at the default parameters.
fn tiny_world() -> World {
    let mut world = World::new(Params::default()).unwrap();
    let container = Aabb {
        min: Vec3::zeros(),
        max: Vec3::repeat(0.5),
    };
    world.add_container(container, 1).unwrap();
    world
        .add_fluid_block(Vec3::repeat(0.1), [3, 2, 2], Vec3::zeros())
        .unwrap();
    world
}

/// Velocities set in insertion order come back in insertion order after the particles
/// were re-sorted by a step; bad input changes nothing.
#[test]
fn set_velocities_uses_insertion_order_and_rejects_bad_input() {
    let mut world = tiny_world();
    world.step().unwrap();
    let wanted: Vec<Vec3> = (0..12).map(|i| Vec3::new(i as f64, 0.5, -1.0)).collect();
    world.set_velocities(&wanted).unwrap();
    assert_eq!(world.velocities(), wanted);
    assert!(world.set_velocities(&wanted[..11]).is_err());
    let mut bad = wanted.clone();
    bad[3].y = f64::NAN;
    assert!(world.set_velocities(&bad).is_err());
    assert_eq!(world.velocities(), wanted);
}

/// The time step, driven through the world.
mod step {
    use crate::boundary::Aabb;
    use crate::solver::{GlobalSolver, Jacobi, SystemMatrix};
    use crate::{Params, Vec3, World};

    fn small_dam_break() -> World {
        small_dam_break_with(Params::default())
    }

    fn small_dam_break_with(params: Params) -> World {
        block_in_box(params, Vec3::new(1.00625, 0.80625, 0.40625), [8, 12, 6])
    }

    /// Takes a step and checks that a stopping rule ended it: the fluid's average
    /// compression at most η, or its last displacement under τ, before K_max.
    fn step_within_rules(world: &mut World, what: &str) -> crate::stats::StepStats {
        let (eta, tau) = (
            world.params().density_tolerance,
            world.params().displacement_tolerance,
        );
        let s = world.step().unwrap().clone();
        assert!(!s.hit_max_iterations, "{what}: {s:?}");
        assert!(
            s.density_error_avg <= eta || s.last_displacement < tau,
            "{what}: {s:?}"
        );
        s
    }

    /// Steps a collapsing column until `seconds`, every step within the stopping rules and the
    /// energy never above its start, and returns the outer iterations taken and the surge's
    /// mean horizontal speed (m/s) at the end.
    fn collapse(mut world: World, seconds: f64, what: &str) -> (usize, f64) {
        let energy = |w: &World| w.kinetic_energy() + w.potential_energy();
        let (initial, mut highest, mut outer) = (energy(&world), f64::MIN, 0);
        while world.time() < seconds {
            let s = step_within_rules(&mut world, what);
            outer += s.outer_iterations;
            highest = highest.max(energy(&world));
        }
        assert!(highest <= initial, "{what}: {highest} J from {initial} J");
        let v = world.velocities();
        let surge = v.iter().map(|v| v.x).sum::<f64>() / v.len() as f64;
        (outer, surge)
    }

    /// A block of `count` particles from (0.05, 0.05, 0.05) m in a container from
    /// −r/4 to `max` (m).
    fn block_in_box(params: Params, max: Vec3, count: [usize; 3]) -> World {
        let mut world = World::new(params).unwrap();
        let container = Aabb {
            min: Vec3::repeat(-0.00625),
            max,
        };
        world.add_container(container, 1).unwrap();
        world
            .add_fluid_block(Vec3::repeat(0.05), count, Vec3::zeros())
            .unwrap();
        world
    }

    /// The single-step shortcut (λ only, gradients recomputed in the gather) must give the
    /// same trajectory as writing every projection's corrections out.
    #[test]
    fn single_step_shortcut_matches_written_corrections() {
        // The displacement rule alone: its longer steps exercise more projections.
        let params = Params {
            density_tolerance: 0.0,
            ..Params::default()
        };
        let mut shortcut = small_dam_break_with(params.clone());
        let mut reference = small_dam_break_with(params);
        reference.constraint.materialize_all = true;
        let (mut active, mut compressed) = (0, 0.0f64);
        // 10 steps: later, round-off differences grow exponentially in the splashing flow.
        for _ in 0..10 {
            let a = shortcut.step().unwrap().outer_iterations;
            compressed = compressed.max(shortcut.last_step().unwrap().density_error_max);
            let b = reference.step().unwrap().outer_iterations;
            assert_eq!(a, b);
            active += a;
        }
        assert!(
            active > 30,
            "the scene must exercise the constraint ({active} iterations)"
        );
        for (a, b) in shortcut.positions().iter().zip(reference.positions()) {
            // Round-off differences grow fast in the splashing flow; a wrong gather would
            // differ by more than a micrometre.
            assert!((a - b).norm() <= 1e-9, "{a:?} vs {b:?}");
        }
        assert!(compressed > 0.0);
    }

    /// With a τ small enough that the displacement rule seldom decides (the density rule
    /// waits for motions below 10τ), every step ends with
    /// the fluid's average compression at most η (or by τ), a tighter η costs more outer
    /// iterations for a smaller error, and the rule binds: some steps end just under η.
    #[test]
    fn density_rule_bounds_the_average_compression() {
        let tau = 1e-4;
        let run = |eta: f64| {
            let mut world = small_dam_break_with(Params {
                density_tolerance: eta,
                displacement_tolerance: tau,
                ..Params::default()
            });
            let (mut outer, mut worst, mut binding) = (0, 0.0f64, 0);
            for _ in 0..40 {
                let s = step_within_rules(&mut world, &format!("η {eta}"));
                outer += s.outer_iterations;
                worst = worst.max(s.density_error_avg);
                binding += usize::from(s.density_error_avg > 0.5 * eta);
            }
            (outer, worst, binding)
        };
        let (loose_outer, loose_worst, loose_binding) = run(5e-4);
        let (tight_outer, tight_worst, tight_binding) = run(1e-4);
        assert!(
            loose_binding > 5 && tight_binding > 5,
            "{loose_binding}, {tight_binding}"
        );
        assert!(tight_worst < loose_worst, "{tight_worst} vs {loose_worst}");
        assert!(
            tight_outer as f64 > 1.1 * loose_outer as f64,
            "{tight_outer} vs {loose_outer} outer iterations"
        );
    }

    /// The warm start (docs/method.md §4.1) spares a tall collapsing column some of the
    /// outer iterations that lift it off the floor anew in every step, the more the larger
    /// its share, and what it saves is not bought with the density error, the energy or the
    /// flow: every step still ends at most η compressed (or by τ), the energy never rises
    /// above its start, and the surge's mean horizontal speed at 0.5 s stays within 4 % of
    /// its speed without the start (1.7 % and 3.2 % short at f = 0.45 and 0.8). Without the
    /// withdrawal of the start where the fluid turns under-dense it fell short by 7 and 15 %.
    #[test]
    fn the_warm_start_spares_the_column_its_lift() {
        let run = |share: f64| {
            let params = Params {
                warm_start: share,
                coarse_correction: false,
                ..Params::default()
            };
            // A column 30 particles tall, which a step lifts off the floor through 15
            // support radii.
            let top = Vec3::new(1.00625, 1.80625, 0.25625);
            let world = block_in_box(params, top, [6, 30, 4]);
            collapse(world, 0.5, &format!("f {share}"))
        };
        let (cold, warm, warmer) = (run(0.0), run(0.45), run(0.8));
        assert!(
            (warm.0 as f64) < 0.97 * cold.0 as f64 && warmer.0 < warm.0,
            "{cold:?}, {warm:?} and {warmer:?} (outer iterations, surge m/s) at f = 0, 0.45 and 0.8"
        );
        for (share, (_, surge)) in [(0.45, warm), (0.8, warmer)] {
            assert!(
                (surge / cold.1 - 1.0).abs() < 0.04,
                "surge {surge} m/s at f = {share} against {} m/s without the start",
                cold.1
            );
        }
    }

    /// The coarse correction (docs/method.md §3.8) holds a deep column up in a few outer
    /// iterations where the local and global steps alone carry its weight up one support
    /// radius per iteration: on a collapsing column 60 particles (30 support radii) tall it
    /// takes at most 60 % of the outer iterations over the first 0.4 s (56 %, measured),
    /// while every step still ends within the stopping rules, the energy never rises above
    /// its start, and the surge's mean horizontal speed at 0.4 s stays within 4 % of the
    /// speed without it (2.3 % lower, measured).
    #[test]
    fn the_coarse_correction_carries_a_deep_column() {
        let run = |coarse: bool| {
            let params = Params {
                coarse_correction: coarse,
                ..Params::default()
            };
            let top = Vec3::new(1.50625, 3.50625, 0.45625);
            let world = block_in_box(params, top, [16, 60, 8]);
            collapse(world, 0.4, &format!("coarse {coarse}"))
        };
        let (fine, coarse) = (run(false), run(true));
        assert!(
            (coarse.0 as f64) <= 0.60 * fine.0 as f64,
            "{coarse:?} with and {fine:?} without the correction (outer iterations, surge m/s)"
        );
        assert!(
            (coarse.1 / fine.1 - 1.0).abs() < 0.04,
            "surge {} m/s with the correction against {} m/s without",
            coarse.1,
            fine.1
        );
    }

    /// The constraints are a penalty, so a column holds up its weight only by staying
    /// compressed, in proportion to m|g|/k (docs/method.md §3.2). At the default k a resting
    /// column 64 particles (3.2 m) tall settles where that compression exceeds η: from 0.2 s
    /// on every step runs to the iteration limit (and its fallback's) and ends above η
    /// (0.077 %, measured). At k = 10⁶ N/m the same steps end by the stopping rules, within η,
    /// in a fraction of the iterations (about 29 a step over 2 s, measured).
    #[test]
    fn a_stiffer_k_holds_deep_water_within_eta() {
        let run = |stiffness: f64| {
            let params = Params {
                stiffness,
                ..Params::default()
            };
            let top = Vec3::new(0.45625, 3.5, 0.45625);
            let mut world = block_in_box(params, top, [8, 64, 8]);
            let (mut outer, mut steps, mut limited, mut above) = (0, 0, 0, 0);
            let eta = world.params().density_tolerance;
            while world.time() < 0.3 {
                let s = world.step().unwrap().clone();
                if world.time() > 0.2 {
                    outer += s.outer_iterations;
                    steps += 1;
                    limited += usize::from(s.hit_max_iterations);
                    above += usize::from(s.density_error_avg > eta);
                }
            }
            (outer as f64 / steps as f64, steps, limited, above)
        };
        let (soft, stiff) = (run(5e4), run(1e6));
        assert!(
            soft.2 == soft.1 && soft.3 == soft.1,
            "k = 5e4: {soft:?} (outer iterations per step, steps, at the limit, above eta)"
        );
        assert!(
            stiff.2 == 0 && stiff.3 == 0 && stiff.0 < 0.25 * soft.0,
            "k = 1e6: {stiff:?} against {soft:?} at k = 5e4"
        );
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
        let gravity = Vec3::from(world.params().gravity);
        for _ in 0..40 {
            // The prediction s = x + Δt v + Δt² g the step will search.
            let dt = world.next_dt();
            let s: Vec<Vec3> = (world.fluid.positions.iter().zip(&world.fluid.velocities))
                .map(|(x, v)| x + v * dt + gravity * (dt * dt))
                .collect();
            world.step().unwrap();
            let grid = world.grid.grid.as_ref().unwrap();
            assert!(grid.covers(&s));
            first.get_or_insert(grid.parts());
        }
        let x = world.positions()[0].x;
        assert!(
            x > 0.3,
            "the block must outrun its first grid (at x = {x} m)"
        );
        assert_ne!(world.grid.grid.as_ref().map(|g| g.parts()), first);
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
            // Round-off differences grow fast in the splashing flow; a wrong gather would
            // differ by more than a micrometre.
            assert!((a - b).norm() <= 1e-9, "{a:?} vs {b:?}");
        }
    }

    /// A step whose local step cannot have the memory for the corrections it keeps (refused
    /// by the test's limit on their segments, as a shortage of memory would refuse them)
    /// fails after its searches, in its iteration, and changes nothing: not the particles or
    /// their order, the grid, the boundary, nor the last step's displacements. With the
    /// memory back it steps on bit for bit as a world that never failed.
    #[test]
    fn a_step_that_cannot_keep_its_corrections_changes_nothing() {
        // Stepped until some constraints are active, whose projections keep corrections.
        let build = || {
            let mut world = small_dam_break();
            world.constraint.materialize_all = true;
            while world.buffers.corrections.kept() == 0 {
                assert!(world.steps() < 50, "no constraint became active");
                world.step().unwrap();
            }
            world
        };
        let everything = |world: &World| {
            let displacements = world.last_displacements().to_vec();
            let boundary = world.boundary_positions().to_vec();
            (fingerprint(world), boundary, displacements)
        };
        let mut world = build();
        let before = everything(&world);
        assert!(!before.2.is_empty());
        world.buffers.corrections.segment_limit = Some(0);
        let error = world.step().map(|_| ()).unwrap_err();
        assert!(matches!(error, crate::Error::OutOfMemory(_)), "{error}");
        assert!(everything(&world) == before);
        world.buffers.corrections.segment_limit = None;
        let mut twin = build();
        for _ in 0..2 {
            world.step().unwrap();
            twin.step().unwrap();
            assert!(everything(&world) == everything(&twin));
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

    /// The exact state of a world, compared bit for bit before and after a rejected call.
    fn fingerprint(world: &World) -> (crate::WorldState, String) {
        (world.export_state(), world.positions_hash())
    }

    /// A duration between 0 and dt_min is rejected naming dt_min, as is one the clock cannot
    /// resolve; dt_min itself steps and moves the clock by exactly it (from t = 0).
    #[test]
    fn durations_below_dt_min_are_rejected_unchanged() {
        let mut world = small_dam_break();
        let before = fingerprint(&world);
        for seconds in [
            1e-13,
            1e-300,
            f64::MIN_POSITIVE,
            0.5 * world.params().dt_min,
        ] {
            let message = world.advance(seconds).unwrap_err().to_string();
            assert!(message.contains("at least dt_min"), "{message}");
            let message = world.relax(seconds, 1.0).unwrap_err().to_string();
            assert!(message.contains("at least dt_min"), "{message}");
            assert!(fingerprint(&world) == before, "{seconds} changed the world");
        }
        assert_eq!(world.advance(0.0).unwrap(), 0);
        let dt_min = world.params().dt_min;
        assert_eq!(world.advance(dt_min).unwrap(), 1);
        assert_eq!(world.time(), dt_min);
        // Far into a run (or for an absurd span) the clock resolves less than dt_min.
        let mut late = small_dam_break();
        let message = late.advance(1e300).unwrap_err().to_string();
        assert!(message.contains("no longer resolves dt_min"), "{message}");
        late.time = 1e9;
        let message = late.advance(dt_min).unwrap_err().to_string();
        assert!(message.contains("no longer resolves dt_min"), "{message}");
        assert_eq!(late.steps(), 0);
        let message = late.step_with_dt(1e-9).unwrap_err().to_string();
        assert!(message.contains("too short to move the clock"), "{message}");
    }

    /// Parameters that validate can be stepped: time steps above MAX_STEP are refused by
    /// validation and by an explicit step alike, with the same rule.
    #[test]
    fn step_sizes_follow_one_rule_in_validation_and_stepping() {
        use crate::params::MAX_STEP;
        for field in ["dt_min", "dt_max", "dt_initial"] {
            let mut params = Params {
                dt_min: 1e-4,
                dt_max: MAX_STEP,
                dt_initial: MAX_STEP,
                ..Params::default()
            };
            params.validate().unwrap();
            let too_long = 1.5 * MAX_STEP;
            match field {
                "dt_min" => params.dt_min = too_long,
                "dt_max" => params.dt_max = too_long,
                _ => params.dt_initial = too_long,
            }
            let message = World::new(params).err().unwrap().to_string();
            assert!(
                message.contains(field) && message.contains("at most 1"),
                "{message}"
            );
        }
        // Without gravity the weight does not bound the first step (docs/method.md §8).
        let mut world = small_dam_break_with(Params {
            dt_max: MAX_STEP,
            dt_initial: MAX_STEP,
            gravity: [0.0; 3],
            ..Params::default()
        });
        assert_eq!(world.next_dt(), MAX_STEP);
        let message = world.step_with_dt(1.5 * MAX_STEP).unwrap_err().to_string();
        assert!(
            message.contains("dt") && message.contains("at most 1"),
            "{message}"
        );
        world.step().unwrap();
    }

    /// An advance whose emitters would exceed the particle limit part-way fails before its
    /// first step, leaving the world exactly as it was; a step alone still works.
    #[test]
    fn an_advance_that_would_fail_part_way_changes_nothing() {
        let mut world = small_dam_break();
        let spec = crate::EmitterSpec {
            shape: crate::EmitterShape::Disc { radius: 0.05 },
            position: Vec3::new(0.1, 0.3, 0.1),
            direction: Vec3::new(0.0, -1.0, 0.0),
            speed: 1e6,
            end_time: None,
        };
        world.add_emitter(spec).unwrap();
        let before = fingerprint(&world);
        let message = world.advance(1.0).unwrap_err().to_string();
        assert!(message.contains("particle limit"), "{message}");
        assert!(fingerprint(&world) == before);
        let message = world.relax(1.0, 4.0).unwrap_err().to_string();
        assert!(message.contains("particle limit"), "{message}");
        assert!(fingerprint(&world) == before);
        let fluid = world.fluid_count();
        world.step_with_dt(1e-4).unwrap();
        assert!(world.fluid_count() >= fluid);
    }
}

/// A pool of resting water, 10 × 4 × 18 particles, in a container 1.5 × 0.6 × 1.0 m, and a
/// `block` of spray at (1.2, 0.3, 0.45) m thrown at `velocity` (m/s), with `params` and the
/// `floor` asked for (the default [`MEMBERSHIP_FLOOR`](crate::constraint::MEMBERSHIP_FLOOR)
/// where `None`), run for 0.2 s: the largest density error at a step's end, the largest
/// speed after the first step (m/s), and whether every particle stayed in the container.
fn spray_on_a_wall(
    params: Params,
    floor: Option<f64>,
    block: [usize; 3],
    velocity: Vec3,
) -> (f64, f64, bool) {
    let mut world = World::new(params).unwrap();
    if let Some(floor) = floor {
        world.constraint.membership_floor = floor;
    }
    // The walls r/4 beyond one spacing from the pool, so that its corners do not start
    // compressed (docs/method.md §7).
    let container = Aabb {
        min: Vec3::repeat(-0.00625),
        max: Vec3::new(1.5, 0.6, 1.0),
    };
    world.add_container(container, 1).unwrap();
    world
        .add_fluid_block(Vec3::repeat(0.05), [10, 4, 18], Vec3::zeros())
        .unwrap();
    world
        .add_fluid_block(Vec3::new(1.2, 0.3, 0.45), block, velocity)
        .unwrap();
    let (mut worst, mut fastest) = (0.0f64, 0.0f64);
    while world.time() < 0.2 {
        worst = worst.max(world.step().unwrap().density_error_max);
        fastest = world
            .velocities()
            .iter()
            .map(|v| v.norm())
            .fold(fastest, f64::max);
    }
    let contained = world.positions().iter().all(|p| container.contains(p, 0.0));
    (worst, fastest, contained)
}

/// A spray particle that hits a wall alone, or with a few others, beside a pool of resting
/// water ends its steps hardly compressed: the membership floor keeps its constraint stiff
/// against its inertia (docs/method.md §3.1). Without the floor, at a soft k, the same drops end
/// steps compressed by several per cent, or go through the wall: the density rule bounds the average
/// over the pool and the spray together, which a few particles hardly move. The fine
/// iteration is measured alone: the coarse correction (docs/method.md §3.8) also pushes a lone
/// drop out of a wall, by up to 8|g|Δt² per correction.
#[test]
fn spray_hitting_a_wall_stays_nearly_incompressed() {
    let params = Params {
        coarse_correction: false,
        ..Params::default()
    };
    let soft = Params {
        stiffness: 5e4,
        ..params.clone()
    };
    // Without the floor, at k = 5·10⁴ N/m, a lone particle falling on the floor at 4–6 m/s
    // ends a step 2–5 % compressed (at 6 m/s and the default λ = 1.25 it goes through the
    // floor); a sideways hit and a small cluster stay below 1 % either way. At the default k
    // the drop without the floor ends only about 0.5 % compressed.
    let cases = [
        ([1, 1, 1], Vec3::new(0.0, -6.0, 0.0), true),
        ([1, 1, 1], Vec3::new(0.0, -4.0, 0.0), true),
        ([1, 1, 1], Vec3::new(3.0, -1.0, 0.0), false),
        ([2, 1, 2], Vec3::new(0.0, -6.0, 0.0), false),
    ];
    for (block, velocity, discriminates) in cases {
        for params in [&params, &soft] {
            let (stiff, _, contained) = spray_on_a_wall(params.clone(), None, block, velocity);
            let k = params.stiffness;
            assert!(
                contained,
                "k = {k}: {block:?} at {velocity:?} m/s: a particle escaped"
            );
            assert!(
                stiff <= 0.01,
                "k = {k}: {block:?} at {velocity:?} m/s: {stiff}"
            );
        }
        if discriminates {
            let (reference, _, contained) =
                spray_on_a_wall(soft.clone(), Some(1.0), block, velocity);
            assert!(
                reference >= 0.02 || !contained,
                "{block:?} at {velocity:?} m/s without the floor: {reference}, contained"
            );
        }
    }
}

/// A lone drop thrown onto a floor one particle layer thick at 6 m/s comes off it no faster
/// than it came (it reaches 6.4 m/s before the impact), at every k from 5·10⁴ to 5·10⁶ N/m:
/// the first Newton step of its projection is bounded (docs/method.md §2.5). Unbounded, a
/// particle driven onto a boundary particle's centre, where the kernel's gradient vanishes,
/// took a step of C/|∇C| and left the floor at 125–750 m/s from k = 2·10⁵ N/m up, through it
/// at 2·10⁵, 5·10⁵ and 5·10⁶.
#[test]
fn a_lone_drop_is_not_thrown_off_a_wall_at_any_stiffness() {
    for k in [5e4, 2e5, 5e5, 1e6, 5e6] {
        let params = Params {
            stiffness: k,
            ..Params::default()
        };
        let (_, fastest, contained) =
            spray_on_a_wall(params, None, [1, 1, 1], Vec3::new(0.0, -6.0, 0.0));
        assert!(contained, "k = {k}: the drop escaped");
        assert!(fastest < 8.0, "k = {k}: {fastest} m/s");
    }
}

/// `step_until` ends the step with the clock on the requested time exactly, where adding the
/// step's size would be off by the round-off; an end not after the clock is rejected and
/// changes nothing.
#[test]
fn step_until_lands_on_the_requested_time() {
    let mut world = tiny_world();
    world.step_with_dt(0.0003).unwrap();
    world.step_with_dt(0.0003).unwrap();
    let end = 0.0017;
    let dt = end - world.time();
    assert_ne!(world.time() + dt, end, "the plain sum must miss here");
    world.step_until(end).unwrap();
    assert_eq!(world.time(), end);
    let steps = world.steps();
    for bad in [end, end - 1e-4, f64::NAN] {
        let err = world.step_until(bad).unwrap_err();
        assert!(err.to_string().starts_with("end must be after"), "{err}");
    }
    assert_eq!((world.time(), world.steps()), (end, steps));
}

/// Every built-in scene starts at rest density at the default mass factor: no fluid particle,
/// against walls, in corners or beside obstacles, starts compressed (at the reference mass
/// factor 0.8 the interior would start at 0.8·ρ0).
#[test]
fn builtin_scenes_start_at_rest_density_and_nowhere_compressed() {
    for name in crate::scene::Scene::builtin_names() {
        let scene = crate::scene::Scene::builtin(name).unwrap();
        if scene.params.mass_factor != Params::default().mass_factor {
            continue;
        }
        let world = scene.build_world().unwrap();
        let rest = world.params().rest_density;
        let rho = world.current_densities();
        let largest = rho.iter().fold(0.0f64, |a, &b| a.max(b)) / rest - 1.0;
        assert!(
            largest <= 1e-4,
            "{name}: starts {:.3} % compressed",
            largest * 100.0
        );
    }
}

/// A lattice block's interior is at rest density after the first step, at the default mass
/// factor (within 0.5 %); at the reference factor 0.8 it is 20 % below.
#[test]
fn lattice_block_interior_is_at_rest_density_after_the_first_step() {
    let interior_densities = |params: Params| {
        let d = params.spacing();
        let mut world = World::new(params).unwrap();
        let n = 12;
        let gap = d + 0.25 * world.params().particle_radius;
        let container = Aabb {
            min: Vec3::repeat(d - gap),
            max: Vec3::repeat(d + (n - 1) as f64 * d + gap),
        };
        world.add_container(container, 1).unwrap();
        world
            .add_fluid_block(Vec3::repeat(d), [n; 3], Vec3::zeros())
            .unwrap();
        world.step().unwrap();
        let inside = |p: &Vec3| p.iter().all(|&c| c > 3.0 * d && c < (n - 2) as f64 * d);
        let rest = world.params().rest_density;
        let (positions, densities) = (world.positions(), world.densities());
        let interior: Vec<f64> = positions
            .iter()
            .zip(densities)
            .filter(|(p, _)| inside(p))
            .map(|(_, rho)| rho / rest)
            .collect();
        assert!(
            interior.len() >= 6 * 6 * 6,
            "{} interior particles",
            interior.len()
        );
        interior
    };
    for ratio in interior_densities(Params::default()) {
        assert!((ratio - 1.0).abs() <= 5e-3, "interior at {ratio:.4}·ρ0");
    }
    let reference = Params {
        mass_factor: crate::params::REFERENCE_MASS_FACTOR,
        ..Params::default()
    };
    for ratio in interior_densities(reference) {
        assert!(
            (ratio - 0.8).abs() <= 5e-3,
            "interior at {ratio:.4}·ρ0 with factor 0.8"
        );
    }
}

/// The box of [`corner_start`].
const CORNER_BOX: Aabb = Aabb {
    min: Vec3::new(0.0, 0.0, 0.0),
    max: Vec3::new(0.5, 0.4, 0.3),
};

/// A 6 × 7 × 5 block of water placed 1.5r from three walls of [`CORNER_BOX`] (r = 0.02 m,
/// τ = 2e-5 m, k = 5·10⁴ N/m) and thrown into their corner at 2√3 m/s, with `params` for the
/// rest: its impact compresses the corner, and at this soft k its first step hits K_max.
fn corner_start(params: Params) -> World {
    let params = Params {
        particle_radius: 0.02,
        displacement_tolerance: 2e-5,
        stiffness: 5e4,
        ..params
    };
    let mut world = World::new(params).unwrap();
    world.add_container(CORNER_BOX, 1).unwrap();
    world
        .add_fluid_block(Vec3::repeat(0.03), [6, 7, 5], Vec3::repeat(-2.0))
        .unwrap();
    world
}

/// Water thrown into a corner hits K_max in its first step. There Chebyshev's extrapolation
/// at the default ρ_c = 0.99 threw corner particles through the walls within the first
/// steps; the step that reaches K_max starts over without the extrapolation
/// (docs/method.md §4, "Fallback"), which keeps them in.
#[test]
fn a_step_whose_extrapolation_reaches_the_limit_starts_over_without_it() {
    let start = |threads| {
        corner_start(Params {
            threads,
            ..Params::default()
        })
    };
    let (mut world, mut other) = (start(1), start(2));
    let limit = world.params().max_outer_iterations;
    let first = world.step().unwrap();
    assert!(
        first.outer_iterations > limit && first.outer_iterations <= 2 * limit,
        "{first:?}"
    );
    // The fallback is as deterministic as the rest of the step.
    other.step().unwrap();
    assert!(world.positions() == other.positions());
    while world.time() < 0.1 {
        let stats = world.step().unwrap();
        assert!(stats.outer_iterations <= 2 * limit);
        assert!(
            world
                .positions()
                .iter()
                .all(|p| CORNER_BOX.contains(p, 0.0)),
            "t = {} s: a particle left the box",
            world.time()
        );
    }
}

/// The fallback pass is the plain iteration from s: a Chebyshev step that falls back ends
/// where the `jacobi1` solver ends the same step, bit for bit, in the particles and in the
/// load on a dynamic box beside the water (whose share of the iteration starts over too).
#[test]
fn a_step_that_falls_back_ends_where_the_plain_iteration_ends() {
    use crate::body::{BodyKind, BodyMass, BodySpec, Pose, Rotation, Shape, Velocity};
    use crate::params::SolverKind;
    let first_step = |solver: SolverKind| {
        let mut world = corner_start(Params {
            solver,
            ..Params::default()
        });
        let half = Vec3::repeat(0.05);
        world
            .add_body(BodySpec {
                kind: BodyKind::Dynamic,
                mesh: Shape::Box { half_extents: half }.mesh(0.02).unwrap(),
                mass: Some(BodyMass::Density(500.0)),
                pose: Pose {
                    position: Vec3::new(0.31, 0.1, 0.15),
                    rotation: Rotation::identity(),
                },
                velocity: Velocity::default(),
                motion: None,
            })
            .unwrap();
        let stats = world.step().unwrap().clone();
        let (force, torque) = {
            let body = world.body(0).unwrap();
            (body.force, body.torque)
        };
        (stats, world.positions(), force, torque)
    };
    let (accelerated, x, force, torque) = first_step(SolverKind::Chebyshev);
    let (plain, x_plain, force_plain, torque_plain) = first_step(SolverKind::Jacobi1);
    let limit = Params::default().max_outer_iterations;
    assert_eq!(
        accelerated.outer_iterations,
        limit + plain.outer_iterations,
        "{accelerated:?} against {plain:?}"
    );
    assert!(force.norm() > 0.0, "the box feels the water");
    assert!(x == x_plain);
    assert_eq!((force, torque), (force_plain, torque_plain));
}

/// A container's walls are sampled r apart by default and at the spacing asked for, from
/// r/4 to 2r: at 2r four times the area per particle, a quarter of the particles, and
/// none farther than the spacing from its nearest neighbour on the wall; the limits as
/// single-precision numbers count as the limits. A spacing outside the range, or not finite,
/// is refused and adds nothing.
#[test]
fn container_walls_are_sampled_at_the_spacing_asked_for() {
    let tank = Aabb {
        min: Vec3::zeros(),
        max: Vec3::new(0.6, 0.4, 0.5),
    };
    let r = Params::default().particle_radius;
    let count = |spacing: Option<f64>| {
        let mut world = World::new(Params::default()).unwrap();
        match spacing {
            Some(s) => world.add_container_spaced(tank, 1, s).unwrap(),
            None => world.add_container(tank, 1).unwrap(),
        }
        world
    };
    let default = count(None);
    assert_eq!(default.boundary_count(), count(Some(r)).boundary_count());
    let sparse = count(Some(2.0 * r));
    // 2r as a C caller's float, a little above 2r, is 2r.
    let float = f64::from((2.0 * r) as f32);
    assert!(float > 2.0 * r);
    assert_eq!(count(Some(float)).boundary_count(), sparse.boundary_count());
    let ratio = default.boundary_count() as f64 / sparse.boundary_count() as f64;
    assert!((3.5..=4.5).contains(&ratio), "{ratio}");
    for (world, spacing) in [(&default, r), (&sparse, 2.0 * r)] {
        let walls = world.boundary_positions();
        // The floor's particles: each has another within the spacing, none closer than
        // half of it.
        let floor: Vec<Vec3> = walls.iter().copied().filter(|p| p.y == 0.0).collect();
        for p in floor.iter().take(200) {
            let nearest = (floor.iter())
                .filter(|q| *q != p)
                .map(|q| (q - p).norm())
                .fold(f64::MAX, f64::min);
            assert!(nearest <= spacing * (1.0 + 1e-9), "{nearest} > {spacing}");
            assert!(nearest >= 0.5 * spacing, "{nearest} < {spacing} / 2");
        }
    }
    let mut world = count(None);
    let before = world.boundary_count();
    for bad in [f64::NAN, 0.0, 0.2 * r, 2.01 * r, f64::INFINITY] {
        let err = world.add_container_spaced(tank, 1, bad).unwrap_err();
        assert!(
            err.to_string().contains("spacing must be from r/4 to 2r"),
            "{err}"
        );
        assert_eq!(world.boundary_count(), before);
    }
}

/// A container whose walls are fields gives the fluid next to it the density walls of
/// particles give: a block placed 2.25r from every wall, as the built-in scenes place theirs,
/// reads within 0.1 % of the same block between walls of particles along the walls (where
/// the field is the particles' average along the wall), and rest density in the bulk. In the
/// edges it reads up to 2 % and in the three-wall corners up to 4.5 % higher, never more
/// than 1 % above ρ0: the field does not shrink its masses next to the box's edges as the
/// particles' Akinci masses do (docs/method.md §7).
#[test]
fn walls_that_are_fields_give_the_density_walls_of_particles_give() {
    let r = Params::default().particle_radius;
    let d = 2.0 * r;
    let tank = Aabb {
        min: Vec3::repeat(-0.25 * r),
        max: Vec3::new(12.0, 10.0, 8.0) * d + Vec3::repeat(0.25 * r),
    };
    let densities = |field: bool| {
        // The fluid first, so that both worlds read it where the lattice put it: fluid added
        // into a container would be settled against its walls (docs/method.md §2.7).
        let mut world = World::new(Params::default()).unwrap();
        world
            .add_fluid_block(Vec3::repeat(d), [11, 9, 7], Vec3::zeros())
            .unwrap();
        if field {
            world.add_container_field(tank).unwrap();
        } else {
            world.add_container(tank, 1).unwrap();
        }
        assert_eq!(world.boundary_count() == 0, field);
        (world.positions(), world.current_densities())
    };
    let (x, particles) = densities(false);
    let (_, field) = densities(true);
    let rho0 = Params::default().rest_density;
    let (mut faces, mut edges) = (0, 0);
    for ((p, a), b) in x.iter().zip(&particles).zip(&field) {
        // How many walls lie within H (the first fluid layer sits 2.25r from its wall).
        let near = (0..3)
            .map(|k| usize::from(p[k] < 3.0 * d) + usize::from(tank.max[k] - p[k] < 2.0 * d))
            .sum::<usize>();
        let difference = (a - b).abs() / rho0;
        match near {
            0 => assert!((b / rho0 - 1.0).abs() < 1e-3, "bulk {p:?}: {b}"),
            1 => {
                faces += 1;
                assert!(difference < 1e-3, "face {p:?}: {a} against {b}");
            }
            walls => {
                edges += 1;
                let bound = if walls == 2 { 2e-2 } else { 4.5e-2 };
                assert!(
                    (b - a) / rho0 < bound && b - a > -1e-3 * rho0,
                    "edge {p:?}: {a} against {b}"
                );
                assert!(b / rho0 < 1.01, "edge {p:?}: {b}");
            }
        }
    }
    assert!(faces > 100 && edges > 20, "{faces} faces, {edges} edges");
}

/// A container with walls that are fields is refused, changing nothing, when its box is not
/// finite, too narrow or too large.
#[test]
fn a_bad_box_for_walls_that_are_fields_is_refused() {
    let mut world = World::new(Params::default()).unwrap();
    let good = Aabb {
        min: Vec3::zeros(),
        max: Vec3::repeat(1.0),
    };
    for (bad, why) in [
        (Vec3::new(f64::NAN, 1.0, 1.0), "finite"),
        (Vec3::new(0.05, 1.0, 1.0), "two particle spacings"),
        (Vec3::new(1e6, 1.0, 1.0), "too large"),
    ] {
        let err = world
            .add_container_field(Aabb { max: bad, ..good })
            .unwrap_err();
        assert!(err.to_string().contains(why), "{err}");
        assert!(world.containers().is_empty());
        assert!(world.boundary.walls.is_empty());
    }
    world.add_container_field(good).unwrap();
    assert_eq!(world.containers(), &[good]);
}
