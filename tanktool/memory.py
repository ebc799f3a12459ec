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
