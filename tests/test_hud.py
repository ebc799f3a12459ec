"""The HUD's pieces: crosshair and impact point (game/aim.py), kill feed, hit-direction
markers, the DESTROYED / respawn screen, spawn protection and the replay marker."""

import math

import numpy as np
import pygame
import pytest

from tanktool.game.aim import predict
from tanktool.game.hud import Hud, hits_taken, kill_feed, killed_by, screen_direction
from tanktool.game.session import GameSession
from tanktool.sim.world import Event

SIZE = (640, 360)


@pytest.fixture
def session():
    pygame.font.init()
    return GameSession("box", bots=3, seed=2, player=True)


def place(tank, x, z, heading):
    tank.place(x, z, heading)


def test_crosshair_points_at_the_wall_and_the_tank_in_the_way(session):
    w = session.world
    me, other = w.tanks[0], w.tanks[1]
    for t in w.tanks[2:]:
        place(t, 5.0, 55.0 - 3 * t.index, 0.0)          # out of the way
    place(me, 30.0, 30.0, 0.0)                          # facing +x: the east wall at x = 59
    place(other, 5.0, 5.0, 0.0)
    aim = predict(w, me)
    assert aim.target is None
    assert aim.aim[0] == pytest.approx(59.0, abs=0.05) and aim.aim[2] == pytest.approx(30.0)
    assert aim.impact[0] == pytest.approx(59.0, abs=0.05)          # the shell stops at the wall too
    assert aim.muzzle[1] == pytest.approx(aim.impact[1])            # the rules' shells fly straight
    place(other, 45.0, 30.5, math.pi / 2)                          # now a tank stands in the line of fire
    aim = predict(w, me)
    assert aim.target == other.index and aim.impact[0] < 46.0 + other.spec.radius


def test_feed_hits_and_killer_read_the_session_feed(session):
    s = session
    s.feed = [Event(10, 1.0, "hit", 2, 30.0, 30.0, 0, 25.0), Event(20, 2.0, "kill", 2, 30.0, 30.0, 0),
              Event(21, 2.0, "kill", 1, 5.0, 5.0, 3)]
    s.world.t = 2.5
    assert kill_feed(s, 2.5) == [(2, 0, 0.5), (1, 3, 0.5)]
    assert hits_taken(s, 0, 2.5) == [(2, 1.5)]
    assert hits_taken(s, 0, 9.0) == []                    # faded
    assert killed_by(s, 0) == 2 and killed_by(s, 1) is None
    # a real match fills the feed with the simulation's own events
    fresh = GameSession("box", bots=5, seed=4, player=False)
    for _ in range(120 * 20):
        fresh.step()
        if any(e.kind == "kill" for e in fresh.feed):
            break
    assert any(e.kind == "kill" for e in fresh.feed)
    assert all(fresh.t - e.t < 8.0 for e in fresh.feed)


def test_screen_direction_of_a_shooter():
    # in 3D, ahead is up the screen and the right of the camera is to the right
    ux, uy = screen_direction(1.0, 0.0, 0.0)            # the camera faces +x, shooter ahead
    assert (round(ux, 6), round(uy, 6)) == (0.0, -1.0)
    ux, uy = screen_direction(0.0, 1.0, 0.0)            # +z is the camera's right (heading + 90 deg)
    assert (round(ux, 6), round(uy, 6)) == (1.0, 0.0)
    assert screen_direction(0.0, 2.0, None) == (0.0, 1.0)   # the top view: +z is down


def draw(session, **kw):
    hud = Hud(session, SIZE)
    surf = pygame.Surface(SIZE, pygame.SRCALPHA)
    rects = hud.draw(surf, session, 60.0, **kw)
    return surf, rects


def red_pixels(surf, rect):
    a = pygame.surfarray.pixels3d(surf.subsurface(rect)).astype(int)
    return int(((a[..., 0] > 180) & (a[..., 1] < 110) & (a[..., 2] < 100)).sum())


