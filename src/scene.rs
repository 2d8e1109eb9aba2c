//! Scenes: a fluid setup (parameters, container boxes, blocks of fluid, duration, output)
//! read from JSON (format in the README ("Scene files")) or taken from the built-in list.
//!
//! ```
//! use projfluid::scene::Scene;
//! let scene = Scene::builtin("dam_break_small").unwrap();
//! let world = scene.build_world().unwrap();
//! assert_eq!(world.fluid_count(), 16 * 20 * 12);
//! ```

mod builtin;
mod file;
mod validate;

use crate::boundary::{Aabb, Transform};
use crate::params::Params;
use crate::{Error, Vec3, World};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A closed box container whose six walls are sampled with boundary particles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContainerSpec {
    /// Lower corner of the walls (m).
    pub min: [f64; 3],
    /// Upper corner of the walls (m).
    pub max: [f64; 3],
    /// Wall thickness in layers of boundary particles (1–3; default 1).
    #[serde(default = "one")]
    pub layers: usize,
}

fn one() -> usize {
    1
}

/// A cubic lattice of fluid particles with spacing 2r.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidBlock {
    /// Centre of the first particle (m).
    pub start: [f64; 3],
    /// Particles along x, y and z.
    pub count: [usize; 3],
    /// Initial velocity of every particle in the block (m/s; default 0).
    #[serde(default)]
    pub velocity: [f64; 3],
}

impl FluidBlock {
    /// Number of particles in the block (saturating on overflow).
    pub fn particle_count(&self) -> usize {
        self.count
            .iter()
            .fold(1usize, |acc, &c| acc.saturating_mul(c))
    }
}

/// Where an obstacle's triangle mesh comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshSource {
    /// A Wavefront OBJ file (a path relative to the scene file when read from one, else to
    /// the working directory).
    Obj(PathBuf),
}

/// A static obstacle: a triangle mesh placed by a transform, its surface sampled with
/// boundary particles (see [`World::add_boundary_mesh`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ObstacleSpec {
    /// The mesh.
    pub mesh: MeshSource,
    /// Scale, rotation and translation applied to the mesh's vertices.
    pub transform: Transform,
}

impl ObstacleSpec {
    /// The placed mesh: read or generated, then transformed. Errors name the OBJ file and line.
    pub fn mesh(&self) -> Result<crate::boundary::mesh::TriangleMesh, Error> {
        let mesh = match &self.mesh {
            MeshSource::Obj(path) => crate::io::load_obj(path)?,
        };
        self.transform.apply(&mesh)
    }
}

/// Where and how often frames are written.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputSpec {
    /// Directory for VTK frames (`None`: no frames); relative paths are relative to the
    /// working directory.
    pub dir: Option<PathBuf>,
    /// A frame every this many steps (≥ 1; default 10).
    pub every: usize,
}

/// Default number of steps between frames.
pub const DEFAULT_OUTPUT_EVERY: usize = 10;

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            dir: None,
            every: DEFAULT_OUTPUT_EVERY,
        }
    }
}

/// A complete simulation setup.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Scene name, used in summaries and statistics.
    pub name: String,
    /// Free-text description (may be empty).
    pub description: String,
    /// Every simulation parameter.
    pub params: Params,
    /// Container boxes; fluid must start inside one of them. May be empty (open space).
    pub containers: Vec<ContainerSpec>,
    /// Static obstacles given as triangle meshes (may be empty).
    pub obstacles: Vec<ObstacleSpec>,
    /// Blocks of fluid (at least one).
    pub fluid_blocks: Vec<FluidBlock>,
    /// Simulated time to run (s).
    pub duration: f64,
    /// Frame output settings.
    pub output: OutputSpec,
}

impl Scene {
    /// The built-in scene called `name`, if there is one (see [`Scene::builtin_names`]).
    pub fn builtin(name: &str) -> Option<Scene> {
        builtin::builtin(name)
    }

