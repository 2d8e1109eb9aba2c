"""The World's lifetime, its reads (shapes, dtypes, no copies), parameters and statistics."""

from __future__ import annotations

import gc
import math

import numpy as np
import pytest

import projfluid
from conftest import small_params

N = 6 * 7 * 5


def test_a_world_closes_once_and_closing_again_is_safe() -> None:
    world = projfluid.World(small_params())
    assert not world.closed
    world.close()
    world.close()
    assert world.closed
    assert repr(world) == "<projfluid.World (closed)>"
    with projfluid.World(small_params()) as inside:
        assert not inside.closed
    assert inside.closed
    inside.close()
    # A world dropped without closing is closed by the garbage collector.
    projfluid.World(small_params())
    gc.collect()


def test_the_context_manager_closes_on_an_exception() -> None:
    with pytest.raises(RuntimeError), projfluid.World(small_params()) as world:
        raise RuntimeError("boom")
    assert world.closed


def test_reads_are_numpy_arrays_of_the_documented_shapes_and_dtypes(
    world: projfluid.World,
) -> None:
    world.advance(0.02)
    positions, velocities = world.positions(), world.velocities()
    densities, ids = world.densities(), world.ids()
    assert positions.shape == (N, 3) and positions.dtype == np.float32
    assert velocities.shape == (N, 3) and velocities.dtype == np.float32
    assert densities.shape == (N,) and densities.dtype == np.float32
    assert ids.shape == (N,) and ids.dtype == np.uint64
    assert all(a.flags.c_contiguous for a in (positions, velocities, densities, ids))
    assert np.array_equal(ids, np.arange(N))
    assert np.isfinite(positions).all() and (positions[:, 1] > 0).all()
    assert (velocities[:, 1] < 0).any()  # falling
    assert 900 < float(np.median(densities)) < 1100  # kg/m³, about water's
    # The first particle of a box is at its start: x fastest, then y, then z.
    with projfluid.World(small_params()) as fresh:
        fresh.add_fluid_box((0.03, 0.03, 0.03), (6, 7, 5))
        xyz = fresh.positions()
        assert xyz[0] == pytest.approx((0.03, 0.03, 0.03))
        assert xyz[1] == pytest.approx((0.07, 0.03, 0.03))  # spacing 2r = 0.04 m
        assert xyz[6] == pytest.approx((0.03, 0.07, 0.03))


def test_reads_fill_a_callers_array_in_place(world: projfluid.World) -> None:
    world.step()
    out = np.zeros((N, 3), dtype=np.float32)
    assert world.positions(out=out) is out
    assert np.array_equal(out, world.positions())
    dens = np.zeros(N, dtype=np.float32)
    assert world.densities(out=dens) is dens
    ids = np.zeros(N, dtype=np.uint64)
    assert world.ids(out=ids) is ids
    for bad in (
        np.zeros((N, 3), dtype=np.float64),
        np.zeros((N + 1, 3), dtype=np.float32),
        np.zeros((3, N), dtype=np.float32).T,
    ):
        with pytest.raises(ValueError):
            world.positions(out=bad)
    frozen = np.zeros((N, 3), dtype=np.float32)
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="writeable"):
        world.velocities(out=frozen)


def test_container_walls_take_the_spacing_asked_for() -> None:
    counts = []
    for spacing in (None, 0.05):
        with projfluid.World(projfluid.Params()) as world:
            world.add_container_box((0, 0, 0), (0.6, 0.4, 0.5), spacing=spacing)
            counts.append(world.boundary_count)
    assert 3.5 <= counts[0] / counts[1] <= 4.5


def test_container_walls_that_are_fields_hold_the_water_without_particles() -> None:
    with projfluid.World(projfluid.Params()) as world:
        world.add_container_box((0, 0, 0), (0.3, 0.4, 0.3), walls="field")
        world.add_fluid_box((0.05, 0.1, 0.05), (5, 4, 5))
        assert world.boundary_count == 0
        stats = world.advance(0.3)
        xyz = world.positions()
        assert stats.escaped_count == 0
        assert (xyz > 0).all() and (xyz[:, 1] > 0.01).all()
        assert (xyz[:, [0, 2]] < 0.3).all()
        for bad in (
            {"walls": "field", "layers": 2},
            {"walls": "field", "spacing": 0.05},
            {"walls": "glass"},
        ):
            with pytest.raises(ValueError):
                world.add_container_box((0, 0, 0), (0.3, 0.4, 0.3), **bad)


