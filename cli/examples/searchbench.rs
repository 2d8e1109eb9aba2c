//! Times the neighbour searches of a saved state: the fluid among itself and the fluid
//! among the boundary, on one thread, repeated (for comparing builds of the search).
//!
//! `cargo run --release --example searchbench -- CHECKPOINT REPETITIONS`, where CHECKPOINT
//! is a file written by `projfluid run --checkpoint-every N`. Prints three rounds of mean
//! times per search (ms) with the number of pairs found.
use projfluid::boundary::Aabb;
use projfluid::neighbors::{CellTable, NeighborLists, UniformGrid};
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() != 2 {
        eprintln!("usage: searchbench CHECKPOINT REPETITIONS");
        std::process::exit(2);
    }
    let checkpoint = std::path::Path::new(&a[0]);
    let world = projfluid::checkpoint::read_checkpoint(checkpoint, Some(1))
        .expect("checkpoint")
        .world;
    let repetitions: usize = a[1].parse().expect("repetitions");
    let fluid = world.positions();
    let boundary = &world.boundary_positions()[..];
    let h = world.params().support_radius();
    let bounds = [&fluid[..], boundary]
        .into_iter()
        .filter_map(Aabb::around)
        .reduce(|a, b| a.union(&b))
        .expect("the checkpoint holds particles");
    let grid = UniformGrid::covering(bounds.min, bounds.max, h).expect("memory for the grid");
    // The points in the grid's order, with the table of their cells.
    let sorted = |points: &[projfluid::Vec3], table: &mut CellTable| {
        let mut order = Vec::new();
        grid.sort(points, &mut order, table)
            .expect("memory for the sort");
        order
            .iter()
            .map(|&i| points[i as usize])
            .collect::<Vec<_>>()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    pool.install(|| {
        let (mut fluid_table, mut boundary_table) = (CellTable::default(), CellTable::default());
        let fluid = sorted(&fluid, &mut fluid_table);
        let boundary = sorted(boundary, &mut boundary_table);
        let (mut fluid_lists, mut boundary_lists) =
            (NeighborLists::default(), NeighborLists::default());
        let time = |search: &mut dyn FnMut()| {
            let start = Instant::now();
            for _ in 0..repetitions {
                search();
            }
            start.elapsed().as_secs_f64() * 1e3 / repetitions as f64
        };
        for round in 0..3 {
            let among_fluid = time(&mut || {
                grid.search(&fluid_table, &fluid, &fluid, h, true, &mut fluid_lists)
                    .expect("memory for the lists")
            });
            let among_boundary = time(&mut || {
                grid.search(&boundary_table, &boundary, &fluid, h, false, &mut boundary_lists)
                    .expect("memory for the lists")
            });
            println!(
                "round {round}: fluid {among_fluid:.3} ms ({} pairs), boundary {among_boundary:.3} ms ({} pairs)",
                fluid_lists.pairs(),
                boundary_lists.pairs()
            );
        }
    });
}
