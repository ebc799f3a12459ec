"""Pictures without a display: run a session of computer tanks for some frames and
render one view to a PNG (``tanktool play --headless --frames N --screenshot F``)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

#: one rendered frame is this much simulated time [s]
FRAME = 1.0 / 60.0
VIEWS = ("3d", "top")


def _headless_sdl() -> None:
    # pygame surfaces and fonts need no window; make sure SDL never tries to open one
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    os.environ.setdefault("SDL_AUDIODRIVER", "dummy")


def run_frames(session: Any, frames: int) -> None:
    """Advance ``session`` by ``frames`` frames of simulated time (bots drive every tank)."""
    steps = max(int(round(frames * FRAME / session.dt)), 0)
    if getattr(session, "max_steps", None) is not None:      # a replay ends with its tape
        steps = min(steps, session.max_steps - session.world.steps)
    for _ in range(steps):
        session.step()


def screenshot(path: str | os.PathLike, view: str = "3d", frames: int = 120, arena: str | None = None,
               vehicle: str | None = None, bots: int = 8, seed: int = 0, size: tuple[int, int] = (1280, 720),
               overlays: tuple[str, ...] = (), difficulty: str = "normal", bot: str = "agent",
               session: Any = None, quality: str = "medium", camera: str = "chase") -> dict[str, Any]:
    """Render ``view`` after ``frames`` frames of a bots-only match (``bot`` drivers at
    ``difficulty``); write it to ``path``.  The 3D view uses the ``quality`` preset
    (game/quality.py; the user's settings play no part in a screenshot) and ``camera``,
    and follows the last second of the match so that its smoke and dust are there.

    Returns what was drawn: ``{"path", "view", "frames", "size", "tanks": [(x, z)...]}``.
    """
    from ..errors import TanktoolError

    if view not in VIEWS:
        raise TanktoolError(f"--view must be one of {', '.join(VIEWS)}, got {view!r}")
    path = Path(path)
    if path.suffix.lower() != ".png":
        raise TanktoolError(f"{path}: screenshots are PNG files (name it .png)")
    if not path.parent.exists():
        raise TanktoolError(f"{path}: folder {path.parent} does not exist")
    _headless_sdl()
    import pygame

    from .hud import save_png, surface_from_rgb
    from .session import GameSession

    pygame.font.init()
    if session is None:  # a prepared session (a replay's, game/replay_session.py) replaces the bots-only match
        session = GameSession(arena, vehicle, bots=bots, seed=seed, player=False, difficulty=difficulty, bot=bot)
    warm = min(frames, 60) if view == "3d" else 0      # the last second, seen by the effects
    run_frames(session, frames - warm)
    if view == "top":
        from .render_top import TopView

        top = TopView(session, size)
        for o in overlays:
            top.toggle(o)
        surf = pygame.Surface(size)
        top.draw(surf, 1.0, fps=0.0)
    else:
        from .quality import preset
        from .render3d import CAMERAS, Renderer3D

        if camera not in CAMERAS:
            raise TanktoolError(f"camera must be one of {', '.join(CAMERAS)}, got {camera!r}")
        r = Renderer3D(session, size, quality=preset(quality))
        r.camera = camera
        try:
            for _ in range(warm):
                run_frames(session, 1)
                r.effects.sync(session, r.floor_y)
            surf = surface_from_rgb(r.render(1.0, fps=0.0))
        finally:
            r.release()
    save_png(surf, path)
    return {"path": str(path), "view": view, "frames": frames, "size": size,
            "tanks": [session.pose(i)[:2] for i in range(len(session.world.tanks))]}
