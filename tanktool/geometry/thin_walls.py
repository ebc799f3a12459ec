"""Thin walls: open cut chains (zero-thickness fences, one-sided faces, loops whose
normals disagree) where they cross free space, as wall segments.

Nothing says which side of such a chain is solid, so each piece inside free space is
a wall both ways (:func:`tanktool.geometry.walls.extract_walls` writes it twice, its
copy reversed).  A level of many one-sided faces (a Sauerbraten map: thousands of
chains over a free space of thousands of vertices) spent 44 of its 48 s of import
clipping chains one at a time; :func:`thin_walls` clips them all in one overlay.
bench/walls.py compares the two in one run.
"""

from __future__ import annotations

import numpy as np
import shapely


def thin_walls(chains: list, free, tolerance: float) -> np.ndarray:
    """Open cut chains where they cross free space, as (n, 2, 2) segments.

    All chains are clipped in one overlay of their union with the free space: clipping
    each chain on its own (:func:`thin_walls_reference`) rebuilt the whole free
    polygon's edge graph once per chain, which on a level of many one-sided faces was
    nearly all of the import (bench/walls.py)."""
    if not chains or free.is_empty:
        return np.zeros((0, 2, 2))
    lines = shapely.simplify(np.array(chains, dtype=object), tolerance)
    lines = lines[shapely.get_type_id(lines) == 1]  # LineStrings (a chain simplified to a point drops out)
    if len(lines) == 0:
        return np.zeros((0, 2, 2))
    inside = shapely.intersection(shapely.multilinestrings(lines), free)
    return line_segments(shapely.get_parts(shapely.line_merge(shapely.union_all(_off_outline(inside, free,
                                                                                            tolerance)))), tolerance)


def _off_outline(inside, free, tolerance: float):
    """``inside`` less what lies on the free space's outline (a chain there is already a
    wall).  ``free`` carries the walls' precision grid (set_precision) and the band
    round its outline does not: GEOS's overlay of the two can fail with a topology
    exception on some inputs (random levels: 5 in 60), and is then done on that grid."""
    band = shapely.buffer(shapely.boundary(free), tolerance, cap_style="flat")
    try:
        return shapely.difference(inside, band)
    except shapely.errors.GEOSException:
        return shapely.difference(inside, band, grid_size=tolerance)


def thin_walls_reference(chains: list, free, tolerance: float) -> np.ndarray:
    """:func:`thin_walls` chain by chain, as it was done before: the brute-force
    reference it is compared with (the same segments, maybe in another order)."""
    if not chains or free.is_empty:
        return np.zeros((0, 2, 2))
    lines = shapely.simplify(np.array(chains, dtype=object), tolerance)
    inside = _off_outline(shapely.intersection(lines, free), free, tolerance)
    return line_segments(shapely.get_parts(shapely.line_merge(shapely.union_all(inside))), tolerance)


def line_segments(parts: np.ndarray, tolerance: float) -> np.ndarray:
    """The (n, 2, 2) segments of the line strings among ``parts`` (other geometries
    left out), those shorter than ``tolerance`` dropped."""
    parts = parts[shapely.get_type_id(parts) == 1]
    if len(parts) == 0:
        return np.zeros((0, 2, 2))
    coords, index = shapely.get_coordinates(parts, return_index=True)
    same = index[1:] == index[:-1]
    seg = np.stack([coords[:-1][same], coords[1:][same]], axis=1)
    length = np.hypot(*(seg[:, 1] - seg[:, 0]).T)
    return seg[length >= tolerance]
