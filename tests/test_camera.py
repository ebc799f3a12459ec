"""The chase camera keeps the followed tank in view (game/camera.py): in every frame
of scripted drives across the hills and through the fort (up its ramp, over its roof);
and its shake."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import MultiPoint, box

from tanktool.game.camera import Camera, arena_mesh
from tanktool.game.meshes import load_model
from tanktool.game.matrices import look_at, perspective, tank_matrix
from tanktool.game.render3d import FOV_Y
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


def route(points, step=0.25):
    """(x, z, heading) every ``step`` metres along a polyline: a scripted drive."""
    out = []
    for (ax, az), (bx, bz) in zip(points, points[1:]):
        n = max(int(math.hypot(bx - ax, bz - az) / step), 1)
        h = math.atan2(bz - az, bx - ax)
        out += [(ax + (bx - ax) * k / n, az + (bz - az) * k / n, h) for k in range(n)]
    return out


#: across the hills over their tops; from the fort's yard up its ramp and over its roof:
#: places to drive through, joined by the bots' own paths (sim.bots.map), and the height
#: the drive must reach
DRIVES = {
    "hills": ([(15.0, 15.0), (41.0, 38.0), (100.0, 40.0), (60.0, 100.0), (20.0, 60.0)], 5.5),
    "fort": ([(10.0, 90.0), (71.0, 63.0), (60.0, 35.0)], 4.9),
}


def drive(session, places):
    """A scripted drive through ``places`` along the navigation grid's paths, as
    (x, z, heading) every quarter metre."""
    from tanktool.sim.bots.map import Map

    me = session.world.tanks[0]
    m = Map.of(session.world, me.spec.radius)
    points = [places[0]]
    for goal in places[1:]:
        here = points[-1]
        points += [(p[0], p[1]) for p in m.path((here[0], here[1]), goal)] or [goal]
    return route(points)


@pytest.mark.parametrize("arena", sorted(DRIVES))
def test_the_chase_camera_keeps_the_tank_in_view(arena):
    points, climbs = DRIVES[arena]
    s = GameSession(arena, bots=1, seed=1, player=True)
    w = s.world
    me = w.tanks[0]
    w.tanks[1].alive = False
    mesh = arena_mesh(load_model(str(Path(s.info.path) / "model.glb")))
    cam = Camera(mesh)
    shares, hidden, top = [], 0, 0.0
    me.place(*points[0], 0.0)
    s.step()
    for x, z, heading in drive(s, points):
        me.place(x, z, heading)                         # 0.25 m a step: 30 m/s at 120 steps a second
        s.step()                                        # the simulation sets the height and tilt
        top = max(top, me.y)
        eye, target = cam.pose(s, 1.0, "chase")
        shares.append(in_frame(s, eye, target))
        centre = (me.x, me.y + 0.6 * me.spec.height, me.z)
        hidden += mesh.first_hit(tuple(eye), centre) is not None
    assert top >= climbs                                # the drive went up the hills / onto the roof
    assert min(shares) >= 0.8, (int(np.argmin(shares)), min(shares))
    assert hidden == 0


def test_the_camera_shakes_when_firing_or_hit_then_settles():
    from tanktool.game.camera import SHAKE_S, shake
    from tanktool.game.session import Effect

    s = GameSession("box", bots=1, seed=1, player=True)
    assert not shake(s, 0, s.t).any()
    s.effects.append(Effect("flash", 10.0, 1.5, 10.0, s.t, heading=0.0, tank=0))
    fired = max(np.linalg.norm(shake(s, 0, s.t + k / 240)) for k in range(1, 20))
    assert 0.02 < fired <= 0.11
    s.effects.append(Effect("impact", 10.0, 1.5, 10.0, s.t, tank=0))
    hit = max(np.linalg.norm(shake(s, 0, s.t + k / 240)) for k in range(1, 20))
    assert hit > 2 * fired
    assert not shake(s, 0, s.t + SHAKE_S + 0.01).any()      # short: gone after SHAKE_S
    assert not shake(s, 1, s.t + 0.01).any()                # the other tank's camera does not shake


@pytest.mark.parametrize("arena", sorted(DRIVES))
def test_the_first_person_eye_never_enters_the_arena_and_looks_along_the_slope(arena):
    """First person across the hills and through the fort (its ramp, its roof): the eye
    is never inside a wall, a roof or the ground (the line from the hull's middle to it
    crosses nothing, and the surface under it is below it), and it looks along the hull
    up and down the slopes."""
    points, climbs = DRIVES[arena]
    s = GameSession(arena, bots=1, seed=1, player=True)
    w = s.world
    me = w.tanks[0]
    w.tanks[1].alive = False
    mesh = arena_mesh(load_model(str(Path(s.info.path) / "model.glb")))
    cam = Camera(mesh)
    me.place(*points[0], 0.0)
    s.step()
    inside, buried, late, top, tilted, recent = 0, 0, [], 0.0, 0.0, []
    for x, z, heading in drive(s, points):
        me.place(x, z, heading)
        s.step()
        top = max(top, me.y)
        tilted = max(tilted, abs(me.pitch))
        eye, target = cam.pose(s, 1.0, "first-person")
        centre = (me.x, me.y + 0.6 * me.spec.height, me.z)
        inside += mesh.first_hit(centre, tuple(eye)) is not None
        buried += mesh.first_hit(tuple(eye), tuple(eye - np.array([0.0, 0.2, 0.0]))) is not None
        look = (target - eye) / np.linalg.norm(target - eye)
        # the view's pitch against the hull's: off by at most how much the hull tilted in
        # the last 0.4 s (the smoothing's lag) and a few degrees (it looks a little down)
        recent = (recent + [me.pitch])[-int(0.4 / s.dt):]
        lag = max(abs(p - me.pitch) for p in recent)
        late.append(abs(math.asin(float(look[1])) - me.pitch) - lag)
    assert top >= climbs and tilted > math.radians(8)        # up the hills / the ramp: real slopes
    assert (inside, buried) == (0, 0), (inside, buried)
    assert math.degrees(max(late)) < 6.0, math.degrees(max(late))


def test_the_first_person_eye_stays_under_a_roof_and_behind_a_wall():
    """A roof just over the turret and a wall at the nose (a low passage, a tank pressed
    against a wall): the eye is pulled in towards the hull's middle, short of both."""
    from tanktool.sim.ground import MeshIndex

    s = GameSession("box", bots=1, seed=1, player=True)
    me = s.world.tanks[0]
    me.place(30.0, 30.0, 0.0)                               # facing +x
    s.step()
    h, r = me.spec.height, me.spec.radius
    y = me.y

    def quad(a, b, c, d):
        return [a, b, c, a, c, d]

    def pose(tris):
        v = np.array(tris, dtype=np.float64)
        cam = Camera(MeshIndex(v, np.arange(len(v), dtype=np.int64).reshape(-1, 3)) if len(v) else None)
        return cam.pose(s, 1.0, "first-person")

    free, _ = pose([])
    assert free[1] == pytest.approx(y + h + 0.4, abs=0.05)            # over the turret when nothing is near
    roof_y = y + h + 0.1
    roof = quad((20, roof_y, 20), (40, roof_y, 20), (40, roof_y, 40), (20, roof_y, 40))
    wall_x = 30.0 + 0.3 * max(r, 1.0) - 0.1                 # right at the nose
    wall = quad((wall_x, y - 1, 20), (wall_x, y + 10, 20), (wall_x, y + 10, 40), (wall_x, y - 1, 40))
    for tris in (roof, wall, roof + wall):
        eye, target = pose(tris)
        assert eye[1] < roof_y or tris is wall
        assert eye[0] < wall_x or tris is roof
        mesh = MeshIndex(np.array(tris, float), np.arange(len(tris), dtype=np.int64).reshape(-1, 3))
        assert mesh.first_hit((me.x, y + 0.6 * h, me.z), tuple(eye)) is None     # the hull's side of both
        assert target[0] > eye[0] + 5.0                                       # still looking ahead


@pytest.mark.parametrize("arena", ["box", "fort", "hills", "maze", "paper2002"])
def test_the_chase_camera_at_every_spawn_sees_the_tank_from_the_first_frame(arena):
    """A match starts (and a tank respawns) with a fresh camera at a spawn point, often in
    a corner or against a wall: its first frame and the next quarter second keep at least 80 %
    of the hull in the frame, nothing of the arena between the eye and the tank."""
    s = GameSession(arena, bots=1, seed=1, player=True)
    me = s.world.tanks[0]
    s.world.tanks[1].alive = False
    mesh = arena_mesh(load_model(str(Path(s.info.path) / "model.glb")))
    worst, hidden = 1.0, []
    for i, (x, z, heading) in enumerate(s.world.spawns):
        cam = Camera(mesh)
        me.place(x, z, heading)
        for _ in range(30):                               # a quarter second standing there
            s.step()
            me.place(x, z, heading)
            eye, target = cam.pose(s, 1.0, "chase")
            worst = min(worst, in_frame(s, eye, target))
            if mesh.first_hit(tuple(eye), (me.x, me.y + 0.6 * me.spec.height, me.z)) is not None:
                hidden.append(i)
    assert worst >= 0.8, worst
    assert not hidden, sorted(set(hidden))
