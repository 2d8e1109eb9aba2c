//! Scenes: a fluid setup (parameters, container boxes, obstacles, rigid bodies, blocks of
//! fluid, duration, output, probes) read from JSON (format in docs/scene-format.md) or taken from the
//! built-in list.
//!
//! ```
//! use projfluid::scene::Scene;
//! let scene = Scene::builtin("dam_break_small").unwrap();
//! let world = scene.build_world().unwrap();
//! assert_eq!(world.fluid_count(), 16 * 20 * 12);
//! ```

mod bodies;
mod builtin;
mod file;
mod flow;
pub mod obstacle;
mod spec;
#[cfg(test)]
mod test_support;
mod validate;

pub use crate::boundary::ContainerWalls;
pub use bodies::{BodyShape, MotionSpec, SceneBody};
pub use spec::{
    BoxSpec, ContainerSpec, DEFAULT_OUTPUT_EVERY, FluidBlock, MeshSource, ObstacleSpec, OutputSpec,
    SceneEmitter, SceneMaterial,
};

use crate::boundary::Aabb;
use crate::params::Params;
use crate::probe::ProbeSet;
use crate::{Error, Vec3, World};
use std::path::Path;

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
    /// Rigid bodies: static, kinematic or dynamic (may be empty). Body `i` gets id `i`.
    pub bodies: Vec<SceneBody>,
    /// Liquids besides the world's own fluid (may be empty): material `i` here is the world's
    /// material `i + 1` (docs/method.md §14).
    pub materials: Vec<SceneMaterial>,
    /// Blocks of fluid (at least one).
    pub fluid_blocks: Vec<FluidBlock>,
    /// Emitters inserting fluid from the start of the first step (may be empty). Emitter `i`
    /// gets index `i`.
    pub emitters: Vec<SceneEmitter>,
    /// Sinks: boxes removing the fluid in them at the end of every step (may be empty).
    pub sinks: Vec<BoxSpec>,
    /// The domain: fluid outside it at the end of a step is removed (`None`: kept).
    pub domain: Option<BoxSpec>,
    /// Simulated time to run (s).
    pub duration: f64,
    /// Frame output settings.
    pub output: OutputSpec,
    /// Water-height gauges and pressure probes read at a set rate (`None`: no probes).
    pub probes: Option<ProbeSet>,
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
    /// duration, output, containers, obstacles, bodies (e.g. `bodies[1].density`), fluid
    /// blocks (every particle centre inside a container), emitters (e.g. `emitters[0].speed`),
    /// sinks, the domain and the probes (e.g. `probes.gauges[0].bottom`).
    pub fn validate(&self) -> Result<(), Error> {
        validate::validate(self)
    }

    /// Total number of fluid particles (saturating on overflow).
    pub fn particle_count(&self) -> usize {
        self.fluid_blocks
            .iter()
            .fold(0usize, |acc, b| acc.saturating_add(b.particle_count()))
    }

    /// A world with the scene's parameters, containers, obstacles, bodies, fluid, emitters,
    /// sinks and domain, ready to step. Obstacle and body meshes are read (or generated)
    /// here; their errors start with `obstacles[i]: ` or `bodies[i]: `.
    pub fn build_world(&self) -> Result<World, Error> {
        self.validate()?;
        let mut world = World::new(self.params.clone())?;
        self.add_to(&mut world)?;
        Ok(world)
    }

    /// Adds the scene's containers, obstacles, bodies, fluid, emitters, sinks and domain to
    /// `world`, an empty world created with the scene's parameters on a thread pool of the
    /// caller's (as the C API's `pf_world_create_from_scene` does); [`Scene::build_world`]
    /// creates one itself. The scene is validated first. On an error the world may hold
    /// part of the scene: discard it.
    pub fn fill_world(&self, world: &mut World) -> Result<(), Error> {
        self.validate()?;
        self.add_to(world)
    }

    /// [`Scene::fill_world`] without the validation.
    fn add_to(&self, world: &mut World) -> Result<(), Error> {
        for (i, c) in self.containers.iter().enumerate() {
            let aabb = Aabb {
                min: Vec3::from(c.min),
                max: Vec3::from(c.max),
            };
            let added = match (c.walls, c.spacing) {
                (ContainerWalls::Field, _) => world.add_container_field(aabb),
                (ContainerWalls::Particles, Some(spacing)) => {
                    world.add_container_spaced(aabb, c.layers, spacing)
                }
                (ContainerWalls::Particles, None) => world.add_container(aabb, c.layers),
            };
            added.map_err(|e| prefixed(e, &format!("container[{i}]: ")))?;
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            let prefix = format!("obstacles[{i}]: ");
            let r = self.params.particle_radius;
            let mesh = o.mesh(r).map_err(|e| prefixed(e, &prefix))?;
            world
                .add_boundary_mesh(&mesh)
                .map_err(|e| prefixed(e, &prefix))?;
        }
        self.add_bodies(world)?;
        for (i, m) in self.materials.iter().enumerate() {
            world
                .add_material(m.material())
                .map_err(|e| prefixed(e, &format!("materials[{i}]: ")))?;
        }
        for (i, b) in self.fluid_blocks.iter().enumerate() {
            let prefix = format!("fluid_blocks[{i}]: ");
            world
                .set_fluid_material(self.material_id(b))
                .map_err(|e| prefixed(e, &prefix))?;
            world
                .add_fluid_block(Vec3::from(b.start), b.count, Vec3::from(b.velocity))
                .map_err(|e| prefixed(e, &prefix))?;
        }
        world.set_fluid_material(0)?;
        self.add_flow(world)?;
        Ok(())
    }

    /// The world's material id of `block`'s material: 0 for the world's own fluid (or a name
    /// the scene lacks, which validation refuses), else one past its index in `materials`.
    pub fn material_id(&self, block: &FluidBlock) -> crate::MaterialId {
        self.material_named(block.material.as_deref())
    }

    /// The id in the built world of the material named `name` (0, the world's own fluid, for
    /// `None` or a name the scene does not define).
    pub fn material_named(&self, name: Option<&str>) -> crate::MaterialId {
        name.and_then(|name| self.materials.iter().position(|m| m.name == name))
            .map_or(0, |i| (i + 1) as crate::MaterialId)
    }

    /// The scene as pretty JSON with every key written out; [`Scene::from_json`] reads it back
    /// to an equal scene.
    pub fn to_json(&self) -> String {
        file::to_json(self)
    }
}

