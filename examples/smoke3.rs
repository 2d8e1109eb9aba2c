use projfluid::{boundary::Aabb, *};
fn main() {
    let mut p = Params::default();
    p.solver = SolverKind::Jacobi1;
    let mut w = World::new(p.clone()).unwrap();
    w.add_container(
        Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(2.0, 1.5, 0.65),
        },
        1,
    )
    .unwrap();
    w.add_fluid_block(Vec3::repeat(0.05), [16, 20, 12], Vec3::zeros())
        .unwrap();
    p.gravity = [0.0; 3];
    p.max_outer_iterations = 1;
    let mut w0 = World::new(p).unwrap();
    w0.add_container(
        Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(2.0, 1.5, 0.65),
        },
        1,
    )
    .unwrap();
    w0.add_fluid_block(Vec3::repeat(0.05), [16, 20, 12], Vec3::zeros())
        .unwrap();
    w0.step_with_dt(1e-9).unwrap();
    let x = w0.positions();
    let d = w0.densities();
    let mut v: Vec<(f64, Vec3)> = d.iter().zip(&x).map(|(a, b)| (*a, *b)).collect();
    v.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
    for (r, p) in v.iter().take(12) {
        println!("{r:.2} at {:?}", p.as_slice());
    }
    let interior: Vec<f64> = d
        .iter()
        .zip(&x)
        .filter(|(_, p)| {
            p.x > 0.3 && p.x < 0.5 && p.y > 0.3 && p.y < 0.6 && p.z > 0.2 && p.z < 0.45
        })
        .map(|(a, _)| *a)
        .collect();
    println!(
        "interior mean {}",
        interior.iter().sum::<f64>() / interior.len() as f64
    );
    let floor: Vec<f64> = d
        .iter()
        .zip(&x)
        .filter(|(_, p)| p.y < 0.06 && p.x > 0.3 && p.x < 0.5 && p.z > 0.2 && p.z < 0.45)
        .map(|(a, _)| *a)
        .collect();
    println!(
        "floor mean {}",
        floor.iter().sum::<f64>() / floor.len() as f64
    );
}
