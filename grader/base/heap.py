"""Python's cyclic garbage collector, paused while a run builds many objects.

A big class makes millions of objects (keys, rows, verdicts, variants) and no cycles worth
collecting: reference counting frees them. Each pass of the collector walks the whole growing heap,
so with it on, time grows faster than the class (reading 1.1 million answers took twice as long;
making a 10,000-student key, superlinear). At the end what the run made is frozen: ``keep_frozen``
leaves it out of every later pass until :func:`gc.unfreeze` (the variants a PDF run still needs),
else ``freeze`` then ``unfreeze`` moves it to the oldest generation, or the first collection after
the run would walk it all once more.

>>> import gc
>>> with collector_paused():
...     gc.isenabled()
False
>>> gc.isenabled()
True
"""

from __future__ import annotations

import functools
import gc
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager


@contextmanager
def collector_paused(*, keep_frozen: bool = False) -> Iterator[None]:
    """The collector off inside; on again after (if it was), with what was made frozen or aged."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if not keep_frozen:
            gc.unfreeze()
        if enabled:
            gc.enable()


def hand_back() -> None:
    """Hand the memory freed since the last call back to the system, where the C library keeps it otherwise
    (glibc's ``malloc_trim``: a million students' key read leaves about 1 GiB free but held, and each piece of a
    class graded a little more). Elsewhere nothing: the memory is reused all the same."""
    trim = _trim()
    if trim is not None:
        trim(0)


@functools.cache
def _trim() -> Callable[[int], int] | None:
    """glibc's ``malloc_trim``, where the C library is glibc."""
    if sys.platform != "linux":
        return None
    import ctypes  # here: only a run that frees much memory needs it

    try:
        return ctypes.CDLL("libc.so.6").malloc_trim
    except (OSError, AttributeError):  # musl (no malloc_trim), or no libc.so.6
        return None