/// Parses and validates a `probes` object ([`ProbeSet`], the value of the scene key `probes`)
/// from JSON text, on its own: the checks that need the scene (gravity along −y for gauges,
/// a container floor under a gauge without a bottom, the rate against `time.dt_min`) come
/// when a scene holding it is validated. Errors name the key (`probes.gauges[0].bottom`).
pub fn probes_from_json(text: &str) -> Result<ProbeSet, Error> {
    let probes = file::parse_probes(text, None)?;
    probes.validate()?;
    Ok(probes)
}

/// [`probes_from_json`] on the text of the file at `path`; every error message starts with
/// the path.
pub fn load_probes(path: &Path) -> Result<ProbeSet, Error> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::Io(format!("cannot read probes file {}: {e}", path.display())))?;
    let probes = file::parse_probes(&text, Some(path))?;
    probes
        .validate()
        .map_err(|e| prefixed(e, &format!("{}: ", path.display())))?;
    Ok(probes)
}

/// Puts `prefix` in front of an error's message.
fn prefixed(error: Error, prefix: &str) -> Error {
    match error {
        Error::InvalidArgument { field, message } => Error::InvalidArgument {
            field,
            message: format!("{prefix}{message}"),
        },
        Error::Io(message) => Error::Io(format!("{prefix}{message}")),
        Error::OutOfMemory(message) => Error::OutOfMemory(format!("{prefix}{message}")),
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::{GOOD, assert_names, message};
    use super::*;

    #[test]
    fn build_world_adds_containers_and_fluid() {
        let scene = Scene::from_json(GOOD).unwrap();
        let world = scene.build_world().unwrap();
        assert_eq!(world.fluid_count(), 76);
        assert!(world.boundary_count() > 0);
        assert_eq!(world.containers().len(), 1);
        // Walls that are fields: no boundary particles.
        let field = GOOD.replace(
            "\"max\": [1, 3, 1]",
            "\"max\": [1, 3, 1], \"walls\": \"field\"",
        );
        let field = Scene::from_json(&field).unwrap().build_world().unwrap();
        assert_eq!(field.boundary_count(), 0);
        assert_eq!(field.containers().len(), 1);
        assert_eq!(world.velocities()[64], Vec3::new(1.0, 0.0, 0.0));
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
}
