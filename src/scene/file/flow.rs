//! One entry of a scene file's `emitters`: one opening (`disc` or `rect`), position,
//! direction, speed, optional end time and material, converted to and from a
//! [`SceneEmitter`]. Sinks and
//! the domain are plain [`BoxSpec`](crate::scene::BoxSpec)s.

use crate::emitter::{EmitterShape, EmitterSpec};
use crate::scene::SceneEmitter;
use crate::{Error, Vec3};
use serde::{Deserialize, Serialize};

/// `disc`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct DiscFile {
    radius: f64,
}

/// `rect`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RectFile {
    half_extents: [f64; 2],
}

/// One entry of `emitters`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct EmitterFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    disc: Option<DiscFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    rect: Option<RectFile>,
    position: [f64; 3],
    direction: [f64; 3],
    speed: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    end_time: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    material: Option<String>,
}

impl EmitterFile {
    /// Emitter `i`.
    pub(super) fn into_emitter(self, i: usize) -> Result<SceneEmitter, Error> {
        let shape = match (self.disc, self.rect) {
            (Some(d), None) => EmitterShape::Disc { radius: d.radius },
            (None, Some(r)) => EmitterShape::Rectangle {
                half_extents: r.half_extents,
            },
            _ => {
                let key = format!("emitters[{i}]");
                return Err(Error::InvalidArgument {
                    message: format!(
                        "{key} needs exactly one opening: `disc` ({{\"radius\": r}}) or `rect` \
                         ({{\"half_extents\": [a, b]}})"
                    ),
                    field: key,
                });
            }
        };
        let spec = EmitterSpec {
            shape,
            position: Vec3::from(self.position),
            direction: Vec3::from(self.direction),
            speed: self.speed,
            end_time: self.end_time,
        };
        Ok(SceneEmitter {
            spec,
            material: self.material,
        })
    }

    /// Every key of the spec written out.
    pub(super) fn from_emitter(emitter: &SceneEmitter) -> Self {
        let spec = &emitter.spec;
        let (disc, rect) = match spec.shape {
            EmitterShape::Disc { radius } => (Some(DiscFile { radius }), None),
            EmitterShape::Rectangle { half_extents } => (None, Some(RectFile { half_extents })),
        };
        let array = |v: Vec3| [v.x, v.y, v.z];
        EmitterFile {
            disc,
            rect,
            position: array(spec.position),
            direction: array(spec.direction),
            speed: spec.speed,
            end_time: spec.end_time,
            material: emitter.material.clone(),
        }
    }
}
