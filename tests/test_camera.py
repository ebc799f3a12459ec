"""The chase camera keeps the followed tank in view (game/camera.py): on the hills and
through the fort (a ramp to its roof), in every frame of a drive."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import MultiPoint, box

from tanktool.game.camera import Camera, arena_mesh
from tanktool.game.meshes import load_model
from tanktool.game.render3d import FOV_Y, look_at, perspective, tank_matrix
from tanktool.game.session import GameSession, pose3d

W, H = 1280, 720


def in_frame(session, eye, target) -> float:
    """The share of the followed tank's projected hull (the convex hull of its hull
    points on the screen) inside the frame; 0 when any of it is behind the eye."""
    t = session.focus_tank()
    x, y, z, h, pitch, roll = pose3d(session, t.index, 1.0)
    pts = np.asarray(t.spec.hull, float)
    world = tank_matrix(x, z, h, y, pitch, roll) @ np.c_[pts, np.ones(len(pts))].T
    clip = perspective(FOV_Y, W / H, 0.3, 1000.0) @ look_at(eye, target) @ world
    if (clip[3] <= 0.05).any():
        return 0.0
    ndc = clip[:2] / clip[3]
    poly = MultiPoint(np.c_[(ndc[0] + 1) / 2 * W, (1 - ndc[1]) / 2 * H]).convex_hull
    return poly.intersection(box(0, 0, W, H)).area / max(poly.area, 1e-9)


@pytest.mark.parametrize("arena, seed, follow, climbs", [("hills", 5, 0, 3.0), ("fort", 3, 1, 2.0)])
def test_the_chase_camera_keeps_the_tank_in_view(arena, seed, follow, climbs):
    s = GameSession(arena, bots=3, seed=seed, player=False)
    s.follow = follow
    mesh = arena_mesh(load_model(str(Path(s.info.path) / "model.glb")))
    cam = Camera(mesh)
    me = s.world.tanks[follow]
    shares, hidden, top = [], 0, 0.0
    for k in range(120 * 45):
        s.step()
        top = max(top, me.y)
        if k % 4:
            continue                                    # 30 frames a second
        eye, target = cam.pose(s, 1.0, "chase")
        shares.append(in_frame(s, eye, target))
        centre = (me.x, me.y + 0.6 * me.spec.height, me.z)
        hidden += mesh.first_hit(tuple(eye), centre) is not None
    assert top >= climbs and me.distance > 60.0         # the drive went up the slopes / the ramp
    assert min(shares) >= 0.8, (np.argmin(shares), min(shares))
    assert hidden == 0