def test_death_screen_and_hit_marker(session):
    s = session
    me = s.world.tanks[0]
    place(me, 30.0, 30.0, 0.0)
    shooter = s.world.tanks[2]
    place(shooter, 30.0, 50.0, 0.0)                     # +z of me: below me in the top view
    s.world.t = 3.0
    s.feed = [Event(300, 2.9, "hit", 2, 30.0, 30.0, 0, 25.0)]
    to_px = lambda x, z: (x * 6.0, z * 6.0)             # noqa: E731  (the top view's mapping, roughly)
    surf, rects = draw(s, to_px=to_px)
    # the hit marker: a red wedge below the centre of the screen, nothing red above it
    below = pygame.Rect(SIZE[0] // 2 - 30, SIZE[1] // 2 + 40, 60, 80)
    above = pygame.Rect(SIZE[0] // 2 - 30, SIZE[1] // 2 - 120, 60, 80)
    assert red_pixels(surf, below) > 30 and red_pixels(surf, above) == 0
    # dead: DESTROYED by bot2 (the killer's name), respawn countdown, in the middle
    me.alive, me.respawn_at = False, 5.5
    s.feed.append(Event(301, 2.95, "kill", 2, 30.0, 30.0, 0))
    surf, rects = draw(s, to_px=to_px)
    middle = pygame.Rect(SIZE[0] // 2 - 120, SIZE[1] // 2 - 70, 240, 120)
    assert red_pixels(surf, middle) > 100                        # the red DESTROYED
    assert any(r.contains(pygame.Rect(SIZE[0] // 2 - 5, SIZE[1] // 2 - 5, 10, 10)) for r in rects)


def test_kill_feed_and_labels_have_panels(session):
    s = session
    s.world.t = 1.0
    s.feed = [Event(100, 0.9, "kill", 1, 5.0, 5.0, 2)]
    surf, rects = draw(s)
    # every text group sits on a dark translucent panel: top left (K/D), top right
    # (scoreboard, then the feed under it)
    corners = [(10, 10), (SIZE[0] - 12, 12)]
    for x, y in corners:
        r, g, b, a = surf.get_at((x, y))
        assert a >= 140 and max(r, g, b) < 60
    right = [r for r in rects if r.right >= SIZE[0] - 20]
    assert len(right) >= 3                    # scoreboard, feed, minimap


def test_spawn_protection_and_replay_marker_drawn_when_present(session):
    s = session
    w = s.world
    w.protected_until[0] = -1.0                 # no protection
    surf0, rects0 = draw(s)
    w.protected_until[0] = w.t + 2.0
    surf1, rects1 = draw(s)
    line = [r for r in rects1 if r not in rects0]
    assert len(line) == 1 and line[0].centery > SIZE[1] // 2      # "spawn protection 2.0 s" low in the middle
    w.protected_until[0] = w.t - 1.0
    assert len(draw(s)[1]) == len(rects0)                         # over: gone
    s.max_steps = 1200                         # a replay's session
    surf2, rects2 = draw(s)
    top = [r for r in rects2 if r.top < 40 and r.centerx > SIZE[0] // 3 and r.centerx < 2 * SIZE[0] // 3]
    assert top, rects2                          # REPLAY at the top centre
    assert red_pixels(surf2, top[0]) > 10       # with its red dot


def test_no_crosshair_without_a_view(session):
    # the HUD cannot place a crosshair without knowing how the world maps to the screen
    surf, rects = draw(session)
    c = pygame.Rect(SIZE[0] // 2 - 20, SIZE[1] // 2 - 20, 40, 40)
    assert not any(r.colliderect(c) for r in rects)
    a = np.asarray(pygame.surfarray.pixels_alpha(surf.subsurface(c)))
    assert a.max() == 0


def test_crosshair_sits_on_the_hit_point_and_never_leaves_the_screen(session):
    """The crosshair and its landing ring are drawn where the predicted hit point
    projects; a point above the screen (a hillside seen from below) is held inside it."""
    me = session.world.tanks[0]
    place(me, 30.0, 30.0, 0.0)
    impact = predict(session.world, me).impact
    centre = {}

    def project(p, lift=0.0):
        # a stand-in camera: the hit point at a chosen pixel, everything else far off
        if np.allclose(p, impact):
            return centre["at"][0], centre["at"][1], 0.5
        return -9999.0, -9999.0, 0.5

    for at in ((200.0, 150.0), (320.0, -400.0), (900.0, 500.0)):
        centre["at"] = at
        surf, rects = draw(session, project=project)
        x = min(max(at[0], 24), SIZE[0] - 25)
        y = min(max(at[1], 24), SIZE[1] - 25)
        ring = pygame.Rect(int(x) - 9, int(y) - 9, 19, 19)
        assert any(r.contains(ring) for r in rects), (at, rects)
        assert all(surf.get_rect().contains(r) for r in rects)
        a = np.asarray(pygame.surfarray.pixels_alpha(surf.subsurface(ring)))
        assert a.max() > 0                       # the ring is drawn there
