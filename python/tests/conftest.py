"""Shared fixtures: small worlds, and C programs of the checkout's C tests compiled against
the very library the package loads, for bit-for-bit comparisons with the C API.

Outside CI a missing C compiler skips the comparisons; under CI (``CI`` set, as ``.ci/run``
runs) it fails them, so that CI cannot pass by skipping."""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

import projfluid
from projfluid._capi import library_path

CHECKOUT = Path(__file__).resolve().parents[2]


def small_params(**overrides: object) -> projfluid.Params:
    """Parameters for small, quick worlds: r = 0.02 m, one worker thread."""
    settings: dict[str, object] = {
        "particle_radius": 0.02,
        "displacement_tolerance": 2e-5,
        "threads": 1,
    }
    settings.update(overrides)
    return projfluid.Params(**settings)  # type: ignore[arg-type]


@pytest.fixture
def world() -> Iterator[projfluid.World]:
    """A 6 × 7 × 5 block of water in a 0.5 × 0.4 × 0.3 m box, not yet stepped."""
    with projfluid.World(small_params()) as w:
        w.add_container_box((0, 0, 0), (0.5, 0.4, 0.3))
        w.add_fluid_box((0.03, 0.03, 0.03), (6, 7, 5))
        yield w


@pytest.fixture(scope="session")
def c_program(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Path]:
    """Compiles a C file of the checkout (e.g. ``tests/c/bitwise.c``) against the library
    this package loads, returning the program."""
    compiler = shutil.which(os.environ.get("CC", "cc"))
    if compiler is None:
        if os.environ.get("CI"):
            pytest.fail("no C compiler (cc), and CI must run every check: install gcc")
        pytest.skip("no C compiler (cc) to build the C side of the comparison")
    directory = tmp_path_factory.mktemp("c")
    library = library_path()

    def build(source: str) -> Path:
        program = directory / Path(source).stem
        if not program.exists():
            command = [
                compiler, "-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O1",
                "-I", str(CHECKOUT / "include"), "-I", str(CHECKOUT / "tests" / "c"),
                str(CHECKOUT / source), "-o", str(program),
                # Exactly the file the package loads, found through an RPATH.
                f"-L{library.parent}", "-lprojfluid", "-Wl,--disable-new-dtags",
                f"-Wl,-rpath,{library.parent}", "-lm",
            ]  # fmt: skip
            done = subprocess.run(command, capture_output=True, text=True)
            assert done.returncode == 0, f"compiling {source} failed:\n{done.stderr}"
        return program

    return build


def run_program(program: Path, *args: str) -> dict[str, str]:
    """Runs ``program`` and returns its ``key value`` output lines as a dict."""
    done = subprocess.run([str(program), *args], capture_output=True, text=True)
    assert done.returncode == 0, f"{program.name} failed:\n{done.stdout}\n{done.stderr}"
    return dict(line.split(" ", 1) for line in done.stdout.splitlines() if " " in line)
