"""A display named but not there (DISPLAY=:99 with no X server): SDL would fall back to
its invisible offscreen driver and the game would run forever showing nothing;
``tanktool play`` says so in one line and exits 2 instead."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tanktool.game.app import stale_display, x_display_socket


def test_x_display_sockets():
    assert x_display_socket(":0") == Path("/tmp/.X11-unix/X0")
    assert x_display_socket(":12.1") == Path("/tmp/.X11-unix/X12")
    assert x_display_socket("unix:3") == Path("/tmp/.X11-unix/X3")
    assert x_display_socket("remote.example:0") is None          # a TCP display: nothing to look at
    assert x_display_socket("nonsense") is None


def test_stale_display_is_named(monkeypatch):
    import pygame

    monkeypatch.setattr(pygame.display, "get_init", lambda: True)
    monkeypatch.setattr(pygame.display, "get_driver", lambda: "offscreen")
    monkeypatch.delenv("SDL_VIDEODRIVER", raising=False)
    monkeypatch.setenv("DISPLAY", ":987")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    why = stale_display()
    assert "DISPLAY=:987 is set but no display answers there" in why
    assert "/tmp/.X11-unix/X987 does not exist" in why and "offscreen" in why
    monkeypatch.setenv("SDL_VIDEODRIVER", "offscreen")              # asked for: not stale
    assert stale_display() is None
    monkeypatch.delenv("SDL_VIDEODRIVER")
    monkeypatch.setattr(pygame.display, "get_driver", lambda: "x11")
    assert stale_display() is None


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="X11 displays")
def test_play_with_a_dead_display_exits_with_one_error(tmp_path):
    n = 987
    while Path(f"/tmp/.X11-unix/X{n}").exists():
        n += 1
    env = {k: v for k, v in os.environ.items() if k not in ("SDL_VIDEODRIVER", "WAYLAND_DISPLAY")}
    env.update(DISPLAY=f":{n}", SDL_AUDIODRIVER="dummy", XDG_CONFIG_HOME=str(tmp_path / "cfg"))
    r = subprocess.run([sys.executable, "-m", "tanktool", "play", "--arena", "box"], env=env, cwd=tmp_path,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, (r.stdout, r.stderr)
    errors = [line for line in r.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1 and f"DISPLAY=:{n} is set but no display answers there" in errors[0]
    assert "Traceback" not in r.stderr
    assert not list(tmp_path.glob("*.png")) and not list(tmp_path.glob("*.ttr"))
