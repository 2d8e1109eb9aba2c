"""Fluid starts calm wherever it is placed (docs/method.md §2.7), through the package: a block
put 0 to 3 particle radii from container walls (of particles and of fields), a closed
obstacle mesh, and a static and a kinematic body takes its first steps without a jolt, on
one and two threads alike; fluid placed inside a solid is not created, and
:meth:`World.add_fluid_box` says how much was. The Rust side is ``tests/placement.rs``."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import projfluid

R = 0.025
"""Particle radius r of every world here (m)."""
BLOCK = 6
"""Blocks are this many particles along each axis."""
GRAVITY = 9.81
"""The default gravity's magnitude (m/s²)."""

SLAB_CENTRE = np.array([0.5, 0.1, 0.3])
"""Centre of the solid box the block rests on where it is not the container (m)."""
SLAB_HALF = np.array([0.2, 0.1, 0.2])
"""Half-extents of that box (m)."""

TANKS = {
    "walls": ((0.0, 0.0, 0.0), (0.4, 0.4, 0.4)),
    "slab": ((0.0, 0.0, 0.0), (1.0, 0.8, 0.6)),
}
"""The container (min, max corners, m): small where its walls are the solid, larger around
the slab."""

CONTAINERS = ("wall_particles", "wall_fields")
"""The block goes against the floor and two walls of a box of particle or field walls."""
SLABS = ("obstacle", "static_body", "kinematic_body")
"""The block rests on the top face of the slab: a closed obstacle mesh, a static box body or
a kinematic box body at rest."""


def tank(solid: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The container of the world against ``solid``."""
    return TANKS["walls" if solid in CONTAINERS else "slab"]


def slab_mesh() -> tuple[np.ndarray, np.ndarray]:
    """The slab as a closed 12-triangle box mesh with outward normals: (8, 3) vertices (m)
    and (12, 3) triangles."""
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=3)))  # vertex v: bits z, y, x
    vertices = SLAB_CENTRE + signs * SLAB_HALF
    triangles = []
    for axis in range(3):
        for side in (-1.0, 1.0):
            a, b, c, d = np.flatnonzero(signs[:, axis] == side)  # a quad, a–d diagonal
            for tri in ((a, b, d), (a, d, c)):
                p, q, s = vertices[list(tri)]
                if np.cross(q - p, s - p)[axis] * side < 0:
                    tri = (tri[0], tri[2], tri[1])
                triangles.append(tri)
    return vertices, np.array(triangles)


def test_the_slab_mesh_is_a_closed_box_with_outward_normals() -> None:
    vertices, triangles = slab_mesh()
    edges = [tuple(t[[i, (i + 1) % 3]]) for t in triangles for i in range(3)]
    assert sorted(edges) == sorted((b, a) for a, b in edges)  # each edge once each way
    for t in triangles:
        p, q, s = vertices[t]
        outward = (p + q + s) / 3 - SLAB_CENTRE
        assert np.dot(np.cross(q - p, s - p), outward) > 0


def world_against(solid: str, threads: int) -> projfluid.World:
    """A world with the solid ``solid`` and an empty container, on ``threads`` threads."""
    world = projfluid.World(projfluid.Params(particle_radius=R, threads=threads))
    lo, hi = tank(solid)
    if solid == "wall_fields":
        world.add_container_box(lo, hi, walls="field")
    else:
        world.add_container_box(lo, hi, layers=1)
    if solid == "obstacle":
        world.add_mesh(*slab_mesh())
    elif solid == "static_body":
        world.add_body_box("static", tuple(SLAB_HALF), pose=tuple(SLAB_CENTRE))
    elif solid == "kinematic_body":
        world.add_body_box("kinematic", tuple(SLAB_HALF), pose=tuple(SLAB_CENTRE))
    return world


def block_start(solid: str, gap: float) -> np.ndarray:
    """The first particle's centre of a block whose lowest layer lies ``gap`` (m) above the
    solid (and, for the container, ``gap`` from two of its walls as well)."""
    if solid in CONTAINERS:
        return np.full(3, gap)
    width = (BLOCK - 1) * 2 * R
    top = SLAB_CENTRE[1] + SLAB_HALF[1]
    return np.array([SLAB_CENTRE[0] - width / 2, top + gap, SLAB_CENTRE[2] - width / 2])


def depth_in_slab(positions: np.ndarray) -> np.ndarray:
    """How deep each of the (n, 3) ``positions`` lies inside the slab (m; negative
    outside)."""
    depth: np.ndarray = np.min(SLAB_HALF - np.abs(positions - SLAB_CENTRE), axis=1)
    return depth


def inside_tank(solid: str, positions: np.ndarray) -> np.ndarray:
    """Which of the (n, 3) ``positions`` lie in the container, walls included (its corners
    as C sees them, in single precision)."""
    lo, hi = (np.array(corner, dtype=np.float32) for corner in tank(solid))
    inside: np.ndarray = np.all((positions >= lo) & (positions <= hi), axis=1)
    return inside


def place_and_check(solid: str, gap: float, threads: int) -> np.ndarray:
    """Places the block ``gap`` (m) from ``solid`` on ``threads`` threads, takes five steps,
    checks each and returns the particles' final positions."""
    case = f"{solid}, {gap / R:.2f} r, {threads} threads"
    with world_against(solid, threads) as world:
        added = world.add_fluid_box(tuple(block_start(solid, gap)), (BLOCK, BLOCK, BLOCK))
        assert added == BLOCK**3, f"{case}: nothing lies inside a solid"
        assert world.fluid_count == added
        start_height = world.positions()[:, 1].mean(dtype=np.float64)
        for step in range(1, 6):
            stats = world.step()
            at = f"{case}, step {step}"
            # Before placement settled new fluid, these steps took 200 outer iterations (the
            # limit, twice) and threw particles at 6–90 m/s.
            assert not stats.hit_max_iterations and stats.outer_iterations <= 12, f"{at}: {stats}"
            assert stats.escaped_count == 0 and stats.nan_count == 0, f"{at}: {stats}"
            # A block resting on a solid collapses sideways under its own weight: no particle
            # may be faster than a fall at twice gravity, plus 5 cm/s.
            fastest = np.linalg.norm(world.velocities().astype(np.float64), axis=1).max()
            bound = 2 * GRAVITY * world.time + 0.05
            assert fastest <= bound, f"{at}: {fastest} m/s > {bound} m/s"
            x = world.positions()
            height = x[:, 1].mean(dtype=np.float64)
            assert height <= start_height + 1e-4, (
                f"{at}: the centre of mass rose from {start_height} m to {height} m"
            )
            assert inside_tank(solid, x).all(), f"{at}: {x[~inside_tank(solid, x)]} left the box"
            if solid in SLABS:
                depth = depth_in_slab(x.astype(np.float64))
                assert depth.max() < 0.2 * R, (
                    f"{at}: {x[depth.argmax()]} lies {depth.max()} m inside the solid"
                )
        return world.positions()


GAPS = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0)
"""Distances of the block from the solid, in particle radii."""


