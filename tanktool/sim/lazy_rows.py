"""Rows of a large array as plain Python lists, each made on its first use.

The ground's per-tank lookups (sim/ground.py) are scalar Python, fastest on nested
lists; but converting a whole 2 km terrain's (16 M nodes) heights and links up front
took a minute and ~2 GB of list and float objects, of which a match reads the rows
near its tanks.  ``LazyRows(array, convert)`` is indexed like that list of rows
(``rows[i][j]``): a dict whose missing row ``i`` is ``convert(array[i])``, kept.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Iterator

import numpy as np


class LazyRows(dict):
    """``rows[i]`` is ``convert(array[i])``, made on first use (see the module docstring)."""

    __slots__ = ("_array", "_convert")

    def __init__(self, array: np.ndarray, convert: Callable[[np.ndarray], Any]) -> None:
        super().__init__()
        self._array = array
        self._convert = convert

    def __missing__(self, i: int) -> Any:
        row = self._convert(self._array[i])   # a negative or too large i: numpy's as a list's
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


def lazy_levels(array: np.ndarray, convert: Callable[[np.ndarray], Any]) -> list[LazyRows]:
    """One LazyRows per level of an (L, nz, ...) array."""
    return [LazyRows(array[lv], convert) for lv in range(len(array))]
