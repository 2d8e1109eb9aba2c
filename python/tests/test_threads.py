"""Worlds in different Python threads step in parallel: every C call releases the GIL."""

from __future__ import annotations

import threading

import pytest

import projfluid
from conftest import small_params


def dam(threads: int = 1) -> projfluid.World:
    """A 10 × 10 × 10 block in a 0.5 m box: long enough a run to be seen running."""
    world = projfluid.World(small_params(threads=threads))
    world.add_container_box((0, 0, 0), (0.5, 0.5, 0.5))
    world.add_fluid_box((0.03, 0.03, 0.03), (10, 10, 10))
    return world


def advance(world: projfluid.World, seconds: float) -> None:
    """``world.advance(seconds)``, retried while the main thread's probe holds the world (a
    rejected call changes nothing)."""
    while True:
        try:
            world.advance(seconds)
            return
        except projfluid.BusyError:
            continue


def busy(world: projfluid.World) -> bool:
    """Whether another thread is inside a C call on ``world`` right now."""
    try:
        _ = world.fluid_count
    except projfluid.BusyError as e:
        assert e.status == projfluid.Status.ERROR_BUSY
        assert e.message.startswith("pf_world_fluid_count: the world is being used")
        return True
    return False


def test_two_worlds_step_in_two_threads_at_the_same_time_as_they_would_alone() -> None:
    seconds = 0.15
    with dam() as alone:
        alone.advance(seconds)
        expected = alone.positions_hash()

    worlds = [dam(), dam()]
    start = threading.Barrier(3)
    errors: list[BaseException] = []

    def run(world: projfluid.World) -> None:
        start.wait()
        try:
            advance(world, seconds)  # one C call for the whole run
        except BaseException as e:  # reported by the main thread
            errors.append(e)

    threads = [threading.Thread(target=run, args=(w,)) for w in worlds]
    for t in threads:
        t.start()
    start.wait()
    # Python code runs here while both threads are inside C: that needs the GIL released.
    # Both worlds busy between two sightings of the first means both were in C at once.
    both = False
    while not both and any(t.is_alive() for t in threads):
        both = busy(worlds[0]) and busy(worlds[1]) and busy(worlds[0])
    for t in threads:
        t.join()
    assert not errors, errors
    assert both, "never saw both worlds inside C at the same time"
    for world in worlds:
        assert world.positions_hash() == expected
        world.close()


def test_one_world_used_from_two_threads_reports_busy_and_is_unharmed() -> None:
    with dam() as world:
        stepping = threading.Thread(target=advance, args=(world, 0.15))
        stepping.start()
        seen = False
        while stepping.is_alive() and not seen:
            seen = busy(world)
        stepping.join()
        assert seen, "the stepping thread held the GIL during its C call"
        assert world.time == pytest.approx(0.15)


def test_closing_waits_for_a_call_in_another_thread() -> None:
    world = dam()
    stepping = threading.Thread(target=advance, args=(world, 0.1))
    stepping.start()
    while stepping.is_alive() and not busy(world):
        pass
    world.close()  # waits for advance to return, then frees the world
    stepping.join()
    assert world.closed
