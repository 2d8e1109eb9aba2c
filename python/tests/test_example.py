"""The example examples/python/dam_break.py runs and reports a sane dam break."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from conftest import CHECKOUT

EXAMPLE = CHECKOUT / "examples" / "python" / "dam_break.py"


def run(*args: str) -> str:
    done = subprocess.run(
        [sys.executable, str(EXAMPLE), "--seconds", "0.12", *args],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_dam_break_example_runs_and_the_front_advances() -> None:
    out = run("--no-plot")
    last = out.splitlines()[-1]
    assert last.startswith("python dam_break: ok, front at ") and last.endswith("escaped 0")
    front = float(last.split("front at ")[1].split()[0])
    assert 0.81 < front < 1.0  # m: the column (0.8 m wide) has started to spread


def test_the_dam_break_example_plots_with_matplotlib(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")  # an optional dependency
    picture = tmp_path / "dam_break.png"
    out = run("--plot", str(picture))
    assert f"wrote {picture}" in out
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
