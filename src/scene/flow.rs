//! Inflow and outflow in a scene: its emitters, sinks and domain (docs/method.md §12), their
//! checks (errors name the JSON key, e.g. `emitters[0].speed`) and how a world gets them.

use super::{BoxSpec, Scene};
use crate::emitter::{Emitter, EmitterShape, EmitterState};
use crate::{Error, World};

/// The JSON key of an emitter's shape: `disc` or `rect`.
pub(super) fn shape_key(shape: &EmitterShape) -> &'static str {
    match shape {
        EmitterShape::Disc { .. } => "disc",
        EmitterShape::Rectangle { .. } => "rect",
    }
}

/// Renames an emitter error's field (`emitter.speed`, `emitter.shape.radius`, …) to the JSON
/// key of emitter `i` (`emitters[i].speed`, `emitters[i].disc.radius`, …).
fn emitter_key(i: usize, shape: &EmitterShape, e: Error) -> Error {
    let Error::InvalidArgument { field, message } = e else {
        return e;
    };
    let rest = field.strip_prefix("emitter.").unwrap_or(&field);
    let rest = match rest.strip_prefix("shape") {
        Some(tail) => format!("{}{tail}", shape_key(shape)),
        None => rest.to_string(),
    };
    let key = format!("emitters[{i}].{rest}");
    let message = match message.strip_prefix(field.as_str()) {
        Some(tail) => format!("{key}{tail}"),
        None => message,
    };
    Error::InvalidArgument {
        field: key,
        message,
    }
}

/// Finite corners with `min ≤ max` along every axis; errors name `key.min` or `key.max`.
fn check_box(key: &str, b: &BoxSpec) -> Result<(), Error> {
    for (name, v) in [("min", b.min), ("max", b.max)] {
        if v.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid(
                format!("{key}.{name}"),
                format!("{v:?}"),
                "must be finite",
            ));
        }
    }
    if let Some(a) = (0..3).find(|&a| b.min[a] > b.max[a]) {
        return Err(Error::invalid(
            format!("{key}.max"),
            format!("{:?}", b.max),
            &format!(
                "must be at least min {:?} along every axis ({})",
                b.min,
                ["x", "y", "z"][a]
            ),
        ));
    }
    Ok(())
}

/// Checks the scene's emitters (on the fluid lattice of spacing 2r), sinks and domain.
pub(super) fn check_flow(scene: &Scene) -> Result<(), Error> {
    let spacing = 2.0 * scene.params.particle_radius;
    for (i, emitter) in scene.emitters.iter().enumerate() {
        let spec = &emitter.spec;
        let key = format!("emitters[{i}]");
        super::validate::check_material_name(scene, &key, emitter.material.as_deref())?;
        let state = EmitterState {
            spec: *spec,
            travelled: spacing,
            emitted: 0,
            material: 0,
        };
        Emitter::new(state, spacing).map_err(|e| emitter_key(i, &spec.shape, e))?;
    }
    for (i, s) in scene.sinks.iter().enumerate() {
        check_box(&format!("sinks[{i}]"), s)?;
    }
    if let Some(d) = &scene.domain {
        check_box("domain", d)?;
    }
    Ok(())
}

