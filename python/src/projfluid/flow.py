"""Fluid entering and leaving a world: the :class:`~projfluid.World` methods for emitters,
sinks, the domain and removal by id (docs/c-api.md, "Emitters, sinks and the domain")."""

from __future__ import annotations

import math
from collections.abc import Callable
from ctypes import byref, c_size_t, c_uint64
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _arrays
from ._arrays import Vector3
from ._capi import lib
from .errors import check

if TYPE_CHECKING:
    from ._handle import WorldHandle


class FlowMixin:
    """The :class:`~projfluid.World` methods for emitters, sinks, the domain and removal."""

    _world: WorldHandle

    def _add(self, function: Callable[..., int], *args: Any) -> int:
        out = c_size_t()
        with self._world.use() as handle:
            check(function(handle, *args, byref(out)))
        return out.value

    def add_emitter_disc(
        self,
        position: Vector3,
        direction: Vector3,
        radius: float,
        speed: float,
        end_time: float | None = None,
    ) -> int:
        """Adds an emitter whose opening is a disc of ``radius`` (m) centred on ``position``
        (m), normal to ``direction``, that from the next step inserts fluid moving at
        ``speed`` (m/s) along ``direction`` until the simulated time ``end_time`` (s; None:
        forever). Returns its index (emitters count from 0)."""
        return self._add(
            lib.pf_world_add_emitter_disc,
            _arrays.doubles3(position, "position"),
            _arrays.doubles3(direction, "direction"),
            float(radius),
            float(speed),
            math.inf if end_time is None else float(end_time),
        )

    def add_emitter_rect(
        self,
        position: Vector3,
        direction: Vector3,
        half_a: float,
        half_b: float,
        speed: float,
        end_time: float | None = None,
    ) -> int:
        """As :meth:`add_emitter_disc` with a rectangular opening of half-extents ``half_a``
        and ``half_b`` (m) along the opening plane's two axes (x and z for a direction −y)."""
        return self._add(
            lib.pf_world_add_emitter_rect,
            _arrays.doubles3(position, "position"),
            _arrays.doubles3(direction, "direction"),
            float(half_a),
            float(half_b),
            float(speed),
            math.inf if end_time is None else float(end_time),
        )

    def add_sink(self, min: Vector3, max: Vector3) -> int:
        """Adds a sink, the box from ``min`` to ``max`` (m): the fluid in it is removed at the
        end of every step. Returns its index (sinks count from 0)."""
        return self._add(
            lib.pf_world_add_sink, _arrays.doubles3(min, "min"), _arrays.doubles3(max, "max")
        )

    def set_domain(self, min: Vector3, max: Vector3) -> None:
        """Sets the domain, the box from ``min`` to ``max`` (m): fluid outside it (or not
        finite) at the end of a step is removed."""
        with self._world.use() as handle:
            check(
                lib.pf_world_set_domain(
                    handle, _arrays.doubles3(min, "min"), _arrays.doubles3(max, "max")
                )
            )

    def clear_domain(self) -> None:
        """Removes the domain, if any."""
        with self._world.use() as handle:
            check(lib.pf_world_clear_domain(handle))

    def remove_particles(self, ids: Any) -> int:
        """Removes the fluid particles with these ``ids`` (from :meth:`World.ids`) now;
        returns how many were removed. An unknown or repeated id raises
        :class:`~projfluid.errors.InvalidArgumentError` and removes nothing."""
        array = np.asarray(ids)
        if array.size and (array.dtype.kind not in "iu" or array.min() < 0):
            raise ValueError("ids must be non-negative integers")
        array = np.ascontiguousarray(array.reshape(-1), dtype=np.uint64)
        removed = c_size_t()
        with self._world.use() as handle:
            check(
                lib.pf_world_remove_particles(
                    handle, _arrays.pointer(array, c_uint64), array.size, byref(removed)
                )
            )
        return removed.value

    def _u64(self, function: Callable[..., int]) -> int:
        out = c_uint64()
        with self._world.use() as handle:
            check(function(handle, byref(out)))
        return out.value

    @property
    def emitted_count(self) -> int:
        """Particles inserted by emitters so far."""
        return self._u64(lib.pf_world_emitted_count)

    @property
    def removed_count(self) -> int:
        """Particles removed so far (by sinks, the domain, by id and by closed solids added
        where fluid stood)."""
        return self._u64(lib.pf_world_removed_count)
