"""Worlds made from scenes: the built-in ones and JSON scene files (docs/scene-format.md)."""

from __future__ import annotations

import os
from ctypes import byref, c_void_p

from ._capi import lib
from .errors import check
from .world import World


def load_scene(name_or_path: str | os.PathLike[str]) -> World:
    """A world built from a scene, at time 0 and ready to step: ``name_or_path`` is a
    built-in scene's name (``"dam_break_small"``, ``"fountain"``, …; ``projfluid scenes``
    lists them) or the path of a JSON scene file. The world has the scene's parameters
    (:attr:`World.params`), walls, obstacles, bodies (with the scene's ids), fluid, emitters,
    sinks and domain; the scene's duration and output settings are not part of it. The
    same scene gives the same world as ``projfluid run``, bit for bit.

    An unknown name or a bad file raises :class:`~projfluid.errors.InvalidArgumentError`
    with the C library's message (which names the file, the key and the value, or lists
    the built-in scenes).
    """
    handle = c_void_p()
    check(lib.pf_world_create_from_scene(os.fsencode(name_or_path), byref(handle)))
    return World._adopt(handle)