def test_inputs_accept_any_array_like_and_are_rounded_to_float32() -> None:
    with projfluid.World(small_params()) as world:
        world.add_container_box([0, 0, 0], np.array([0.5, 0.4, 0.3]))
        world.add_fluid_particles(np.array([[0.1, 0.1, 0.1], [0.2, 0.1, 0.1]]))
        world.add_fluid_particles([(0.3, 0.1, 0.1)], velocities=[(1.0, 0.0, 0.0)])
        assert world.fluid_count == 3
        assert world.positions()[2, 0] == np.float32(0.3)
        assert world.velocities()[2, 0] == 1.0


def test_params_default_to_the_c_librarys_and_round_trip(world: projfluid.World) -> None:
    defaults = projfluid.Params()
    assert defaults.particle_radius == 0.025
    assert defaults.solver == projfluid.Solver.CHEBYSHEV
    assert defaults.gravity == (0.0, -9.81, 0.0)
    assert defaults.chebyshev_auto_rho is False and defaults.chebyshev_rho == 0.99
    assert defaults.density_tolerance == 3e-4 and defaults.cfl_factor == 1.25
    p = projfluid.Params(solver="cg", projection_weight=1, threads=np.int64(3))
    assert p.solver is projfluid.Solver.CG
    assert p.projection_weight is projfluid.ProjectionWeight.UNIT
    assert p.threads == 3 and type(p.threads) is int
    assert projfluid.Params.from_c(p.to_c()) == p
    assert world.params == small_params()
    calm = defaults.calm()
    assert calm.projection_weight == projfluid.ProjectionWeight.UNIFORM
    assert calm.chebyshev_rho == 0.99 and calm.chebyshev_auto_rho is False
    assert calm.density_tolerance == 0.0
    assert calm.particle_radius == defaults.particle_radius


def test_the_coarse_correction_is_a_switch_a_world_reports_back() -> None:
    assert projfluid.Params().coarse_correction is False
    assert projfluid.Params(coarse_correction=True).calm().coarse_correction is False
    off = small_params(coarse_correction=False)
    assert off.coarse_correction is False and off.to_c().coarse_correction == 0
    assert small_params(coarse_correction=1).to_c().coarse_correction == 1
    assert projfluid.Params.from_c(off.to_c()) == off
    with projfluid.World(off) as world:
        assert world.params.coarse_correction is False
        assert world.params == off
        world.add_container_box((0, 0, 0), (0.5, 0.4, 0.3))
        world.add_fluid_box((0.03, 0.03, 0.03), (6, 7, 5))
        stats = world.advance(0.02)
        assert stats.nan_count == 0 and stats.escaped_count == 0


def test_the_physical_viscosity_and_its_wall_condition_reach_the_world() -> None:
    defaults = projfluid.Params()
    assert defaults.kinematic_viscosity == 0.0 and defaults.no_slip is True
    honey = small_params(kinematic_viscosity=1e-2, no_slip=False)
    c = honey.to_c()
    assert c.kinematic_viscosity == 1e-2 and c.no_slip == 0
    assert small_params(no_slip=1).to_c().no_slip == 1
    assert projfluid.Params.from_c(c) == honey
    calm = honey.calm()
    assert calm.kinematic_viscosity == 1e-2 and calm.no_slip is False
    with projfluid.World(honey) as world:
        assert world.params.kinematic_viscosity == 1e-2 and world.params.no_slip is False
        assert world.params == honey
    for bad in (-1e-6, math.nan, math.inf):
        with pytest.raises(projfluid.InvalidArgumentError) as caught:
            small_params(kinematic_viscosity=bad)
        assert caught.value.message.startswith(
            "pf_params_validate: params->kinematic_viscosity must be finite and not negative"
        ), caught.value.message
    with pytest.raises(ValueError, match="kinematic_viscosity must be a number"):
        small_params(kinematic_viscosity="honey")


