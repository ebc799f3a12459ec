"""The compiled kernels (tanktool/_kernels.c), when they were built.

``pip install`` compiles tanktool/_kernels.c when it finds a C compiler (setup.py);
without one the extension is simply missing and every caller runs its numpy code,
which gives identical results (tests/test_kernels.py runs both and compares).  The
environment variable ``TANKTOOL_NO_KERNELS=1`` forces the numpy code (the bench
and the tests use :func:`use_kernels` for the same).

The kernels are the loops over spans that visit a variable number of neighbour spans
(Recast's ledge filter, the links between open spans) and the chamfer distance
relaxed to its fixed point: in numpy those are passes over every span per neighbour
rank or per round, in C one pass (or a few sweeps).
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from typing import Iterator

import numpy as np

#: the kernels' interface this code calls (TANKTOOL_KERNELS_ABI in tanktool/_kernels.c)
ABI = 18

try:  # built by setup.py when a compiler was there
    from .. import _kernels as _compiled
except ImportError:  # pragma: no cover - depends on the install
    _compiled = None
if _compiled is not None and getattr(_compiled, "ABI", None) != ABI:
    # a build left from older sources (an editable install is not rebuilt by a pull):
    # its functions may take other arguments, so the numpy code is used until it is rebuilt
    import warnings

    warnings.warn(f"{_compiled.__file__} was built from other sources than this tanktool; "
                  "using the numpy code (rebuild: pip install -e . or make install)", RuntimeWarning,
                  stacklevel=1)
    _compiled = None

_enabled = os.environ.get("TANKTOOL_NO_KERNELS", "") in ("", "0")


def available() -> bool:
    """Whether the compiled kernels are built (whether or not they are in use)."""
    return _compiled is not None


def active():
    """The compiled module when it is built and in use, else None (use numpy)."""
    return _compiled if _enabled else None


@contextmanager
def use_kernels(on: bool) -> Iterator[None]:
    """Within the block, use the compiled kernels (when built) or force numpy."""
    global _enabled
    before = _enabled
    _enabled = on
    try:
        yield
    finally:
        _enabled = before


def i64(a: np.ndarray) -> np.ndarray:
    """A C-contiguous int64 array (the kernels' buffers), copied only when needed."""
    return np.ascontiguousarray(a, dtype=np.int64)
