"""Several liquids in one world (docs/method.md §14): materials are added and chosen, every
particle reads back as the material it was made of, in the order of the other reads, bad
values raise and change nothing, and a dense blob sinks through water."""

from __future__ import annotations

import math

import numpy as np
import pytest

import projfluid
from conftest import small_params
from projfluid import InvalidArgumentError, Status


def lattice(count: tuple[int, int, int], spacing: float, gap: float) -> tuple[np.ndarray, ...]:
    """The (n, 3) positions of a lattice of ``count`` particles from ``gap`` (x fastest, then
    y, then z) and the (n, 3) integer indices of each."""
    k, j, i = np.meshgrid(*(np.arange(c) for c in reversed(count)), indexing="ij")
    ijk = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)
    return ijk * spacing + gap, ijk


def test_a_heavy_blob_reads_back_as_its_material(world: projfluid.World) -> None:
    n = world.fluid_count
    assert world.material_count == 1 and world.fluid_material == 0
    assert world.material_rest_density(0) == world.params.rest_density
    heavy = world.add_material(1500.0)
    assert heavy == 1 and world.material_count == 2
    assert world.fluid_material == 0  # adding a material does not choose it
    assert world.material_rest_density(heavy) == 1500.0
    world.set_fluid_material(heavy)
    assert world.fluid_material == heavy
    assert world.add_fluid_box((0.35, 0.2, 0.1), (2, 2, 2)) == 8
    world.set_fluid_material(0)
    assert world.add_fluid_particles([[0.4, 0.35, 0.2]]) == 1

    materials = world.materials()
    assert materials.shape == (n + 9,) and materials.dtype == np.uint16
    assert materials.flags.c_contiguous
    assert np.array_equal(materials, np.repeat(np.uint16([0, heavy, 0]), [n, 8, 1]))
    # The blob's particles are the ones at the blob's box, in the order of positions().
    blob = world.positions()[materials == heavy]
    assert blob[0] == pytest.approx((0.35, 0.2, 0.1)) and blob.shape == (8, 3)
    assert (blob[:, 0] > 0.34).all() and (blob[:, 1] > 0.19).all()

    # Steps reorder the particles' storage; every read keeps the order of the ids.
    world.advance(0.02)
    out = np.full(n + 9, 7, dtype=np.uint16)
    assert world.materials(out=out) is out
    assert np.array_equal(out, materials)
    ids = world.ids()
    assert np.array_equal(ids[out == heavy], np.arange(n, n + 8))
    with pytest.raises(ValueError):
        world.materials(out=np.zeros(n + 9, dtype=np.int32))


def test_bad_materials_raise_and_leave_the_world_unchanged(world: projfluid.World) -> None:
    heavy = world.add_material(2000.0)
    world.set_fluid_material(heavy)
    world.step()
    before = (world.material_count, world.fluid_material, world.positions_hash())
    materials = world.materials()

    for density in (math.nan, math.inf, -math.inf, 0.0, -1000.0, 99.0, 10_001.0):
        with pytest.raises(InvalidArgumentError) as error:
            world.add_material(density)
        assert error.value.status == Status.ERROR_INVALID_ARGUMENT
        assert error.value.message.startswith(
            "pf_world_add_material: rest_density must be between 100 and 10000 kg/m³"
        )
    for unknown in (2, 3, 65535):
        with pytest.raises(InvalidArgumentError, match="material must name one of the world's 2"):
            world.set_fluid_material(unknown)
        with pytest.raises(InvalidArgumentError) as error:
            world.material_rest_density(unknown)
        assert error.value.message == (
            "pf_world_get_material_rest_density: material must name one of the world's 2 "
            f"materials (0 to 1), got {unknown}"
        )
    # Ids C cannot hold never reach it (C would see them wrapped).
    for wrapped in (-1, 65536, 65537):
        with pytest.raises(ValueError, match="material id in 0..65535"):
            world.set_fluid_material(wrapped)
        with pytest.raises(ValueError, match="material id in 0..65535"):
            world.material_rest_density(wrapped)
    with pytest.raises(TypeError):
        world.set_fluid_material(1.0)  # type: ignore[arg-type]

    assert (world.material_count, world.fluid_material, world.positions_hash()) == before
    assert np.array_equal(world.materials(), materials)
    assert world.material_rest_density(heavy) == 2000.0
    world.close()
    with pytest.raises(projfluid.WorldClosedError):
        world.add_material(1500.0)
    with pytest.raises(projfluid.WorldClosedError):
        world.materials()


def test_a_world_holds_at_most_256_materials() -> None:
    with projfluid.World(small_params()) as world:
        ids = [world.add_material(100.0 + i) for i in range(1, 256)]
        assert ids == list(range(1, 256)) and world.material_count == 256
        with pytest.raises(InvalidArgumentError, match="at most 256 materials"):
            world.add_material(1000.0)
        assert world.material_count == 256
        assert world.material_rest_density(255) == 355.0