    /// Names of the built-in scenes.
    pub fn builtin_names() -> &'static [&'static str] {
        builtin::NAMES
    }

    /// Parses and validates a scene from JSON text. Without a `name` key the scene is called
    /// `scene`. Errors name the offending field and value (and line and column for JSON errors).
    pub fn from_json(text: &str) -> Result<Scene, Error> {
        let scene = file::parse(text, None, "scene")?;
        scene.validate()?;
        Ok(scene)
    }

    /// Reads, parses and validates a scene file. Without a `name` key the scene is named after
    /// the file's stem. Every error message starts with the path.
    pub fn load(path: &Path) -> Result<Scene, Error> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::Io(format!("cannot read scene file {}: {e}", path.display())))?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".to_string());
        let scene = file::parse(&text, Some(path), &stem)?;
        scene
            .validate()
            .map_err(|e| prefixed(e, &format!("{}: ", path.display())))?;
        Ok(scene)
    }

    /// A built-in scene by name, else the scene file at that path. An unknown name that is not
    /// an existing file is an error listing the built-in names.
    pub fn resolve(name_or_path: &str) -> Result<Scene, Error> {
        if let Some(scene) = Scene::builtin(name_or_path) {
            return Ok(scene);
        }
        let path = Path::new(name_or_path);
        if path.is_file() {
            return Scene::load(path);
        }
        let names = Scene::builtin_names().join(", ");
        let looks_like_path = name_or_path.ends_with(".json")
            || name_or_path.contains(std::path::MAIN_SEPARATOR)
            || name_or_path.contains('/');
        let message = if looks_like_path {
            format!("scene file {name_or_path} does not exist (built-in scenes: {names})")
        } else {
            format!(
                "scene `{name_or_path}` is neither a built-in scene ({names}) nor an existing file"
            )
        };
        Err(Error::InvalidArgument {
            field: "scene".to_string(),
            message,
        })
    }

    /// Checks the whole scene: parameters (named by their JSON keys, e.g. `solver.rho`),
    /// duration, output, containers and fluid blocks (every particle centre inside a container).
    pub fn validate(&self) -> Result<(), Error> {
        validate::validate(self)
    }

    /// Total number of fluid particles (saturating on overflow).
    pub fn particle_count(&self) -> usize {
        self.fluid_blocks
            .iter()
            .fold(0usize, |acc, b| acc.saturating_add(b.particle_count()))
    }

    /// A world with the scene's parameters, containers, obstacles and fluid, ready to step.
    /// Obstacle meshes are read (or generated) here; their errors start with `obstacles[i]: `.
    pub fn build_world(&self) -> Result<World, Error> {
        self.validate()?;
        let mut world = World::new(self.params.clone())?;
        for (i, c) in self.containers.iter().enumerate() {
            let aabb = Aabb {
                min: Vec3::from(c.min),
                max: Vec3::from(c.max),
            };
            world
                .add_container(aabb, c.layers)
                .map_err(|e| prefixed(e, &format!("container[{i}]: ")))?;
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            let prefix = format!("obstacles[{i}]: ");
            let mesh = o.mesh().map_err(|e| prefixed(e, &prefix))?;
            world
                .add_boundary_mesh(&mesh)
                .map_err(|e| prefixed(e, &prefix))?;
        }
        for (i, b) in self.fluid_blocks.iter().enumerate() {
            world
                .add_fluid_block(Vec3::from(b.start), b.count, Vec3::from(b.velocity))
                .map_err(|e| prefixed(e, &format!("fluid_blocks[{i}]: ")))?;
        }
        Ok(world)
    }

    /// The scene as pretty JSON with every key written out; [`Scene::from_json`] reads it back
    /// to an equal scene.
    pub fn to_json(&self) -> String {
        file::to_json(self)
    }
}

