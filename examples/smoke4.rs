use projfluid::{boundary::Aabb, *};
fn main() {
    for off in [0.0, 0.001, 0.002, 0.0025, 0.003, 0.004, 0.005] {
        let mut p = Params::default();
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
        w0.add_fluid_block(Vec3::repeat(0.05 + off), [16, 20, 12], Vec3::zeros())
            .unwrap();
        w0.step_with_dt(1e-9).unwrap();
        let d = w0.densities();
        println!(
            "offset {off}: max density {:.2}",
            d.iter().cloned().fold(0.0, f64::max)
        );
    }
}
