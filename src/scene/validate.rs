//! Checks of a [`Scene`]'s values; errors name the JSON key and the value.

use super::{ContainerSpec, ContainerWalls, FluidBlock, ObstacleSpec, Scene};
use crate::Error;
use crate::body::Shape;
use crate::boundary::{MAX_WALL_SPACING, MIN_WALL_SPACING, wall_spacing};

/// The most fluid particles a world accepts (see `World::add_fluid_particles`).
const MAX_PARTICLES: usize = u32::MAX as usize / 64;

/// Largest container extent in particle radii (see `World::add_container`).
const MAX_EXTENT_PER_RADIUS: f64 = 1e5;

/// Checks the whole scene; the first problem found is returned.
pub(super) fn validate(scene: &Scene) -> Result<(), Error> {
    let r = scene.params.particle_radius;
    if !(r.is_finite() && r > 0.0) {
        return Err(Error::invalid(
            "particle_radius",
            r,
            "must be a positive finite number",
        ));
    }
    scene.params.validate().map_err(to_json_key)?;
    if !(scene.duration.is_finite() && scene.duration > 0.0) {
        return Err(Error::invalid(
            "duration",
            scene.duration,
            "must be a positive finite number of seconds",
        ));
    }
    if scene.output.every < 1 {
        return Err(Error::invalid(
            "output.every",
            scene.output.every,
            "must be at least 1",
        ));
    }
    if let Some(fps) = scene.output.fps
        && !(fps.is_finite() && fps > 0.0 && 1.0 / fps >= scene.params.dt_min)
    {
        return Err(Error::invalid(
            "output.fps",
            fps,
            &format!(
                "must be positive and at most 1/dt_min ({} frames per second)",
                1.0 / scene.params.dt_min
            ),
        ));
    }
    for (i, c) in scene.containers.iter().enumerate() {
        check_container(i, c, r)?;
    }
    for (i, o) in scene.obstacles.iter().enumerate() {
        check_mesh_source(&format!("obstacles[{i}]"), o)?;
    }
    for (i, b) in scene.bodies.iter().enumerate() {
        super::bodies::check_body(i, b)?;
    }
    if scene.fluid_blocks.is_empty() {
        return Err(Error::invalid(
            "fluid_blocks",
            "[]",
            "must not be empty (a scene needs at least one block of fluid)",
        ));
    }
    check_materials(scene)?;
    let mut total = 0usize;
    for (i, b) in scene.fluid_blocks.iter().enumerate() {
        check_block(i, b)?;
        check_material_name(scene, &format!("fluid_blocks[{i}]"), b.material.as_deref())?;
        total = total.saturating_add(b.particle_count());
        if total > MAX_PARTICLES {
            return Err(Error::invalid(
                "fluid_blocks",
                total,
                &format!("must hold at most {MAX_PARTICLES} particles in all"),
            ));
        }
        check_inside(i, b, &scene.containers, 2.0 * r)?;
    }
    super::flow::check_flow(scene)?;
    check_probes(scene)
}

/// A `material` key of the entry `key` (e.g. `emitters[0]`): absent, or the name of one of the
/// scene's materials.
pub(super) fn check_material_name(
    scene: &Scene,
    key: &str,
    name: Option<&str>,
) -> Result<(), Error> {
    match name {
        Some(name) if scene.material_named(Some(name)) == 0 => Err(Error::invalid(
            format!("{key}.material"),
            format!("{name:?}"),
            "must name one of the scene's materials",
        )),
        _ => Ok(()),
    }
}

/// The materials: unique, non-empty names and rest densities a world of the scene's rest
/// density takes (docs/method.md §14).
fn check_materials(scene: &Scene) -> Result<(), Error> {
    let limit = crate::material::MAX_MATERIALS - 1;
    if scene.materials.len() > limit {
        return Err(Error::invalid(
            "materials",
            scene.materials.len(),
            &format!("must hold at most {limit} materials"),
        ));
    }
    for (i, m) in scene.materials.iter().enumerate() {
        if m.name.is_empty() || scene.materials[..i].iter().any(|o| o.name == m.name) {
            return Err(Error::invalid(
                format!("materials[{i}].name"),
                format!("{:?}", m.name),
                "must be a name no other material has",
            ));
        }
        m.material()
            .check(scene.params.rest_density)
            .map_err(|e| super::prefixed(e, &format!("materials[{i}].")))?;
    }
    Ok(())
}