@pytest.mark.parametrize("gap", GAPS, ids=lambda g: f"{g}r")
@pytest.mark.parametrize("solid", CONTAINERS + SLABS)
def test_a_block_placed_0_to_3_radii_from_a_solid_starts_calm_on_one_and_two_threads(
    solid: str, gap: float
) -> None:
    one = place_and_check(solid, gap * R, threads=1)
    two = place_and_check(solid, gap * R, threads=2)
    assert np.array_equal(one, two), f"{solid}, {gap} r: thread counts differ"


@pytest.mark.parametrize("solid", SLABS)
def test_fluid_placed_inside_a_solid_is_not_created_and_the_count_says_so(solid: str) -> None:
    # A 10 × 6 × 6 block whose first two columns lie inside the slab up to its third layer,
    # the third column on the slab's face, and whose last columns reach the container's far
    # wall and beyond.
    start = SLAB_CENTRE + np.array([0.1, SLAB_HALF[1] - 0.12, -0.1])
    count = (10, 6, 6)
    # The lattice as the library lays it: from the start C reads (single precision), 2r
    # apart in double precision, x fastest. A centre on the slab's surface is not inside it;
    # through single precision the third column lies 2.4e-8 m outside the slab and the ninth
    # 2.4e-8 m beyond the far wall (in tests/placement.rs, on it).
    steps = np.array([(i, j, k) for k in range(6) for j in range(6) for i in range(10)])
    lattice = start.astype(np.float32).astype(np.float64) + steps * (2 * R)
    kept = inside_tank(solid, lattice) & (depth_in_slab(lattice) <= 1e-12)
    expected = int(kept.sum())
    assert 0 < expected < 10 * 6 * 6 - 36, expected
    with world_against(solid, threads=1) as world:
        added = world.add_fluid_box(tuple(start), count)
        assert added == expected, solid
        assert world.fluid_count == expected
        x = world.positions()
        assert inside_tank(solid, x).all(), f"{solid}: {x[~inside_tank(solid, x)]} outside the box"
        depth = depth_in_slab(x.astype(np.float64))
        assert depth.max() < 0, f"{solid}: {x[depth.argmax()]} inside the solid"
        # Particles given one by one are filtered the same way.
        inside, outside = SLAB_CENTRE, SLAB_CENTRE + np.array([0.0, SLAB_HALF[1] + 0.2, 0.0])
        assert world.add_fluid_particles([inside, outside]) == 1
        assert world.fluid_count == expected + 1
