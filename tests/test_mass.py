"""Mass properties: solids from the mesh, open models from the hull prism; drive defaults."""

import numpy as np
import pytest
import trimesh

from tanktool.geometry.hull import hull_points
from tanktool.geometry.mass import DEFAULT_DENSITY, drive_defaults, mass_properties, polygon_moments


def test_box_mass_properties_match_formulas():
    box = trimesh.creation.box([4.0, 2.0, 2.0])
    box.apply_translation([0.5, 1.0, 0])
    _, fp = hull_points(box.vertices, 8)
    mp = mass_properties(box, fp.polygon)
    assert mp.method == "mesh"
    assert mp.volume == pytest.approx(16.0)
    assert mp.mass == pytest.approx(16.0 * DEFAULT_DENSITY)
    assert np.allclose(mp.centre_of_mass, [0.5, 1.0, 0])
    # about the vertical axis: m (a^2 + c^2) / 12 with a, c the x and z sides
    assert mp.inertia == pytest.approx(mp.mass * (16 + 4) / 12)


def test_mass_override_scales_inertia():
    box = trimesh.creation.box([4.0, 2.0, 2.0])
    _, fp = hull_points(box.vertices, 8)
    mp = mass_properties(box, fp.polygon, mass=1000.0)
    assert mp.mass == 1000.0 and mp.inertia == pytest.approx(1000.0 * 20 / 12)


def test_open_model_uses_hull_box():
    box = trimesh.creation.box([4.0, 2.0, 2.0])
    box.apply_translation([0, 1.0, 0])
    open_box = trimesh.Trimesh(box.vertices, box.faces[:-2])  # one side missing
    _, fp = hull_points(open_box.vertices, 8)
    mp = mass_properties(open_box, fp.polygon)
    assert mp.method == "hull-box"
    assert mp.volume == pytest.approx(16.0, rel=1e-3)  # the 0.1 mm footprint margin
    assert np.allclose(mp.centre_of_mass, [0, 1.0, 0], atol=1e-6)
    assert mp.inertia == pytest.approx(mp.mass * 20 / 12, rel=1e-3)


def test_polygon_moments_of_rectangle_and_triangle():
    a, c, j = polygon_moments(np.array([[0, 0], [4, 0], [4, 2], [0, 2]], float))
    assert a == 8 and np.allclose(c, [2, 1]) and j == pytest.approx(8 * (16 + 4) / 12)
    a, c, _ = polygon_moments(np.array([[0, 0], [0, 3], [3, 0]], float))  # clockwise input
    assert a == pytest.approx(4.5) and np.allclose(c, [1, 1])


def test_drive_defaults_scale_with_mass():
    light, heavy = drive_defaults(20000, 40000), drive_defaults(60000, 200000)
    assert light["top_speed"] == 15.0 and heavy["top_speed"] == 10.0
    for d, m in ((light, 20000), (heavy, 60000)):
        # drive and drag balance at the top speed
        assert d["engine_force"] == pytest.approx(m * d["friction"] * d["top_speed"], rel=1e-3)
        assert d["shell_speed"] == 200 and 0 <= d["restitution"] <= 1
    assert light["hit_points"] == 100 and heavy["hit_points"] > 100
    assert heavy["fire_interval"] > light["fire_interval"]
    assert heavy["turn_torque"] > light["turn_torque"]


def test_drive_defaults_of_a_toy_keep_their_digits():
    # fixed decimals wrote turn_torque = 0.0 for a small vehicle: it never turned
    d = drive_defaults(2.0, 4.5e-4)
    assert d["turn_torque"] == pytest.approx(6.75e-4) and d["engine_force"] == pytest.approx(6.0)
    assert all(v > 0 for v in d.values())


def test_significant_digits_and_scaled_rounding():
    from tanktool.geometry.mass import sig, to_scale

    assert sig(1.23456789e-5, 3) == 1.23e-5 and sig(26241.7291, 8) == 26241.729 and sig(-0.0) == 0.0
    assert to_scale(-0.48499989, 5.8) == -0.4849999 and to_scale(0.0123456789, 0.05) == 0.012345679
    assert str(to_scale(-1e-12, 5.0)) == "0.0"      # no "-0.0"