/// The probes on their own and against the scene's gravity and containers; a rate of at most
/// 1/dt_min, as for `output.fps`.
fn check_probes(scene: &Scene) -> Result<(), Error> {
    let Some(probes) = &scene.probes else {
        return Ok(());
    };
    let containers: Vec<_> = scene
        .containers
        .iter()
        .map(|c| crate::boundary::Aabb {
            min: c.min.into(),
            max: c.max.into(),
        })
        .collect();
    probes.validate_for(scene.params.gravity, &containers)?;
    if 1.0 / probes.rate < scene.params.dt_min {
        return Err(Error::invalid(
            "probes.rate",
            probes.rate,
            &format!(
                "must be at most 1/dt_min ({} readings per second)",
                1.0 / scene.params.dt_min
            ),
        ));
    }
    Ok(())
}

/// An obstacle-style mesh source (the obstacle or body mesh at JSON key `key`): a known
/// generated mesh or a primitive with positive sizes, and a valid transform.
pub(super) fn check_mesh_source(key: &str, o: &ObstacleSpec) -> Result<(), Error> {
    if let &super::MeshSource::Primitive(shape) = &o.mesh {
        let sized = match shape {
            Shape::Box { half_extents } => super::BodyShape::Box {
                half_extents: half_extents.into(),
            },
            Shape::Sphere { radius } => super::BodyShape::Sphere { radius },
            Shape::Cylinder { radius, height } => super::BodyShape::Cylinder { radius, height },
        };
        super::bodies::check_shape(key, &sized)?;
    }
    if let super::MeshSource::Generated(name) = &o.mesh
        && !super::obstacle::NAMES.contains(&name.as_str())
    {
        return Err(Error::invalid(
            format!("{key}.generated"),
            format!("`{name}`"),
            &format!(
                "must name a generated mesh ({})",
                super::obstacle::NAMES.join(", ")
            ),
        ));
    }
    o.transform.validate().map_err(|e| match e {
        Error::InvalidArgument { field, message } => Error::InvalidArgument {
            field: format!("{key}.{field}"),
            message: format!("{key}.{message}"),
        },
        other => other,
    })
}

/// Renames a [`crate::Params::validate`] error's field to its JSON key (e.g. `rho` → `solver.rho`).
fn to_json_key(error: Error) -> Error {
    let Error::InvalidArgument { field, message } = error else {
        return error;
    };
    let key = match field.as_str() {
        "rho" | "delay" | "gamma" | "warm_start" | "coarse_correction" => {
            format!("solver.{field}")
        }
        "displacement_tolerance" => "solver.tau".to_string(),
        "density_tolerance" => "solver.eta".to_string(),
        "min_outer_iterations" => "solver.min_iterations".to_string(),
        "max_outer_iterations" => "solver.max_iterations".to_string(),
        "cfl_factor" | "dt_min" | "dt_max" | "dt_initial" => format!("time.{field}"),
        _ => field.clone(),
    };
    let message = match message.strip_prefix(field.as_str()) {
        Some(rest) => format!(
            "{key}{}",
            rest.replace("min_outer_iterations", "solver.min_iterations")
        ),
        None => message,
    };
    let message = message.replace("must not exceed dt_max", "must not exceed time.dt_max");
    Error::InvalidArgument {
        field: key,
        message,
    }
}

/// Finite corners, a non-degenerate box of at least two spacings per axis, 1–3 layers, a
/// wall spacing from r/4 to 2r.
fn check_container(i: usize, c: &ContainerSpec, r: f64) -> Result<(), Error> {
    let field = format!("container[{i}]");
    for (name, v) in [("min", c.min), ("max", c.max)] {
        if v.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid(
                format!("{field}.{name}"),
                format!("{v:?}"),
                "must be finite",
            ));
        }
    }
    for (a, axis) in AXES.iter().enumerate() {
        let size = c.max[a] - c.min[a];
        if size < 4.0 * r {
            return Err(Error::invalid(
                format!("{field}.max"),
                format!("{:?}", c.max),
                &format!(
                    "must exceed min {:?} by at least two particle spacings ({}) along {axis}",
                    c.min,
                    short(4.0 * r)
                ),
            ));
        }
        if size / r > MAX_EXTENT_PER_RADIUS {
            return Err(Error::invalid(
                field,
                format!("{:?}..{:?}", c.min, c.max),
                "is too large for the particle radius (at most 1e5 radii per axis)",
            ));
        }
    }
    if !(1..=3).contains(&c.layers) {
        return Err(Error::invalid(
            format!("{field}.layers"),
            c.layers,
            "must be 1, 2 or 3",
        ));
    }
    if c.walls == ContainerWalls::Field {
        let particles = "applies to walls of particles (\"walls\": \"particles\")";
        if c.layers != 1 {
            let why = format!("{particles}; walls that are fields stand for one layer");
            return Err(Error::invalid(format!("{field}.layers"), c.layers, &why));
        }
        if let Some(spacing) = c.spacing {
            return Err(Error::invalid(
                format!("{field}.spacing"),
                spacing,
                particles,
            ));
        }
    }
    if let Some(spacing) = c.spacing.filter(|&s| wall_spacing(s, r).is_none()) {
        return Err(Error::invalid(
            format!("{field}.spacing"),
            spacing,
            &format!(
                "must be from r/4 to 2r ({} to {} m)",
                short(MIN_WALL_SPACING * r),
                short(MAX_WALL_SPACING * r)
            ),
        ));
    }
    Ok(())
}

