//! Fluid and triangle-mesh obstacles: water poured onto and around walls thinner than a
//! particle radius stays out of the solid and inside the tank.

#[path = "support/cup.rs"]
mod cup;

use cup::thin_walled_cup;
use projfluid::boundary::Aabb;
use projfluid::boundary::winding::{is_closed_and_oriented, is_inside};
use projfluid::{Params, Vec3, World};

/// A block of water falls onto a cup whose walls are 2 cm thick (less than r = 2.5 cm and a
/// fifth of the kernel support): part of it lands in the cup, the rest splashes around it.
/// After every step no particle centre may lie inside the walls or outside the tank. Steps
/// move particles at most 0.2·2r = 1 cm (CFL), so a particle crossing a wall would be seen
/// inside it for at least one step.
#[test]
fn water_poured_over_a_thin_walled_cup_does_not_leak_through_its_walls() {
    let cup = thin_walled_cup(0.02);
    assert!(is_closed_and_oriented(&cup));
    let mut world = World::new(Params {
        threads: 2,
        ..Params::default()
    })
    .unwrap();
    let tank = Aabb {
        min: Vec3::repeat(-0.00625),
        max: Vec3::new(0.80625, 0.90625, 0.80625),
    };
    world.add_container(tank, 1).unwrap();
    world.add_boundary_mesh(&cup).unwrap();
    // 12 × 6 × 12 particles above the cup, overhanging it by about 0.1 m on every side.
    world
        .add_fluid_block(Vec3::new(0.125, 0.35, 0.125), [12, 6, 12], Vec3::zeros())
        .unwrap();
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
