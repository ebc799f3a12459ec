"""Quality presets and the settings file (game/quality.py), and the renderer at each
preset (EGL)."""

import ctypes.util

import numpy as np
import pytest

from tanktool.errors import FormatError
from tanktool.game.quality import PRESETS, Settings, load_settings, preset, save_settings


def test_presets_and_overrides():
    assert preset("medium").shadows == "low" and preset("high").arena_light == "pixel"
    assert preset("low").shadow_size == 0 and preset("high").shadow_size == 2048
    s = Settings(quality="low", shadows="high")
    q = s.graphics()
    assert q.name == "custom" and q.shadows == "high" and q.particles == PRESETS["low"].particles
    assert Settings(quality="high", shadows="high").graphics() is PRESETS["high"]   # no override really
    with pytest.raises(FormatError, match="quality must be one of"):
        preset("ultra")


def test_settings_round_trip_and_missing_file(tmp_path):
    f = tmp_path / "cfg" / "settings.toml"
    assert load_settings(f) == Settings()
    s = Settings(quality="high", particles="low", resolution="1600x900", fullscreen=True, name="alice")
    assert save_settings(s, f) == f
    assert load_settings(f) == s


@pytest.mark.parametrize("line, key", [('quality = "ultra"', "quality"), ('shadows = 3', "shadows"),
                                       ('resolution = "big"', "resolution"), ('fullscreen = "yes"', "fullscreen"),
                                       ('name = "a b c"', "name")])
def test_bad_settings_name_the_file_and_key(tmp_path, line, key):
    f = tmp_path / "settings.toml"
    f.write_text(line + "\n")
    with pytest.raises(FormatError) as e:
        load_settings(f)
    assert str(f) in str(e.value) and key in str(e.value)


@pytest.mark.skipif(ctypes.util.find_library("EGL") is None, reason="libEGL is not installed")
def test_every_preset_renders_and_shadows_darken_behind_a_crate():
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.session import GameSession

    s = GameSession("box", bots=1, seed=0, player=False)
    s.world.tanks[0].place(8.0, 8.0, 0.0)
    shots = {}
    for name, q in PRESETS.items():
        r = Renderer3D(s, (320, 180), quality=q)
        try:
            r.camera = "overview"
            shots[name] = r.render(hud=False).astype(int)
            if name == "medium":
                # the crate at (40, 40) is 4 m wide and 2 m high, the light over (30, 30):
                # its shadow reaches about 0.8 m beyond its far (+x) face; a point 0.4 m
                # from that face is shadowed at medium and lit without shadows
                assert r.light_pos[0] == 30.0 and r.light_pos[2] == 30.0
                px, py, _ = r.project((42.4, 0.0, 40.0))
                shadowed = shots[name][int(py) - 1:int(py) + 2, int(px) - 1:int(px) + 2].mean()
                assert sum(b.triangles for b in r.arena) > 4 * r.arena_model.triangles   # split for its light
        finally:
            r.release()
    lit = shots["low"][int(py) - 1:int(py) + 2, int(px) - 1:int(px) + 2].mean()
    assert shadowed < 0.8 * lit
    for name, img in shots.items():
        assert img.std() > 10, name


@pytest.mark.skipif(ctypes.util.find_library("EGL") is None, reason="libEGL is not installed")
def test_a_tank_shadow_follows_the_tank_and_leaves_nothing_behind():
    """The tanks are drawn into the arena's shadow map every frame (game/shadows.py): a
    tank's shadow darkens the floor beside it, and once it has moved on the floor there
    is drawn exactly as by a renderer that never saw it there."""
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.session import GameSession

    s = GameSession("box", bots=1, seed=0, player=True)        # one tank: the player's, standing
    tank = s.world.tanks[0]
    tank.place(15.0, 30.0, 0.0)             # the light is over (30, 30): its shadow falls towards -x
    s.step()
    r = Renderer3D(s, (320, 180), quality=PRESETS["medium"])
    try:
        r.camera = "overview"
        first = r.render(hud=False).astype(int)
        px, py, _ = r.project((15.0, 0.0, 30.0))
        tank.place(45.0, 20.0, 0.0)
        s.step()
        moved = r.render(hud=False).astype(int)
    finally:
        r.release()
    fresh = Renderer3D(s, (320, 180), quality=PRESETS["medium"])
    try:
        fresh.camera = "overview"
        clean = fresh.render(hud=False).astype(int)
    finally:
        fresh.release()
    # the shadow: floor darker with the tank there than once it has gone, next to it
    darker = np.argwhere(first.sum(axis=2) < 0.8 * moved.sum(axis=2))
    assert np.sum(np.abs(darker - (py, px)).max(axis=1) < 25) >= 20
    assert np.abs(moved - clean).max() <= 2                       # nothing left behind anywhere
