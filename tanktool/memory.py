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
    """Raise glibc's thresholds once (and stop numpy asking for huge pages); False
    where there is no glibc (the thresholds untouched)."""
    global _done
    if _done:
        return True
    _no_huge_pages()
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


def _no_huge_pages() -> None:
    """numpy marks arrays of 4 MB and more for transparent huge pages (madvise): each
    first touch then faults in 2 MB, which the kernel must find or compact; with freed
    memory kept for reuse that buys little, and on a fragmented machine it costs: the
    2 km terrain's import 20.9-22.2 -> 19.7-20.0 s (system time 6.0-7.1 -> 4.2-4.6 s),
    1 km 4.47-4.58 -> 4.36-4.38 s, hix the same (in turn, quiet, this project's 2-core
    virtual machine).  A private numpy switch, so asked for with care."""
    try:
        try:
            from numpy._core.multiarray import _set_madvise_hugepage
        except ImportError:  # numpy 1.x
            from numpy.core.multiarray import _set_madvise_hugepage
        _set_madvise_hugepage(False)
    except Exception:  # not there (another numpy): numpy's default stays
        pass


#: builds that made less than this give nothing back (trimming costs a walk of the heap)
GIVE_BACK_MIN = 256 * 1024 * 1024
#: a heap smaller than this keeps its free pages: the next stage takes them again, and
#: pages given back and taken again are faulted in and zeroed anew (hix's import, a
#: 0.34-0.46 GB heap: 46,000 page faults fewer, 4.3-4.6 -> 3.9-4.2 s of CPU, peak 582 ->
#: 604 MB); the large levels, where the memory matters, are trimmed as before (2 km
#: terrain: peak 1942 / 1943 MB; at 1 GB it was 1969 MB: a trim there still pays)
GIVE_BACK_HEAP = 512 * 1024 * 1024
_trim = None
_heap = None


class _MallInfo2(ctypes.Structure):
    """glibc's struct mallinfo2 (2.33 and later)."""

    _fields_ = [(n, ctypes.c_size_t) for n in ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks",
                                               "uordblks", "fordblks", "keepcost")]


def _libc_functions() -> None:
    """malloc_trim and mallinfo2 from glibc, once (False where missing)."""
    global _trim, _heap
    try:
        name = ctypes.util.find_library("c")
        libc = ctypes.CDLL(name) if name else None
    except OSError:
        libc = None
    _trim = getattr(libc, "malloc_trim", False) if libc is not None else False
    _heap = getattr(libc, "mallinfo2", False) if libc is not None else False
    if _heap:
        _heap.restype = _MallInfo2


def heap_bytes() -> int | None:
    """The size of glibc's main heap (in use and free), None where it cannot be asked."""
    if _heap is None:
        _libc_functions()
    return int(_heap().arena) if _heap else None


def give_back(nbytes: int) -> bool:
    """After a build that made ``nbytes`` of arrays and let most of them go, hand the
    heap's free pages back to the kernel (glibc's malloc_trim; nothing below
    GIVE_BACK_MIN, nor while the heap is under GIVE_BACK_HEAP, or without glibc).
    keep_freed_memory keeps freed arrays' pages for reuse, and the ones between live
    arrays are never reused by the next, larger stage: on a 2 km terrain's import they
    were ~0.3 GB of the 3.8 GB peak resident size."""
    if nbytes < GIVE_BACK_MIN:
        return False
    if _trim is None:
        _libc_functions()
    if not _trim:
        return False
    heap = heap_bytes()
    if heap is not None and heap < GIVE_BACK_HEAP:
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
        # a nested call is known by our own count: get_freeze_count() walks every frozen
        # object (~15 ms a call under the import's freeze on hix: build_grid, twice)
        if _FROZEN[0] or gc.get_freeze_count():
            return fn(*args, **kwargs)
        gc.freeze()
        _FROZEN[0] += 1
        try:
            return fn(*args, **kwargs)
        finally:
            _FROZEN[0] -= 1
            gc.unfreeze()

    return wrapper


#: how many frozen_heap calls froze the heap and are running (0 or 1)
_FROZEN = [0]
