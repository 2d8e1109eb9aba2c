//! One entry of a scene file's `obstacles`: a mesh source (`obj`, `generated`, or a `box`,
//! `sphere` or `cylinder`) and its placement, converted to and from [`ObstacleSpec`].

use super::bodies::{BoxFile, CylinderFile, SphereFile};
use crate::body::Shape;
use crate::boundary::Transform;
use crate::scene::{MeshSource, ObstacleSpec};
use crate::{Error, Vec3};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One entry of `obstacles`: a mesh source and its placement.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ObstacleFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    obj: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    generated: Option<String>,
    #[serde(rename = "box", default, skip_serializing_if = "Option::is_none")]
    cuboid: Option<BoxFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    sphere: Option<SphereFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cylinder: Option<CylinderFile>,
    scale: Option<Scale>,
    rotate_deg: Option<[f64; 3]>,
    translate: Option<[f64; 3]>,
}

/// `scale`: one factor for all axes, or one per axis.
#[derive(Serialize, Deserialize, Clone, Copy)]
#[serde(untagged)]
enum Scale {
    Uniform(f64),
    PerAxis([f64; 3]),
}

impl ObstacleFile {
    /// The obstacle, with a relative `obj` path taken relative to `base` (the scene file's
    /// directory, if any). `key` names the entry in errors (e.g. `obstacles[2]`).
    pub(super) fn into_spec(self, key: &str, base: Option<&Path>) -> Result<ObstacleSpec, Error> {
        let mut sources = Vec::new();
        if let Some(obj) = self.obj {
            let path = PathBuf::from(obj);
            sources.push(MeshSource::Obj(match base {
                Some(dir) if path.is_relative() => dir.join(path),
                _ => path,
            }));
        }
        if let Some(name) = self.generated {
            sources.push(MeshSource::Generated(name));
        }
        if let Some(b) = self.cuboid {
            sources.push(MeshSource::Primitive(Shape::Box {
                half_extents: Vec3::from(b.half_extents),
            }));
        }
        if let Some(b) = self.sphere {
            sources.push(MeshSource::Primitive(Shape::Sphere { radius: b.radius }));
        }
        if let Some(c) = self.cylinder {
            sources.push(MeshSource::Primitive(Shape::Cylinder {
                radius: c.radius,
                height: c.height,
            }));
        }
        let mesh = match sources.pop() {
            Some(mesh) if sources.is_empty() => mesh,
            _ => {
                return Err(Error::InvalidArgument {
                    field: key.to_string(),
                    message: format!(
                        "{key} needs exactly one mesh: `obj` (an OBJ file path), `generated` \
                         (one of {}), `box` ({{\"half_extents\": [x, y, z]}}), `sphere` \
                         ({{\"radius\": r}}) or `cylinder` ({{\"radius\": r, \"height\": h}})",
                        crate::scene::obstacle::NAMES.join(", ")
                    ),
                });
            }
        };
        let identity = Transform::default();
        Ok(ObstacleSpec {
            mesh,
            transform: Transform {
                scale: match self.scale {
                    None => identity.scale,
                    Some(Scale::Uniform(s)) => [s; 3],
                    Some(Scale::PerAxis(s)) => s,
                },
                rotate_deg: self.rotate_deg.unwrap_or(identity.rotate_deg),
                translate: self.translate.unwrap_or(identity.translate),
            },
        })
    }

