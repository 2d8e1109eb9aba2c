//! One entry of a scene file's `obstacles`: a mesh source (`obj` or `generated`) and its
//! placement, converted to and from [`ObstacleSpec`].

use crate::Error;
use crate::boundary::Transform;
use crate::scene::{MeshSource, ObstacleSpec};
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
        let mesh = match (self.obj, self.generated) {
            (Some(obj), None) => {
                let path = PathBuf::from(obj);
                MeshSource::Obj(match base {
                    Some(dir) if path.is_relative() => dir.join(path),
                    _ => path,
                })
            }
            (None, Some(name)) => MeshSource::Generated(name),
            _ => {
                return Err(Error::InvalidArgument {
                    field: key.to_string(),
                    message: format!(
                        "{key} needs exactly one mesh: `obj` (an OBJ file path) or \
                         `generated` (one of {})",
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
        ObstacleFile {
            obj: match &spec.mesh {
                MeshSource::Obj(path) => Some(path.to_string_lossy().into_owned()),
                MeshSource::Generated(_) => None,
            },
            generated: match &spec.mesh {
                MeshSource::Generated(name) => Some(name.clone()),
                MeshSource::Obj(_) => None,
            },
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
        assert_names(&msg, &["obstacles[0] needs exactly one mesh", "sculpture"]);
        let msg = message(Scene::from_json(&with_obstacle(
            r#"{"obj": "a.obj", "scale": [1, -1, 1]}"#,
        )));
        assert_eq!(
            msg,
            "obstacles[0].scale must be positive along every axis, got [1.0, -1.0, 1.0]"
        );
    }
}
