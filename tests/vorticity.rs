//! Vorticity confinement (docs/method.md §15): a vortex in a closed tank, filled and without
//! gravity, keeps more of its rotation with the confinement than without, whose projections
//! and XSPH damp it; and the confined flow is the same on one thread and on two.

#[path = "support/vortex.rs"]
mod vortex;

use projfluid::{Params, World};
use vortex::{swirl, vortex};

/// Without confinement the vortex's core (0.10–0.25 m from the axis, the core radius being
/// 0.15 m) loses a third of its swirl in 1 s (0.68 kept); ε = 0.3 keeps 0.84 of it and ε = 1
/// all of it.
#[test]
fn confinement_keeps_a_vortex_turning() {
    let kept = |epsilon: f64| {
        let params = Params {
            vorticity_confinement: epsilon,
            ..Params::default()
        };
        let (mut world, axis) = vortex(params, [20, 20, 4], 0.15);
        let start = swirl(&world, axis, 0.1, 0.25);
        world.advance(1.0).unwrap();
        assert_eq!(world.escaped_count() + world.nan_count(), 0);
        swirl(&world, axis, 0.1, 0.25) / start
    };
    let (plain, confined, strong) = (kept(0.0), kept(0.3), kept(1.0));
    assert!(
        plain < 0.8,
        "without confinement the core keeps {plain} of its swirl"
    );
    assert!(
        confined > plain + 0.1 && strong > confined + 0.1,
        "the core keeps {plain}, {confined} and {strong} of its swirl at ε = 0, 0.3 and 1"
    );
}

/// The confinement's sums are gathers: one thread and two give the same bits.
#[test]
fn confinement_is_the_same_on_one_thread_and_two() {
    let run = |threads: usize| {
        let params = Params {
            vorticity_confinement: 0.5,
            threads,
            ..Params::default()
        };
        let (mut world, _) = vortex(params, [12, 12, 4], 0.1);
        for _ in 0..20 {
            world.step().unwrap();
        }
        world.positions_hash()
    };
    assert_eq!(run(1), run(2));
}

/// Bad coefficients are refused, naming the field.
#[test]
fn bad_coefficients_are_refused() {
    for bad in [-0.1, 10.5, f64::NAN, f64::INFINITY] {
        let params = Params {
            vorticity_confinement: bad,
            ..Params::default()
        };
        let e = World::new(params).err().expect("refused").to_string();
        assert!(e.contains("vorticity_confinement"), "{e}");
    }
}
