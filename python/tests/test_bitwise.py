"""The package computes exactly what the C API computes: the same world built and stepped
from C and from Python gives bitwise equal particles."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import projfluid
from conftest import CHECKOUT, run_program


def test_a_world_built_in_python_matches_tests_c_bitwise_bit_for_bit(
    c_program: Callable[[str], Path], tmp_path: Path
) -> None:
    written = tmp_path / "positions.f32"
    c = run_program(c_program("tests/c/bitwise.c"), str(written))

    # tests/c/bitwise.c, call for call.
    params = projfluid.Params(
        particle_radius=0.02,
        displacement_tolerance=2e-5,
        solver=projfluid.Solver.CHEBYSHEV,
        chebyshev_rho=0.85,
        threads=2,
    )
    with projfluid.World(params) as world:
        world.add_container_box((-0.005, -0.005, -0.005), (0.5, 0.4, 0.3), layers=2)
        world.add_fluid_box((0.03, 0.03, 0.03), (6, 7, 5), velocity=(0.25, 0.0, -0.125))
        drops = [[0.4, 0.3, 0.15], [0.41, 0.25, 0.1], [0.2, 0.35, 0.2]]
        drop_velocities = [[-0.5, 0.0, 0.0], [0.0, -1.0, 0.1], [0.0, 0.0, 0.0]]
        world.add_fluid_particles(drops, drop_velocities)
        world.add_boundary_particles([[0.25, 0.01, 0.15], [0.25, 0.03, 0.15]])
        world.step(0.002)
        world.step()
        world.step()
        world.advance(0.01)

        assert world.positions_hash() == c["hash"]
        from_c = np.fromfile(written, dtype=np.float32).reshape(-1, 3)
        positions = world.positions()
        assert positions.shape == from_c.shape == (6 * 7 * 5 + 3, 3)
        assert np.array_equal(positions.view(np.uint32), from_c.view(np.uint32))


@pytest.mark.parametrize(
    ("scene", "steps"),
    [
        ("fountain", 12),  # an emitter and a sink
        ("floating_boxes", 2),  # dynamic bodies
        ("droplet", 5),  # surface tension
        (str(CHECKOUT / "scenes" / "dam_break_small.json"), 5),  # a scene file
    ],
)
def test_a_scene_stepped_from_python_matches_the_c_api_bit_for_bit(
    c_program: Callable[[str], Path], scene: str, steps: int
) -> None:
    c = run_program(c_program("tests/c/scene.c"), scene, str(steps))
    with projfluid.load_scene(scene) as world:
        for _ in range(steps):
            world.step()
        assert world.fluid_count == int(c["fluid"])
        assert world.body_count == int(c["bodies"])
        assert world.time == float(c["time"])
        assert world.positions_hash() == c["hash"]
