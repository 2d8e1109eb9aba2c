//! Fluid and triangle-mesh obstacles: water poured onto and around walls thinner than a
//! particle radius stays out of the solid and inside the tank.

#[path = "support/cup.rs"]
mod cup;

use cup::{pour_over_cup, thin_walled_cup};
use projfluid::Params;
use projfluid::boundary::winding::{is_closed_and_oriented, is_inside};

/// A block of water falls onto a cup whose walls are 2 cm thick (less than r = 2.5 cm and a
/// fifth of the kernel support): part of it lands in the cup, the rest splashes around it.
/// After every step no particle centre may lie inside the walls or outside the tank. Steps
/// move particles at most 0.2·2r = 1 cm (CFL), so a particle crossing a wall would be seen
/// inside it for at least one step.
#[test]
fn water_poured_over_a_thin_walled_cup_does_not_leak_through_its_walls() {
    let cup = thin_walled_cup(0.02);
    assert!(is_closed_and_oriented(&cup));
    let params = Params {
        threads: 2,
        ..Params::default()
    };
    let mut world = pour_over_cup(params, &cup);
    let (mut in_cup_at_end, mut worst_inside, mut worst_escaped) = (0, 0, 0);
    while world.time() < 0.8 {
        world.step().unwrap();
        let positions = world.positions();
        let inside = positions.iter().filter(|p| is_inside(&cup, p)).count();
        worst_inside = worst_inside.max(inside);
        worst_escaped = worst_escaped.max(world.escaped_count());
        assert_eq!(world.nan_count(), 0);
        in_cup_at_end = positions
            .iter()
            .filter(|p| (0.27..0.53).contains(&p.x) && (0.27..0.53).contains(&p.z) && p.y < 0.25)
            .count();
    }
    assert_eq!(worst_inside, 0, "particles inside the cup's walls");
    assert_eq!(worst_escaped, 0, "particles outside the tank");
    // The test must exercise both sides of the walls: water in the cup and around it.
    let n = world.fluid_count();
    assert!(
        in_cup_at_end > n / 10 && in_cup_at_end < n * 9 / 10,
        "{in_cup_at_end} of {n} particles ended in the cup"
    );
}