/// Finite start and velocity, at least one particle per axis.
fn check_block(i: usize, b: &FluidBlock) -> Result<(), Error> {
    let field = format!("fluid_blocks[{i}]");
    for (name, v) in [("start", b.start), ("velocity", b.velocity)] {
        if v.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid(
                format!("{field}.{name}"),
                format!("{v:?}"),
                "must be finite",
            ));
        }
    }
    if b.count.contains(&0) {
        return Err(Error::invalid(
            format!("{field}.count"),
            format!("{:?}", b.count),
            "must be at least 1 along every axis",
        ));
    }
    Ok(())
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// Every particle centre of block `i` (lattice spacing `d`) lies in some container (or there
/// are no containers). A block that straddles two containers is fine.
fn check_inside(
    i: usize,
    b: &FluidBlock,
    containers: &[ContainerSpec],
    d: f64,
) -> Result<(), Error> {
    if containers.is_empty() {
        return Ok(());
    }
    let tol = 1e-6 * d;
    let lo = b.start;
    let hi: [f64; 3] = std::array::from_fn(|a| b.start[a] + (b.count[a] - 1) as f64 * d);
    let inside = |c: &ContainerSpec, p: &[f64; 3], q: &[f64; 3]| {
        (0..3).all(|a| p[a] >= c.min[a] - tol && q[a] <= c.max[a] + tol)
    };
    if containers.iter().any(|c| inside(c, &lo, &hi)) {
        return Ok(());
    }
    let field = format!("fluid_blocks[{i}]");
    if let [c] = containers {
        for (a, axis) in AXES.iter().enumerate() {
            let why = if lo[a] < c.min[a] - tol {
                format!(
                    "min {axis} {} < container min {}",
                    short(lo[a]),
                    short(c.min[a])
                )
            } else if hi[a] > c.max[a] + tol {
                format!(
                    "max {axis} {} > container max {}",
                    short(hi[a]),
                    short(c.max[a])
                )
            } else {
                continue;
            };
            return Err(Error::InvalidArgument {
                message: format!("{field} lies outside the container: {why}"),
                field,
            });
        }
    }
    // Several containers: look for the first particle in none of them.
    for k in 0..b.count[2] {
        for j in 0..b.count[1] {
            for n in 0..b.count[0] {
                let p = [n, j, k].map(|c| c as f64 * d);
                let p: [f64; 3] = std::array::from_fn(|a| b.start[a] + p[a]);
                if !containers.iter().any(|c| inside(c, &p, &p)) {
                    return Err(Error::InvalidArgument {
                        message: format!(
                            "{field} lies outside every container: particle [{n}, {j}, {k}] at ({}, {}, {})",
                            short(p[0]),
                            short(p[1]),
                            short(p[2])
                        ),
                        field,
                    });
                }
            }
        }
    }
    Ok(())
}

