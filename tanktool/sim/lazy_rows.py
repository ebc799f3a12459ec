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

import math
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
    """A row of heights as floats, None where there is no node (NaN)."""
    return [None if not math.isfinite(v) else float(v) for v in row.tolist()]


def plain_row(row: np.ndarray) -> list:
    """A row as nested Python lists (ints, bools)."""
    return row.tolist()


_TUPLES: dict[tuple, tuple] = {}


def tuple_row(row: np.ndarray) -> list:
    """A row of small tuples (a node's links) as a list of shared tuples: a row of a
    2 km terrain's links as lists of lists took 380 KB, as shared tuples 32 KB."""
    shared = _TUPLES
    if len(shared) > 4096:   # a few distinct link patterns on any ground; bounded anyway
        shared.clear()
    return [shared.setdefault(t, t) for t in map(tuple, row.tolist())]


def lazy_levels(array: np.ndarray, convert: Callable[[np.ndarray], Any], keep: int | None = None) -> list[LazyRows]:
    """One LazyRows per level of an (L, nz, ...) array (``keep``: rows kept per level)."""
    return [LazyRows(array[lv], convert, keep) for lv in range(len(array))]
