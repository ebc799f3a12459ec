"""The bundled tanks: loadable, conservative, and not stale (run `make vehicles`)."""

from pathlib import Path

import numpy as np
import pytest

from tanktool.cli.import_vehicle import derive, load_vehicle_source, rebuild_params
from tanktool.formats.bundle import read_toml, sha256_file
from tanktool.formats.vehicle_bundle import load_vehicle, read_hull
from tanktool.geometry.hull import points_in_prism
from tanktool.geometry.spheres import contains_points, read_spheres

ROOT = Path(__file__).resolve().parent.parent
BUNDLES = sorted(p.parent for p in (ROOT / "vehicles").glob("*/vehicle.toml"))
STALE = "stale: run `make vehicles`"


def test_there_are_a_light_and_a_heavy_tank():
    names = {b.name for b in BUNDLES}
    assert {"light", "heavy"} <= names
    light, heavy = load_vehicle(ROOT / "vehicles" / "light"), load_vehicle(ROOT / "vehicles" / "heavy")
    assert heavy.mass > light.mass and heavy.top_speed < light.top_speed
    assert heavy.footprint_radius > light.footprint_radius


@pytest.mark.parametrize("bundle", BUNDLES, ids=lambda p: p.name)
def test_bundle_loads_and_wraps_every_vertex(bundle):
    b = load_vehicle(bundle)
    doc = b.toml
    assert doc["source"]["file"].lower().endswith(".3ds")
    mesh = load_vehicle_source(bundle)
    assert len(mesh.faces) > 200  # a real model: hull, tracks, turret, barrel
    v = mesh.vertices
    assert points_in_prism(b.hull, v, tol=0).all()
    assert contains_points(b.spheres, v, tol=0).all()
    assert doc["hull"]["footprint_area"] <= 1.15 * doc["hull"]["convex_area"]
    assert doc["mass"]["method"] == "mesh"


@pytest.mark.parametrize("bundle", BUNDLES, ids=lambda p: p.name)
def test_bundle_is_not_stale(bundle):
    doc = read_toml(bundle / "vehicle.toml")
    assert sha256_file(bundle / doc["source"]["file"]) == doc["source"]["sha256"], STALE
    for name, digest in doc["derived"].items():
        assert sha256_file(bundle / name) == digest, f"{bundle.name}/{name}: {STALE}"
    # what the current code derives from the source must match the stored files
    params = rebuild_params(doc)
    hull, fp, tree, mp = derive(load_vehicle_source(bundle), params["hull_points_n"], params["levels"],
                                params["branching"], params["mass"])
    stored_hull = read_hull(bundle / "hull.txt")
    assert stored_hull.shape == hull.shape, f"{bundle.name}/hull.txt: {STALE}"
    assert np.allclose(stored_hull, hull, atol=2e-4), f"{bundle.name}/hull.txt: {STALE}"
    stored = read_spheres(bundle / "spheres.txt")
    assert len(stored) == len(tree) and np.array_equal(stored.parent, tree.parent), f"{bundle.name}/spheres.txt: {STALE}"
    assert np.allclose(stored.centers, tree.centers, atol=2e-4), f"{bundle.name}/spheres.txt: {STALE}"
    assert np.allclose(stored.radii, tree.radii, atol=3e-4), f"{bundle.name}/spheres.txt: {STALE}"
    assert doc["mass"]["mass"] == pytest.approx(mp.mass, rel=1e-6), f"{bundle.name}/vehicle.toml: {STALE}"
