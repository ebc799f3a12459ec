"""Issue 25's end-to-end check: generated levels (tools/make_levels.py: a room with a
platform reached by ramps, a rolling terrain, a floor on pillars over another) imported
with import-arena alone and played with 8 tanks over several seeds keep every tank on
the model's surface (within 0.3 m of a surface under it) and none inside the solid."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from tanktool.sim.ground import Ground
from tanktool.sim.match import load_match_arena, load_tank_spec, run_match

#: how far a tank may stand from the model's surface under it [m]
ON_SURFACE = 0.3


def _surface_heights(mesh: trimesh.Trimesh, x: float, z: float) -> np.ndarray:
    """Heights of every upward-facing surface of the model at (x, z)."""
    top = float(mesh.bounds[1][1]) + 10.0
    locs, _, tri = mesh.ray.intersects_location([[x, top, z]], [[0.0, -1.0, 0.0]], multiple_hits=True)
    up = mesh.face_normals[tri][:, 1] > 0.0
    return locs[up][:, 1] if len(locs) else np.zeros(0)


@pytest.fixture(scope="module")
def levels(imported_level):
    return {name: imported_level(name) for name in LEVELS}


#: a room with a platform on a solid block, a terrain, and an upper floor on pillars over
#: the ground floor, its ramp's top on the upper floor's level (nav/level_lift.py)
LEVELS = ("ramps_and_decks", "rolling_terrain", "two_storeys")


@pytest.mark.parametrize("name", LEVELS)
def test_imported_and_played_tanks_stay_on_the_surface(levels, name):
    folder = levels[name]
    info = load_match_arena(folder)
    assert isinstance(info.ground, Ground)          # one command gave the match its ground
    mesh = trimesh.load(folder / "model.glb", force="mesh")
    spec = load_tank_spec("light")
    seen = 0
    for seed in (1, 2, 3):
        samples = []

        def wrap(world, drivers):
            samples.append(world)
            return drivers

        def sample(_n):
            w = samples[0]
            for t in w.tanks:
                if t.alive:
                    samples.append((t.name, t.x, t.y, t.z))

        run_match(info, spec, bots=8, seconds=12.0, seed=seed, wrap_drivers=wrap, on_progress=sample,
                  progress_every=60)
        world = samples[0]
        solids = world.ground.solids
        for name_, x, y, z in samples[1:]:
            hs = _surface_heights(mesh, x, z)
            assert len(hs) and np.abs(hs - y).min() <= ON_SURFACE, (name, seed, name_, x, y, z, hs)
            # the hull's middle is in the air, not in the solid
            assert not solids.inside(np.array([x]), np.array([y + 0.5 * spec.height]), np.array([z]))[0], \
                (name, seed, name_, x, y, z)
            seen += 1
    assert seen > 3 * 8 * 5
