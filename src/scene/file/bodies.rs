//! One entry of a scene file's `bodies`: its kind, one shape (`box`, `sphere`, `cylinder` or
//! an obstacle-style `mesh`), density, pose, velocities and scripted motion, converted to and
//! from [`SceneBody`].

use super::obstacles::ObstacleFile;
use crate::Error;
use crate::body::BodyKind;
use crate::scene::{BodyShape, MotionSpec, SceneBody};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// `kind`: how the body moves.
#[derive(Serialize, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum KindFile {
    Static,
    Kinematic,
    Dynamic,
}

/// `box`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BoxFile {
    pub(super) half_extents: [f64; 3],
}

/// `sphere`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SphereFile {
    pub(super) radius: f64,
}

/// `cylinder`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CylinderFile {
    pub(super) radius: f64,
    pub(super) height: f64,
}

/// One entry of `bodies`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BodyFile {
    kind: KindFile,
    #[serde(rename = "box", default, skip_serializing_if = "Option::is_none")]
    cuboid: Option<BoxFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    sphere: Option<SphereFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cylinder: Option<CylinderFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    mesh: Option<ObstacleFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    density: Option<f64>,
    position: [f64; 3],
    rotation: Option<[f64; 4]>,
    velocity: Option<[f64; 3]>,
    angular_velocity: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    motion: Option<MotionSpec>,
}

impl BodyFile {
    /// Body `i`, with a relative mesh `obj` path taken relative to `base` (the scene file's
    /// directory, if any).
    pub(super) fn into_body(self, i: usize, base: Option<&Path>) -> Result<SceneBody, Error> {
        let key = format!("bodies[{i}]");
        let given = [
            self.cuboid.is_some(),
            self.sphere.is_some(),
            self.cylinder.is_some(),
            self.mesh.is_some(),
        ];
        if given.iter().filter(|&&g| g).count() != 1 {
            return Err(Error::InvalidArgument {
                message: format!(
                    "{key} needs exactly one shape: `box` ({{\"half_extents\": [x, y, z]}}), \
                     `sphere` ({{\"radius\": r}}), `cylinder` ({{\"radius\": r, \"height\": h}}) \
                     or `mesh` (an obstacle-style {{\"obj\": PATH}} or {{\"generated\": NAME}})"
                ),
                field: key,
            });
        }
        let shape = if let Some(b) = self.cuboid {
            BodyShape::Box {
                half_extents: b.half_extents,
            }
        } else if let Some(s) = self.sphere {
            BodyShape::Sphere { radius: s.radius }
        } else if let Some(c) = self.cylinder {
            BodyShape::Cylinder {
                radius: c.radius,
                height: c.height,
            }
        } else {
            let mesh = self.mesh.expect("exactly one shape was given");
            BodyShape::Mesh(mesh.into_spec(&format!("{key}.mesh"), base)?)
        };
        Ok(SceneBody {
            kind: match self.kind {
                KindFile::Static => BodyKind::Static,
                KindFile::Kinematic => BodyKind::Kinematic,
                KindFile::Dynamic => BodyKind::Dynamic,
            },
            shape,
            density: self.density,
            position: self.position,
            rotation: self.rotation.unwrap_or([1.0, 0.0, 0.0, 0.0]),
            velocity: self.velocity.unwrap_or_default(),
            angular_velocity: self.angular_velocity.unwrap_or_default(),
            motion: self.motion,
        })
    }

    /// Every key written out.
    pub(super) fn from_body(b: &SceneBody) -> Self {
        let mut file = BodyFile {
            kind: match b.kind {
                BodyKind::Static => KindFile::Static,
                BodyKind::Kinematic => KindFile::Kinematic,
                BodyKind::Dynamic => KindFile::Dynamic,
            },
            cuboid: None,
            sphere: None,
            cylinder: None,
            mesh: None,
            density: b.density,
            position: b.position,
            rotation: Some(b.rotation),
            velocity: Some(b.velocity),
            angular_velocity: Some(b.angular_velocity),
            motion: b.motion,
        };
        match &b.shape {
            BodyShape::Box { half_extents } => {
                file.cuboid = Some(BoxFile {
                    half_extents: *half_extents,
                })
            }
            &BodyShape::Sphere { radius } => file.sphere = Some(SphereFile { radius }),
            &BodyShape::Cylinder { radius, height } => {
                file.cylinder = Some(CylinderFile { radius, height })
            }
            BodyShape::Mesh(source) => file.mesh = Some(ObstacleFile::from_spec(source)),
        }
        file
    }
}

