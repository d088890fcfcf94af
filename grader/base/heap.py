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

import gc
from collections.abc import Iterator
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
