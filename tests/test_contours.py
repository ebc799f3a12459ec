"""Contours simplified as Recast does (geometry/contours.py) and the walls they give
on terrain (nav/level_walls.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import shapely

from tanktool.geometry.contours import simplify_contour, split_long_edges

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import make_levels  # noqa: E402


def _staircase(steps: int, cell: float = 0.5) -> shapely.Polygon:
    """A right triangle whose hypotenuse is a 45 degree staircase of ``cell`` steps."""
    pts = [(0.0, 0.0), (steps * cell, 0.0)]
    for k in range(steps, 0, -1):
        pts += [(k * cell, (steps - k + 1) * cell), ((k - 1) * cell, (steps - k + 1) * cell)]
    return shapely.Polygon(pts)


def test_a_staircase_within_the_edge_error_is_one_wall():
    stairs = _staircase(40)
    # 0.35 m off the diagonal at every corner: kept at 0.3 m, one edge at Recast's 0.65 m
    assert len(shapely.get_coordinates(shapely.simplify(stairs, 0.3))) > 40
    simple = simplify_contour(stairs, 0.65)
    assert len(simple.exterior.coords) <= 5  # the triangle and its first step
    assert abs(simple.area - stairs.area) < 0.5 * 40 * 0.5 * 0.5


def test_long_edges_over_a_curve_get_raw_vertices_back_straight_runs_do_not():
    circle = shapely.Point(0, 0).buffer(50, quad_segs=64)
    simple = simplify_contour(circle, 5.0)
    capped = simplify_contour(circle, 5.0, 12.0)
    edge = np.hypot(*np.diff(np.asarray(capped.exterior.coords), axis=0).T)
    assert edge.max() <= 12.0 and len(capped.exterior.coords) > len(simple.exterior.coords)
    assert capped.is_valid and set(map(tuple, capped.exterior.coords)) <= set(map(tuple, circle.exterior.coords))
    square = shapely.box(0, 0, 100, 100)
    assert len(simplify_contour(square, 0.65, 12.0).exterior.coords) == 5


def test_split_long_edges_keeps_the_ring_order():
    raw = np.array([[0, 0], [10, 1], [20, 0], [30, 1], [40, 0], [40, 40], [0, 40], [0, 0]], dtype=float)
    simple = raw[[0, 4, 5, 6, 7]]
    # 0 -> 4 (40 m over a zigzag) takes its middle vertex 2, then 1 and 3; the 40 m
    # edges up the sides are straight raw runs and stay
    assert split_long_edges(raw, simple, 15.0).tolist() == raw.tolist()
    assert split_long_edges(raw, simple, 25.0).tolist() == raw[[0, 2, 4, 5, 6, 7]].tolist()


def test_terrain_walls_are_not_voxel_steps():
    """Rolling terrain scaled x3: the walls along its steep ridge follow the ridge in a
    few walls instead of a staircase of half-cell steps (bench/walls.py measures it)."""
    from tanktool.arena import walkable_params
    from tanktool.fleet import bundled_fleet
    from tanktool.nav.level_walls import level_walls
    from tanktool.nav.walkable import walkable_surface

    m = make_levels.level("rolling_terrain")
    v, f = np.asarray(m.vertices) * 3, np.asarray(m.faces)
    fleet = bundled_fleet()
    p, _ = walkable_params(fleet=fleet)
    s = walkable_surface(v, f, p, fleet.radius)
    args = (s, v, f, 1.0, p.headroom, p.climb, 0.01, p.max_slope)
    old = level_walls(*args, edge_error=0.6, edge_max_len=None, smooth_margin=False)
    new = level_walls(*args)
    assert len(new.walls) < 0.6 * len(old.walls)
    # the same free space, give or take the edge error along the ridge
    assert abs(new.free().area - old.free().area) < 0.002 * old.free().area


def test_exact_floors_are_modelled_floors_not_hilltops():
    """The exact cut replaces the cells' outline on floors made of level faces, not on
    the top of a smooth hill (a few terrain triangles a degree or two off level)."""
    from tanktool.nav.level_walls import modelled_floors

    yard = make_levels.join(make_levels.walled_yard(40, 30))
    assert np.allclose(modelled_floors(np.asarray(yard.vertices), np.asarray(yard.faces)), [0.0, 3.0])
    m = make_levels.level("rolling_terrain")
    assert len(modelled_floors(np.asarray(m.vertices) * 3, np.asarray(m.faces))) == 0


def test_cells_polygon_looks_cells_up_as_the_winding_number_counts():
    """cells_polygon classifies the faces of the cells' outline by their cells: the
    same region as the crossing count of the generic winding rule."""
    from tanktool.geometry import cross_section as xs
    from tanktool.nav.level_walls import cells_polygon

    rng = np.random.default_rng(5)
    mask = rng.random((40, 50)) < 0.55
    origin, cell = np.array([-3.25, 7.5]), 0.5
    fast = cells_polygon(mask, origin, cell, 0.01)
    saved = xs.winding_region
    try:
        xs.winding_region = lambda seg, tol, inside=None: saved(seg, tol)
        slow = cells_polygon(mask, origin, cell, 0.01)
    finally:
        xs.winding_region = saved
    assert shapely.equals(fast, slow) and abs(fast.area - mask.sum() * cell * cell) < 1e-6
