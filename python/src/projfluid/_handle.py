"""The ``PfWorld *`` a :class:`~projfluid.World` owns: lent to one C call at a time per
thread, and destroyed once, after every call in flight has returned."""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator
from ctypes import c_void_p

from ._capi import lib
from .errors import WorldClosedError


class WorldHandle:
    """Owns a world handle from ``pf_world_create``.

    Calls from several threads are let through to C, which detects a world used by two
    threads at once (``PF_ERROR_BUSY``); :meth:`close` waits for calls in flight, so a
    handle is never destroyed while C uses it.
    """

    def __init__(self, handle: c_void_p) -> None:
        self._handle: c_void_p | None = handle
        self._in_flight = 0
        self._idle = threading.Condition(threading.Lock())

    @property
    def closed(self) -> bool:
        """Whether the world has been closed."""
        return self._handle is None

    @contextlib.contextmanager
    def use(self) -> Iterator[c_void_p]:
        """The handle, for the C calls inside the ``with`` block; raises
        :class:`~projfluid.errors.WorldClosedError` when the world is closed."""
        with self._idle:
            handle = self._handle
            if handle is None:
                raise WorldClosedError("the world is closed")
            self._in_flight += 1
        try:
            yield handle
        finally:
            with self._idle:
                self._in_flight -= 1
                if self._in_flight == 0:
                    self._idle.notify_all()

    def close(self) -> None:
        """Destroys the world (``pf_world_destroy``) after the calls in flight return.
        Closing a closed world does nothing."""
        with self._idle:
            handle, self._handle = self._handle, None
            if handle is None:
                return
            self._idle.wait_for(lambda: self._in_flight == 0)
        lib.pf_world_destroy(handle)