#[cfg(test)]
mod tests {
    use crate::body::BodyKind;
    use crate::scene::test_support::{GOOD, assert_names, message};
    use crate::scene::{BodyShape, MeshSource, Scene};

    fn with_bodies(bodies: &str) -> String {
        GOOD.replace(
            "\"duration\": 0.5",
            &format!("\"duration\": 0.5, \"bodies\": [{bodies}]"),
        )
    }

    /// A kinematic paddle with a script, a dynamic box, a static generated mesh and a
    /// turned cylinder, clear of the fluid of `GOOD`.
    const BODIES: &str = r#"
        {"kind": "kinematic", "box": {"half_extents": [0.02, 0.4, 0.45]}, "position": [0.9, 1.2, 0.5],
         "motion": {"amplitude": [0.03, 0, 0], "period": 0.8, "phase": 0.5}},
        {"kind": "dynamic", "sphere": {"radius": 0.1}, "density": 600, "position": [0.5, 2.5, 0.5],
         "velocity": [0, -1, 0], "angular_velocity": [0, 0, 2]},
        {"kind": "static", "mesh": {"generated": "sculpture", "scale": 0.1}, "position": [0.5, 2.0, 0.5]},
        {"kind": "static", "cylinder": {"radius": 0.05, "height": 0.3}, "density": 2000,
         "position": [0.2, 2.6, 0.3], "rotation": [0.7071067811865476, 0, 0, 0.7071067811865476]}"#;

