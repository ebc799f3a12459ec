"""The top-down view in plain pygame (no OpenGL), with debug overlays.

Seen from above with x to the right, +z points down the screen (a right-handed,
Y-up world seen from +y), so a heading that grows turns clockwise on screen, which
is a right turn, as ``Command.rotate > 0`` means.

Overlays (toggled by the ``overlay_*`` actions): the wall quadtree's leaf cells, the
navigation grid's valid nodes, and for each computer driver its state, vision cone
and path — read from whatever the driver exposes (``state``, ``path`` or
``waypoint``, ``sight``, ``fov``), so agents show what they know without this view
importing them.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pygame

from ..errors import TanktoolError
from .hud import Hud, text
from .session import GameSession, tank_colour

FLOOR = (52, 58, 50)
#: the walkable surface of an arena with relief or levels, from its lowest to its highest
HEIGHT_LOW, HEIGHT_HIGH = (40, 66, 44), (196, 184, 128)
WALL = (225, 205, 160)
MARGIN = 24
OVERLAYS = ("quadtree", "navgrid", "agents")


def agent_view(driver: Any, world: Any, tank: Any) -> dict[str, Any]:
    """What a computer driver lets us see: state (str), path [(x, z)...], sight [m],
    fov (half angle, rad).  Missing pieces are None."""
    if driver is None:
        return {}
    if hasattr(driver, "debug"):
        return dict(driver.debug())
    state = getattr(driver, "state", None)
    if state is None and hasattr(driver, "reverse_until"):
        # the scripted bot has no state machine: name what its fields say it is doing
        state = "backing off" if world.t < driver.reverse_until else "roaming"
        cmd = getattr(driver, "command", None)
        if cmd is not None and (cmd.fire or getattr(cmd, "strafe", 0.0)):
            state = "attacking"
    # an agent plans a path (search, evade) or walks a route (wander); the bot has a waypoint
    path = getattr(driver, "path", None) or getattr(driver, "route", None) or None
    if path is None and getattr(driver, "waypoint", None) is not None:
        path = [driver.waypoint]
    senses = getattr(driver, "senses", None)
    sight = getattr(senses, "vision_range", None) or getattr(driver, "sight", None)
    fov = getattr(senses, "half_angle", None) or getattr(driver, "fov", math.radians(60.0))
    return {"state": None if state is None else str(state), "path": path, "sight": sight, "fov": fov}


class TopView:
    """Draws a session from above onto a surface of ``size``."""

    def __init__(self, session: GameSession, size: tuple[int, int] = (1280, 720)) -> None:
        self.size = size
        self.session = session
        self.overlays: set[str] = set()
        (x0, z0), (x1, z1) = session.world.bounds.tolist()
        w, h = size
        self.scale = min((w - 2 * MARGIN) / max(x1 - x0, 1e-6), (h - 2 * MARGIN) / max(z1 - z0, 1e-6))
        # centre the arena in the window
        self.ox = (w - (x1 - x0) * self.scale) / 2 - x0 * self.scale
        self.oz = (h - (z1 - z0) * self.scale) / 2 - z0 * self.scale
        self.base = self._draw_arena()
        self._quadtree: pygame.Surface | None = None
        self._navgrid: pygame.Surface | None = None
        #: overlay -> why its file could not be used (shown on the overlay, the game goes on)
        self.problems: dict[str, str] = {}
        self.hud = Hud(session, size)

    def to_px(self, x: float, z: float) -> tuple[float, float]:
        return self.ox + x * self.scale, self.oz + z * self.scale

    def toggle(self, overlay: str) -> None:
        if overlay not in OVERLAYS:
            raise ValueError(f"overlay must be one of {OVERLAYS}")
        self.overlays ^= {overlay}

    # ------------------------------------------------------------------ static layers
    def _draw_arena(self) -> pygame.Surface:
        surf = pygame.Surface(self.size)
        surf.fill((22, 24, 22))
        (x0, z0), (x1, z1) = self.session.world.bounds.tolist()
        a, b = self.to_px(x0, z0), self.to_px(x1, z1)
        pygame.draw.rect(surf, FLOOR, pygame.Rect(a, (b[0] - a[0], b[1] - a[1])))
        ground = getattr(self.session.world, "ground", None)
        if getattr(ground, "relief", False):   # a flat ground is one shade: the floor's
            self._draw_heights(surf, ground)
        width = max(int(round(0.6 * self.scale)), 2)
        for (ax, az), (bx, bz) in self.session.world.walls.segments.tolist():
            pygame.draw.line(surf, WALL, self.to_px(ax, az), self.to_px(bx, bz), width)
        return surf

    def _draw_heights(self, surf: pygame.Surface, ground: Any) -> None:
        """The walkable surface shaded by height (its highest level where levels
        stack: the deck over the passage), lighter when higher, with a scale bar."""
        h = np.asarray(ground.h, dtype=np.float64)
        top = np.where(np.isfinite(h), h, -np.inf).max(axis=0)
        have = np.isfinite(top)
        if not have.any():
            return
        lo, hi = float(top[have].min()), float(top[have].max())
        u = np.clip((top - lo) / max(hi - lo, 1e-6), 0.0, 1.0)
        c0, c1 = np.array(HEIGHT_LOW, float), np.array(HEIGHT_HIGH, float)
        rgb = (c0 + (c1 - c0) * u[..., None]).astype(np.uint8)
        rgba = np.zeros(top.shape + (4,), np.uint8)
        rgba[..., :3] = rgb
        rgba[..., 3] = np.where(have, 255, 0)
        nz, nx = top.shape
        img = pygame.image.frombuffer(np.ascontiguousarray(rgba).tobytes(), (nx, nz), "RGBA")
        p = self.to_px(ground.ox, ground.oz)
        q = self.to_px(ground.ox + nx * ground.cell, ground.oz + nz * ground.cell)
        surf.blit(pygame.transform.smoothscale(img, (max(int(q[0] - p[0]), 1), max(int(q[1] - p[1]), 1))), p)
        # the scale: low .. high, top centre (the HUD holds the corners)
        w, bh = 120, 10
        x, y = self.size[0] // 2 - w // 2, 24
        for k in range(w):
            col = tuple(int(v) for v in c0 + (c1 - c0) * (k / (w - 1)))
            pygame.draw.line(surf, col, (x + k, y), (x + k, y + bh))
        text(surf, f"{lo:.1f} m", (x, y - 2), 16, anchor="bottomleft")
        text(surf, f"{hi:.1f} m", (x + w, y - 2), 16, anchor="bottomright")

    def _quadtree_layer(self) -> pygame.Surface:
        from ..nav.quadtree import WallQuadtree

        path = self.session.info.path
        qt_file = Path(path) / "quadtree.npz" if path is not None else None
        tree = None
        if qt_file is not None and qt_file.is_file():
            try:
                tree = WallQuadtree.load(qt_file)
            except TanktoolError as e:      # a damaged file: say so, draw one built from the walls
                self.problems["quadtree"] = f"{e} (showing one built from the walls)"
        if tree is None:
            tree = WallQuadtree.build(self.session.world.walls.segments, self.session.world.bounds, depth=3)
        surf = pygame.Surface(self.size, pygame.SRCALPHA)
        if "quadtree" in self.problems:
            text(surf, self.problems["quadtree"], (self.size[0] // 2, 20), 18, anchor="midtop")
        counts = tree.leaf_counts()
        for leaf, n in zip(tree.leaves.tolist(), counts.tolist()):
            (ax, az), (bx, bz) = tree.box[leaf].tolist()
            p, q = self.to_px(ax, az), self.to_px(bx, bz)
            r = pygame.Rect(p, (q[0] - p[0], q[1] - p[1]))
            if n:
                surf.fill((80, 140, 255, min(20 + 12 * n, 110)), r)
            pygame.draw.rect(surf, (120, 170, 255, 200), r, 1)
        return surf

    def _navgrid_layer(self) -> pygame.Surface:
        surf = pygame.Surface(self.size, pygame.SRCALPHA)
        path = self.session.info.path
        f = Path(path) / "navgrid.npz" if path is not None else None
        if f is None or not f.is_file():
            text(surf, "no navgrid.npz (tanktool build-navgrid)", (self.size[0] // 2, 20), 22, anchor="midtop")
            return surf
        from ..nav.navgrid import NavGrid

        try:
            grid = NavGrid.load(f)
        except TanktoolError as e:          # a damaged file: said on the overlay, the match goes on
            self.problems["navgrid"] = str(e)
            text(surf, str(e), (self.size[0] // 2, 20), 18, anchor="midtop")
            return surf
        nz, nx = grid.shape
        valid = grid.valid.any(axis=0)                  # valid on any level
        rgba = np.zeros((nz, nx, 4), np.uint8)
        rgba[valid] = (90, 230, 120, 90)
        rgba[~valid] = (230, 60, 60, 40)
        img = pygame.image.frombuffer(np.ascontiguousarray(rgba).tobytes(), (nx, nz), "RGBA")
        ox, oz = (float(v) for v in grid.origin)
        p = self.to_px(ox, oz)
        q = self.to_px(ox + nx * grid.cell, oz + nz * grid.cell)
        surf.blit(pygame.transform.scale(img, (max(int(q[0] - p[0]), 1), max(int(q[1] - p[1]), 1))), p)
        return surf

    # ------------------------------------------------------------------ frame
    def draw(self, surface: pygame.Surface, alpha: float = 1.0, fps: float = 0.0, message: str | None = None,
             controls: list[tuple[str, str]] | None = None) -> None:
        s = self.session
        surface.blit(self.base, (0, 0))
        if "quadtree" in self.overlays:
            self._quadtree = self._quadtree or self._quadtree_layer()
            surface.blit(self._quadtree, (0, 0))
        if "navgrid" in self.overlays:
            self._navgrid = self._navgrid or self._navgrid_layer()
            surface.blit(self._navgrid, (0, 0))
        if "agents" in self.overlays:
            self._draw_agents(surface, alpha)
        for t in s.world.tanks:
            self._draw_tank(surface, t, alpha)
        for sh, (x, _, z) in zip(s.world.shells, s.shell_points(alpha).tolist()):
            # a tracer: the shell and a streak behind it
            speed = math.hypot(sh.vx, sh.vz) or 1.0
            tail = min(14.0, math.hypot(x - sh.ox, z - sh.oz))
            pygame.draw.line(surface, (255, 200, 90), self.to_px(x - sh.vx / speed * tail, z - sh.vz / speed * tail),
                             self.to_px(x, z), max(int(0.2 * self.scale), 1))
            pygame.draw.circle(surface, (255, 240, 120), self.to_px(x, z), max(int(0.35 * self.scale), 2))
        for e in s.effects:
            a = e.age(s.t)
            if a >= 1.0:
                continue
            radius = {"flash": 1.5, "impact": 1.2, "explosion": 5.0}[e.kind] * self.scale * (0.4 + a)
            colour = {"flash": (255, 230, 140), "impact": (255, 150, 60), "explosion": (255, 110, 30)}[e.kind]
            pygame.draw.circle(surface, colour, self.to_px(e.x, e.z), max(int(radius), 2), 0 if a < 0.5 else 2)
        self.hud.draw(surface, s, fps, alpha, message, view="top view", to_px=self.to_px, controls=controls)

    def _draw_tank(self, surface: pygame.Surface, t: Any, alpha: float) -> None:
        x, z, h = self.session.pose(t.index, alpha)
        c, sn = math.cos(h), math.sin(h)
        cx, _, cz = (float(v) for v in t.spec.centre_of_mass)
        # footprint is about the centre of mass; the pose is the vehicle-frame origin
        pts = [self.to_px(x + (lx + cx) * c - (lz + cz) * sn, z + (lx + cx) * sn + (lz + cz) * c)
               for lx, lz in t.spec.footprint]
        colour = tank_colour(t.index) if t.alive else (90, 90, 90)
        pygame.draw.polygon(surface, colour, pts)
        pygame.draw.polygon(surface, (10, 10, 10), pts, 2)
        mx = t.spec.muzzle_local[0] + cx
        gun = self.to_px(x + mx * 1.05 * c, z + mx * 1.05 * sn)
        pygame.draw.line(surface, (20, 20, 20), self.to_px(x, z), gun, max(int(0.3 * self.scale), 2))
        if t.index == self.session.focus():
            px, pz = self.to_px(x, z)
            pygame.draw.circle(surface, (255, 255, 255), (px, pz), int(t.spec.radius * self.scale) + 4, 2)
        if getattr(getattr(self.session.world, "ground", None), "relief", False) and t.alive:
            # which floor it is on: its height beside it (a deck and the passage under it look alike)
            px, pz = self.to_px(x, z)
            text(surface, f"{t.y:.1f} m", (int(px + t.spec.radius * self.scale) + 2, int(pz)), 15, anchor="midleft")

    def _vision(self, x: float, z: float, h: float, sight: float, fov: float, rays: int = 25) -> list[tuple[float, float]]:
        """The vision cone cut by the walls: rays from the tank stop at the first wall."""
        walls = self.session.world.walls
        pts = [self.to_px(x, z)]
        for a in np.linspace(h - fov, h + fov, rays).tolist():
            bx, bz = x + sight * math.cos(a), z + sight * math.sin(a)
            hit = walls.first_hit(x, z, bx, bz)
            f = hit[0] if hit is not None else 1.0
            pts.append(self.to_px(x + f * (bx - x), z + f * (bz - z)))
        return pts

    def _draw_agents(self, surface: pygame.Surface, alpha: float) -> None:
        s = self.session
        labels = []
        for d, t in zip(s.drivers, s.world.tanks):
            info = agent_view(d, s.world, t)
            if not info or not t.alive:
                continue
            x, z, h = s.pose(t.index, alpha)
            colour = tank_colour(t.index)
            sight, fov = info.get("sight"), info.get("fov")
            if sight and fov:
                cone = self._vision(x, z, h, float(sight), float(fov))
                # each cone on its own small layer so overlapping cones blend
                xs, zs = [p[0] for p in cone], [p[1] for p in cone]
                box = pygame.Rect(int(min(xs)) - 1, int(min(zs)) - 1, int(max(xs) - min(xs)) + 3, int(max(zs) - min(zs)) + 3)
                layer = pygame.Surface(box.size, pygame.SRCALPHA)
                local = [(px - box.x, pz - box.y) for px, pz in cone]
                pygame.draw.polygon(layer, colour + (45,), local)
                pygame.draw.lines(layer, colour + (160,), True, local, 1)
                surface.blit(layer, box.topleft)
            path = info.get("path")
            if path:
                pts = [self.to_px(x, z)] + [self.to_px(float(px), float(pz)) for px, pz in path]
                pygame.draw.lines(surface, colour, False, pts, 2)
                pygame.draw.circle(surface, colour, pts[-1], 5, 2)
            if info.get("state"):
                px, pz = self.to_px(x, z)
                labels.append((info["state"], (int(px), int(pz - t.spec.radius * self.scale - 6))))
        for label, pos in labels:       # last, so no cone covers a label
            text(surface, label, pos, 18, anchor="midbottom")
