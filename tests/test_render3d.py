"""The 3D view through EGL: screenshots are not blank and show the arena and every
tank where the camera says they are.  Skipped only when the EGL library is missing
(CI installs libegl1 and libgl1-mesa-dri, so there they run)."""

import ctypes.util

import numpy as np
import pytest
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.game.headless import run_frames
from tanktool.game.session import GameSession, tank_colour

pytestmark = pytest.mark.skipif(ctypes.util.find_library("EGL") is None,
                                reason="libEGL is not installed (apt-get install libegl1 libgl1-mesa-dri)")

SIZE = (480, 270)


@pytest.fixture(scope="module")
def overview():
    from tanktool.game.render3d import Renderer3D

    s = GameSession("box", bots=8, seed=1, player=False)
    run_frames(s, 30)
    r = Renderer3D(s, SIZE)
    r.camera = "overview"
    img = r.render(hud=False)
    yield s, r, img
    r.release()


def closest_tint(rgb, n):
    """Index of the tank colour whose direction in RGB is closest to this pixel's."""
    v = np.asarray(rgb, float)
    v = v / (np.linalg.norm(v) + 1e-9)
    tints = np.array([tank_colour(i) for i in range(n)], float)
    tints /= np.linalg.norm(tints, axis=1, keepdims=True)
    return int(np.argmax(tints @ v))


def test_not_blank_and_sized(overview):
    s, r, img = overview
    assert img.shape == (SIZE[1], SIZE[0], 3) and img.dtype == np.uint8
    assert img.std() > 10 and len(np.unique(img.reshape(-1, 3), axis=0)) > 50


def test_arena_floor_and_walls_are_where_projected(overview):
    from tanktool.game.render3d import SKY

    s, r, img = overview
    sky = np.array(SKY) * 255
    (x0, z0), (x1, z1) = s.world.bounds.tolist()
    for x, z in [((x0 + x1) / 2, z0 + 12), ((x0 + x1) / 2, z1 - 12), (x0 + 12, (z0 + z1) / 2), (x1 - 12, (z0 + z1) / 2)]:
        px, py, _ = r.project((x, 0.0, z))
        assert 0 <= px < SIZE[0] and 0 <= py < SIZE[1]
        assert np.abs(img[int(py), int(px)] - sky).sum() > 60      # floor, not sky
    # the inner face of the outer wall (1 m thick, 3 m high) is drawn in its texture's
    # colours: red-brown brick (tools/make_textures.py)
    px, py, _ = r.project(((x0 + x1) / 2, 1.5, z0 + 1.02))
    red, green, blue = img[int(py) - 1:int(py) + 2, int(px) - 3:int(px) + 4].reshape(-1, 3).astype(int).mean(axis=0)
    assert red > green + 20 and red > blue + 20


def test_every_tank_shows_in_its_colour(overview):
    s, r, img = overview
    n = len(s.world.tanks)
    for t in s.world.tanks:
        x, z, _ = s.pose(t.index)
        cx, _, cz = t.spec.centre_of_mass
        # the roof of the hull beside the turret, seen from above
        px, py, depth = r.project((x, t.spec.height * 0.7, z))
        assert -1 < depth < 1
        patch = img[int(py) - 1:int(py) + 2, int(px) - 1:int(px) + 2].reshape(-1, 3)
        votes = [closest_tint(p, n) for p in patch]
        assert votes.count(t.index) >= 5, (t.name, patch.tolist())


def test_cameras_cycle_and_chase_sees_the_followed_tank():
    from tanktool.game.render3d import CAMERAS, Renderer3D

    s = GameSession("paper2002", bots=2, seed=2, player=True)
    run_frames(s, 10)
    r = Renderer3D(s, SIZE)
    try:
        assert r.camera == "chase"
        img = r.render(hud=False)
        x, z, _ = s.pose(0)
        px, py, _ = r.project((x, s.spec.height * 0.7, z))
        patch = img[int(py) - 2:int(py) + 3, int(px) - 2:int(px) + 3].reshape(-1, 3)
        assert sum(closest_tint(p, 3) == 0 for p in patch) >= 13
        seen = [r.toggle_camera() for _ in CAMERAS]
        assert seen == ["first-person", "overview", "chase"]
        r.camera = "first-person"
        fp = r.render(hud=True, fps=60.0)
        assert fp.std() > 5 and not np.array_equal(fp, img)
    finally:
        r.release()


def test_effects_and_shells_are_drawn():
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.session import Effect

    s = GameSession("box", bots=2, seed=0, player=False)
    r = Renderer3D(s, SIZE)
    try:
        r.camera = "overview"
        before = r.render(hud=False)
        s.effects.append(Effect("explosion", 30.0, 1.0, 30.0, s.t))
        after = r.render(hud=False)
        assert len(r.effects.particles) > 20                   # flash, fire, smoke, debris, sparks
        px, py, _ = r.project((30.0, 1.0, 30.0))
        patch = after[int(py) - 2:int(py) + 3, int(px) - 2:int(px) + 3].reshape(-1, 3).astype(int)
        red, green, blue = patch.mean(axis=0)
        assert red > 200 and red > blue + 40                    # a bright, warm flash
        assert not np.array_equal(before, after)
    finally:
        r.release()


