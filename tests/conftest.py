import os
from pathlib import Path

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("MPLBACKEND", "Agg")

ROOT = Path(__file__).resolve().parent.parent
DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture
def data_dir() -> Path:
    return DATA


@pytest.fixture
def root_dir() -> Path:
    return ROOT


@pytest.fixture
def make_app(tmp_path, monkeypatch):
    """Game windows made on demand on SDL's dummy driver (box arena, top view, no sound,
    bindings in a private config folder); all stopped at the end of the test."""
    import pygame

    from tanktool.game.app import App, Presenter

    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "cfg"))
    pygame.display.init()
    pygame.font.init()
    apps = []

    from app_helpers import match_config

    def make(size=(320, 240), settings_file=None, **kw):
        presenter = Presenter(size, fullscreen=False, want_gl=False)
        a = App(presenter, match_config(size=size, **kw), settings_file=settings_file)
        apps.append(a)
        return a

    yield make
    for a in apps:
        a.stop()
    pygame.display.quit()


@pytest.fixture(scope="session")
def imported_level(tmp_path_factory):
    """``imported_level(name)``: the bundle of generated level ``name``
    (tools/make_levels.py) imported once per session (per xdist worker) and shared by
    every module that plays on it -- a 1-3 s import each, otherwise repeated by
    test_sim_ground, test_levels_played and test_agent_levels.  Read it, do not change it."""
    from level_helpers import import_level

    base = tmp_path_factory.mktemp("imported-levels")
    cache: dict[str, Path] = {}

    def get(name: str) -> Path:
        if name not in cache:
            cache[name] = import_level(base, name)
        return cache[name]

    return get
