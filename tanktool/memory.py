"""Keep freed memory for reuse (glibc only).

numpy's temporaries of more than 128 KB are mapped from the kernel one by one and
given back when freed (glibc's default), so a vectorised pass over a few hundred
thousand spans pays a page fault every 4 KB on every call: on this project's
machines that was a quarter of the walkable-surface pipeline's time.  Raising glibc's
mmap and trim thresholds keeps those pages in the heap for the next array.  The
command-line entry point calls this once; it changes nothing but the process's
memory reuse (its peak size is the same, it is just not handed back early).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import gc
from typing import Any, Callable, TypeVar

T = TypeVar("T")

#: glibc's mallopt parameters
M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
#: arrays up to this size come from the heap, and this much free heap is kept
THRESHOLD = 256 * 1024 * 1024

_done = False


def keep_freed_memory() -> bool:
    """Raise glibc's thresholds once; False where there is no glibc (nothing done)."""
    global _done
    if _done:
        return True
    try:
        name = ctypes.util.find_library("c")
        libc = ctypes.CDLL(name) if name else None
        mallopt = getattr(libc, "mallopt", None) if libc is not None else None
        if mallopt is None:
            return False
        mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
        ok = bool(mallopt(M_MMAP_THRESHOLD, THRESHOLD)) and bool(mallopt(M_TRIM_THRESHOLD, THRESHOLD))
    except (OSError, AttributeError):
        return False
    _done = ok
    return ok


#: builds that made less than this give nothing back (trimming costs a walk of the heap)
GIVE_BACK_MIN = 256 * 1024 * 1024
_trim = None


def give_back(nbytes: int) -> bool:
    """After a build that made ``nbytes`` of arrays and let most of them go, hand the
    heap's free pages back to the kernel (glibc's malloc_trim; nothing below
    GIVE_BACK_MIN, or without glibc).  keep_freed_memory keeps freed arrays' pages for
    reuse, and the ones between live arrays are never reused by the next, larger stage:
    on a 2 km terrain's import they were ~0.3 GB of the 3.8 GB peak resident size."""
    global _trim
    if nbytes < GIVE_BACK_MIN:
        return False
    if _trim is None:
        try:
            name = ctypes.util.find_library("c")
            _trim = getattr(ctypes.CDLL(name), "malloc_trim", False) if name else False
        except OSError:
            _trim = False
    if not _trim:
        return False
    _trim(0)
    return True


def frozen_heap(fn: Callable[..., T]) -> Callable[..., T]:
    """``fn`` with the objects alive before it frozen (gc.freeze) while it runs: a full
    collection (the import's, after the scene read and the preview's figure) then scans
    only what the build made, not the ~120,000 objects of the modules loaded before it
    (matplotlib, scipy, trimesh, shapely: ~85 ms a collection on hix's import).  What
    was garbage before the call is collected after it.  Nothing is done when the caller
    froze objects itself (unfreezing would undo its freeze) or in a nested call."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> T:
        if gc.get_freeze_count():
            return fn(*args, **kwargs)
        gc.freeze()
        try:
            return fn(*args, **kwargs)
        finally:
            gc.unfreeze()

    return wrapper
