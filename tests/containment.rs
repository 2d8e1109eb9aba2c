//! Fluid stays in its container whatever the particle size and however the steps are chosen
//! (docs/method.md §7, §8): a tank at rest of particles a tenth of a millimetre and smaller
//! stays at rest under the CFL rule, and water driven at a floor by steps far longer than the
//! rule allows, as an engine stepping at its frame rate drives it, stays inside.

#[path = "support/thrown.rs"]
mod thrown;

use thrown::{clearance, tank, thrown_at_the_floor};

/// A block of 10³ particles at rest in a tank, stepped by the CFL rule, stays at rest for 300
/// steps at r = 0.1 mm, 30 µm and 10 µm: no particle leaves, the root-mean-square speed stays
/// below 5 cm/s (a settling column: 3–11 mm/s) and the average density error at the target's
/// order. Without the weight's bound on the step (docs/method.md §8) the steps grew until the
/// column's weight pushed its bottom layer a whole r into the floor each step, and at 0.1 mm
/// and 10 µm the tank burst in its first steps (54 and 560 particles lost, 0.4–0.5 m/s).
#[test]
fn a_tank_of_tiny_particles_stays_at_rest() {
    for r in [1e-4, 3e-5, 1e-5] {
        let mut world = tank(r, 12.0, [10, 10, 10]);
        let mut error = 0.0;
        for _ in 0..300 {
            error += world.step().unwrap().density_error_avg / 300.0;
        }
        let escaped = world.escaped_count();
        let rms = world.rms_velocity();
        assert_eq!(escaped, 0, "r = {r}: {escaped} particles lost");
        assert!(rms < 0.05, "r = {r}: rms speed {rms} m/s");
        assert!(error < 1e-3, "r = {r}: average density error {error}");
    }
}

/// Water thrown at a floor one layer thick at 4 m/s, stepped at a fixed 1/60 s as an engine
/// would step it (a step moves it some 5r where the CFL rule allows r), stays inside the
/// container, every particle at least r/2 from the walls' planes after every step
/// (docs/method.md §7). Without the clearance most of the block passed through the floor in
/// the first step.
#[test]
fn water_stepped_at_a_frame_rate_stays_in_its_container() {
    let (mut world, r, side) = thrown_at_the_floor();
    for step in 0..60 {
        world.step_with_dt(1.0 / 60.0).unwrap();
        let least = clearance(&world, side);
        assert!(
            least >= 0.5 * r * (1.0 - 1e-12),
            "step {step}: a particle {least} m from a wall's plane"
        );
        assert_eq!(world.escaped_count(), 0, "step {step}");
    }
}
