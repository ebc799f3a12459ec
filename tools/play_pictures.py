"""The pictures of docs/play.md, rendered headless (EGL, SDL's dummy driver).

    .venv/bin/python tools/play_pictures.py [--only NAME]

* ``docs/arena-<name>.png``: every bundled arena in the 3D view (chase camera, the
  default ``medium`` preset) during a match of 8 computer tanks;
* ``docs/play-3d.png``: the maze from the overview camera at the ``high`` preset
  (everything on);
* ``docs/play-menu.png`` and ``docs/play-settings.png``: the start menu with its
  previews and the settings page;
* ``docs/play-destroyed.png``: the HUD while the followed tank is a wreck (kill feed,
  DESTROYED, respawn countdown);
* ``docs/play-top.png``: the top view of the maze with its three overlays.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
DOCS = ROOT / "docs"
SIZE = (960, 540)
#: (frames, seed) that show each arena with tanks in view and something happening
MOMENTS = {"box": (420, 3), "maze": (600, 5), "paper2002": (480, 3)}


def arenas() -> list[str]:
    from tanktool.game.app import bundled

    return bundled("arenas")


def arena_shots(only: list[str] | None) -> None:
    from tanktool.game.headless import screenshot

    for name in arenas():
        if only and f"arena-{name}" not in only:
            continue
        frames, seed = MOMENTS.get(name, (480, 3))
        shot = screenshot(DOCS / f"arena-{name}.png", frames=frames, arena=name, bots=8, seed=seed, size=SIZE)
        print(shot["path"])
    if not only or "play-top" in only:
        shot = screenshot(DOCS / "play-top.png", view="top", frames=150, arena="maze", bots=6, seed=3, size=SIZE,
                          overlays=("quadtree", "navgrid", "agents"))
        print(shot["path"])
    if not only or "play-3d" in only:
        shot = screenshot(DOCS / "play-3d.png", frames=600, arena="maze", bots=8, seed=5, size=SIZE,
                          quality="high", camera="overview")
        print(shot["path"])


def menu_shots(only: list[str] | None) -> None:
    import tempfile

    import pygame

    from tanktool.game.app import App, Presenter
    from tanktool.game.config import MatchConfig, Opponents, ViewConfig
    from tanktool.game.hud import save_png

    with tempfile.TemporaryDirectory() as cfg:
        os.environ["XDG_CONFIG_HOME"] = cfg           # the default settings, not the user's
        pygame.display.init()
        pygame.font.init()
        app = App(Presenter(SIZE, False, want_gl=False),
                  MatchConfig(arena="maze", vehicle="heavy", opponents=Opponents(5), view=ViewConfig("3d", SIZE),
                              sound=False))
        app.frame(0.0)
        app.frame(0.0)                                 # the previews are made on the second frame
        if not only or "play-menu" in only:
            print(save_png(app.presenter.canvas, DOCS / "play-menu.png"))
        app.state = "settings"
        app.frame(0.0)
        if not only or "play-settings" in only:
            print(save_png(app.presenter.canvas, DOCS / "play-settings.png"))
        app.stop()


def destroyed_shot(only: list[str] | None) -> None:
    if only and "play-destroyed" not in only:
        return
    from tanktool.game.headless import run_frames
    from tanktool.game.hud import save_png, surface_from_rgb
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.session import GameSession

    s = GameSession("box", bots=6, seed=1, player=False)
    for _ in range(120 * 60):                          # until someone is destroyed
        s.step()
        dead = [e for e in s.feed if e.kind == "kill"]
        if dead and s.t - dead[-1].t > 0.7:
            break
    s.follow = dead[-1].other
    r = Renderer3D(s, SIZE)
    try:
        run_frames(s, 0)
        print(save_png(surface_from_rgb(r.render(1.0, fps=0.0)), DOCS / "play-destroyed.png"))
    finally:
        r.release()


def controls_shot(only: list[str] | None) -> None:
    """A first match: the controls overlay over the 3D chase view, player in the hills."""
    if only and "play-controls" not in only:
        return
    from tanktool.game.controls import controls_rows
    from tanktool.game.hud import save_png, surface_from_rgb
    from tanktool.game.input import Bindings
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.session import GameSession

    s = GameSession("hills", bots=3, seed=2, player=True)
    for _ in range(90):
        s.step()
    r = Renderer3D(s, SIZE)
    try:
        pic = r.render(1.0, fps=0.0, controls=controls_rows(Bindings()))
        print(save_png(surface_from_rgb(pic), DOCS / "play-controls.png"))
    finally:
        r.release()


def slope_shot(only: list[str] | None) -> None:
    """The chase camera on a hillside: the steepest moment of a bot's drive in the hills."""
    if only and "play-slope" not in only:
        return
    from tanktool.game.hud import save_png, surface_from_rgb
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.session import GameSession

    def drive() -> GameSession:
        return GameSession("hills", bots=3, seed=5, player=False)

    s = drive()
    steepest = max(range(120 * 40), key=lambda k: (s.step(), abs(s.world.tanks[0].pitch))[1])
    s = drive()                                      # again, to that moment
    s.follow = 0
    r = Renderer3D(s, SIZE)
    try:
        for k in range(steepest + 1):
            s.step()
            if k % 4 == 0 and k > steepest - 240:
                r.matrices(1.0)                      # the camera eases as in the window
        print(save_png(surface_from_rgb(r.render(1.0, fps=0.0)), DOCS / "play-slope.png"))
    finally:
        r.release()


def explosion_shot(only: list[str] | None) -> None:
    """A kill seen by the killer's chase camera a quarter second on: the explosion,
    debris and the burning wreck."""
    if only and "play-explosion" not in only:
        return
    from tanktool.game.hud import save_png, surface_from_rgb
    from tanktool.game.render3d import Renderer3D
    from tanktool.game.session import GameSession

    s = GameSession("box", bots=6, seed=1, player=False)
    r = Renderer3D(s, SIZE)
    try:
        seen = 0
        for _ in range(120 * 120):
            s.step()
            kills = [e for e in s.feed if e.kind == "kill"]
            if len(kills) > seen:                          # a new kill: ride with the killer
                seen, kill = len(kills), kills[-1]
                s.follow = kill.tank
            if seen and 0.28 <= s.t - kill.t < 0.29:
                r.matrices(1.0)
                x, y, _ = r.project((kill.x, 1.0, kill.z))
                if 0.2 * SIZE[0] < x < 0.8 * SIZE[0] and 0.2 * SIZE[1] < y < 0.8 * SIZE[1]:
                    break                                  # the explosion is in the picture
            if seen and s.t - kill.t < 0.3:
                r.render(1.0, fps=0.0)                     # the particles and the camera live on
        print(save_png(surface_from_rgb(r.render(1.0, fps=0.0)), DOCS / "play-explosion.png"))
    finally:
        r.release()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", action="append",
                    help="arena-box, play-3d, play-top, play-menu, play-settings, play-destroyed, play-controls, play-slope, play-explosion")
    args = ap.parse_args(argv)
    arena_shots(args.only)
    menu_shots(args.only)
    destroyed_shot(args.only)
    controls_shot(args.only)
    slope_shot(args.only)
    explosion_shot(args.only)
    return 0


if __name__ == "__main__":
    sys.exit(main())
