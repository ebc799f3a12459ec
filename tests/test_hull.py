"""Hull points: conservative footprints, minimum rectangles, k-gons near the convex hull."""

import numpy as np
import pytest
import trimesh

from tanktool.geometry.hull import (
    convex_hull_2d, footprint_polygon, hull_points, points_in_prism, polygon_area,
)


def test_convex_hull_2d_square_with_inside_points():
    rng = np.random.default_rng(0)
    pts = np.vstack([[[0, 0], [2, 0], [2, 2], [0, 2]], rng.uniform(0.1, 1.9, (50, 2))])
    hull = convex_hull_2d(pts)
    assert len(hull) == 4 and polygon_area(hull) == pytest.approx(4.0)


def test_min_area_rectangle_of_rotated_rectangle():
    rng = np.random.default_rng(1)
    a = 0.4
    rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    pts = (rng.uniform([-2, -0.5], [2, 0.5], (400, 2)) @ rot.T)
    corners = np.array([[-2, -0.5], [2, -0.5], [2, 0.5], [-2, 0.5]]) @ rot.T
    pts = np.vstack([pts, corners])
    fp = footprint_polygon(pts, 4)
    assert len(fp.polygon) == 4
    assert fp.area == pytest.approx(4.0, rel=1e-3)  # 0.1 mm margin


def test_octagon_around_circle_is_near_optimal():
    t = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    pts = np.column_stack([np.cos(t), np.sin(t)])
    fp = footprint_polygon(pts, 8)
    # the optimum circumscribed octagon has area 8 tan(pi/8) = 3.3137
    assert fp.area == pytest.approx(8 * np.tan(np.pi / 8), rel=2e-3)
    assert fp.ratio < 1.06


@pytest.mark.parametrize("count", [8, 10, 12, 14, 16])
def test_hull_points_conservative_and_shaped(count):
    rng = np.random.default_rng(count)
    v = rng.normal(size=(3000, 3)) * [2.0, 0.5, 1.0] + [0.3, 1.0, -0.2]
    hull, fp = hull_points(v, count)
    k = count // 2
    assert hull.shape == (count, 3)
    assert np.allclose(hull[:k, [0, 2]], hull[k:, [0, 2]])
    assert np.allclose(hull[:k, 1], v[:, 1].min()) and np.allclose(hull[k:, 1], v[:, 1].max())
    assert points_in_prism(hull, v, tol=0).all()
    assert polygon_area(fp.polygon) > 0  # counter-clockwise
    assert fp.area >= fp.convex_area * (1 - 1e-9)


def test_more_points_never_worse_and_sixteen_meets_goal():
    m = trimesh.creation.icosphere(4)
    m.apply_scale([3.0, 1.0, 1.5])
    areas = [hull_points(m.vertices, n)[1] for n in (8, 12, 16)]
    assert areas[0].area >= areas[1].area >= areas[2].area
    assert areas[2].ratio < 1.15


def test_few_hull_corners_use_the_convex_hull():
    tri = trimesh.creation.box([2, 1, 2])
    hull, fp = hull_points(tri.vertices, 16)
    assert len(hull) == 8 and fp.ratio == pytest.approx(1.0, rel=1e-3)


@pytest.mark.parametrize("bad", [6, 7, 9, 18])
def test_bad_point_counts(bad):
    with pytest.raises(ValueError, match="even number from 8 to 16"):
        hull_points(np.zeros((4, 3)), bad)


def test_degenerate_footprint_line():
    v = np.array([[0, 0, 0], [1, 1, 0], [2, 0.5, 0]], float)
    hull, fp = hull_points(v, 8)
    assert points_in_prism(hull, v, tol=0).all() and fp.area > 0
