//! The JSON form of a scene: serde structures mirroring docs/scene-format.md and their
//! conversion to and from [`Scene`].

mod bodies;
mod error;
mod flow;
mod obstacles;
mod print;
#[cfg(test)]
mod tests;

use super::{BoxSpec, ContainerSpec, FluidBlock, OutputSpec, Scene, SceneMaterial};
use crate::params::{ChebyshevParams, Omega2Rule, Params, ProjectionWeight, SolverKind};
use crate::probe::ProbeSet;
use crate::{Backend, Error};
use bodies::BodyFile;
use error::json_error;
use flow::EmitterFile;
use obstacles::ObstacleFile;
use print::inline_number_arrays;
use serde::de::value::{MapAccessDeserializer, SeqAccessDeserializer};
use serde::de::{MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;
use std::path::{Path, PathBuf};

/// The top-level JSON object. Optional keys are `None` when absent.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    name: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    description: Option<String>,
    particle_radius: f64,
    rest_density: Option<f64>,
    mass_factor: Option<f64>,
    stiffness: Option<f64>,
    gravity: Option<[f64; 3]>,
    container: Option<Containers>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    obstacles: Option<Vec<ObstacleFile>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    bodies: Option<Vec<BodyFile>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    materials: Option<Vec<SceneMaterial>>,
    fluid_blocks: Vec<FluidBlock>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    emitters: Option<Vec<EmitterFile>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    sinks: Option<Vec<BoxSpec>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    domain: Option<BoxSpec>,
    solver: Option<SolverFile>,
    time: Option<TimeFile>,
    viscosity: Option<f64>,
    kinematic_viscosity: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    surface_tension: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    wall_adhesion: Option<f64>,
    vorticity_confinement: Option<f64>,
    no_slip: Option<bool>,
    threads: Option<usize>,
    backend: Option<Backend>,
    duration: f64,
    output: Option<OutputFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    probes: Option<ProbeSet>,
}

/// `solver`: the global solver and the outer iteration.
#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct SolverFile {
    kind: Option<SolverKind>,
    rho: Option<RhoSetting>,
    delay: Option<usize>,
    omega2: Option<Omega2Rule>,
    gamma: Option<f64>,
    eta: Option<f64>,
    tau: Option<f64>,
    warm_start: Option<f64>,
    coarse_correction: Option<bool>,
    max_iterations: Option<usize>,
    min_iterations: Option<usize>,
    projection_weight: Option<ProjectionWeight>,
}

/// `time`: step size control.
#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct TimeFile {
    cfl_factor: Option<f64>,
    dt_min: Option<f64>,
    dt_max: Option<f64>,
    dt_initial: Option<f64>,
}

/// `output`: frame directory and interval.
#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct OutputFile {
    dir: Option<String>,
    every: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    fps: Option<f64>,
}

/// `solver.rho`: a number in [0, 1), or `"auto"` for the online estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
enum RhoSetting {
    Value(f64),
    Auto,
}

impl Serialize for RhoSetting {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            RhoSetting::Value(v) => s.serialize_f64(*v),
            RhoSetting::Auto => s.serialize_str("auto"),
        }
    }
}

