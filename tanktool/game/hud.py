"""The heads-up display, drawn with pygame on a transparent surface so that both views
use it: the top view blits it, the 3D view uploads it as a texture over the scene.

Health of the followed tank, its score, the frame rate, a scoreboard and a minimap
drawn from the walls.  Also the atomic PNG writer used for screenshots.
"""

from __future__ import annotations

import os
import tempfile
from functools import lru_cache
from pathlib import Path
from typing import Any

import pygame

from .session import GameSession, tank_colour

TEXT = (240, 240, 230)
SHADOW = (0, 0, 0)


@lru_cache(maxsize=8)
def font(size: int) -> "pygame.font.Font":
    if not pygame.font.get_init():
        pygame.font.init()
    return pygame.font.Font(None, size)


def text(surface: "pygame.Surface", s: str, pos: tuple[int, int], size: int = 22, colour=TEXT,
         anchor: str = "topleft") -> "pygame.Rect":
    """Text with a 1-pixel shadow, readable on any background."""
    f = font(size)
    img = f.render(s, True, colour)
    rect = img.get_rect(**{anchor: pos})
    surface.blit(f.render(s, True, SHADOW), rect.move(1, 1))
    surface.blit(img, rect)
    return rect


class Minimap:
    """The arena's walls scaled into a box, drawn once; tanks are dots on top."""

    def __init__(self, session: GameSession, size: int) -> None:
        (x0, z0), (x1, z1) = session.world.bounds.tolist()
        span = max(x1 - x0, z1 - z0, 1e-6)
        self.scale = (size - 8) / span
        self.origin = (x0, z0)
        w = int((x1 - x0) * self.scale) + 8
        h = int((z1 - z0) * self.scale) + 8
        self.base = pygame.Surface((w, h), pygame.SRCALPHA)
        self.base.fill((10, 14, 10, 170))
        pygame.draw.rect(self.base, (200, 200, 200, 200), self.base.get_rect(), 1)
        for (ax, az), (bx, bz) in session.world.walls.segments.tolist():
            pygame.draw.line(self.base, (220, 210, 180, 255), self.to_px(ax, az), self.to_px(bx, bz), 1)

    def to_px(self, x: float, z: float) -> tuple[int, int]:
        # screen y grows with z: seen from above with x to the right, +z points down
        return int(4 + (x - self.origin[0]) * self.scale), int(4 + (z - self.origin[1]) * self.scale)

    def draw(self, surface: "pygame.Surface", session: GameSession, topleft: tuple[int, int], alpha: float) -> None:
        img = self.base.copy()
        focus = session.focus()
        for t in session.world.tanks:
            if not t.alive:
                continue
            x, z, h = session.pose(t.index, alpha)
            p = self.to_px(x, z)
            r = 4 if t.index == focus else 3
            pygame.draw.circle(img, tank_colour(t.index), p, r)
            if t.index == focus:
                import math
                pygame.draw.line(img, (255, 255, 255), p, (p[0] + 9 * math.cos(h), p[1] + 9 * math.sin(h)), 2)
        surface.blit(img, topleft)


class Hud:
    """Draws the HUD for one session onto a surface of the window's size."""

    def __init__(self, session: GameSession, size: tuple[int, int]) -> None:
        self.size = size
        self.minimap = Minimap(session, max(min(size) // 4, 80))

    def draw(self, surface: "pygame.Surface", session: GameSession, fps: float, alpha: float = 1.0,
             message: str | None = None, view: str = "") -> list["pygame.Rect"]:
        """Draw the HUD; return the rectangles it covers (the 3D view blends only those:
        a full-window blend costs a software renderer more than the scene)."""
        w, h = self.size
        focus = session.focus_tank()
        # health bar
        frac = max(focus.hp, 0.0) / focus.spec.hit_points
        bar = pygame.Rect(16, h - 40, 260, 22)
        health = [bar.inflate(4, 4)]
        pygame.draw.rect(surface, (20, 20, 20, 200), health[0])
        colour = (60, 200, 80) if frac > 0.5 else (230, 190, 40) if frac > 0.25 else (220, 50, 40)
        pygame.draw.rect(surface, colour + (255,), (bar.x, bar.y, int(bar.w * frac), bar.h))
        label = f"{focus.name}  HP {max(focus.hp, 0):.0f}/{focus.spec.hit_points:.0f}"
        if not focus.alive:
            label += f"  respawn in {max(focus.respawn_at - session.t, 0):.1f} s"
        health.append(text(surface, label, (bar.x + 6, bar.centery), 22, anchor="midleft"))
        reload = focus.reload / focus.spec.fire_interval if focus.spec.fire_interval > 0 else 0.0
        health.append(pygame.draw.rect(surface, (200, 200, 220, 255),
                                       (bar.x, bar.bottom + 4, max(int(bar.w * (1 - reload)), 1), 4)))
        # score and frame rate
        rate = f"{fps:5.1f} fps" if fps > 0 else "headless"      # a screenshot has no frame rate
        info = [text(surface, f"score {focus.kills}   deaths {focus.deaths}", (16, 12), 30),
                text(surface, f"{rate}  {view}", (16, 40), 20, colour=(190, 190, 190)),
                text(surface, f"t {session.t:6.1f} s  {session.info.name}", (16, 58), 20, colour=(190, 190, 190))]
        # scoreboard
        y = 12
        board = []
        for name, kills, deaths, hp, alive in session.scoreboard():
            i = session.world.names.index(name)
            colour = tank_colour(i) if alive else (120, 120, 120)
            board.append(text(surface, f"{name:>6} {kills:2d}/{deaths:<2d}", (w - 16, y), 20, colour=colour,
                              anchor="topright"))
            y += 17
        mm = self.minimap.base.get_size()
        topleft = (w - mm[0] - 12, h - mm[1] - 12)
        self.minimap.draw(surface, session, topleft, alpha)
        rects = [g[0].unionall(g[1:]) for g in (health, info, board) if g]
        rects.append(pygame.Rect(topleft, mm))
        if message:
            rects.append(text(surface, message, (w // 2, h // 2), 56, anchor="center"))
        # one pixel of slack: text shadows and antialiasing sit on the edges
        return [r.inflate(2, 2).clip(surface.get_rect()) for r in rects]


def save_png(surface: "pygame.Surface", path: str | os.PathLike) -> Path:
    """Write a PNG atomically: a temporary file in the same folder, then a rename."""
    path = Path(path)
    if not path.parent.exists():
        from ..errors import TanktoolError

        raise TanktoolError(f"{path}: folder {path.parent} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}-", suffix=".png", dir=path.parent)
    os.close(fd)
    try:
        pygame.image.save(surface, tmp)
        from ..formats.bundle import _umask

        os.chmod(tmp, 0o666 & ~_umask())      # mkstemp makes 0600; a picture is for everyone
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def surface_from_rgb(pixels: Any) -> "pygame.Surface":
    """An (h, w, 3) uint8 array (top row first) as a pygame surface."""
    import numpy as np

    a = np.ascontiguousarray(pixels[:, :, :3])
    return pygame.image.frombuffer(a.tobytes(), (a.shape[1], a.shape[0]), "RGB").copy()
