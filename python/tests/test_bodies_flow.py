"""Rigid bodies, emitters, sinks, the domain and removal through the package."""

from __future__ import annotations

import numpy as np
import pytest

import projfluid
from conftest import small_params


def test_bodies_are_added_moved_and_read(world: projfluid.World) -> None:
    paddle = world.add_body_box("kinematic", (0.01, 0.1, 0.1), pose=(0.3, 0.15, 0.15))
    ball = world.add_body_sphere(projfluid.BodyKind.DYNAMIC, 0.04, 500.0, (0.4, 0.3, 0.15))
    post = world.add_body_cylinder("static", 0.02, 0.2, pose=projfluid.Pose((0.45, 0.1, 0.05)))
    assert [b.id for b in world.bodies] == [0, 1, 2] and world.body_count == 3
    assert [b.kind for b in (paddle, ball, post)] == [
        projfluid.BodyKind.KINEMATIC,
        projfluid.BodyKind.DYNAMIC,
        projfluid.BodyKind.STATIC,
    ]
    assert ball.centre_of_mass == pytest.approx([0.4, 0.3, 0.15])
    paddle.set_velocity((-0.5, 0.0, 0.0))
    world.step(0.004)
    assert paddle.pose.position == pytest.approx((0.298, 0.15, 0.15))
    linear, angular = paddle.velocity
    assert linear.dtype == np.float64 and linear.shape == (3,)
    assert linear == pytest.approx([-0.5, 0, 0]) and angular == pytest.approx([0, 0, 0])
    assert ball.velocity[0][1] < 0  # falling
    force, torque = paddle.force_torque
    assert force.shape == torque.shape == (3,)
    assert world.wall_force().shape == (3,)
    paddle.set_target_pose(projfluid.Pose((0.29, 0.15, 0.15)))
    world.step(0.004)
    assert paddle.pose.position == pytest.approx((0.29, 0.15, 0.15))
    ball.set_pose((0.4, 0.35, 0.15))
    assert ball.pose.position == (0.4, 0.35, 0.15)
    tetra = world.add_body_mesh(
        "kinematic",
        [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]],
        [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        pose=(0.05, 0.3, 0.05),
    )
    assert tetra.id == 3 and world.body(3).kind == projfluid.BodyKind.KINEMATIC


def test_emitters_pour_and_sinks_drain_and_the_counts_add_up() -> None:
    with projfluid.World(small_params()) as world:
        world.add_container_box((0, 0, 0), (0.6, 0.6, 0.6))
        world.add_fluid_box((0.05, 0.05, 0.05), (5, 3, 5))
        initial = world.fluid_count
        assert world.add_emitter_disc((0.3, 0.5, 0.3), (0, -1, 0), 0.06, 1.0) == 0
        assert world.add_emitter_rect((0.45, 0.5, 0.45), (0, -1, 0), 0.05, 0.05, 1.0, 0.05) == 1
        assert world.add_sink((0.0, 0.0, 0.0), (0.12, 0.08, 0.12)) == 0
        world.set_domain((-1, -1, -1), (2, 2, 2))
        world.advance(0.1)
        emitted, removed = world.emitted_count, world.removed_count
        assert emitted > 0 and removed > 0
        assert world.fluid_count == initial + emitted - removed
        ids = world.ids()
        assert np.all(np.diff(ids.astype(np.int64)) > 0)  # ascending, gaps where removed
        assert world.remove_particles(ids[:3]) == 3
        assert world.removed_count == removed + 3
        assert world.remove_particles([]) == 0
        world.clear_domain()
