"""The heads-up display, drawn with pygame on a transparent surface so that both views
use it: the top view blits it, the 3D view uploads the rectangles it drew as a texture.

What it shows, for the followed tank (the player's, or the one a replay rides with):

* health and reload bars, name and hit points (bottom left);
* kills and deaths with their labels, frame rate, match time (top left);
* the scoreboard, K and D columns (top right) and under it the **kill feed**;
* the **crosshair** on the point the shell would hit now, with the landing ring on it
  (red when it would hit a tank), from game/aim.py (the simulation's own ``fire``),
  never off the screen; a hit marker when your shell hits;
* **hit-direction markers**: an arc towards whoever just hit you, fading;
* **"DESTROYED by ... / respawn in N s"** across the middle while you are a wreck;
  a spawn-protection line while the simulation says you are protected
  (``World.protection_left``);
* **REPLAY** with the tape's time and the tank followed, while watching a recording;
* a minimap drawn from the walls (bottom right).

Every text sits on a dark translucent panel so it reads on the sky as on the floor.
Rendered texts are cached: a frame re-renders only what changed.  Also the atomic PNG
writer used for screenshots.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections import OrderedDict
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable

import pygame

from .session import GameSession, tank_colour

TEXT = (240, 240, 230)
DIM = (190, 190, 185)
SHADOW = (0, 0, 0)
PANEL = (8, 10, 12, 150)
RED = (235, 70, 55)
#: seconds a hit-direction marker stays; a hit marker on the crosshair; a kill in the feed
HIT_MARK_S = 1.6
HIT_CONFIRM_S = 0.35
FEED_SHOW_S = 6.0
FEED_LINES = 5
#: the crosshair stays this many pixels inside the screen's edge
EDGE = 24
_CACHE: "OrderedDict[tuple, pygame.Surface]" = OrderedDict()
_CACHE_MAX = 600


@lru_cache(maxsize=16)
def font(size: int) -> "pygame.font.Font":
    if not pygame.font.get_init():
        pygame.font.init()
    return pygame.font.Font(None, size)


def _rendered(s: str, size: int, colour: tuple) -> "pygame.Surface":
    """Text with a 1-pixel shadow as one surface, cached (font rendering is the HUD's
    main cost)."""
    key = (s, size, tuple(colour))
    img = _CACHE.get(key)
    if img is not None:
        _CACHE.move_to_end(key)
        return img
    f = font(size)
    fg = f.render(s, True, colour)
    img = pygame.Surface((fg.get_width() + 1, fg.get_height() + 1), pygame.SRCALPHA)
    img.blit(f.render(s, True, SHADOW), (1, 1))
    img.blit(fg, (0, 0))
    _CACHE[key] = img
    if len(_CACHE) > _CACHE_MAX:
        _CACHE.popitem(last=False)
    return img


def text(surface: "pygame.Surface", s: str, pos: tuple[int, int], size: int = 22, colour=TEXT,
         anchor: str = "topleft") -> "pygame.Rect":
    """Text with a 1-pixel shadow, readable on any background."""
    img = _rendered(s, size, colour)
    rect = img.get_rect(**{anchor: pos})
    surface.blit(img, rect)
    return rect


def panel(surface: "pygame.Surface", rect: "pygame.Rect", colour=PANEL) -> "pygame.Rect":
    """A dark translucent backing for a group of texts (contrast on the sky)."""
    r = rect.inflate(12, 8)
    surface.fill(colour, r)
    return r


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
                pygame.draw.line(img, (255, 255, 255), p, (p[0] + 9 * math.cos(h), p[1] + 9 * math.sin(h)), 2)
        surface.blit(img, topleft)


def _name(session: Any, i: int) -> str:
    tanks = getattr(session, "world_all", session.world).tanks
    return tanks[i].name if 0 <= i < len(tanks) else "?"


def kill_feed(session: Any, now: float) -> list[tuple[int, int, float]]:
    """(killer, victim, age in s) of the last kills, newest last."""
    out = [(e.tank, e.other, now - e.t) for e in getattr(session, "feed", []) if e.kind == "kill"]
    return [k for k in out if k[2] < FEED_SHOW_S][-FEED_LINES:]


def hits_taken(session: Any, who: int, now: float) -> list[tuple[int, float]]:
    """(shooter, age) of the hits ``who`` took in the last HIT_MARK_S seconds."""
    return [(e.tank, now - e.t) for e in getattr(session, "feed", [])
            if e.kind == "hit" and e.other == who and now - e.t < HIT_MARK_S]


def killed_by(session: Any, who: int) -> int | None:
    """Who destroyed ``who`` last (None if the feed does not say)."""
    for e in reversed(getattr(session, "feed", [])):
        if e.kind == "kill" and e.other == who:
            return e.tank
    return None


def screen_direction(dx: float, dz: float, facing: float | None) -> tuple[float, float]:
    """A world direction (dx, dz) as a unit screen vector (x right, y down): relative to
    the camera's heading ``facing`` in 3D (ahead is up), or as the top view draws the
    world (x right, +z down) when None."""
    if facing is None:
        n = math.hypot(dx, dz) or 1.0
        return dx / n, dz / n
    rel = math.atan2(dz, dx) - facing
    return math.sin(rel), -math.cos(rel)


class Hud:
    """Draws the HUD for one session onto a surface of the window's size."""

    def __init__(self, session: GameSession, size: tuple[int, int]) -> None:
        self.size = size
        self.minimap = Minimap(session, max(min(size) // 4, 80))

    def draw(self, surface: "pygame.Surface", session: GameSession, fps: float, alpha: float = 1.0,
             message: str | None = None, view: str = "",
             project: Callable[[Any], tuple[float, float, float]] | None = None,
             facing: float | None = None, to_px: Callable[[float, float], tuple[float, float]] | None = None,
             controls: list[tuple[str, str]] | None = None) -> list["pygame.Rect"]:
        """Draw the HUD; return the rectangles it covers (the 3D view blends only those:
        a full-window blend costs a software renderer more than the scene).

        ``project`` maps a world point to (column, row, depth) in the 3D view; the top
        view passes ``to_px`` (world x, z to pixels) instead; ``facing`` is the 3D
        camera's heading (None in the top view); ``controls``: the controls overlay's rows
        (game/controls.py), drawn when given."""
        w, h = self.size
        focus = session.focus_tank()
        now = float(session.t)
        rects: list[pygame.Rect] = []
        rects += self._crosshair(surface, session, focus, project, to_px)
        rects += self._hit_markers(surface, session, focus, facing, now)
        rects.append(self._health(surface, session, focus))
        rates = f"{fps:5.1f} fps" if fps > 0 else "headless"      # a screenshot has no frame rate
        info = [text(surface, f"K {focus.kills}   D {focus.deaths}", (16, 12), 30),
                text(surface, f"kills {focus.kills}, deaths {focus.deaths}", (16, 38), 18, DIM),
                text(surface, f"{rates}  {view}", (16, 54), 18, DIM),
                text(surface, f"t {now:6.1f} s  {session.info.name}", (16, 70), 18, DIM)]
        rects.append(self._behind(surface, info))
        board = self._scoreboard(surface, session, w)
        rects.append(board)
        feed = self._feed(surface, session, w, board.bottom + 10, now)
        if feed is not None:
            rects.append(feed)
        mm = self.minimap.base.get_size()
        topleft = (w - mm[0] - 12, h - mm[1] - 12)
        self.minimap.draw(surface, session, topleft, alpha)
        rects.append(pygame.Rect(topleft, mm))
        rects += self._status(surface, session, focus, now)
        if controls:
            from .controls import draw_controls

            rects.append(draw_controls(surface, controls))
        if message:
            # a quarter down the screen: the crosshair and the respawn count are at its middle
            m = text(surface, message, (w // 2, h // 4 + 24), 48, anchor="center")
            rects.append(self._behind(surface, [m]))
        # one pixel of slack: text shadows and antialiasing sit on the edges
        area = surface.get_rect()
        return [r.inflate(2, 2).clip(area) for r in rects if r.w > 0 and r.h > 0]

    # ------------------------------------------------------------------ pieces
    @staticmethod
    def _behind(surface: "pygame.Surface", rects: list["pygame.Rect"]) -> "pygame.Rect":
        """Put a panel behind texts already drawn: redraw them over it (cheap: cached)."""
        box = rects[0].unionall(rects[1:])
        under = surface.subsurface(box.clip(surface.get_rect())).copy()
        r = panel(surface, box).clip(surface.get_rect())
        surface.blit(under, box.topleft)
        return r

    def _health(self, surface: "pygame.Surface", session: Any, focus: Any) -> "pygame.Rect":
        h = self.size[1]
        frac = max(focus.hp, 0.0) / focus.spec.hit_points
        bar = pygame.Rect(16, h - 44, 260, 22)
        back = panel(surface, bar.inflate(4, 14).move(0, 3))
        colour = (60, 200, 80) if frac > 0.5 else (230, 190, 40) if frac > 0.25 else (220, 50, 40)
        pygame.draw.rect(surface, (40, 40, 40, 220), bar)
        pygame.draw.rect(surface, colour + (255,), (bar.x, bar.y, int(bar.w * frac), bar.h))
        text(surface, f"{focus.name}  HP {max(focus.hp, 0):.0f}/{focus.spec.hit_points:.0f}",
             (bar.x + 6, bar.centery), 22, anchor="midleft")
        reload = focus.reload / focus.spec.fire_interval if focus.spec.fire_interval > 0 else 0.0
        ready = reload <= 0.0
        pygame.draw.rect(surface, ((120, 230, 140) if ready else (200, 200, 220)) + (255,),
                         (bar.x, bar.bottom + 4, max(int(bar.w * (1 - reload)), 1), 5))
        return back

    def _scoreboard(self, surface: "pygame.Surface", session: Any, w: int) -> "pygame.Rect":
        x = w - 16
        rows = [text(surface, f"{'tank':<8}  K   D", (x, 12), 20, DIM, anchor="topright")]
        y = 30
        focus = session.focus()
        index = {t.name: t.index for t in session.world.tanks}
        for name, kills, deaths, hp, alive in session.scoreboard():
            i = index.get(name, 0)
            colour = tank_colour(i) if alive else (130, 130, 130)
            mark = ">" if i == focus else " "
            rows.append(text(surface, f"{mark}{name:<8} {kills:3d} {deaths:3d}", (x, y), 20, colour, anchor="topright"))
            y += 17
        return self._behind(surface, rows)

    def _feed(self, surface: "pygame.Surface", session: Any, w: int, y: int, now: float) -> "pygame.Rect | None":
        kills = kill_feed(session, now)
        if not kills:
            return None
        rows = []
        for killer, victim, age in kills:
            fade = 1.0 if age < FEED_SHOW_S - 1.0 else max(FEED_SHOW_S - age, 0.0)
            colour = tuple(int(c * (0.4 + 0.6 * fade)) for c in TEXT)
            rows.append(text(surface, f"{_name(session, killer)}  destroyed  {_name(session, victim)}",
                             (w - 16, y), 20, colour, anchor="topright"))
            y += 18
        return self._behind(surface, rows)

    def _crosshair(self, surface: "pygame.Surface", session: Any, focus: Any,
                   project: Callable | None, to_px: Callable | None) -> list["pygame.Rect"]:
        """The crosshair on the point the shell would hit now (the simulation's own
        ``fire``, game/aim.py) with the landing ring on it; red when that is a tank.
        Kept inside the screen: a point off it is drawn at the edge, towards it."""
        if not focus.alive or (project is None and to_px is None):
            return []
        from .aim import predict

        aim = predict(session.world, focus)
        colour = RED if aim.target is not None else (250, 250, 240)
        c = self._on_screen(aim.impact, project, to_px)
        if c is None:                            # behind the camera: where the barrel points
            c = self._on_screen(aim.aim, project, to_px)
        if c is None:
            return []
        x, y = c
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            a = (x + dx * 10, y + dy * 10)
            b = (x + dx * 18, y + dy * 18)
            pygame.draw.line(surface, SHADOW, (a[0] + 1, a[1] + 1), (b[0] + 1, b[1] + 1), 3)
            pygame.draw.line(surface, colour, a, b, 2)
        pygame.draw.circle(surface, SHADOW, (x + 1, y + 1), 7, 2)      # the landing ring, on the hit point
        pygame.draw.circle(surface, colour, (x, y), 7, 2)
        pygame.draw.circle(surface, colour, (x, y), 1)
        out = [pygame.Rect(x - 20, y - 20, 42, 42)]
        if any(e.kind == "hit" and e.tank == focus.index and session.t - e.t < HIT_CONFIRM_S
               for e in getattr(session, "feed", [])):
            for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):     # a hit marker: your shell struck
                pygame.draw.line(surface, (255, 220, 80), (x + 9 * sx, y + 9 * sy), (x + 15 * sx, y + 15 * sy), 2)
        if to_px is not None:                    # top view: the line of fire
            m = to_px(aim.muzzle[0], aim.muzzle[2])
            out.append(pygame.draw.line(surface, colour + (120,), m, (x, y), 1))
        return out

    def _on_screen(self, p: tuple[float, float, float], project: Callable | None,
                   to_px: Callable | None) -> tuple[int, int] | None:
        """A world point in pixels, held ``EDGE`` pixels inside the screen; None when it is
        behind the 3D camera."""
        if project is not None:
            cx, cy, depth = project(p)
            if not -1.0 < depth < 1.0 or not (math.isfinite(cx) and math.isfinite(cy)):
                return None
        else:
            cx, cy = to_px(p[0], p[2])
        w, h = self.size
        return (int(min(max(cx, EDGE), w - 1 - EDGE)), int(min(max(cy, EDGE), h - 1 - EDGE)))

    def _hit_markers(self, surface: "pygame.Surface", session: Any, focus: Any, facing: float | None,
                     now: float) -> list["pygame.Rect"]:
        hits = hits_taken(session, focus.index, now)
        if not hits or not focus.alive:
            return []
        w, h = self.size
        cx, cy = w // 2, h // 2
        radius = min(w, h) * 0.22
        tanks = getattr(session, "world_all", session.world).tanks
        out = []
        for shooter, age in hits:
            if not 0 <= shooter < len(tanks):
                continue
            s = tanks[shooter]
            ux, uy = screen_direction(s.x - focus.x, s.z - focus.z, facing)
            a = max(1.0 - age / HIT_MARK_S, 0.0)
            colour = (255, 60, 40, int(230 * a))
            # a wedge pointing out towards the shooter
            tip = (cx + ux * (radius + 26), cy + uy * (radius + 26))
            px, py = -uy, ux
            left = (cx + ux * radius + px * 16, cy + uy * radius + py * 16)
            right = (cx + ux * radius - px * 16, cy + uy * radius - py * 16)
            out.append(pygame.draw.polygon(surface, colour, [tip, left, right]))
        return out

    def _status(self, surface: "pygame.Surface", session: Any, focus: Any, now: float) -> list["pygame.Rect"]:
        w, h = self.size
        out = []
        if not focus.alive:
            killer = killed_by(session, focus.index)
            left = max(focus.respawn_at - now, 0.0)
            lines = [text(surface, "DESTROYED", (w // 2, h // 2 - 40), 64, RED, anchor="center")]
            if killer is not None:
                lines.append(text(surface, f"by {_name(session, killer)}", (w // 2, h // 2 + 2), 30, anchor="center"))
            lines.append(text(surface, f"respawn in {left:.1f} s", (w // 2, h // 2 + 32), 30, anchor="center"))
            out.append(self._behind(surface, lines))
        world = getattr(session, "world_all", getattr(session, "world", None))
        left = world.protection_left(focus.index) if hasattr(world, "protection_left") else 0.0
        if focus.alive and left > 0.0:
            out.append(self._behind(surface, [text(surface, f"spawn protection {left:.1f} s (firing ends it)",
                                                   (w // 2, h - 80), 24, (140, 210, 255), anchor="center")]))
        if getattr(session, "max_steps", None) is not None:          # watching a recording
            total = session.max_steps * session.dt
            blink = (255, 60, 50) if int(now * 2) % 2 == 0 else (140, 40, 35)
            r = text(surface, f"REPLAY  {now:5.1f} / {total:.1f} s   following {focus.name}   (Tab: next tank)",
                     (w // 2 + 10, 14), 24, anchor="midtop")
            pygame.draw.circle(surface, blink, (r.x - 12, r.centery), 7)
            out.append(self._behind(surface, [r, pygame.Rect(r.x - 20, r.y, 20, r.h)]))
        return out


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
        from ..formats.bundle import current_umask as _umask

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