impl Scene {
    /// Adds the scene's emitters (emitter `i` gets index `i` in a world without emitters),
    /// sinks and domain to `world`. Errors start with `emitters[i]: `, `sinks[i]: ` or
    /// `domain: `. [`Scene::build_world`] calls it.
    pub fn add_flow(&self, world: &mut World) -> Result<(), Error> {
        for (i, emitter) in self.emitters.iter().enumerate() {
            let prefix = format!("emitters[{i}]: ");
            world
                .set_fluid_material(self.material_named(emitter.material.as_deref()))
                .and_then(|()| world.add_emitter(emitter.spec))
                .map_err(|e| super::prefixed(e, &prefix))?;
        }
        world.set_fluid_material(0)?;
        for (i, s) in self.sinks.iter().enumerate() {
            world
                .add_sink(s.aabb())
                .map_err(|e| super::prefixed(e, &format!("sinks[{i}]: ")))?;
        }
        if let Some(d) = &self.domain {
            world
                .set_domain(Some(d.aabb()))
                .map_err(|e| super::prefixed(e, "domain: "))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::Scene;
    use crate::scene::test_support::{GOOD, assert_names, message};
    use crate::{EmitterShape, Vec3};

    /// `GOOD` with these extra top-level keys.
    fn with(extra: &str) -> String {
        GOOD.replace("\"duration\": 0.5", &format!("\"duration\": 0.5, {extra}"))
    }

    const FLOW: &str = r#""emitters": [
            {"disc": {"radius": 0.2}, "position": [0.5, 2.5, 0.5], "direction": [0, -1, 0],
             "speed": 1.5, "end_time": 0.3},
            {"rect": {"half_extents": [0.2, 0.1]}, "position": [0.1, 2, 0.5],
             "direction": [1, 0, 0], "speed": 2}
        ],
        "sinks": [{"min": [0, 0, 0], "max": [0.2, 0.2, 0.2]}],
        "domain": {"min": [0, 0, 0], "max": [1, 3, 1]}"#;

    #[test]
    fn emitters_sinks_and_domain_are_read_built_and_written_back() {
        let scene = Scene::from_json(&with(FLOW)).unwrap();
        assert_eq!(scene.emitters.len(), 2);
        assert_eq!(
            scene.emitters[0].spec.shape,
            EmitterShape::Disc { radius: 0.2 }
        );
        assert_eq!(scene.emitters[0].spec.end_time, Some(0.3));
        assert_eq!(scene.emitters[1].spec.end_time, None);
        assert_eq!(scene.emitters[1].spec.direction, Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(scene.sinks[0].max, [0.2; 3]);
        assert_eq!(scene.domain.unwrap().max, [1.0, 3.0, 1.0]);
        assert_eq!(Scene::from_json(&scene.to_json()).unwrap(), scene);
        let mut world = scene.build_world().unwrap();
        assert_eq!((world.emitters().len(), world.sinks().len()), (2, 1));
        assert_eq!(world.domain(), Some(&scene.domain.unwrap().aabb()));
        world.step().unwrap();
        assert!(world.emitted_count() > 0 && world.removed_count() > 0);
        // Without them nothing is written.
        let plain = Scene::from_json(GOOD).unwrap().to_json();
        assert!(!plain.contains("emitters") && !plain.contains("sinks"));
        assert!(!plain.contains("domain"));
    }

    /// An emitter's `material` names one of the scene's materials: it emits that liquid,
    /// fluid blocks keep theirs, and the key is written back.
    #[test]
    fn an_emitter_emits_the_material_it_names() {
        let json = with(
            r#""materials": [{"name": "oil", "rest_density": 800}],
        "emitters": [{"disc": {"radius": 0.2}, "position": [0.5, 2.5, 0.5],
                      "direction": [0, -1, 0], "speed": 1.5, "material": "oil"}]"#,
        );
        let scene = Scene::from_json(&json).unwrap();
        assert_eq!(scene.emitters[0].material.as_deref(), Some("oil"));
        assert_eq!(Scene::from_json(&scene.to_json()).unwrap(), scene);
        let mut world = scene.build_world().unwrap();
        let blocks = world.fluid_count();
        assert_eq!(world.fluid_material(), 0);
        world.step().unwrap();
        let materials = world.particle_materials();
        assert!(materials.len() > blocks);
        assert!(materials[..blocks].iter().all(|&m| m == 0));
        assert!(materials[blocks..].iter().all(|&m| m == 1));
        let unknown = json.replace("\"material\": \"oil\"", "\"material\": \"tar\"");
        let e = message(Scene::from_json(&unknown));
        assert!(
            e.contains("emitters[0].material")
                && e.contains("must name one of the scene's materials"),
            "{e}"
        );
    }

    #[test]
    fn bad_emitters_sinks_and_domains_name_the_key() {
        let emitter = |body: &str| with(&format!("\"emitters\": [{body}]"));
        let disc =
            r#""disc": {"radius": 0.2}, "position": [0.5, 2.5, 0.5], "direction": [0, -1, 0]"#;
        let cases = [
            (
                emitter(&format!("{{{disc}, \"speed\": -1}}")),
                "emitters[0].speed must be a positive finite speed (m/s), got -1",
            ),
            (
                emitter(
                    r#"{"disc": {"radius": -0.2}, "position": [0, 0, 0], "direction": [0, -1, 0], "speed": 1}"#,
                ),
                "emitters[0].disc.radius must be a positive finite length (m), got -0.2",
            ),
            (
                emitter(
                    r#"{"rect": {"half_extents": [0.2, 0]}, "position": [0, 0, 0], "direction": [0, -1, 0], "speed": 1}"#,
                ),
                "emitters[0].rect.half_extents[1] must be a positive finite length (m), got 0",
            ),
            (
                emitter(
                    r#"{"disc": {"radius": 0.01}, "position": [0, 0, 0], "direction": [0, -1, 0], "speed": 1}"#,
                ),
                "emitters[0].disc has zero area",
            ),
            (
                emitter(
                    r#"{"disc": {"radius": 0.2}, "position": [0, 0, 0], "direction": [0, 0, 0], "speed": 1}"#,
                ),
                "emitters[0].direction must be a non-zero finite vector",
            ),
            (
                emitter(r#"{"position": [0, 0, 0], "direction": [0, -1, 0], "speed": 1}"#),
                "emitters[0] needs exactly one opening",
            ),
            (
                with(r#""sinks": [{"min": [0, 0, 0], "max": [1, -1, 1]}]"#),
                "sinks[0].max must be at least min [0.0, 0.0, 0.0] along every axis (y), got [1.0, -1.0, 1.0]",
            ),
            (
                with(r#""domain": {"min": [0, 0, 0], "max": [1, 1, 1], "layers": 1}"#),
                "unknown field `layers`",
            ),
            (
                with(r#""domain": {"min": [0, 0, 0]}"#),
                "missing field `max`",
            ),
        ];
        for (text, expected) in cases {
            assert_names(&message(Scene::from_json(&text)), &[expected]);
        }
    }
}