    /// Every key written out.
    pub(super) fn from_spec(spec: &ObstacleSpec) -> Self {
        let t = &spec.transform;
        let [x, y, z] = t.scale;
        let (mut obj, mut generated) = (None, None);
        let (mut cuboid, mut sphere, mut cylinder) = (None, None, None);
        match &spec.mesh {
            MeshSource::Obj(path) => obj = Some(path.to_string_lossy().into_owned()),
            MeshSource::Generated(name) => generated = Some(name.clone()),
            &MeshSource::Primitive(Shape::Box { half_extents }) => {
                cuboid = Some(BoxFile {
                    half_extents: half_extents.into(),
                })
            }
            &MeshSource::Primitive(Shape::Sphere { radius }) => {
                sphere = Some(SphereFile { radius })
            }
            &MeshSource::Primitive(Shape::Cylinder { radius, height }) => {
                cylinder = Some(CylinderFile { radius, height })
            }
        }
        ObstacleFile {
            obj,
            generated,
            cuboid,
            sphere,
            cylinder,
            scale: Some(if x == y && y == z {
                Scale::Uniform(x)
            } else {
                Scale::PerAxis(t.scale)
            }),
            rotate_deg: Some(t.rotate_deg),
            translate: Some(t.translate),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::Vec3;
    use crate::scene::test_support::{GOOD, assert_names, message};
    use crate::scene::{MeshSource, Scene};
    use std::path::PathBuf;

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
        let mesh = scene.obstacles[0].mesh(0.025).unwrap();
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
        assert_names(&msg, &["obstacles[0] needs exactly one mesh", "sculpture"]);
        let msg = message(Scene::from_json(&with_obstacle(
            r#"{"obj": "a.obj", "scale": [1, -1, 1]}"#,
        )));
        assert_eq!(
            msg,
            "obstacles[0].scale must be positive along every axis, got [1.0, -1.0, 1.0]"
        );
    }

    /// Boxes, spheres and cylinders need no OBJ: each is tessellated, placed by the transform
    /// and sampled like a mesh, reads back from the JSON it writes, and has its sizes checked.
    #[test]
    fn primitive_obstacles_are_meshes_placed_like_any_other() {
        let text = with_obstacle(
            r#"{"box": {"half_extents": [0.1, 0.2, 0.1]}, "translate": [0.5, 2.5, 0.5]},
               {"sphere": {"radius": 0.15}, "translate": [0.5, 1.6, 0.5]},
               {"cylinder": {"radius": 0.1, "height": 0.4}, "rotate_deg": [90, 0, 0], "translate": [0.3, 2.0, 0.7]}"#,
        );
        let scene = Scene::from_json(&text).unwrap();
        let r = scene.params.particle_radius;
        let bounds: Vec<_> = scene
            .obstacles
            .iter()
            .map(|o| o.mesh(r).unwrap().bounds())
            .collect();
        let close = |a: Vec3, b: Vec3| (a - b).norm() < 1e-9;
        assert!(
            close(bounds[0].min, Vec3::new(0.4, 2.3, 0.4)),
            "{:?}",
            bounds[0]
        );
        assert!(
            close(bounds[0].max, Vec3::new(0.6, 2.7, 0.6)),
            "{:?}",
            bounds[0]
        );
        // A tessellated sphere lies within its radius and reaches it at the poles.
        assert!((bounds[1].max.y - 1.75).abs() < 1e-9, "{:?}", bounds[1]);
        assert!(bounds[1].max.x <= 0.65 + 1e-9 && bounds[1].min.x >= 0.35 - 1e-9);
        // Turned 90° about x, the cylinder's axis lies along z.
        assert!(
            (bounds[2].max.z - bounds[2].min.z - 0.4).abs() < 1e-9,
            "{:?}",
            bounds[2]
        );
        assert_eq!(Scene::from_json(&scene.to_json()).unwrap(), scene);
        let with = scene.build_world().unwrap();
        let mut without = scene.clone();
        without.obstacles.clear();
        assert!(with.boundary_count() > without.build_world().unwrap().boundary_count() + 100);

        let msg = message(Scene::from_json(&with_obstacle(
            r#"{"sphere": {"radius": -0.1}}"#,
        )));
        assert_names(&msg, &["obstacles[0].sphere.radius", "-0.1", "positive"]);
        let msg = message(Scene::from_json(&with_obstacle(
            r#"{"box": {"half_extents": [0.1, 0, 0.1]}, "sphere": {"radius": 0.1}}"#,
        )));
        assert_names(&msg, &["obstacles[0] needs exactly one mesh", "cylinder"]);
    }
}
