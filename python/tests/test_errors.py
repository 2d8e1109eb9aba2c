"""Every kind of rejected call raises the exception for its C status, carrying the C
library's message, and changes nothing."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import projfluid
from projfluid import InvalidArgumentError, Status

# (what is done to the world, the C message); every one is PF_ERROR_INVALID_ARGUMENT.
REJECTED: list[tuple[Callable[[projfluid.World], Any], str]] = [
    (
        lambda w: w.add_fluid_box((0.03, 0.03, 0.03), (0, 4, 4)),
        "pf_world_add_fluid_box: count must be positive and not absurdly large, got [0, 4, 4]",
    ),
    (
        lambda w: w.add_fluid_particles([[0.1, math.nan, 0.1]]),
        "pf_world_add_fluid_particles: xyz[0] must be finite, got [0.10000000149011612, NaN, "
        "0.10000000149011612]",
    ),
    (
        lambda w: w.add_fluid_particles([[0.1, 0.1, 0.1]], [[math.inf, 0.0, 0.0]]),
        "pf_world_add_fluid_particles_with_velocities: velocities[0] must be finite",
    ),
    (
        lambda w: w.add_container_box((0, 0, 0), (0.5, 0.5, 0.5), layers=4),
        "pf_world_add_container_box: layers must be 1, 2 or 3, got 4",
    ),
    (
        lambda w: w.add_container_box((0, 0, 0), (0.5, 0.5, 0.5), spacing=math.nan),
        "pf_world_add_container_box_spaced: spacing must be from r/4 to 2r",
    ),
    (
        lambda w: w.add_container_box((0, 0, 0), (0.5, math.nan, 0.5), walls="field"),
        "pf_world_add_container_field: max must be finite",
    ),
    (
        lambda w: w.add_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]]),
        "pf_world_add_mesh: triangles[0][2] must be a vertex index below the vertex count 3, got 3",
    ),
    (
        lambda w: w.add_mesh(
            [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], projfluid.Transform(scale=(0, 1, 1))
        ),
        "pf_world_add_mesh_transformed: transform.scale",
    ),
    (
        lambda w: w.add_obj("/no/such/file.obj"),
        "pf_world_add_obj: cannot read OBJ file /no/such/file.obj: ",
    ),
    (
        lambda w: w.step(2.0),
        "pf_world_step: dt must be a positive finite number of seconds (at most 1), got 2",
    ),
    (lambda w: w.advance(math.nan), "pf_world_advance: "),
    (lambda w: w.relax(0.1, -1.0), "pf_world_relax: "),
    (
        lambda w: w.add_body_box("dynamic", (0.05, 0.05, 0.05), density=0.0),
        "pf_world_add_body_box: density must be positive for a dynamic body (PF_BODY_DYNAMIC), "
        "got 0",
    ),
    (
        lambda w: w.add_body_box(7, (0.05, 0.05, 0.05)),
        "pf_world_add_body_box: kind must be a PfBodyKind (PF_BODY_STATIC, PF_BODY_KINEMATIC "
        "or PF_BODY_DYNAMIC), got 7",
    ),
    (lambda w: w.add_body_sphere("kinematic", -0.1), "pf_world_add_body_sphere: radius"),
    (
        lambda w: w.add_body_cylinder("kinematic", 0.1, math.inf),
        "pf_world_add_body_cylinder: height",
    ),
    (
        lambda w: w.add_body_mesh("dynamic", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], 500.0),
        "pf_world_add_body_mesh: ",
    ),
    (
        lambda w: w.body(3).pose,
        "pf_body_get_pose: id 3 is not a body of this world, which has 0 bodies",
    ),
    (
        lambda w: w.add_emitter_disc((0.2, 0.3, 0.15), (0, -1, 0), 0.05, -1.0),
        "pf_world_add_emitter_disc: speed must be a positive finite speed (m/s), got -1",
    ),
    (
        lambda w: w.add_emitter_rect((0.2, 0.3, 0.15), (0, 0, 0), 0.05, 0.05, 1.0),
        "pf_world_add_emitter_rect: direction",
    ),
    (
        lambda w: w.add_sink((1, 1, 1), (0, 0, 0)),
        "pf_world_add_sink: max must be at least min along every axis, got min[0] = 1 > max[0] = 0",
    ),
    (lambda w: w.set_domain((0, 0, math.nan), (1, 1, 1)), "pf_world_set_domain: min"),
    (
        lambda w: w.remove_particles([12345]),
        "pf_world_remove_particles: ids must name fluid particles of this world (never given, "
        "or removed already), got 12345",
    ),
    (lambda w: w.remove_particles([3, 3]), "pf_world_remove_particles: "),
]


@pytest.mark.parametrize(("call", "message"), REJECTED)
def test_a_rejected_call_raises_the_c_status_and_message_and_changes_nothing(
    world: projfluid.World, call: Callable[[projfluid.World], Any], message: str
) -> None:
    world.step()
    before = (world.fluid_count, world.boundary_count, world.body_count, world.time)
    hash_before = world.positions_hash()
    with pytest.raises(InvalidArgumentError) as caught:
        call(world)
    error = caught.value
    assert error.status == Status.ERROR_INVALID_ARGUMENT
    assert error.message.startswith(message), error.message
    assert str(error) == f"PF_ERROR_INVALID_ARGUMENT: {error.message}"
    assert isinstance(error, ValueError)  # as Python callers expect of a bad argument
    assert (world.fluid_count, world.boundary_count, world.body_count, world.time) == before
    assert world.positions_hash() == hash_before
    world.step()  # the world works on


def test_moving_a_static_body_is_rejected(world: projfluid.World) -> None:
    body = world.add_body_box("static", (0.05, 0.05, 0.05), pose=(0.3, 0.3, 0.2))
    for move in (
        lambda: body.set_velocity((1, 0, 0)),
        lambda: body.set_pose((0.3, 0.3, 0.1)),
        lambda: body.set_target_pose((0.3, 0.3, 0.1)),
    ):
        with pytest.raises(InvalidArgumentError) as caught:
            move()
        assert "body 0 is static (PF_BODY_STATIC)" in caught.value.message
    assert body.pose.position == (0.3, 0.3, 0.2)


def test_stepping_an_empty_world_is_rejected() -> None:
    with projfluid.World(projfluid.Params(threads=1)) as world:
        with pytest.raises(InvalidArgumentError) as caught:
            world.step()
        assert caught.value.message == (
            "pf_world_step: fluid particles must be present before stepping, got 0"
        )


def test_bad_parameters_raise_the_c_message_naming_the_field() -> None:
    with pytest.raises(InvalidArgumentError) as caught:
        projfluid.Params(chebyshev_rho=1.5)
    assert caught.value.status == Status.ERROR_INVALID_ARGUMENT
    assert caught.value.message == "pf_params_validate: params->rho must lie in [0, 1), got 1.5"
    with pytest.raises(InvalidArgumentError) as caught:
        projfluid.Params(dt_min=0.1, dt_max=0.01)
    assert caught.value.message.startswith("pf_params_validate: params->dt_min must not exceed")
    # A Params changed after construction is checked again by the world.
    params = projfluid.Params()
    params.particle_radius = -1.0
    with pytest.raises(InvalidArgumentError) as caught:
        projfluid.World(params)
    assert caught.value.message.startswith("pf_world_create: params->particle_radius")


def test_values_c_cannot_hold_are_python_errors() -> None:
    with pytest.raises(ValueError, match="threads must be an integer in 0..4294967295, got -1"):
        projfluid.Params(threads=-1)
    with pytest.raises(ValueError, match="solver must be one of chebyshev, jacobi1"):
        projfluid.Params(solver="fast")
    with pytest.raises(ValueError, match="gravity must be three numbers"):
        projfluid.Params(gravity=(0, -9.81))
    with pytest.raises(TypeError):
        projfluid.Params(no_such_setting=1)  # type: ignore[call-arg]
    with projfluid.World(projfluid.Params(threads=1)) as world:
        with pytest.raises(ValueError, match=r"positions must have shape \(n, 3\)"):
            world.add_fluid_particles([0.1, 0.2, 0.3])
        with pytest.raises(ValueError, match="triangles must hold indices in 0..4294967295"):
            world.add_mesh(np.zeros((3, 3)), [[0, 1, -1]])
        with pytest.raises(ValueError, match="kind must be static, kinematic or dynamic"):
            world.add_body_sphere("floating", 0.1)


NO_GPU = "backend gpu: not available: this build of projfluid has no `gpu` feature"


def test_the_gpu_is_refused_where_the_library_lacks_it(tmp_path: Path) -> None:
    # The tests' library is built without the `gpu` feature: the choice is a valid value,
    # but no world is made on the GPU, neither from parameters nor from a scene.
    params = projfluid.Params(backend="gpu", threads=1)
    with pytest.raises(InvalidArgumentError) as caught:
        projfluid.World(params)
    assert caught.value.status == Status.ERROR_INVALID_ARGUMENT
    assert caught.value.message == f"pf_world_create: {NO_GPU}"
    scene = tmp_path / "gpu.json"
    scene.write_text(
        '{"particle_radius": 0.025, "backend": "gpu", "duration": 1,'
        ' "container": {"min": [0, 0, 0], "max": [0.5, 0.5, 0.5]},'
        ' "fluid_blocks": [{"start": [0.0625, 0.0625, 0.0625], "count": [2, 2, 2]}]}'
    )
    with pytest.raises(InvalidArgumentError) as caught:
        projfluid.load_scene(scene)
    assert caught.value.message == f"pf_world_create_from_scene: {NO_GPU}"
    # The same scene on the CPU makes its world.
    scene.write_text(scene.read_text().replace('"gpu"', '"cpu"'))
    with projfluid.load_scene(scene) as world:
        assert world.params.backend == "cpu" and world.fluid_count == 8


def test_unknown_scenes_and_bad_scene_files_raise_the_c_message(tmp_path: Path) -> None:
    with pytest.raises(InvalidArgumentError) as caught:
        projfluid.load_scene("no_such_scene")
    assert caught.value.message.startswith(
        "pf_world_create_from_scene: scene `no_such_scene` is neither a built-in scene "
        "(dam_break_small, fountain"
    )
    missing = tmp_path / "missing.json"
    with pytest.raises(InvalidArgumentError) as caught:
        projfluid.load_scene(missing)
    assert caught.value.message.startswith(
        f"pf_world_create_from_scene: scene file {missing} does not exist"
    )
    bad = tmp_path / "bad.json"
    bad.write_text('{"particle_radius": 0.02}')
    with pytest.raises(InvalidArgumentError) as caught:
        projfluid.load_scene(bad)
    assert caught.value.message == (
        f"pf_world_create_from_scene: {bad}: line 1 column 25: missing field `fluid_blocks`"
    )


def test_a_closed_world_refuses_every_call_without_reaching_c(world: projfluid.World) -> None:
    body = world.add_body_sphere("kinematic", 0.05, pose=(0.4, 0.3, 0.15))
    world.close()
    for call in (
        lambda: world.step(),
        lambda: world.positions(),
        lambda: world.fluid_count,
        lambda: world.add_sink((0, 0, 0), (1, 1, 1)),
        lambda: body.pose,
    ):
        with pytest.raises(projfluid.WorldClosedError, match="the world is closed"):
            call()