/// Puts `prefix` in front of an error's message.
fn prefixed(error: Error, prefix: &str) -> Error {
    match error {
        Error::InvalidArgument { field, message } => Error::InvalidArgument {
            field,
            message: format!("{prefix}{message}"),
        },
        Error::Io(message) => Error::Io(format!("{prefix}{message}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"{
        "name": "box",
        "particle_radius": 0.05,
        "container": {"min": [0, 0, 0], "max": [1, 3, 1]},
        "fluid_blocks": [
            {"start": [0.1, 0.1, 0.1], "count": [4, 4, 4]},
            {"start": [0.1, 1.0, 0.1], "count": [2, 3, 2], "velocity": [1, 0, 0]}
        ],
        "duration": 0.5
    }"#;

    fn message(result: Result<Scene, Error>) -> String {
        match result {
            Ok(scene) => panic!("expected an error, got {scene:?}"),
            Err(e) => e.to_string(),
        }
    }

    fn assert_names(msg: &str, parts: &[&str]) {
        for part in parts {
            assert!(msg.contains(part), "{msg:?} should mention {part:?}");
        }
    }

    #[test]
    fn defaults_come_from_params_with_radius() {
        let scene = Scene::from_json(GOOD).unwrap();
        assert_eq!(scene.params, Params::with_radius(0.05));
        assert_eq!(scene.containers[0].layers, 1);
        assert_eq!(scene.fluid_blocks[0].velocity, [0.0; 3]);
        assert_eq!(scene.output, OutputSpec::default());
        assert_eq!(scene.particle_count(), 64 + 12);
    }

    #[test]
    fn every_key_is_read() {
        let text = r#"{
            "name": "all", "description": "every key",
            "particle_radius": 0.02, "rest_density": 998, "mass_factor": 0.9, "stiffness": 1e5,
            "gravity": [0, 0, -9.8],
            "container": [{"min": [0, 0, 0], "max": [1, 1, 1], "layers": 2}],
            "fluid_blocks": [{"start": [0.1, 0.1, 0.1], "count": [2, 2, 2], "velocity": [0, 1, 0]}],
            "solver": {"kind": "jacobi", "rho": 0.8, "delay": 2, "omega2": "seed", "gamma": 0.9,
                       "tau": 1e-6, "max_iterations": 50, "min_iterations": 2,
                       "projection_weight": "unit"},
            "time": {"cfl_factor": 0.4, "dt_min": 1e-5, "dt_max": 1e-2, "dt_initial": 2e-3},
            "viscosity": 0.02, "threads": 2, "duration": 3,
            "output": {"dir": "frames", "every": 5}
        }"#;
        let s = Scene::from_json(text).unwrap();
        let p = &s.params;
        assert_eq!(
            (
                p.particle_radius,
                p.rest_density,
                p.mass_factor,
                p.stiffness
            ),
            (0.02, 998.0, 0.9, 1e5)
        );
        assert_eq!(p.gravity, [0.0, 0.0, -9.8]);
        assert_eq!(p.solver, crate::SolverKind::Jacobi);
        assert_eq!(p.chebyshev.rho, 0.8);
        assert_eq!(p.chebyshev.delay, 2);
        assert_eq!(p.chebyshev.omega2_rule, crate::Omega2Rule::SeedLiteral);
        assert_eq!(p.chebyshev.gamma, 0.9);
        assert_eq!(p.displacement_tolerance, 1e-6);
        assert_eq!((p.min_outer_iterations, p.max_outer_iterations), (2, 50));
        assert_eq!(p.projection_weight, crate::ProjectionWeight::Unit);
        assert_eq!(
            (p.cfl_factor, p.dt_min, p.dt_max, p.dt_initial),
            (0.4, 1e-5, 1e-2, 2e-3)
        );
        assert_eq!((p.viscosity, p.threads), (0.02, 2));
        assert_eq!(s.containers[0].layers, 2);
        assert_eq!(s.fluid_blocks[0].velocity, [0.0, 1.0, 0.0]);
        assert_eq!(s.duration, 3.0);
        assert_eq!(s.description, "every key");
        assert_eq!(s.output.dir.as_deref(), Some(Path::new("frames")));
        assert_eq!(s.output.every, 5);
    }

    #[test]
    fn round_trip_through_json() {
        let mut scenes: Vec<Scene> = Scene::builtin_names()
            .iter()
            .map(|n| Scene::builtin(n).unwrap())
            .collect();
        let mut custom = Scene::from_json(GOOD).unwrap();
        custom.params.displacement_tolerance = 1.0 / 3.0 * 1e-4;
        custom.params.solver = crate::SolverKind::Jacobi1;
        custom.params.projection_weight = crate::ProjectionWeight::Unit;
        custom.params.chebyshev.omega2_rule = crate::Omega2Rule::SeedLiteral;
        custom.output.dir = Some(PathBuf::from("out [1]/frames"));
        custom.description = "quotes \" and [brackets]".to_string();
        scenes.push(custom);
        for scene in scenes {
            let json = scene.to_json();
            assert_eq!(Scene::from_json(&json).unwrap(), scene, "{json}");
        }
    }

    #[test]
    fn to_json_keeps_number_arrays_on_one_line() {
        let json = Scene::builtin("dam_break_small").unwrap().to_json();
        assert!(json.contains("\"count\": [16, 20, 12]"), "{json}");
    }

    #[test]
    fn builtin_files_match_builtins() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        for name in Scene::builtin_names() {
            let loaded = Scene::load(&dir.join(format!("{name}.json"))).unwrap();
            assert_eq!(Some(loaded), Scene::builtin(name), "{name}");
        }
    }

    #[test]
    fn builtins_are_valid_and_sized_as_named() {
        assert!(Scene::builtin("nope").is_none());
        for name in Scene::builtin_names() {
            let scene = Scene::builtin(name).unwrap();
            scene.validate().unwrap();
            assert_eq!(&scene.name, name);
        }
        assert_eq!(
            Scene::builtin("dam_break_30k").unwrap().particle_count(),
            30_000
        );
    }

    #[test]
    fn build_world_adds_containers_and_fluid() {
        let scene = Scene::from_json(GOOD).unwrap();
        let world = scene.build_world().unwrap();
        assert_eq!(world.fluid_count(), 76);
        assert!(world.boundary_count() > 0);
        assert_eq!(world.containers().len(), 1);
        assert_eq!(world.velocities()[64], Vec3::new(1.0, 0.0, 0.0));
    }

    #[test]
    fn negative_radius_names_field_and_value() {
        let text = GOOD.replace("\"particle_radius\": 0.05", "\"particle_radius\": -0.1");
        assert_eq!(
            message(Scene::from_json(&text)),
            "particle_radius must be a positive finite number, got -0.1"
        );
    }

    #[test]
    fn missing_required_fields_are_named() {
        let text = GOOD.replace("\"duration\": 0.5", "\"threads\": 1");
        assert_names(
            &message(Scene::from_json(&text)),
            &["missing field `duration`"],
        );
        let text = GOOD.replace("\"particle_radius\": 0.05,", "");
        assert_names(&message(Scene::from_json(&text)), &["`particle_radius`"]);
        let text = r#"{"particle_radius": 0.05, "duration": 1}"#;
        assert_names(&message(Scene::from_json(text)), &["`fluid_blocks`"]);
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
    fn unknown_keys_are_errors_with_their_path() {
        let text = GOOD.replace("\"duration\": 0.5", "\"duration\": 0.5, \"foo\": 1");
        let msg = message(Scene::from_json(&text));
        assert_names(&msg, &["unknown field `foo`", "line 9"]);
        let text = GOOD.replace("\"count\": [4, 4, 4]", "\"count\": [4, 4, 4], \"speed\": 2");
        assert_names(
            &message(Scene::from_json(&text)),
            &["fluid_blocks[0]", "unknown field `speed`"],
        );
        let text = GOOD.replace("\"max\": [1, 3, 1]", "\"max\": [1, 3, 1], \"layer\": 2");
        assert_names(
            &message(Scene::from_json(&text)),
            &["container", "unknown field `layer`"],
        );
    }

    #[test]
    fn wrong_types_and_names_say_where() {
        let text = GOOD.replace(
            "\"duration\": 0.5",
            "\"duration\": 0.5, \"solver\": {\"kind\": \"sor\"}",
        );
        assert_names(
            &message(Scene::from_json(&text)),
            &["solver.kind", "`sor`", "chebyshev"],
        );
        let text = GOOD.replace("[4, 4, 4]", "[4, -4, 4]");
        assert_names(
            &message(Scene::from_json(&text)),
            &["fluid_blocks[0].count[1]", "-4"],
        );
    }

    #[test]
    fn bad_values_name_the_json_key() {
        let cases = [
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
                "time.dt_max must be a positive finite number, got 0",
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
        let text = GOOD.replace("\"max\": [1, 3, 1]", "\"max\": [1, -3, 1]");
        assert_names(&message(Scene::from_json(&text)), &["container[0]", "-3"]);
    }

    #[test]
    fn malformed_json_names_file_line_and_column() {
        let dir = std::env::temp_dir().join(format!("projfluid-scene-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("broken.json");
        std::fs::write(
            &path,
            "{\n  \"particle_radius\": 0.05,\n  \"duration\" 1\n}\n",
        )
        .unwrap();
        let msg = message(Scene::load(&path));
        assert_names(&msg, &["broken.json", "line 3", "column", "invalid JSON"]);
        let path = dir.join("negative.json");
        std::fs::write(
            &path,
            GOOD.replace("\"particle_radius\": 0.05", "\"particle_radius\": -0.1"),
        )
        .unwrap();
        assert_names(
            &message(Scene::load(&path)),
            &["negative.json: particle_radius", "-0.1"],
        );
        let path = dir.join("unnamed.json");
        std::fs::write(&path, GOOD.replace("\"name\": \"box\",", "")).unwrap();
        assert_eq!(Scene::load(&path).unwrap().name, "unnamed");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn resolve_prefers_builtins_then_files() {
        assert_eq!(
            Scene::resolve("dam_break_small").unwrap(),
            Scene::builtin("dam_break_small").unwrap()
        );
        let msg = message(Scene::resolve("no_such_scene"));
        assert_names(&msg, &["no_such_scene", "dam_break_small", "dam_break_30k"]);
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dam_break_30k.json");
        assert_eq!(
            Scene::resolve(path.to_str().unwrap()).unwrap().name,
            "dam_break_30k"
        );
        assert_names(
            &message(Scene::load(Path::new("/nonexistent/x.json"))),
            &["/nonexistent/x.json"],
        );
    }

    #[test]
    fn documented_example_is_valid() {
        let doc = include_str!("../README.md");
        let example = doc
            .split("```json\n")
            .nth(1)
            .and_then(|rest| rest.split("```").next())
            .expect("README.md has a json scene example");
        let scene = Scene::from_json(example).unwrap();
        let mut expected = Scene::builtin("dam_break_small").unwrap();
        expected.description = scene.description.clone();
        expected.output = OutputSpec {
            dir: Some(PathBuf::from("frames")),
            every: 20,
        };
        assert_eq!(scene, expected);
    }

    /// A scratch directory for scene and OBJ files, removed on drop.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(name: &str) -> Self {
            let dir =
                std::env::temp_dir().join(format!("projfluid-scene-{name}-{}", std::process::id()));
            std::fs::create_dir_all(dir.join("meshes")).unwrap();
            Self(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// A closed unit cube as OBJ text (8 vertices, 6 quads).
    const CUBE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
        f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";

    fn with_obstacle(obstacle: &str) -> String {
        GOOD.replace(
            "\"duration\": 0.5",
            &format!("\"duration\": 0.5, \"obstacles\": [{obstacle}]"),
        )
    }

    #[test]
    fn obstacles_load_relative_to_the_scene_file_and_are_placed() {
        let dir = TempDir::new("obstacle");
        std::fs::write(dir.0.join("meshes/cube.obj"), CUBE_OBJ).unwrap();
        let path = dir.0.join("scene.json");
        let text = with_obstacle(
            r#"{"obj": "meshes/cube.obj", "scale": [0.2, 0.1, 0.2], "rotate_deg": [0, 90, 0], "translate": [0.4, 2.0, 0.6]}"#,
        );
        std::fs::write(&path, &text).unwrap();
        let scene = Scene::load(&path).unwrap();
        assert_eq!(
            scene.obstacles[0].mesh,
            MeshSource::Obj(dir.0.join("meshes/cube.obj"))
        );
        let mesh = scene.obstacles[0].mesh().unwrap();
        // The cube scaled to 0.2 × 0.1 × 0.2, turned 90° about y (x → −z), moved.
        let bounds = mesh.bounds();
        let expected_min = Vec3::new(0.4, 2.0, 0.4);
        let expected_max = Vec3::new(0.6, 2.1, 0.6);
        assert!((bounds.min - expected_min).norm() < 1e-12, "{bounds:?}");
        assert!((bounds.max - expected_max).norm() < 1e-12, "{bounds:?}");
        let with = scene.build_world().unwrap();
        let mut without = scene.clone();
        without.obstacles.clear();
        let without = without.build_world().unwrap();
        let added = with.boundary_count() - without.boundary_count();
        let expected = crate::boundary::mesh::sample_poisson_disk(&mesh, 0.05).len();
        assert_eq!(added, expected);
        // Written back and read again, the scene is the same (the path now absolute).
        assert_eq!(Scene::from_json(&scene.to_json()).unwrap(), scene);
        // A uniform scale may be one number.
        let uniform = Scene::from_json(&with_obstacle(r#"{"obj": "a.obj", "scale": 2}"#)).unwrap();
        assert_eq!(uniform.obstacles[0].transform.scale, [2.0; 3]);
        assert_eq!(uniform.obstacles[0].transform.rotate_deg, [0.0; 3]);
    }

    #[test]
    fn obstacle_errors_name_the_entry_file_and_line() {
        let dir = TempDir::new("obstacle-errors");
        let path = dir.0.join("scene.json");
        std::fs::write(&path, with_obstacle(r#"{"obj": "meshes/missing.obj"}"#)).unwrap();
        let scene = Scene::load(&path).unwrap();
        let msg = scene.build_world().err().unwrap().to_string();
        assert_names(&msg, &["obstacles[0]: cannot read OBJ file", "missing.obj"]);

        std::fs::write(
            dir.0.join("meshes/bad.obj"),
            CUBE_OBJ.replace("f 1 5 8 4", "f 1 5 9 4"),
        )
        .unwrap();
        std::fs::write(&path, with_obstacle(r#"{"obj": "meshes/bad.obj"}"#)).unwrap();
        let msg = Scene::load(&path)
            .unwrap()
            .build_world()
            .err()
            .unwrap()
            .to_string();
        assert_names(
            &msg,
            &[
                "obstacles[0]: ",
                "bad.obj:13: face vertex index 9 is out of range",
            ],
        );

        let msg = message(Scene::from_json(&with_obstacle(
            r#"{"obj": "a.obj", "spin": 1}"#,
        )));
        assert_names(&msg, &["obstacles[0]", "unknown field `spin`"]);
        let msg = message(Scene::from_json(&with_obstacle(r#"{"scale": 1}"#)));
        assert_names(&msg, &["obstacles[0] needs a mesh"]);
        let msg = message(Scene::from_json(&with_obstacle(
            r#"{"obj": "a.obj", "scale": [1, -1, 1]}"#,
        )));
        assert_eq!(
            msg,
            "obstacles[0].scale must be positive along every axis, got [1.0, -1.0, 1.0]"
        );
    }

    #[test]
    fn trailing_garbage_is_an_error() {
        let msg = message(Scene::from_json(&format!("{GOOD} x")));
        assert_names(&msg, &["line 10", "trailing"]);
    }
}