impl<'de> Deserialize<'de> for RhoSetting {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = RhoSetting;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number in [0, 1) or \"auto\"")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<RhoSetting, E> {
                Ok(RhoSetting::Value(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<RhoSetting, E> {
                Ok(RhoSetting::Value(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<RhoSetting, E> {
                Ok(RhoSetting::Value(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<RhoSetting, E> {
                match v {
                    "auto" => Ok(RhoSetting::Auto),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// `container`: one object or an array of objects; written back as an array.
struct Containers(Vec<ContainerSpec>);

impl Serialize for Containers {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(s)
    }
}

impl<'de> Deserialize<'de> for Containers {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct OneOrMany;
        impl<'de> Visitor<'de> for OneOrMany {
            type Value = Containers;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a container object or an array of container objects")
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Containers, A::Error> {
                ContainerSpec::deserialize(MapAccessDeserializer::new(map))
                    .map(|c| Containers(vec![c]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Containers, A::Error> {
                Vec::deserialize(SeqAccessDeserializer::new(seq)).map(Containers)
            }
        }
        d.deserialize_any(OneOrMany)
    }
}

/// Parses a `probes` object (the scene key's value, e.g. a file of its own) without
/// validating values. `origin` (the file, if any) and the line and column start the message
/// of a JSON error, whose key path starts with `probes`.
pub(super) fn parse_probes(text: &str, origin: Option<&Path>) -> Result<ProbeSet, Error> {
    let mut de = serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(&mut de)
        .map_err(|e| {
            let inner = e.path().to_string();
            let path = match inner.as_str() {
                "." => "probes".to_string(),
                _ => format!("probes.{inner}"),
            };
            json_error(e.into_inner(), &path, origin)
        })
        .and_then(|p| de.end().map(|()| p).map_err(|e| json_error(e, ".", origin)))
}

/// Parses scene JSON without validating values. `origin` (the file, if any) and the line and
/// column start the message of a JSON error; `default_name` names a scene without `name`.
pub(super) fn parse(text: &str, origin: Option<&Path>, default_name: &str) -> Result<Scene, Error> {
    let mut de = serde_json::Deserializer::from_str(text);
    let file: SceneFile = serde_path_to_error::deserialize(&mut de)
        .map_err(|e| {
            let path = e.path().to_string();
            json_error(e.into_inner(), &path, origin)
        })
        .and_then(|f| de.end().map(|()| f).map_err(|e| json_error(e, ".", origin)))?;
    let base = origin.and_then(Path::parent);
    file.into_scene(default_name, base)
}

impl SceneFile {
    /// Fills in defaults from [`Params::with_radius`]; relative obstacle paths are taken
    /// relative to `base`.
    fn into_scene(self, default_name: &str, base: Option<&Path>) -> Result<Scene, Error> {
        let mut p = Params::with_radius(self.particle_radius);
        let set = |slot: &mut f64, v: Option<f64>| *slot = v.unwrap_or(*slot);
        set(&mut p.rest_density, self.rest_density);
        set(&mut p.mass_factor, self.mass_factor);
        set(&mut p.stiffness, self.stiffness);
        p.gravity = self.gravity.unwrap_or(p.gravity);
        set(&mut p.viscosity, self.viscosity);
        set(&mut p.kinematic_viscosity, self.kinematic_viscosity);
        set(&mut p.surface_tension, self.surface_tension);
        set(&mut p.wall_adhesion, self.wall_adhesion);
        set(&mut p.vorticity_confinement, self.vorticity_confinement);
        p.no_slip = self.no_slip.unwrap_or(p.no_slip);
        p.threads = self.threads.unwrap_or(p.threads);
        p.backend = self.backend.unwrap_or(p.backend);
        let s = self.solver.unwrap_or_default();
        p.solver = s.kind.unwrap_or(p.solver);
        let c: &mut ChebyshevParams = &mut p.chebyshev;
        match s.rho {
            Some(RhoSetting::Value(v)) => {
                c.rho = v;
                c.auto_rho = false;
            }
            Some(RhoSetting::Auto) => c.auto_rho = true,
            None => {}
        }
        c.delay = s.delay.unwrap_or(c.delay);
        c.omega2_rule = s.omega2.unwrap_or(c.omega2_rule);
        set(&mut c.gamma, s.gamma);
        set(&mut p.density_tolerance, s.eta);
        set(&mut p.displacement_tolerance, s.tau);
        set(&mut p.warm_start, s.warm_start);
        p.coarse_correction = s.coarse_correction.unwrap_or(p.coarse_correction);
        p.max_outer_iterations = s.max_iterations.unwrap_or(p.max_outer_iterations);
        p.min_outer_iterations = s.min_iterations.unwrap_or(p.min_outer_iterations);
        p.projection_weight = s.projection_weight.unwrap_or(p.projection_weight);
        let t = self.time.unwrap_or_default();
        set(&mut p.cfl_factor, t.cfl_factor);
        set(&mut p.dt_min, t.dt_min);
        set(&mut p.dt_max, t.dt_max);
        set(&mut p.dt_initial, t.dt_initial);
        let obstacles = self
            .obstacles
            .unwrap_or_default()
            .into_iter()
            .enumerate()
            .map(|(i, o)| o.into_spec(&format!("obstacles[{i}]"), base))
            .collect::<Result<_, _>>()?;
        let bodies = self
            .bodies
            .unwrap_or_default()
            .into_iter()
            .enumerate()
            .map(|(i, b)| b.into_body(i, base))
            .collect::<Result<_, _>>()?;
        let emitters = self
            .emitters
            .unwrap_or_default()
            .into_iter()
            .enumerate()
            .map(|(i, e)| e.into_emitter(i))
            .collect::<Result<_, _>>()?;
        let o = self.output.unwrap_or_default();
        Ok(Scene {
            name: self.name.unwrap_or_else(|| default_name.to_string()),
            description: self.description.unwrap_or_default(),
            params: p,
            containers: self.container.map(|c| c.0).unwrap_or_default(),
            obstacles,
            bodies,
            materials: self.materials.unwrap_or_default(),
            fluid_blocks: self.fluid_blocks,
            emitters,
            sinks: self.sinks.unwrap_or_default(),
            domain: self.domain,
            duration: self.duration,
            output: OutputSpec {
                dir: o.dir.map(PathBuf::from),
                every: o.every.unwrap_or(super::DEFAULT_OUTPUT_EVERY),
                fps: o.fps,
            },
            probes: self.probes,
        })
    }

    /// Every key written out.
    fn from_scene(scene: &Scene) -> Self {
        let p = &scene.params;
        let c = &p.chebyshev;
        SceneFile {
            name: Some(scene.name.clone()),
            description: Some(scene.description.clone()).filter(|d| !d.is_empty()),
            particle_radius: p.particle_radius,
            rest_density: Some(p.rest_density),
            mass_factor: Some(p.mass_factor),
            stiffness: Some(p.stiffness),
            gravity: Some(p.gravity),
            container: Some(Containers(scene.containers.clone())),
            obstacles: Some(
                scene
                    .obstacles
                    .iter()
                    .map(ObstacleFile::from_spec)
                    .collect(),
            )
            .filter(|o: &Vec<ObstacleFile>| !o.is_empty()),
            bodies: Some(scene.bodies.iter().map(BodyFile::from_body).collect())
                .filter(|b: &Vec<BodyFile>| !b.is_empty()),
            materials: Some(scene.materials.clone()).filter(|m| !m.is_empty()),
            fluid_blocks: scene.fluid_blocks.clone(),
            emitters: Some(
                scene
                    .emitters
                    .iter()
                    .map(EmitterFile::from_emitter)
                    .collect(),
            )
            .filter(|e: &Vec<EmitterFile>| !e.is_empty()),
            sinks: Some(scene.sinks.clone()).filter(|s| !s.is_empty()),
            domain: scene.domain,
            solver: Some(SolverFile {
                kind: Some(p.solver),
                rho: Some(if c.auto_rho {
                    RhoSetting::Auto
                } else {
                    RhoSetting::Value(c.rho)
                }),
                delay: Some(c.delay),
                omega2: Some(c.omega2_rule),
                gamma: Some(c.gamma),
                eta: Some(p.density_tolerance),
                tau: Some(p.displacement_tolerance),
                warm_start: Some(p.warm_start),
                coarse_correction: Some(p.coarse_correction),
                max_iterations: Some(p.max_outer_iterations),
                min_iterations: Some(p.min_outer_iterations),
                projection_weight: Some(p.projection_weight),
            }),
            time: Some(TimeFile {
                cfl_factor: Some(p.cfl_factor),
                dt_min: Some(p.dt_min),
                dt_max: Some(p.dt_max),
                dt_initial: Some(p.dt_initial),
            }),
            viscosity: Some(p.viscosity),
            kinematic_viscosity: Some(p.kinematic_viscosity),
            surface_tension: Some(p.surface_tension).filter(|&sigma| sigma > 0.0),
            wall_adhesion: Some(p.wall_adhesion).filter(|&w| w > 0.0),
            vorticity_confinement: Some(p.vorticity_confinement),
            no_slip: Some(p.no_slip),
            threads: Some(p.threads),
            backend: Some(p.backend),
            duration: scene.duration,
            output: Some(OutputFile {
                dir: scene
                    .output
                    .dir
                    .as_ref()
                    .map(|d| d.to_string_lossy().into_owned()),
                every: Some(scene.output.every),
                fps: scene.output.fps,
            }),
            probes: scene.probes.clone(),
        }
    }
}

/// Pretty JSON of every key, with arrays of numbers on one line.
pub(super) fn to_json(scene: &Scene) -> String {
    // Serialising plain data with string keys cannot fail; fall back to compact output anyway.
    let file = SceneFile::from_scene(scene);
    let pretty = serde_json::to_string_pretty(&file)
        .or_else(|_| serde_json::to_string(&file))
        .unwrap_or_default();
    inline_number_arrays(&pretty)
}