def test_vorticity_confinement_reaches_the_world() -> None:
    assert projfluid.Params().vorticity_confinement == 0.0
    swirl = small_params(vorticity_confinement=0.3)
    assert swirl.to_c().vorticity_confinement == 0.3
    assert projfluid.Params.from_c(swirl.to_c()) == swirl
    with projfluid.World(swirl) as world:
        assert world.params.vorticity_confinement == 0.3
    for bad in (-0.1, 11.0, math.nan):
        with pytest.raises(projfluid.InvalidArgumentError) as caught:
            small_params(vorticity_confinement=bad)
        assert "params->vorticity_confinement must lie in [0, 10]" in caught.value.message


def test_the_backend_is_a_choice_passed_to_the_c_library() -> None:
    defaults = projfluid.Params()
    assert defaults.backend == "cpu" and defaults.to_c().backend == 0
    gpu = small_params(backend="gpu")
    c = gpu.to_c()
    assert c.backend == 1
    assert projfluid.Params.from_c(c) == gpu
    assert gpu.calm().backend == "gpu"
    assert small_params(backend="GPU") == gpu
    for bad in ("tpu", "", 1, None):
        with pytest.raises(ValueError, match=r"^backend must be 'cpu' or 'gpu', got "):
            small_params(backend=bad)
    c.backend = 7
    with pytest.raises(ValueError, match=r"^backend must be 'cpu' or 'gpu', got 7$"):
        projfluid.Params.from_c(c)
    with projfluid.World(small_params(backend="cpu")) as world:
        assert world.params.backend == "cpu"


def _sliding_speed(**settings: object) -> float:
    """Mean x velocity (m/s) of a block sliding at 0.2 m/s along the floor of a tank without
    gravity or XSPH, after one step of 2 ms."""
    params = small_params(gravity=(0, 0, 0), viscosity=0, **settings)
    with projfluid.World(params) as world:
        world.add_container_box((0, 0, 0), (0.5, 0.4, 0.3))
        world.add_fluid_box((0.03, 0.03, 0.03), (6, 7, 5), velocity=(0.2, 0, 0))
        stats = world.step(0.002)
        assert stats.nan_count == 0
        return float(world.velocities()[:, 0].mean())


def test_no_slip_walls_hold_a_viscous_block_that_free_slip_walls_let_slide() -> None:
    water = _sliding_speed()
    free = _sliding_speed(kinematic_viscosity=0.5, no_slip=False)
    held = _sliding_speed(kinematic_viscosity=0.5, no_slip=True)
    # Without walls to hold it a uniform motion has no shear for the viscosity to act on.
    assert free == pytest.approx(water, rel=1e-3) and water > 0.19
    assert held < 0.8 * free, (held, free)
    # no_slip is only a wall condition: without a viscosity it changes nothing.
    assert _sliding_speed(no_slip=False) == water


def test_steps_report_their_statistics(world: projfluid.World) -> None:
    assert world.last_step.step_count == 0
    first = world.step(0.002)
    assert first.step_count == 1 and first.dt == 0.002 and first.time == 0.002
    assert first.outer_iterations >= 1
    stats = world.advance(0.05)
    assert math.isclose(stats.time, 0.052) and world.time == stats.time
    assert stats.escaped_count == 0 and stats.nan_count == 0
    assert 0.0 <= stats.density_error_avg_percent <= stats.density_error_max_percent
    assert world.last_step == stats
    relaxed = world.relax(0.01, 4.0)
    assert relaxed.step_count > stats.step_count


def test_obstacles_add_boundary_particles(world: projfluid.World) -> None:
    walls = world.boundary_count
    cube = np.array([[x, y, z] for z in (0.2, 0.28) for y in (0.1, 0.18) for x in (0.3, 0.38)])
    faces = [[0, 1, 3], [0, 3, 2], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
             [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 3, 7], [1, 7, 5]]  # fmt: skip
    world.add_mesh(cube, faces)
    with_cube = world.boundary_count
    assert with_cube > walls
    world.add_mesh(
        cube, np.array(faces, dtype=np.int64), projfluid.Transform(translate=(0, 0.1, 0))
    )
    assert world.boundary_count == 2 * with_cube - walls
    world.add_boundary_particles([[0.25, 0.01, 0.15]])
    assert world.boundary_count == 2 * with_cube - walls + 1


def test_the_version_is_the_c_librarys() -> None:
    assert projfluid.__version__ == "0.1.0"
