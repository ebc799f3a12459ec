"""Rows of a large array as plain Python lists, each made on its first use.

The ground's per-tank lookups (sim/ground.py) are scalar Python, fastest on nested
lists; but converting a whole 2 km terrain's (16 M nodes) heights and links up front
took a minute and ~2 GB of list and float objects, of which a match reads the rows
near its tanks.  ``LazyRows(array, convert)`` is indexed like that list of rows
(``rows[i][j]``): a dict whose missing row ``i`` is ``convert(array[i])``, kept --
up to ``keep`` rows, past which the oldest made is dropped (made again when read):
the tanks' rows stay, where keeping every row they crossed grew a 2 km match by
~35 MB a simulated second.
"""

from __future__ import annotations

from typing import Any, Callable, Iterator

import numpy as np


class LazyRows(dict):
    """``rows[i]`` is ``convert(array[i])``, made on first use (see the module docstring)."""

    __slots__ = ("_array", "_convert", "_keep")

    def __init__(self, array: np.ndarray, convert: Callable[[np.ndarray], Any], keep: int | None = None) -> None:
        super().__init__()
        self._array = array
        self._convert = convert
        self._keep = keep

    def __missing__(self, i: int) -> Any:
        row = self._convert(self._array[i])   # a negative or too large i: numpy's as a list's
        if self._keep is not None and dict.__len__(self) >= self._keep:
            del self[next(iter(self.keys()))]   # the oldest made (dicts keep insertion order)
        self[i] = row
        return row

    def __len__(self) -> int:
        return len(self._array)

    def __iter__(self) -> Iterator[Any]:
        return (self[i] for i in range(len(self._array)))


def heights_row(row: np.ndarray) -> list:
    """A row of heights as floats, None where there is no node (NaN).  Through an
    object array: a Python comprehension over a 2 km row (4002 nodes) took ~1.2 ms,
    and the tanks' moves make a few hundred rows a simulated second."""
    out = row.astype(object)
    out[~np.isfinite(row)] = None
    return out.tolist()


def plain_row(row: np.ndarray) -> list:
    """A row as nested Python lists (ints, bools)."""
    return row.tolist()


_TUPLES: dict[tuple, tuple] = {}


def tuple_row(row: np.ndarray) -> list:
    """A row of small tuples (a node's links) as a list of shared tuples: a row of a
    2 km terrain's links as lists of lists took 380 KB, as shared tuples 32 KB.  A
    node's bytes read as one integer pick its tuple among the row's few distinct
    ones (numpy's unique), so only those few are made in Python: the per-node
    comprehension took ~5 ms a 2 km row, most of a terrain match's steps."""
    shared = _TUPLES
    if len(shared) > 4096:   # a few distinct link patterns on any ground; bounded anyway
        shared.clear()
    code = _codes(row)
    if code is None:
        return [shared.setdefault(t, t) for t in map(tuple, row.tolist())]
    uniq, first, inverse = np.unique(code, return_index=True, return_inverse=True)
    table = np.empty(len(uniq), dtype=object)
    for k, t in enumerate(map(tuple, row[first].tolist())):
        table[k] = shared.setdefault(t, t)
    return table[inverse.reshape(-1)].tolist()


_CODE_TYPES = {1: np.uint8, 2: np.uint16, 4: np.uint32, 8: np.uint64}


def _codes(row: np.ndarray) -> np.ndarray | None:
    """Each (n, m) row's node as one unsigned integer of its m items' bytes, or None
    when they do not make 1, 2, 4 or 8 bytes."""
    if row.ndim != 2 or len(row) == 0:
        return None
    kind = _CODE_TYPES.get(row.shape[1] * row.dtype.itemsize)
    if kind is None:
        return None
    return np.ascontiguousarray(row).view(kind).reshape(-1)


def lazy_levels(array: np.ndarray, convert: Callable[[np.ndarray], Any], keep: int | None = None) -> list[LazyRows]:
    """One LazyRows per level of an (L, nz, ...) array (``keep``: rows kept per level)."""
    return [LazyRows(array[lv], convert, keep) for lv in range(len(array))]