def test_own_explosion_never_blinds():
    # the followed tank blows up under the chase camera: the fireball shows, but at no
    # moment of it does it cover more than a fifth of the view or white it out
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.session import Effect

    s = GameSession("box", bots=2, seed=0, player=True)
    run_frames(s, 20)
    r = Renderer3D(s, SIZE)
    try:
        base = r.render(hud=False).astype(int)
        t = s.world.tanks[0]
        x, z = t.position
        t.alive, t.respawn_at = False, 99.0
        s.effects.append(Effect("explosion", x, 0.8 * t.spec.height, z, s.t))
        changed = []
        for _ in range(30):
            for _ in range(4):
                s.world.t += s.dt                 # time passes; nothing else moves
            img = r.render(hud=False).astype(int)
            assert (img.sum(axis=2) > 720).mean() < 0.02         # no white-out
            changed.append((np.abs(img - base).sum(axis=2) > 120).mean())
        assert max(changed) < 0.2 and max(changed) > 0.01, changed
    finally:
        r.release()


def test_tracers_follow_the_shells():
    from tanktool.game.particles import SessionEffects

    s = GameSession("box", bots=4, seed=1, player=False)
    for _ in range(600):
        s.step()
        if s.world.shells:
            break
    assert s.world.shells, "nobody fired in 5 s"
    sh = s.world.shells[0]
    ribbons = SessionEffects.tracers(s, 1.0, (30.0, 40.0, 30.0))
    assert ribbons.shape[1] == 9 and len(ribbons) % 6 == 0 and len(ribbons) >= 6
    head = ribbons[2, :3]                                   # the third corner is at the head
    assert np.linalg.norm(head - np.array([sh.x, sh.y, sh.z])) < 0.5


def test_headless_3d_screenshot_cli(tmp_path):
    import pygame

    out = tmp_path / "shot.png"
    r = CliRunner().invoke(cli, ["play", "--headless", "--frames", "30", "--screenshot", str(out),
                                 "--arena", "paper2002", "--bots", "4", "--size", "320x180"])
    assert r.exit_code == 0, r.output
    img = pygame.surfarray.array3d(pygame.image.load(str(out)))
    assert img.shape[:2] == (320, 180) and img.std() > 10


def test_far_tanks_drop_their_small_parts():
    from tanktool.game.render3d import Renderer3D

    s = GameSession("box", bots=2, seed=0, player=True)
    r = Renderer3D(s, (1280, 720))
    try:
        name = s.world.tanks[0].spec.name
        near, far = r.tanks[name], r.tanks_far[name]
        assert sum(b.triangles for b in far) < sum(b.triangles for b in near) / 3     # no wheels
        _, _, eye = r.matrices(1.0)
        me, other = s.world.tanks[0], s.world.tanks[1]
        assert r._lod(me, r._tank_model_matrix(me, 1.0), eye) is near          # the chase camera's own tank
        other.place(me.x + 55.0 * me.c, me.z + 55.0 * me.s, 0.0)
        r._placed.clear()
        assert r._lod(other, r._tank_model_matrix(other, 1.0), eye) is far     # 55 m away: a few dozen pixels
    finally:
        r.release()


def test_quality_option_picks_the_preset_for_the_run(tmp_path, monkeypatch):
    from tanktool.game.app import App
    from tanktool.game.quality import preset

    # the window's settings page may say "high" with its own shadows; --quality low wins, unsaved
    cfg = tmp_path / "settings.toml"
    cfg.write_text('quality = "high"\nshadows = "high"\n')
    from app_helpers import match_config

    app = App(None, match_config(bots=1, size=(320, 180), quality="low"), settings_file=cfg)
    assert app.quality == preset("low")
    assert 'quality = "high"' in cfg.read_text()
    r = CliRunner().invoke(cli, ["play", "--headless", "--frames", "5", "--screenshot", str(tmp_path / "q.png"),
                                 "--arena", "box", "--bots", "2", "--size", "160x90", "--quality", "low"])
    assert r.exit_code == 0 and (tmp_path / "q.png").is_file(), r.output
    r = CliRunner().invoke(cli, ["play", "--headless", "--quality", "ultra"])
    assert r.exit_code == 2 and "ultra" in r.output


def test_renderers_in_one_process_each_draw_in_their_own_context():
    """Each headless renderer has its own EGL context; one made after another must not
    steal the first one's drawing (bench/render.py keeps one per preset side by side)."""
    from tanktool.game.quality import PRESETS
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.thumbnails import vehicle_picture

    s = GameSession("box", bots=2, seed=1, player=False)
    run_frames(s, 10)
    a = Renderer3D(s, SIZE, quality=PRESETS["low"])
    try:
        before = a.render(hud=False)
        b = Renderer3D(s, SIZE, quality=PRESETS["high"])
        try:
            b.render(hud=False)
            vehicle_picture("light", (64, 48))           # the previews' own context, too
            assert np.array_equal(a.render(hud=False), before)
            assert np.array_equal(a.render_reference(), a.render_reference())
        finally:
            b.release()
    finally:
        a.release()


def test_the_sky_under_the_clouds_base_is_drawn_without_them_and_looks_the_same():
    """The sky's rows with no corner over the clouds' base are drawn by the program
    without the cloud lookup (game/sky.py): the picture is the one all clouds give."""
    from tanktool.game.render3d import Renderer3D

    s = GameSession("hills", bots=2, seed=0, player=False)
    run_frames(s, 10)
    r = Renderer3D(s, SIZE)
    try:
        r.camera = "first-person"                   # level: the horizon across the middle
        r.render(hud=False)
        split = r.render(hud=False).astype(int)
        rows = []
        real = r.sky._cloudy_from
        r.sky._cloudy_from = lambda inv, eye, lowest: rows.append((lowest, real(inv, eye, lowest))) or lowest
        whole = r.render(hud=False).astype(int)
    finally:
        r.release()
    lowest, cloudy = rows[0]
    assert lowest < cloudy < r.sky.rows              # some rows had no clouds to draw, some had
    assert np.abs(split - whole).max() <= 1