def test_a_blob_of_3000_kg_per_m3_sinks_through_water() -> None:
    """An 8 × 12 × 8 tank of water with a 4 × 4 × 4 blob three times as dense as water in its
    upper part: within 1 s the blob sinks from above the water's mean height to below it."""
    params = small_params()
    d = 2 * params.particle_radius
    gap = d + 0.25 * params.particle_radius
    count = (8, 12, 8)
    extent = [(c - 1) * d + 2 * gap for c in count]
    xyz, ijk = lattice(count, d, gap)
    i, j, k = ijk.T
    inside = (2 <= i) & (i < 6) & (6 <= j) & (j < 10) & (2 <= k) & (k < 6)
    assert inside.sum() == 64
    with projfluid.World(params) as world:
        world.add_container_box((0, 0, 0), (extent[0], 1.5 * extent[1], extent[2]))
        assert world.add_fluid_particles(xyz[~inside]) == len(xyz) - 64
        blob = world.add_material(3000.0)
        world.set_fluid_material(blob)
        assert world.add_fluid_particles(xyz[inside]) == 64

        def heights() -> tuple[float, float]:
            y, materials = world.positions()[:, 1], world.materials()
            return float(y[materials == blob].mean()), float(y[materials == 0].mean())

        blob_start, water_start = heights()
        assert blob_start > water_start + 0.05
        stats = world.advance(1.0)
        blob_end, water_end = heights()
        assert stats.escaped_count == 0 and stats.nan_count == 0
        assert blob_start - blob_end > 0.15, f"the blob sank {blob_start - blob_end:.3f} m"
        assert blob_end < water_end - 0.05, f"blob at {blob_end:.3f} m, water {water_end:.3f} m"
        assert (world.materials() == blob).sum() == 64


def test_material_viscosity_is_set_read_and_checked(world: projfluid.World) -> None:
    honey = world.add_material(1420.0)
    assert world.material_kinematic_viscosity(honey) == 0.0
    assert world.material_kinematic_viscosity(0) == world.params.kinematic_viscosity
    world.set_material_kinematic_viscosity(honey, 0.1)
    assert world.material_kinematic_viscosity(honey) == 0.1
    for bad in (math.nan, -1e-3, math.inf):
        with pytest.raises(InvalidArgumentError) as raised:
            world.set_material_kinematic_viscosity(honey, bad)
        assert (
            "pf_world_set_material_kinematic_viscosity: kinematic_viscosity must be finite"
            in str(raised.value)
        )
        assert world.material_kinematic_viscosity(honey) == 0.1
    with pytest.raises(InvalidArgumentError):
        world.set_material_kinematic_viscosity(2, 0.1)
    with pytest.raises(InvalidArgumentError):
        world.material_kinematic_viscosity(2)


def test_material_surface_tension_is_set_read_and_checked(world: projfluid.World) -> None:
    oil = world.add_material(800.0)
    assert world.material_surface_tension(oil) == 0.0
    assert world.material_surface_tension(0) == world.params.surface_tension == 0.0
    world.set_material_surface_tension(oil, 0.03)
    assert world.material_surface_tension(oil) == 0.03
    for bad in (math.nan, -1e-3, math.inf, 11.0):
        with pytest.raises(InvalidArgumentError) as raised:
            world.set_material_surface_tension(oil, bad)
        assert (
            "pf_world_set_material_surface_tension: surface_tension must be finite"
            in str(raised.value)
        )
        assert world.material_surface_tension(oil) == 0.03
    with pytest.raises(InvalidArgumentError):
        world.set_material_surface_tension(2, 0.03)
    with pytest.raises(InvalidArgumentError):
        world.material_surface_tension(2)


def test_surface_tension_and_wall_adhesion_are_parameters() -> None:
    params = small_params()
    params.surface_tension = 0.05
    params.wall_adhesion = 0.08
    assert projfluid.Params.from_c(params.to_c()) == params
    with projfluid.World(params) as world:
        assert world.material_surface_tension(0) == 0.05
    params.surface_tension = -1.0
    with pytest.raises(InvalidArgumentError) as raised:
        params.validate()
    assert "surface_tension" in str(raised.value)


def test_a_viscous_material_collapses_more_slowly(world: projfluid.World) -> None:
    """The fixture's column, with its material given ν = 0.5 m²/s, runs less than half as
    far in 0.3 s as the same column of water."""
    with projfluid.World(small_params()) as water:
        water.add_container_box((0, 0, 0), (0.5, 0.4, 0.3))
        water.add_fluid_box((0.03, 0.03, 0.03), (6, 7, 5))
        world.set_material_kinematic_viscosity(0, 0.5)
        for w in (water, world):
            w.advance(0.3)
        start = 0.03 + 5 * 0.04
        runs = [np.percentile(w.positions()[:, 0], 99) - start for w in (water, world)]
    assert runs[1] < 0.5 * runs[0], runs
