"""Status codes of the C API and the exceptions that carry them.

Every failed C call raises a :class:`ProjfluidError` subclass chosen by its status, carrying
the status and the library's message, which names the C function, the argument and the
value (e.g. ``pf_world_add_fluid_box: count[1] must be positive, got 0``). As in C, a
failed call changes nothing.
"""

from __future__ import annotations

import enum

from ._capi import lib


class Status(enum.IntEnum):
    """``PfStatus``: what a C function did."""

    OK = 0
    ERROR_NULL_POINTER = 1
    ERROR_INVALID_ARGUMENT = 2
    ERROR_BUFFER_TOO_SMALL = 3
    ERROR_OUT_OF_MEMORY = 4
    ERROR_PANIC = 5
    ERROR_WORLD_POISONED = 6
    ERROR_BUSY = 7

    @property
    def c_name(self) -> str:
        """The name C gives the code, e.g. ``"PF_ERROR_INVALID_ARGUMENT"``."""
        return str(lib.pf_status_name(int(self)).decode())


class ProjfluidError(Exception):
    """A C call failed.

    Attributes:
        status: the :class:`Status` the C function returned.
        message: ``pf_last_error_message()`` after the call, naming the function.
    """

    def __init__(self, status: Status, message: str) -> None:
        super().__init__(f"{status.c_name}: {message}")
        self.status = status
        self.message = message


class NullPointerError(ProjfluidError):
    """``PF_ERROR_NULL_POINTER``: a required argument was missing."""


class InvalidArgumentError(ProjfluidError, ValueError):
    """``PF_ERROR_INVALID_ARGUMENT``: a value out of range, non-finite or inconsistent, bad
    parameters, an unknown scene or id, or a call the world's state does not allow."""


class BufferTooSmallError(ProjfluidError):
    """``PF_ERROR_BUFFER_TOO_SMALL``: an output array was too short (e.g. the particle
    count changed between sizing and reading)."""


class OutOfMemoryError(ProjfluidError, MemoryError):
    """``PF_ERROR_OUT_OF_MEMORY``: particle storage could not be allocated."""


class PanicError(ProjfluidError, RuntimeError):
    """``PF_ERROR_PANIC``: a bug inside the library; the world involved is now poisoned."""


class WorldPoisonedError(ProjfluidError, RuntimeError):
    """``PF_ERROR_WORLD_POISONED``: the world hit a bug earlier; only closing it is allowed."""


class BusyError(ProjfluidError, RuntimeError):
    """``PF_ERROR_BUSY``: another thread is using the same world right now."""


class WorldClosedError(ValueError):
    """The :class:`~projfluid.World` was closed; its handle is gone (no C call was made)."""


_BY_STATUS: dict[Status, type[ProjfluidError]] = {
    Status.ERROR_NULL_POINTER: NullPointerError,
    Status.ERROR_INVALID_ARGUMENT: InvalidArgumentError,
    Status.ERROR_BUFFER_TOO_SMALL: BufferTooSmallError,
    Status.ERROR_OUT_OF_MEMORY: OutOfMemoryError,
    Status.ERROR_PANIC: PanicError,
    Status.ERROR_WORLD_POISONED: WorldPoisonedError,
    Status.ERROR_BUSY: BusyError,
}


def check(status: int) -> None:
    """Raises the exception for a C ``status`` other than ``PF_OK``, with the calling thread's
    last error message (read at once, before any other C call)."""
    if status == Status.OK:
        return
    message = lib.pf_last_error_message().decode("utf-8", errors="replace")
    try:
        code = Status(status)
    except ValueError:
        raise ProjfluidError(Status.ERROR_PANIC, f"unknown status {status}: {message}") from None
    raise _BY_STATUS[code](code, message)
