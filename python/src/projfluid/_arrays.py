"""Conversions between Python values, numpy arrays and the C API's pointers and buffers."""

from __future__ import annotations

import ctypes
from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

Vector3 = Sequence[float]
"""Three numbers x, y, z (a tuple, a list or a numpy array)."""


def vector3(value: Any, name: str) -> tuple[float, float, float]:
    """``value`` as three floats; :class:`ValueError` naming ``name`` otherwise."""
    try:
        x, y, z = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be three numbers, got {value!r}") from None
    return (x, y, z)


def floats3(value: Any, name: str) -> ctypes.Array[ctypes.c_float]:
    """``value`` as a C ``float[3]`` (the C API's particle vectors are single precision)."""
    return (ctypes.c_float * 3)(*vector3(value, name))


def doubles3(value: Any, name: str) -> ctypes.Array[ctypes.c_double]:
    """``value`` as a C ``double[3]`` (bodies, emitters and sinks take doubles)."""
    return (ctypes.c_double * 3)(*vector3(value, name))


def rows(value: Any, columns: int, dtype: npt.DTypeLike, name: str) -> np.ndarray:
    """``value`` as a C-contiguous ``(n, columns)`` array of ``dtype``, copied only when it is
    not one already; :class:`ValueError` naming ``name`` for another shape."""
    array = np.ascontiguousarray(value, dtype=dtype)
    if array.ndim != 2 or array.shape[1] != columns:
        raise ValueError(f"{name} must have shape (n, {columns}), got {array.shape}")
    return array


def indices(value: Any, name: str) -> np.ndarray:
    """``value`` as a C-contiguous ``(m, 3)`` ``uint32`` array of vertex indices; a negative
    or too large index is a :class:`ValueError` (C would see it wrapped)."""
    array = np.asarray(value)
    if array.dtype.kind not in "iu":
        raise ValueError(f"{name} must hold integers, got dtype {array.dtype}")
    if array.size and (array.min() < 0 or array.max() > 0xFFFF_FFFF):
        raise ValueError(f"{name} must hold indices in 0..4294967295")
    return rows(array, 3, np.uint32, name)


def output(
    out: np.ndarray | None, shape: tuple[int, ...], dtype: npt.DTypeLike, name: str
) -> np.ndarray:
    """The array a read fills: a new one when ``out`` is None, otherwise ``out`` itself, which
    must have exactly this shape and dtype and be C-contiguous and writeable (so that C
    writes into it directly, without a copy)."""
    if out is None:
        return np.empty(shape, dtype=dtype)
    if not isinstance(out, np.ndarray):
        raise TypeError(f"{name} must be a numpy array, got {type(out).__name__}")
    if out.shape != shape or out.dtype != np.dtype(dtype):
        raise ValueError(
            f"{name} must have shape {shape} and dtype {np.dtype(dtype)}, "
            f"got {out.shape} and {out.dtype}"
        )
    if not out.flags.c_contiguous or not out.flags.writeable:
        raise ValueError(f"{name} must be C-contiguous and writeable")
    return out


def pointer(array: np.ndarray, ctype: Any) -> Any:
    """A C pointer to ``array``'s data, typed as ``ctype *``."""
    return array.ctypes.data_as(ctypes.POINTER(ctype))
