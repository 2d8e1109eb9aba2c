"""The :class:`World`: a simulation behind a C ``PfWorld`` handle, which it fills, steps and
reads; rigid bodies are in :mod:`projfluid.bodies`, emitters and sinks in
:mod:`projfluid.flow`."""

from __future__ import annotations

import contextlib
import operator
import os
from collections.abc import Callable
from ctypes import (
    byref,
    c_char,
    c_double,
    c_float,
    c_size_t,
    c_uint16,
    c_uint32,
    c_uint64,
    c_void_p,
)
from types import TracebackType
from typing import Any

import numpy as np

from . import _arrays
from ._arrays import Vector3
from ._capi import PfParams, PfStepStats, lib
from ._handle import WorldHandle
from .bodies import BodiesMixin
from .errors import check
from .flow import FlowMixin
from .geometry import Transform
from .params import Params
from .stats import StepStats


class World(BodiesMixin, FlowMixin):
    """A simulation: fluid particles, walls and bodies, stepped by the C library.

    Use it as a context manager, which closes it (frees the C world and joins its worker
    threads) on leaving the block; :meth:`close` does the same and may be called again::

        with projfluid.World(projfluid.Params(threads=2)) as world:
            world.add_container_box((0, 0, 0), (0.5, 0.5, 0.5))
            world.add_fluid_box((0.05, 0.05, 0.05), (6, 6, 6))
            world.advance(0.1)
            xyz = world.positions()      # (216, 3) float32, metres

    Every method calls the C API; a rejected call raises a
    :class:`~projfluid.errors.ProjfluidError` subclass carrying the C status and message, and
    changes nothing. Vectors are in SI units (m, m/s). The GIL is released during every C
    call, so worlds in different Python threads step in parallel; one world must be used by
    one thread at a time (another thread's call raises
    :class:`~projfluid.errors.BusyError`).
    """

    def __init__(self, params: Params | None = None) -> None:
        """Creates an empty world with ``params`` (the defaults when None) on the backend
        ``params.backend`` names. ``backend="gpu"`` where the library has no GPU backend or
        the machine no Vulkan adapter raises
        :class:`~projfluid.errors.InvalidArgumentError` with the library's reason."""
        c_params = (params if params is not None else Params()).to_c()
        handle = c_void_p()
        check(lib.pf_world_create(byref(c_params), byref(handle)))
        self._world = WorldHandle(handle)

    @classmethod
    def _adopt(cls, handle: c_void_p) -> World:
        """A world owning ``handle``, a live world from the C API."""
        world = cls.__new__(cls)
        world._world = WorldHandle(handle)
        return world

    # --- lifetime ---------------------------------------------------------------------

    def close(self) -> None:
        """Frees the C world, waiting for its worker threads (and for calls other threads
        are making on it) to finish. Safe to call more than once; afterwards every other
        method raises :class:`~projfluid.errors.WorldClosedError`."""
        self._world.close()

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` was called."""
        return self._world.closed

    def __enter__(self) -> World:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()

    def __del__(self) -> None:
        world = getattr(self, "_world", None)
        if world is None:
            return
        # At interpreter exit the library or the threading module may be gone already.
        with contextlib.suppress(Exception):
            world.close()

    def __repr__(self) -> str:
        if self.closed:
            return "<projfluid.World (closed)>"
        return f"<projfluid.World: {self.fluid_count} fluid particles, t = {self.time:.6g} s>"

    def _call(self, function: Callable[..., int], *args: Any) -> None:
        """Calls the C ``function`` with the handle and ``args``; raises on failure."""
        with self._world.use() as handle:
            check(function(handle, *args))

    # --- filling ----------------------------------------------------------------------

    def add_fluid_box(
        self,
        start: Vector3,
        count: tuple[int, int, int],
        velocity: Vector3 | None = None,
    ) -> int:
        """Adds a block of ``count`` = (nx, ny, nz) fluid particles on a lattice of spacing
        2r whose first particle is at ``start`` (m), all moving at ``velocity`` (m/s; None:
        at rest), and returns how many it made: particles whose centres lie inside a solid
        (outside every container, inside a closed obstacle or body) are not created. The
        block starts calm however close to a wall it is put. Particles are numbered x
        fastest, then y, then z."""
        try:
            nx, ny, nz = (int(n) for n in count)
        except (TypeError, ValueError):
            raise ValueError(f"count must be three integers, got {count!r}") from None
        if min(nx, ny, nz) < 0:
            raise ValueError(f"count must not be negative, got {(nx, ny, nz)}")
        c_velocity = None if velocity is None else _arrays.floats3(velocity, "velocity")
        self._call(
            lib.pf_world_add_fluid_box,
            _arrays.floats3(start, "start"),
            (c_size_t * 3)(nx, ny, nz),
            c_velocity,
        )
        return self._size(lib.pf_world_last_added_count)

    def add_fluid_particles(self, positions: Any, velocities: Any = None) -> int:
        """Adds fluid particles at ``positions``, an (n, 3) array (m), at rest or moving at
        ``velocities``, an (n, 3) array (m/s), and returns how many it made (as
        :meth:`add_fluid_box`). Values are rounded to float32, as C sees them."""
        xyz = _arrays.rows(positions, 3, np.float32, "positions")
        if velocities is None:
            self._call(lib.pf_world_add_fluid_particles, _arrays.pointer(xyz, c_float), len(xyz))
            return self._size(lib.pf_world_last_added_count)
        v = _arrays.rows(velocities, 3, np.float32, "velocities")
        if v.shape != xyz.shape:
            raise ValueError(f"velocities has shape {v.shape}, positions {xyz.shape}")
        self._call(
            lib.pf_world_add_fluid_particles_with_velocities,
            _arrays.pointer(xyz, c_float),
            _arrays.pointer(v, c_float),
            len(xyz),
        )
        return self._size(lib.pf_world_last_added_count)

    def add_boundary_particles(self, positions: Any) -> None:
        """Adds static boundary particles at ``positions``, an (n, 3) array (m), for
        surfaces sampled by other means (spacing about r)."""
        xyz = _arrays.rows(positions, 3, np.float32, "positions")
        self._call(lib.pf_world_add_boundary_particles, _arrays.pointer(xyz, c_float), len(xyz))

    def add_container_box(
        self,
        min: Vector3,
        max: Vector3,
        layers: int = 1,
        spacing: float | None = None,
        walls: str = "particles",
    ) -> None:
        """Adds a closed box from corner ``min`` to corner ``max`` (m). With ``walls`` =
        "particles" its walls are ``layers`` (1–3) layers of boundary particles growing
        outward, at most ``spacing`` (m, from r/4 to 2r; None: r) apart; with "field" each
        wall is a smooth field that adds what such a wall adds on average, with no particles
        (a scene file's ``"walls": "field"``; ``layers`` 1 and ``spacing`` None only)."""
        if walls not in ("particles", "field"):
            raise ValueError(f'walls must be "particles" or "field", got {walls!r}')
        if layers < 0:
            raise ValueError(f"layers must not be negative, got {layers}")
        corners = (_arrays.floats3(min, "min"), _arrays.floats3(max, "max"))
        if walls == "field":
            if layers != 1 or spacing is not None:
                raise ValueError("layers and spacing apply to walls of particles")
            self._call(lib.pf_world_add_container_field, *corners)
        elif spacing is None:
            self._call(lib.pf_world_add_container_box, *corners, int(layers))
        else:
            spaced = lib.pf_world_add_container_box_spaced
            self._call(spaced, *corners, int(layers), float(spacing))

    def add_mesh(self, vertices: Any, triangles: Any, transform: Transform | None = None) -> None:
        """Adds a static obstacle: the triangle mesh with ``vertices``, an (n, 3) array (m),
        and ``triangles``, an (m, 3) integer array of zero-based vertex indices, placed by
        ``transform`` (None: as given). Its surface is sampled with boundary particles about
        r apart. A closed mesh is also kept, so that fluid added later is not created inside
        it; fluid already inside it or nearer than r to its surface is removed (see
        ``removed_count``) and the fluid next to it is settled (docs/method.md §2.7)."""
        v = _arrays.rows(vertices, 3, np.float32, "vertices")
        t = _arrays.indices(triangles, "triangles")
        args = (_arrays.pointer(v, c_float), len(v), _arrays.pointer(t, c_uint32), len(t))
        if transform is None:
            self._call(lib.pf_world_add_mesh, *args)
        else:
            self._call(lib.pf_world_add_mesh_transformed, *args, byref(transform.to_c()))

    def add_obj(self, path: str | os.PathLike[str], transform: Transform | None = None) -> None:
        """Adds a static obstacle read from the Wavefront OBJ file at ``path`` (coordinates in
        metres), placed by ``transform`` and sampled as :meth:`add_mesh`."""
        c_transform = None if transform is None else byref(transform.to_c())
        self._call(lib.pf_world_add_obj, os.fsencode(path), c_transform)

    # --- materials --------------------------------------------------------------------

    def add_material(self, rest_density: float) -> int:
        """Adds a fluid material, a liquid of ``rest_density`` (kg/m³, 0.1 to 10 times the
        world's ``rest_density``), and returns its id: 1 for the first one added, then 2,
        3, …; material 0 is the world's own fluid. Fluid of it is made after
        :meth:`set_fluid_material` chooses it. A rest density that is not finite or out of
        range, or a 257th material, raises :class:`~projfluid.errors.InvalidArgumentError`
        and adds nothing."""
        out = c_uint16()
        self._call(lib.pf_world_add_material, float(rest_density), byref(out))
        return out.value

    def set_fluid_material(self, material: int) -> None:
        """Chooses ``material`` (an id from :meth:`add_material`, or 0) as the material of
        the fluid added from now on: by :meth:`add_fluid_box`, :meth:`add_fluid_particles`
        and the emitters added from now on. Fluid already in the world keeps its material.
        An id the world does not have raises :class:`~projfluid.errors.InvalidArgumentError`
        and changes nothing."""
        self._call(lib.pf_world_set_fluid_material, _material_id(material))

    @property
    def fluid_material(self) -> int:
        """The material the fluid added next is made of (0, the world's own fluid, until
        :meth:`set_fluid_material` chooses another)."""
        out = c_uint16()
        self._call(lib.pf_world_fluid_material, byref(out))
        return out.value

    @property
    def material_count(self) -> int:
        """Number of materials, the world's own fluid included (ids 0 to count − 1)."""
        return self._size(lib.pf_world_material_count)

    def material_rest_density(self, material: int) -> float:
        """The rest density (kg/m³) of ``material``: the world's ``rest_density`` for 0.
        An id the world does not have raises
        :class:`~projfluid.errors.InvalidArgumentError`."""
        out = c_double()
        self._call(lib.pf_world_get_material_rest_density, _material_id(material), byref(out))
        return out.value

    def set_material_kinematic_viscosity(self, material: int, kinematic_viscosity: float) -> None:
        """Sets the kinematic viscosity ν (m²/s) of ``material`` from the next step on: 0
        leaves it without physical viscosity, water is 1e-6, honey 1e-2 and more. Material 0
        is the world's own fluid (its ``Params.kinematic_viscosity`` so far); the others
        start without one. An unknown id, a negative or non-finite ν, or a ν above 0 in a
        world on the GPU raises :class:`~projfluid.errors.InvalidArgumentError` and changes
        nothing."""
        self._call(
            lib.pf_world_set_material_kinematic_viscosity,
            _material_id(material),
            float(kinematic_viscosity),
        )

    def material_kinematic_viscosity(self, material: int) -> float:
        """The kinematic viscosity ν (m²/s) of ``material``. An id the world does not have
        raises :class:`~projfluid.errors.InvalidArgumentError`."""
        out = c_double()
        self._call(
            lib.pf_world_get_material_kinematic_viscosity, _material_id(material), byref(out)
        )
        return out.value

    def set_material_surface_tension(self, material: int, surface_tension: float) -> None:
        """Sets the surface tension σ (N/m) of ``material`` from the next step on: 0 leaves
        it without surface tension, water against air is 0.0728. Material 0 is the world's
        own fluid (its ``Params.surface_tension`` so far); the others start without one. An
        unknown id, a negative or non-finite σ, one above 10 N/m, or a σ above 0 in a world
        on the GPU raises :class:`~projfluid.errors.InvalidArgumentError` and changes
        nothing."""
        self._call(
            lib.pf_world_set_material_surface_tension,
            _material_id(material),
            float(surface_tension),
        )

    def material_surface_tension(self, material: int) -> float:
        """The surface tension σ (N/m) of ``material``. An id the world does not have raises
        :class:`~projfluid.errors.InvalidArgumentError`."""
        out = c_double()
        self._call(lib.pf_world_get_material_surface_tension, _material_id(material), byref(out))
        return out.value

    def materials(self, out: np.ndarray | None = None) -> np.ndarray:
        """Every fluid particle's material id as an (n,) uint16 array, in ascending id
        order like :meth:`positions`; ``out`` as in :meth:`positions`."""
        return self._read(lib.pf_world_get_materials, out, 1, np.uint16, c_uint16, "out")

    # --- stepping ---------------------------------------------------------------------

    def step(self, dt: float = 0.0) -> StepStats:
        """Takes one step: of the CFL-limited size when ``dt`` is 0, else of ``dt`` seconds
        (at most 1). Returns what it did."""
        return self._stepped(lib.pf_world_step, float(dt))

    def advance(self, seconds: float) -> StepStats:
        """Takes CFL-limited steps until ``seconds`` (s) have passed, shortening the last one
        to land exactly. Returns what the last step did."""
        return self._stepped(lib.pf_world_advance, float(seconds))

    def relax(self, seconds: float, damping: float) -> StepStats:
        """Steps like :meth:`advance` for ``seconds``, scaling every fluid velocity by
        exp(−damping·Δt) after each step (``damping`` in 1/s), to settle a tank."""
        return self._stepped(lib.pf_world_relax, float(seconds), float(damping))

    def _stepped(self, function: Callable[..., int], *args: Any) -> StepStats:
        """Calls the stepping ``function``, then reads the statistics, holding the handle
        for both (so that a :meth:`close` from another thread comes after them)."""
        stats = PfStepStats()
        with self._world.use() as handle:
            check(function(handle, *args))
            check(lib.pf_world_last_step_stats(handle, byref(stats)))
        return StepStats.from_c(stats)

    # --- reading ----------------------------------------------------------------------

    def _size(self, function: Callable[..., int]) -> int:
        out = c_size_t()
        self._call(function, byref(out))
        return out.value

    @property
    def fluid_count(self) -> int:
        """Number of fluid particles."""
        return self._size(lib.pf_world_fluid_count)

    @property
    def boundary_count(self) -> int:
        """Number of boundary particles (walls, obstacles and bodies)."""
        return self._size(lib.pf_world_boundary_count)

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        out = c_double()
        self._call(lib.pf_world_time, byref(out))
        return out.value

    @property
    def params(self) -> Params:
        """The world's parameters (a copy; a world's parameters cannot change)."""
        out = PfParams()
        self._call(lib.pf_world_get_params, byref(out))
        return Params.from_c(out)

    @property
    def last_step(self) -> StepStats:
        """What the last step did, and the step count and time."""
        out = PfStepStats()
        self._call(lib.pf_world_last_step_stats, byref(out))
        return StepStats.from_c(out)

    def _read(
        self,
        function: Callable[..., int],
        out: np.ndarray | None,
        columns: int,
        dtype: Any,
        ctype: Any,
        name: str,
    ) -> np.ndarray:
        """Fills ``out`` (or a new array) of shape (n, columns) or (n,) with ``function``."""
        with self._world.use() as handle:
            n = c_size_t()
            check(lib.pf_world_fluid_count(handle, byref(n)))
            shape = (n.value, columns) if columns > 1 else (n.value,)
            array = _arrays.output(out, shape, dtype, name)
            check(function(handle, _arrays.pointer(array, ctype), array.size, None))
        return array

    def positions(self, out: np.ndarray | None = None) -> np.ndarray:
        """The fluid particles' positions (m) as an (n, 3) float32 array, in ascending id
        order. Given ``out`` (C-contiguous, that shape and dtype), C writes into it and it is
        returned: no copy, no allocation."""
        return self._read(lib.pf_world_get_positions, out, 3, np.float32, c_float, "out")

    def velocities(self, out: np.ndarray | None = None) -> np.ndarray:
        """The fluid particles' velocities (m/s) as an (n, 3) float32 array; ``out`` as in
        :meth:`positions`."""
        return self._read(lib.pf_world_get_velocities, out, 3, np.float32, c_float, "out")

    def densities(self, out: np.ndarray | None = None) -> np.ndarray:
        """The fluid particles' densities (kg/m³) as an (n,) float32 array, as the last step
        left them (before a particle's first step, as evaluated when fluid was last added);
        ``out`` as in :meth:`positions`."""
        return self._read(lib.pf_world_get_densities, out, 1, np.float32, c_float, "out")

    def ids(self, out: np.ndarray | None = None) -> np.ndarray:
        """The fluid particles' ids as an (n,) uint64 array, ascending: the order of every
        other read. Ids count from 0 in the order particles were added and are never
        reused. ``out`` as in :meth:`positions`."""
        return self._read(lib.pf_world_get_ids, out, 1, np.uint64, c_uint64, "out")

    def positions_hash(self) -> str:
        """SHA-256 (64 hex digits) of the positions' exact double-precision bits, in id
        order: equal strings mean bitwise equal simulations (C, Rust or Python)."""
        out = (c_char * 65)()
        self._call(lib.pf_world_positions_hash, out, len(out), None)
        return out.value.decode()


def _material_id(material: int) -> int:
    """``material`` as a C ``uint16_t`` material id: an integer (else :class:`TypeError`) in
    0..65535 (else :class:`ValueError`; C would see it wrapped)."""
    value = operator.index(material)
    if not 0 <= value <= 0xFFFF:
        raise ValueError(f"material must be a material id in 0..65535, got {value}")
    return value
