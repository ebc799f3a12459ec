"""Round-off in a region's free space: parts and holes too thin to be space or solid.

Where the cells' outline of a walkable region meets the exact 2002 cut of the model
(:mod:`tanktool.nav.level_walls`), their union leaves slivers a few millimetres or
centimetres wide; these would become walls nobody modelled.
"""

from __future__ import annotations

import shapely


def fill_sliver_holes(R, tolerance: float, cell: float):
    """Holes narrower than the walls' tolerance and shorter than a cell are round-off
    where a cell corner meets the exact cut of a steep face (a pyramid's foot), not
    solid: filled, so they do not become walls a few centimetres long.  A real thin
    solid is longer than a cell or wider than the tolerance and stays."""
    parts = shapely.get_parts(R)
    changed, out = False, []
    for p in parts:
        holes = [shapely.Polygon(h) for h in p.interiors]
        keep = [h for h in holes
                if h.length / 2 >= 1.5 * cell or not shapely.buffer(h, -2 * tolerance, quad_segs=1).is_empty]
        if len(keep) < len(holes):
            changed = True
            p = shapely.Polygon(p.exterior, [h.exterior for h in keep])
        out.append(p)
    if not changed:
        return R
    # the other parts exactly as they were (a union would node them again)
    return out[0] if len(out) == 1 else shapely.MultiPolygon(out)


def drop_slivers(R, tolerance: float):
    """Parts of a region narrower than the walls' tolerance everywhere (round-off
    between exact and cell outlines) are not space."""
    parts = shapely.get_parts(R)
    if len(parts) == 0:
        return shapely.Polygon()
    keep = ~shapely.is_empty(shapely.buffer(parts, -2 * tolerance, quad_segs=1))
    if not keep.any():
        return shapely.Polygon()
    R = shapely.union_all(parts[keep])
    # and slivers within a part (a pillar that touches a wall in the model, a few mm
    # off): an opening by half the tolerance closes them, so the pillar's walls meet
    # the wall instead of leaving a gap or a crossing
    # (in floating point: a buffer keeps its input's precision grid, and on that grid a
    # half-tolerance erosion rounds everything away)
    half = tolerance / 2
    opened = shapely.buffer(shapely.buffer(shapely.set_precision(R, 0.0), -half, join_style="mitre"), half,
                            join_style="mitre")
    opened = shapely.set_precision(opened, tolerance)
    # where nothing closed, the region as it was (the same walls in the same order)
    return R if shapely.equals(opened, R) else opened