    #[test]
    fn bodies_are_read_built_and_written_back() {
        let scene = Scene::from_json(&with_bodies(BODIES)).unwrap();
        assert_eq!(scene.bodies.len(), 4);
        let paddle = &scene.bodies[0];
        assert_eq!(paddle.kind, BodyKind::Kinematic);
        assert_eq!(paddle.rotation, [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(paddle.density, None);
        let motion = paddle.motion.unwrap();
        assert_eq!((motion.angular_amplitude, motion.period), ([0.0; 3], 0.8));
        assert_eq!(scene.bodies[1].angular_velocity, [0.0, 0.0, 2.0]);
        assert!(matches!(
            &scene.bodies[2].shape,
            BodyShape::Mesh(o) if o.mesh == MeshSource::Generated("sculpture".into())
        ));
        let world = scene.build_world().unwrap();
        assert_eq!(world.bodies().len(), 4);
        assert_eq!(world.bodies()[1].kind(), BodyKind::Dynamic);
        assert_eq!(world.bodies()[1].velocity().linear.y, -1.0);
        let cylinder = world.bodies()[3].centre_of_mass();
        assert!((cylinder - crate::Vec3::new(0.2, 2.6, 0.3)).norm() < 1e-9);
        // Written back and read again, the scene is the same.
        let json = scene.to_json();
        assert!(json.contains("\"bodies\""), "{json}");
        assert_eq!(Scene::from_json(&json).unwrap(), scene, "{json}");
    }

    #[test]
    fn body_errors_name_the_key() {
        let body = |rest: &str| with_bodies(&format!(r#"{{"kind": "kinematic", {rest}}}"#));
        let at = "\"position\": [0.5, 2.5, 0.5]";
        let sphere = "\"sphere\": {\"radius\": 0.1}";
        let cases = [
            (
                with_bodies(
                    r#"{"kind": "floating", "sphere": {"radius": 0.1}, "position": [0, 0, 0]}"#,
                ),
                &["bodies[0].kind", "`floating`", "dynamic"][..],
            ),
            (
                body(at),
                &["bodies[0] needs exactly one shape", "`box`"][..],
            ),
            (
                body(&format!(
                    "{sphere}, \"box\": {{\"half_extents\": [1, 1, 1]}}, {at}"
                )),
                &["bodies[0] needs exactly one shape"][..],
            ),
            (body(sphere), &["bodies[0]", "missing field `position`"][..]),
            (
                body(&format!("{sphere}, {at}, \"spin\": 1")),
                &["bodies[0]", "unknown field `spin`"][..],
            ),
            (
                body(&format!(
                    "\"box\": {{\"half_extents\": [0.1, 0, 0.1]}}, {at}"
                )),
                &["bodies[0].box.half_extents[1] must be a positive finite length (m), got 0"][..],
            ),
            (
                body(&format!(
                    "\"cylinder\": {{\"radius\": 0.1, \"height\": -1}}, {at}"
                )),
                &["bodies[0].cylinder.height", "-1"][..],
            ),
            (
                body(&format!("{sphere}, {at}, \"density\": -3")),
                &["bodies[0].density must be a positive finite number of kg/m³, got -3"][..],
            ),
            (
                body(&format!("{sphere}, {at}, \"rotation\": [1, 0.1, 0, 0]")),
                &["bodies[0].rotation must be a finite unit quaternion"][..],
            ),
            (
                body(&format!("{sphere}, {at}, \"motion\": {{\"period\": 0}}")),
                &["bodies[0].motion.period", "got 0"][..],
            ),
            (
                body(&format!(
                    "{sphere}, {at}, \"motion\": {{\"amplitude\": [1, 0, 0]}}"
                )),
                &["bodies[0].motion", "missing field `period`"][..],
            ),
            (
                body(&format!("\"mesh\": {{\"generated\": \"squirrel\"}}, {at}")),
                &["bodies[0].mesh.generated", "`squirrel`"][..],
            ),
            (
                body(&format!("\"mesh\": {{\"scale\": 2}}, {at}")),
                &["bodies[0].mesh needs exactly one mesh"][..],
            ),
        ];
        for (text, parts) in cases {
            assert_names(&message(Scene::from_json(&text)), parts);
        }
        let dynamic = with_bodies(
            r#"{"kind": "dynamic", "sphere": {"radius": 0.1}, "position": [0.5, 2.5, 0.5]}"#,
        );
        assert_eq!(
            message(Scene::from_json(&dynamic)),
            "bodies[0].density must be given for a dynamic body (kg/m³), got none"
        );
        let scripted = with_bodies(
            r#"{"kind": "static", "sphere": {"radius": 0.1}, "position": [0.5, 2.5, 0.5],
                "motion": {"period": 1}}"#,
        );
        assert_names(
            &message(Scene::from_json(&scripted)),
            &["bodies[0].motion", "kinematic bodies only", "a static body"],
        );
        // A mesh that cannot be read fails when the world is built, naming the body.
        let missing = with_bodies(
            r#"{"kind": "static", "mesh": {"obj": "/nonexistent/paddle.obj"}, "position": [0, 0, 0]}"#,
        );
        let msg = Scene::from_json(&missing)
            .unwrap()
            .build_world()
            .err()
            .unwrap()
            .to_string();
        assert_names(&msg, &["bodies[0]: cannot read OBJ file", "paddle.obj"]);
    }

    /// The wave maker of docs/scene-format.md reads, and its paddle is `wave_tank`'s.
    #[test]
    fn documented_bodies_example_is_valid() {
        let doc = include_str!("../../../docs/scene-format.md");
        let example = doc
            .split("```json\n")
            .find(|block| block.starts_with("\"bodies\""))
            .and_then(|rest| rest.split("```").next())
            .expect("docs/scene-format.md has a bodies example");
        let text = GOOD.replace(
            "\"duration\": 0.5",
            &format!("\"duration\": 0.5, {example}"),
        );
        let scene = Scene::from_json(&text).unwrap();
        assert_eq!(scene.bodies.len(), 2);
        let builtin = Scene::builtin("wave_tank").unwrap();
        assert_eq!(scene.bodies[0], builtin.bodies[0]);
        assert_eq!(scene.bodies[1].density, Some(600.0));
    }
}
