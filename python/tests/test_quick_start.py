"""The README's Python quick start runs as written and prints a sane dam break: its
```python block, taken from README.md verbatim, runs with this interpreter and this library."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np

import projfluid
from conftest import CHECKOUT

README = CHECKOUT / "README.md"
HEADING = "## Python quick start"

PRINTED = re.compile(
    r"(?P<count>\d+) particles, mean height (?P<height>[\d.]+) m "
    r"\((?P<start>[\d.]+) m at the start\), last step (?P<outer>\d+) outer iterations "
    r"\(limit hit: (?P<hit>True|False)\), density error (?P<error>[\d.]+) %"
)
"""The line the snippet prints."""


def quick_start() -> str:
    """The fenced ```python block of the README's "Python quick start" section."""
    lines = README.read_text(encoding="utf-8").splitlines()
    start = lines.index(HEADING) + 1
    end = next((i for i in range(start, len(lines)) if lines[i].startswith("## ")), len(lines))
    section = lines[start:end]
    assert "```python" in section, f"no ```python block under {HEADING!r}"
    first = section.index("```python") + 1
    last = section.index("```", first)
    return "\n".join(section[first:last]) + "\n"


def test_the_readme_python_quick_start_runs_and_the_water_settles() -> None:
    code = quick_start()
    assert 'load_scene("dam_break_small")' in code and "world.advance(0.5)" in code
    # PYTHONPATH and PROJFLUID_LIB as this test has them: the same package and library.
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=dict(os.environ)
    )
    assert done.returncode == 0, f"the quick start failed:\n{done.stdout}\n{done.stderr}"
    printed = PRINTED.fullmatch(done.stdout.strip())
    assert printed, f"unexpected output: {done.stdout!r}"

    with projfluid.load_scene("dam_break_small") as scene:
        count = scene.fluid_count
        start = scene.positions()[:, 1].mean(dtype=np.float64)
        limit = scene.params.max_outer_iterations
    assert int(printed["count"]) == count == 16 * 20 * 12  # no emitter or sink changes it
    assert abs(float(printed["start"]) - start) <= 5e-4 + 1e-6  # printed to 1 mm
    # The column (0.525 m high on average) collapses: 0.256 m at 0.5 s.
    assert float(printed["height"]) < float(printed["start"])
    assert printed["hit"] == "False" and 1 <= int(printed["outer"]) < limit
    # About 0.02 % at 0.5 s; the solver stops at 0.03 % on average (density_tolerance).
    assert float(printed["error"]) < 0.1
