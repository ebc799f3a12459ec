"""vehicle.toml / hull.txt loading: the contract the simulation and check code against."""

import numpy as np
import pytest

from tanktool.errors import FormatError, VehicleError
from tanktool.formats.bundle import write_toml
from tanktool.formats.vehicle_bundle import load_vehicle, read_hull, write_hull
from tanktool.geometry.hull import hull_points, points_in_prism
from tanktool.geometry.spheres import SphereTree, write_spheres


def make_bundle(folder, **changes):
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(0)
    v = rng.uniform([-2, 0, -1], [2, 1.5, 1], (200, 3))
    hull, fp = hull_points(v, 12)
    write_hull(folder / "hull.txt", hull)
    write_spheres(folder / "spheres.txt", SphereTree([[0, 0.75, 0], [1, 0.7, 0], [-1, 0.7, 0]], [2.5, 1.5, 1.5], [-1, 0, 0], [1, 2, 2]))
    doc = {
        "name": "t", "tool_version": "0",
        "mass": {"mass": 20000.0, "inertia": 30000.0, "centre_of_mass": [0.0, 0.7, 0.0], "method": "mesh", "volume": 10.0},
        "drive": {"engine_force": 60000.0, "turn_torque": 60000.0, "strafe_force": 0.0, "friction": 0.25,
                  "restitution": 0.3, "top_speed": 12.0, "fire_interval": 1.0, "shell_speed": 200.0, "hit_points": 100},
        "hull": {"file": "hull.txt", "points": 12}, "spheres": {"file": "spheres.txt", "levels": 2, "branching": 2, "count": 3},
    }
    for key, value in changes.items():
        table, _, k = key.partition(".")
        if value is None:
            del doc[table][k]
        else:
            doc[table][k] = value
    write_toml(folder / "vehicle.toml", doc)
    return v


def test_load_vehicle(tmp_path):
    v = make_bundle(tmp_path / "t")
    b = load_vehicle(tmp_path / "t")
    assert b.name == "t" and b.mass == 20000 and b.inertia == 30000
    assert b.hull.shape == (12, 3) and len(b.spheres) == 3
    assert b.engine_force == 60000 and b.drive["top_speed"] == 12.0 and b.hit_points == 100
    assert np.allclose(b.centre_of_mass, [0, 0.7, 0])
    assert b.footprint_radius == pytest.approx(np.hypot(b.hull[:, 0], b.hull[:, 2]).max())
    assert points_in_prism(b.hull, v, tol=0).all()  # rounding in hull.txt went outwards
    assert load_vehicle(tmp_path / "t" / "vehicle.toml").name == "t"


@pytest.mark.parametrize("change, message", [
    ({"mass.mass": -5.0}, "[mass] mass = -5.0 is outside"),
    ({"mass.inertia": None}, "missing [mass] inertia"),
    ({"drive.top_speed": "fast"}, "[drive] top_speed must be a finite number"),
    ({"drive.restitution": 1.5}, "[drive] restitution = 1.5 is outside"),
    ({"mass.centre_of_mass": [0, 1]}, "centre_of_mass must be a list of 3"),
])
def test_load_vehicle_bad_values(tmp_path, change, message):
    make_bundle(tmp_path / "t", **change)
    with pytest.raises(VehicleError) as e:
        load_vehicle(tmp_path / "t")
    assert message in str(e.value) and "vehicle.toml" in str(e.value)


def test_load_vehicle_missing(tmp_path):
    with pytest.raises(VehicleError, match="no such vehicle bundle"):
        load_vehicle(tmp_path / "nothing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(VehicleError, match="no vehicle.toml"):
        load_vehicle(tmp_path / "empty")


@pytest.mark.parametrize("text, message", [
    ("1 2\n" * 8, "expected 3 numbers"),
    ("1 2 x\n" * 8, "expected 3 numbers"),
    ("1 2 3\n" * 7, "expected 8 to 16 hull points, found 7"),
    ("1 2 3\n" * 17, "found 17"),
    ("1 2 inf\n" * 8, "finite"),
])
def test_read_hull_errors(tmp_path, text, message):
    f = tmp_path / "hull.txt"
    f.write_text(text)
    with pytest.raises(FormatError) as e:
        read_hull(f)
    assert message in str(e.value) and str(f) in str(e.value)


def test_hull_text_rounding_keeps_vertices_inside(tmp_path):
    rng = np.random.default_rng(5)
    for trial in range(20):
        v = rng.normal(size=(300, 3)) * rng.uniform(0.5, 3, 3)
        hull, _ = hull_points(v, 8 + 2 * (trial % 5))
        write_hull(tmp_path / "h.txt", hull)
        assert points_in_prism(read_hull(tmp_path / "h.txt"), v, tol=0).all()
