"""Rigid bodies: :class:`BodyKind`, :class:`Body` (one body of a world, by id) and the
:class:`~projfluid.World` methods that add them (docs/c-api.md, "Rigid bodies")."""

from __future__ import annotations

import enum
from collections.abc import Callable
from ctypes import byref, c_double, c_float, c_int, c_size_t, c_uint32
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _arrays
from ._arrays import Vector3
from ._capi import PfPose, lib
from .errors import check
from .geometry import Pose, pose_or_at

if TYPE_CHECKING:
    from ._handle import WorldHandle


class BodyKind(enum.IntEnum):
    """``PfBodyKind``: how a body moves."""

    STATIC = 0
    """Never moves; its particles join the walls'."""
    KINEMATIC = 1
    """Moves as the program says (pose, velocity, target pose); the fluid does not move it."""
    DYNAMIC = 2
    """Moved by gravity and the fluid's force and torque; needs a density."""


KindLike = BodyKind | int | str


def _kind(kind: KindLike) -> int:
    """``kind`` as the ``int`` C takes: a :class:`BodyKind` or its name in any case. Other
    integers are passed on for C to check."""
    if isinstance(kind, str):
        try:
            return int(BodyKind[kind.upper()])
        except KeyError:
            raise ValueError(f"kind must be static, kinematic or dynamic, got {kind!r}") from None
    return int(kind)


class Body:
    """Body ``id`` of a world: its ids count from 0 in the order bodies were added and never
    change. A handle only: it reads and moves the body through the C API on every call."""

    def __init__(self, world: WorldHandle, id: int) -> None:
        self._world = world
        self.id = id
        """The body's id."""

    def __repr__(self) -> str:
        return f"<projfluid.Body {self.id}>"

    def _call(self, function: Callable[..., int], *args: Any) -> None:
        with self._world.use() as handle:
            check(function(handle, self.id, *args))

    def _pair(self, function: Callable[..., int]) -> tuple[np.ndarray, np.ndarray]:
        a, b = np.empty(3), np.empty(3)
        self._call(function, _arrays.pointer(a, c_double), _arrays.pointer(b, c_double))
        return a, b

    @property
    def kind(self) -> BodyKind:
        """How the body moves."""
        out = c_int()
        self._call(lib.pf_body_get_kind, byref(out))
        return BodyKind(out.value)

    @property
    def pose(self) -> Pose:
        """The pose of the body's frame; after a step, where the step left it."""
        out = PfPose()
        self._call(lib.pf_body_get_pose, byref(out))
        return Pose.from_c(out)

    def set_pose(self, pose: Pose | Vector3) -> None:
        """Moves a kinematic or dynamic body to ``pose`` (a :class:`Pose` or a position)
        now, keeping its velocity; cancels a target pose."""
        self._call(lib.pf_body_set_pose, byref(pose_or_at(pose).to_c()))

    def set_target_pose(self, pose: Pose | Vector3) -> None:
        """Makes the next step move a kinematic body to ``pose``, with the velocity that
        takes it there in that step."""
        self._call(lib.pf_body_set_target_pose, byref(pose_or_at(pose).to_c()))

    def set_velocity(self, linear: Vector3, angular: Vector3 = (0.0, 0.0, 0.0)) -> None:
        """Sets the velocity of a kinematic or dynamic body: ``linear`` of its centre of mass
        (m/s) and ``angular`` about it (rad/s, world axes); cancels a target pose."""
        self._call(
            lib.pf_body_set_velocity,
            _arrays.doubles3(linear, "linear"),
            _arrays.doubles3(angular, "angular"),
        )

    @property
    def velocity(self) -> tuple[np.ndarray, np.ndarray]:
        """``(linear, angular)``: of the centre of mass (m/s) and about it (rad/s), each a
        (3,) float64 array."""
        return self._pair(lib.pf_body_get_velocity)

    @property
    def centre_of_mass(self) -> np.ndarray:
        """The centre of mass in world coordinates (m), a (3,) float64 array."""
        out = np.empty(3)
        self._call(lib.pf_body_get_centre_of_mass, _arrays.pointer(out, c_double))
        return out

    @property
    def force_torque(self) -> tuple[np.ndarray, np.ndarray]:
        """``(force, torque)``: the fluid's force (N) and torque about the centre of mass
        (N·m) during the last step, each a (3,) float64 array (0 before the first step)."""
        return self._pair(lib.pf_body_get_force_torque)


