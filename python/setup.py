"""Builds the projfluid C library with cargo and puts it inside the package, so that
`pip install ./python` from a projfluid checkout gives a self-contained wheel.

The build is the one `cargo run --release`, `cargo test --release` and `make install` make
(the workspace's libraries, release profile), so after any of them cargo finds the library up
to date and the package reuses it. pip shows a build's output only with `-v`, so cargo's
progress goes to the terminal when there is one, and to stderr otherwise.

Environment:
  CARGO                    the cargo to run (default: cargo on PATH)
  CARGO_TARGET_DIR         cargo's target directory (default: target/ of the checkout)
  PROJFLUID_CARGO_PROFILE  the cargo profile (default: release)
  PROJFLUID_LIBRARY        an already built libprojfluid.so to bundle instead of running
                           cargo
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import TextIO

from setuptools import setup
from setuptools.command.bdist_wheel import bdist_wheel
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent
CHECKOUT = HERE.parent


def library_file_name() -> str:
    """The shared library's file name on this platform (as `_capi.library_file_name`)."""
    if sys.platform == "darwin":
        return "libprojfluid.dylib"
    if sys.platform == "win32":
        return "projfluid.dll"
    return "libprojfluid.so"


def cargo_version() -> str:
    """The version of the Rust package, which the Python package shares."""
    text = (CHECKOUT / "Cargo.toml").read_text(encoding="utf-8")
    match = re.search(r'^\[workspace\.package\][^\[]*?^version\s*=\s*"([^"]+)"', text, re.M | re.S)
    if match is None:
        raise RuntimeError(f"no workspace version in {CHECKOUT / 'Cargo.toml'}")
    return match.group(1)


def terminal() -> TextIO | None:
    """The terminal pip runs in, if any: pip captures a build's stdout and stderr and shows
    them only with -v, so the build reports its progress there."""
    try:
        return open("/dev/tty", "w", encoding="utf-8")  # noqa: SIM115 (closed by the caller)
    except OSError:
        return None


def build_library() -> Path:
    """Runs cargo to build the C library and returns the built file."""
    if not (CHECKOUT / "include" / "projfluid.h").exists():
        raise RuntimeError(
            f"{CHECKOUT} is not a projfluid checkout: build the package from python/ inside "
            "one (pip install ./python)"
        )
    profile = os.environ.get("PROJFLUID_CARGO_PROFILE", "release")
    cargo = os.environ.get("CARGO", "cargo")
    # The workspace's libraries, as `make install` builds them: the features `cargo run` and
    # `cargo test` give the dependencies, and so the same build, which cargo finds up to date
    # after any of them. Its messages (the progress bar, errors) go to the terminal; its
    # standard output says what it built.
    command = [cargo, "build", "--workspace", "--lib", "--profile", profile]
    tty = terminal()
    out = tty or sys.stderr
    try:
        print(
            ("\n" if tty else "") + f"projfluid: building the C library: {' '.join(command)}\n"
            "projfluid: (minutes the first time; a second after `cargo run --release`, "
            "`cargo test --release` or `make install`, which build the same)",
            file=out,
            flush=True,
        )
        done = subprocess.run(
            [*command, "--message-format=json-render-diagnostics"],
            cwd=CHECKOUT,
            check=True,
            stdout=subprocess.PIPE,
            stderr=out,
            text=True,
        )
        built: Path | None = None
        fresh = False
        for line in done.stdout.splitlines():
            message = json.loads(line)
            if message.get("reason") != "compiler-artifact":
                continue
            for file in message["filenames"]:
                if Path(file).name == library_file_name():
                    built, fresh = Path(file), message["fresh"]
        if built is None or not built.exists():
            raise RuntimeError(f"`{' '.join(command)}` built no {library_file_name()}")
        print(
            f"projfluid: {'already built, up to date' if fresh else 'built'}: {built}",
            file=out,
            flush=True,
        )
    finally:
        if tty:
            tty.close()
    return built


def library() -> Path:
    """The library to bundle: `$PROJFLUID_LIBRARY`, or the one cargo builds."""
    prebuilt = os.environ.get("PROJFLUID_LIBRARY")
    if not prebuilt:
        return build_library()
    path = Path(prebuilt).resolve()
    if not path.is_file():
        raise RuntimeError(f"PROJFLUID_LIBRARY={prebuilt} is not a file")
    print(f"bundling the C library {path}", flush=True)
    return path


class BuildWithCargo(build_py):
    """`build_py` that also builds the C library and copies it, stripped, into the package."""

    def run(self) -> None:
        super().run()
        built = library()
        destination = Path(self.build_lib) / "projfluid" / library_file_name()
        destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, destination)
        strip = shutil.which("strip")
        if strip and sys.platform.startswith("linux"):
            # Line tables and debugging sections are of no use to a wheel and double its size.
            subprocess.run([strip, "--strip-unneeded", str(destination)], check=True)


class PlatformWheel(bdist_wheel):
    """A wheel for this platform (it carries a shared library) that works with any Python 3
    (the library is loaded with ctypes, not as an extension module)."""

    def finalize_options(self) -> None:
        super().finalize_options()
        self.root_is_pure = False

    def get_tag(self) -> tuple[str, str, str]:
        _, _, platform = super().get_tag()
        return "py3", "none", platform


setup(
    version=cargo_version(),
    cmdclass={"build_py": BuildWithCargo, "bdist_wheel": PlatformWheel},
)
