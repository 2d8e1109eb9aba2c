"""projfluid: liquids as SPH particles with Projective Dynamics and Chebyshev acceleration.

A Python binding of the projfluid C library (bundled inside this package) through its C
API only. Quick start::

    import projfluid
    with projfluid.load_scene("dam_break_small") as world:
        world.advance(0.2)                        # seconds of CFL-limited steps
        print(world.positions().shape)            # (3840, 3) float32, metres

Arrays are numpy arrays; units are SI (m, s, kg). Every failed C call raises a
:class:`ProjfluidError` subclass carrying the C status and message.
"""

from ._capi import lib as _lib
from .bodies import Body, BodyKind
from .errors import (
    BufferTooSmallError,
    BusyError,
    InvalidArgumentError,
    NullPointerError,
    OutOfMemoryError,
    PanicError,
    ProjfluidError,
    Status,
    WorldClosedError,
    WorldPoisonedError,
)
from .geometry import Pose, Transform
from .params import Omega2Rule, Params, ProjectionWeight, Solver
from .scene import load_scene
from .stats import StepStats
from .world import World

#: The version of the bundled C library (``pf_version_string()``), e.g. ``"0.1.0"``.
__version__: str = _lib.pf_version_string().decode()

__all__ = [
    "Body",
    "BodyKind",
    "BufferTooSmallError",
    "BusyError",
    "InvalidArgumentError",
    "NullPointerError",
    "Omega2Rule",
    "OutOfMemoryError",
    "PanicError",
    "Params",
    "Pose",
    "ProjectionWeight",
    "ProjfluidError",
    "Solver",
    "Status",
    "StepStats",
    "Transform",
    "World",
    "WorldClosedError",
    "WorldPoisonedError",
    "load_scene",
]