class BodiesMixin:
    """The :class:`~projfluid.World` methods for rigid bodies."""

    _world: WorldHandle

    def _add_body(self, function: Callable[..., int], *args: Any) -> Body:
        out = c_size_t()
        with self._world.use() as handle:
            check(function(handle, *args, byref(out)))
        return Body(self._world, out.value)

    def add_body_box(
        self,
        kind: KindLike,
        half_extents: Vector3,
        density: float = 0.0,
        pose: Pose | Vector3 | None = None,
    ) -> Body:
        """Adds a box of ``half_extents`` (m) centred on its frame's origin, placed by
        ``pose`` (a :class:`Pose`, a position, or None for the origin). ``density``
        (kg/m³) is required for dynamic bodies; for others 0 means none. Bodies start at
        rest."""
        return self._add_body(
            lib.pf_world_add_body_box,
            _kind(kind),
            _arrays.doubles3(half_extents, "half_extents"),
            float(density),
            byref(pose_or_at(pose).to_c()),
        )

    def add_body_sphere(
        self,
        kind: KindLike,
        radius: float,
        density: float = 0.0,
        pose: Pose | Vector3 | None = None,
    ) -> Body:
        """Adds a sphere of ``radius`` (m) centred on its frame's origin; otherwise as
        :meth:`add_body_box`."""
        return self._add_body(
            lib.pf_world_add_body_sphere,
            _kind(kind),
            float(radius),
            float(density),
            byref(pose_or_at(pose).to_c()),
        )

    def add_body_cylinder(
        self,
        kind: KindLike,
        radius: float,
        height: float,
        density: float = 0.0,
        pose: Pose | Vector3 | None = None,
    ) -> Body:
        """Adds a cylinder of ``radius`` and ``height`` (m) along its frame's y axis, centred
        on the origin; otherwise as :meth:`add_body_box`."""
        return self._add_body(
            lib.pf_world_add_body_cylinder,
            _kind(kind),
            float(radius),
            float(height),
            float(density),
            byref(pose_or_at(pose).to_c()),
        )

    def add_body_mesh(
        self,
        kind: KindLike,
        vertices: Any,
        triangles: Any,
        density: float = 0.0,
        pose: Pose | Vector3 | None = None,
    ) -> Body:
        """Adds a body whose surface is the triangle mesh ``vertices`` ((n, 3), m, in the
        body's frame) and ``triangles`` ((m, 3) vertex indices); with a density the mesh
        must be closed. Otherwise as :meth:`add_body_box`."""
        v = _arrays.rows(vertices, 3, np.float32, "vertices")
        t = _arrays.indices(triangles, "triangles")
        return self._add_body(
            lib.pf_world_add_body_mesh,
            _kind(kind),
            _arrays.pointer(v, c_float),
            len(v),
            _arrays.pointer(t, c_uint32),
            len(t),
            float(density),
            byref(pose_or_at(pose).to_c()),
        )

    @property
    def body_count(self) -> int:
        """Number of bodies; their ids are 0 to this minus 1."""
        out = c_size_t()
        with self._world.use() as handle:
            check(lib.pf_world_body_count(handle, byref(out)))
        return out.value

    def body(self, id: int) -> Body:
        """Body ``id``. An id that names no body is rejected by the C library on the
        body's first call; a negative one raises :class:`ValueError` here."""
        if id < 0:
            raise ValueError(f"a body id is not negative, got {id}")
        return Body(self._world, int(id))

    @property
    def bodies(self) -> list[Body]:
        """Every body, by id."""
        return [Body(self._world, i) for i in range(self.body_count)]

    def wall_force(self) -> np.ndarray:
        """The fluid's force (N) on the container walls, obstacles and boundary particles
        together during the last step, a (3,) float64 array; measured only in worlds with
        bodies."""
        out = np.empty(3)
        with self._world.use() as handle:
            check(lib.pf_world_get_wall_force(handle, _arrays.pointer(out, c_double)))
        return out
