"""Poses of rigid bodies and transforms of meshes, as the C API's ``PfPose`` and
``PfTransform``."""

from __future__ import annotations

import dataclasses

from ._arrays import Vector3, vector3
from ._capi import PfPose, PfTransform


@dataclasses.dataclass(frozen=True)
class Pose:
    """Where a body's frame is: ``position`` of its origin (m) and ``rotation``, a unit
    quaternion ``(w, x, y, z)`` from the body frame to the world (finite, of length 1 within
    1e-6; the library normalises it). ``Pose()`` is the identity."""

    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)

    def to_c(self) -> PfPose:
        """The ``PfPose`` struct."""
        w, x, y, z = (float(v) for v in self.rotation)
        return PfPose(vector3(self.position, "position"), (w, x, y, z))

    @classmethod
    def from_c(cls, c: PfPose) -> Pose:
        """The pose held in a ``PfPose`` struct."""
        return cls(tuple(c.position), tuple(c.rotation))


def pose_or_at(pose: Pose | Vector3 | None) -> Pose:
    """A :class:`Pose`, given one, a position (no rotation), or None (the identity)."""
    if pose is None:
        return Pose()
    if isinstance(pose, Pose):
        return pose
    return Pose(vector3(pose, "pose"))


@dataclasses.dataclass(frozen=True)
class Transform:
    """Where a mesh goes: every vertex p becomes ``translate + R·(scale ∘ p)``: a per-axis
    ``scale`` about the origin (positive factors), then rotations ``rotate_deg`` (degrees)
    about the fixed world x, y and z axes in that order, then ``translate`` (m)."""

    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    rotate_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    translate: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def to_c(self) -> PfTransform:
        """The ``PfTransform`` struct."""
        return PfTransform(
            vector3(self.scale, "scale"),
            vector3(self.rotate_deg, "rotate_deg"),
            vector3(self.translate, "translate"),
        )