/// A length for messages: at most nine decimals, trailing zeros dropped, one decimal kept.
fn short(x: f64) -> String {
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0');
    if s.ends_with('.') {
        format!("{s}0")
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::Scene;
    use crate::scene::test_support::{GOOD, assert_names, message};

    #[test]
    fn negative_radius_names_field_and_value() {
        let text = GOOD.replace("\"particle_radius\": 0.05", "\"particle_radius\": -0.1");
        assert_eq!(
            message(Scene::from_json(&text)),
            "particle_radius must be a positive finite number, got -0.1"
        );
    }

    #[test]
    fn materials_are_read_built_and_checked() {
        let scene = |materials: &str, block: &str| {
            format!(
                r#"{{"particle_radius": 0.05, "duration": 1,
                "container": {{"min": [0, 0, 0], "max": [2, 2, 2]}},
                "materials": {materials},
                "fluid_blocks": [{{"start": [0.2, 0.2, 0.2], "count": [2, 2, 2]}},
                                 {{"start": [0.2, 0.8, 0.2], "count": [2, 2, 2]{block}}}]}}"#
            )
        };
        let oil = r#"[{"name": "oil", "rest_density": 800}]"#;
        let good = Scene::from_json(&scene(oil, r#", "material": "oil""#)).unwrap();
        assert_eq!(good.materials[0].rest_density, 800.0);
        let world = good.build_world().unwrap();
        assert_eq!(world.material_count(), 2);
        assert_eq!(world.material(1).unwrap().kinematic_viscosity, 0.0);
        let honey = r#"[{"name": "oil", "rest_density": 1420, "kinematic_viscosity": 0.1}]"#;
        let viscous = Scene::from_json(&scene(honey, r#", "material": "oil""#)).unwrap();
        let built = viscous.build_world().unwrap();
        assert_eq!(built.material(1).unwrap().kinematic_viscosity, 0.1);
        assert_eq!(Scene::from_json(&viscous.to_json()).unwrap(), viscous);
        let tense = r#"[{"name": "oil", "rest_density": 800, "surface_tension": 0.03}]"#;
        let tense = Scene::from_json(&scene(tense, r#", "material": "oil""#)).unwrap();
        let built = tense.build_world().unwrap();
        assert_eq!(built.material(1).unwrap().surface_tension, 0.03);
        assert_eq!(built.material(0).unwrap().surface_tension, 0.0);
        assert_eq!(Scene::from_json(&tense.to_json()).unwrap(), tense);
        assert_eq!(world.particle_materials(), [[0; 8], [1; 8]].concat());
        assert_eq!(world.fluid_material(), 0);
        assert_eq!(Scene::from_json(&good.to_json()).unwrap(), good);
        let cases = [
            (
                oil.to_string(),
                r#", "material": "tar""#,
                vec!["fluid_blocks[1].material", "tar"],
            ),
            (
                r#"[{"name": "oil", "rest_density": 5}]"#.into(),
                "",
                vec!["materials[0].rest_density", "5"],
            ),
            (
                r#"[{"name": "oil", "rest_density": 800, "kinematic_viscosity": -1}]"#.into(),
                "",
                vec!["materials[0].kinematic_viscosity", "-1"],
            ),
            (
                r#"[{"name": "oil", "rest_density": 800, "surface_tension": -0.1}]"#.into(),
                "",
                vec!["materials[0].surface_tension", "-0.1"],
            ),
            (
                r#"[{"name": "", "rest_density": 800}]"#.into(),
                "",
                vec!["materials[0].name"],
            ),
            (
                r#"[{"name": "a", "rest_density": 800}, {"name": "a", "rest_density": 900}]"#
                    .into(),
                "",
                vec!["materials[1].name", "\"a\""],
            ),
            (
                r#"[{"name": "a", "density": 800}]"#.into(),
                "",
                vec!["unknown field `density`"],
            ),
        ];
        for (materials, block, parts) in cases {
            assert_names(
                &message(Scene::from_json(&scene(&materials, block))),
                &parts,
            );
        }
    }

    #[test]
    fn empty_fluid_blocks_is_an_error() {
        let text = r#"{"particle_radius": 0.05, "duration": 1, "fluid_blocks": []}"#;
        assert_names(&message(Scene::from_json(text)), &["fluid_blocks", "empty"]);
    }

    #[test]
    fn fluid_outside_the_container_is_an_error() {
        let text = GOOD.replace("\"start\": [0.1, 1.0, 0.1]", "\"start\": [0.1, 2.9, 0.1]");
        let msg = message(Scene::from_json(&text));
        assert_eq!(
            msg,
            "fluid_blocks[1] lies outside the container: max y 3.1 > container max 3.0"
        );
        let text = GOOD.replace("\"start\": [0.1, 0.1, 0.1]", "\"start\": [-0.1, 0.1, 0.1]");
        assert_names(
            &message(Scene::from_json(&text)),
            &["fluid_blocks[0]", "min x -0.1 < container min 0.0"],
        );
    }

    #[test]
    fn fluid_may_straddle_two_containers_but_not_leave_both() {
        let two = r#"{"particle_radius": 0.05, "duration": 1,
            "container": [{"min": [0, 0, 0], "max": [1, 1, 1]}, {"min": [1, 0, 0], "max": [2, 1, 1]}],
            "fluid_blocks": [{"start": [0.1, 0.1, 0.1], "count": [15, 2, 2]}]}"#;
        Scene::from_json(two).unwrap();
        let out = two.replace("[15, 2, 2]", "[15, 11, 2]");
        assert_names(
            &message(Scene::from_json(&out)),
            &["fluid_blocks[0] lies outside every container", "[0, 10, 0]"],
        );
    }

    #[test]
    fn bad_values_name_the_json_key() {
        let cases = [
            (
                "\"output\": {\"fps\": 0}",
                "output.fps must be positive and at most 1/dt_min (10000 frames per second), got 0",
            ),
            (
                "\"output\": {\"fps\": 20000}",
                "output.fps must be positive and at most 1/dt_min (10000 frames per second), got 20000",
            ),
            (
                "\"solver\": {\"rho\": 1.5}",
                "solver.rho must lie in [0, 1), got 1.5",
            ),
            (
                "\"solver\": {\"tau\": -1}",
                "solver.tau must be a positive finite number, got -1",
            ),
            (
                "\"time\": {\"dt_max\": 0}",
                "time.dt_max must be a positive finite number of seconds (at most 1), got 0",
            ),
            (
                "\"output\": {\"every\": 0}",
                "output.every must be at least 1, got 0",
            ),
            ("\"viscosity\": 2", "viscosity must lie in [0, 1], got 2"),
        ];
        for (extra, expected) in cases {
            let text = GOOD.replace("\"duration\": 0.5", &format!("\"duration\": 0.5, {extra}"));
            assert_eq!(message(Scene::from_json(&text)), expected);
        }
        let text = GOOD.replace("\"duration\": 0.5", "\"duration\": -2");
        assert_eq!(
            message(Scene::from_json(&text)),
            "duration must be a positive finite number of seconds, got -2"
        );
        let text = GOOD.replace("[4, 4, 4]", "[4, 0, 4]");
        assert_names(
            &message(Scene::from_json(&text)),
            &["fluid_blocks[0].count", "[4, 0, 4]"],
        );
        let text = GOOD.replace("\"max\": [1, 3, 1]", "\"max\": [1, 3, 1], \"layers\": 7");
        assert_eq!(
            message(Scene::from_json(&text)),
            "container[0].layers must be 1, 2 or 3, got 7"
        );
        let text = GOOD.replace(
            "\"max\": [1, 3, 1]",
            "\"max\": [1, 3, 1], \"walls\": \"particles\", \"spacing\": 0.11",
        );
        assert_eq!(
            message(Scene::from_json(&text)),
            "container[0].spacing must be from r/4 to 2r (0.0125 to 0.1 m), got 0.11"
        );
        // Walls that are fields take neither layers nor a spacing, and no unknown kind.
        for (extra, expected) in [
            (
                "\"walls\": \"field\", \"layers\": 2",
                "container[0].layers applies to walls of particles (\"walls\": \"particles\"); \
                 walls that are fields stand for one layer, got 2",
            ),
            (
                "\"walls\": \"field\", \"spacing\": 0.05",
                "container[0].spacing applies to walls of particles (\"walls\": \"particles\"), \
                 got 0.05",
            ),
        ] {
            let text = GOOD.replace(
                "\"max\": [1, 3, 1]",
                &format!("\"max\": [1, 3, 1], {extra}"),
            );
            assert_eq!(message(Scene::from_json(&text)), expected);
        }
        let text = GOOD.replace(
            "\"max\": [1, 3, 1]",
            "\"max\": [1, 3, 1], \"walls\": \"glass\"",
        );
        assert_names(&message(Scene::from_json(&text)), &["glass"]);
        // A spacing in range is kept, builds walls that sparse, and round-trips.
        let particles = "\"max\": [1, 3, 1], \"walls\": \"particles\"";
        let sparse = GOOD.replace(
            "\"max\": [1, 3, 1]",
            &format!("{particles}, \"spacing\": 0.1"),
        );
        let scene = Scene::from_json(&sparse).unwrap();
        assert_eq!(scene.containers[0].spacing, Some(0.1));
        assert_eq!(Scene::from_json(&scene.to_json()).unwrap(), scene);
        let walls = |scene: &Scene| scene.build_world().unwrap().boundary_count() as f64;
        let dense = Scene::from_json(&GOOD.replace("\"max\": [1, 3, 1]", particles)).unwrap();
        let ratio = walls(&dense) / walls(&scene);
        assert!((3.5..=4.5).contains(&ratio), "{ratio}");
        let text = GOOD.replace("\"max\": [1, 3, 1]", "\"max\": [1, -3, 1]");
        assert_names(&message(Scene::from_json(&text)), &["container[0]", "-3"]);
    }
}
