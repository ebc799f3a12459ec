"""An arena's levels from its triangles: walkable surface, walls, spawns and the report.

The one place ``import-arena`` asks "where can a tank be?":

1. the walkable surface (:mod:`tanktool.nav.walkable`) on a grid over the model;
2. its walls per level and region (:mod:`tanktool.nav.level_walls`);
3. a navigation grid at the largest bundled tank's footprint radius, measured to
   those walls exactly: where that tank fits (where it fits nowhere, the next
   smaller vehicle's, down to the smallest: the arena is then for those only);
4. spawn points where it fits, on the largest part of the grid it can drive around
   in, at least a tank's length apart (tanktool.geometry.spawns);
5. per level its area and height range, and what was left out and why
   (:mod:`tanktool.nav.surface_report`).

A model where no bundled tank fits anywhere is refused (ArenaError).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import shapely

from ..errors import ArenaError
from ..fleet import Fleet
from ..memory import give_back
from ..geometry.spawns import SPAWN_CLEARANCE, SPAWN_COUNT, facing_centre, spawn_candidates, spread
from .grid_window import model_lattice
from .level_walls import LevelWalls, level_walls
from .navgrid import NavGrid, on_wall_tolerance, too_close
from .surface_report import LeftOut, left_out
from .walkable import Surface, WalkableParams, walkable_surface

#: spawn points keep this much more than the footprint radius from walls (m)
SPAWN_MARGIN = 0.25
#: stages reported to a progress callback
STAGES = ("surface", "walls", "grid", "spawns", "report")


@dataclass
class LevelInfo:
    level: int
    area: float
    y_lo: float
    y_hi: float
    regions: int


@dataclass
class ArenaLevels:
    surface: Surface
    params: WalkableParams
    walls: LevelWalls
    grid: NavGrid  # valid where the largest bundled tank fits
    spawns: np.ndarray  # (k, 4) x, z, heading, y
    levels: list[LevelInfo]
    left_out: list[LeftOut]
    floor_y: float
    flat: bool  # one level, one region, one floor height: the 2002 case
    vertices: np.ndarray | None = None  # the model (world frame), for pictures of steep faces
    faces: np.ndarray | None = None
    timings: dict[str, float] = field(default_factory=dict)
    fleet: Fleet | None = None  # the vehicles the grid and spawns are for (the largest that fit)
    too_big: list[tuple[str, str]] = field(default_factory=list)  # (vehicle, why) the arena is not for

    @property
    def free(self):
        return self.walls.free()


def walls_too_close(walls, origin: np.ndarray, cell: float, shape: tuple[int, int], levels: int,
                    clearance: float) -> np.ndarray:
    """(L, nz, nx): nodes closer than ``clearance`` to a wall of their own level."""
    tol = on_wall_tolerance(walls.bounds)
    out = np.zeros((levels, *shape), dtype=bool)
    # a band of rows at a time (each row's nodes are decided alone): too_close's running
    # sums over the whole grid were three int64 arrays of a node each (+0.26 GB on 2 km)
    rows = max(1, BAND_NODES // max(shape[1], 1))
    for lv in range(levels):
        seg = walls.segments[walls.level == lv]
        for a in range(0, shape[0], rows):
            out[lv, a:a + rows] = too_close(seg, origin, cell, shape, clearance, rows=slice(a, a + rows), tol=tol)
    return out


#: nodes of a band of rows of walls_too_close
BAND_NODES = 1 << 20


def tank_grid(surface: Surface, lw: LevelWalls, radius: float, runs: bool = True,
              like: NavGrid | None = None) -> NavGrid:
    """The grid of nodes where a tank of ``radius`` fits (exact distance to the walls).
    ``runs`` False: its run arrays empty, never worked out: spawns are chosen by its
    nodes, links and heights alone (choose_spawns); the runs are 16 bytes a node (0.26
    GB on a 2 km terrain, where two such grids stacked at the import's peak).  ``like``:
    another tank's grid of this surface, whose nodes (a finite height), heights and
    links are this one's (shared, not scattered from the surface again)."""
    from .walkable import grid_from_layers, grid_from_surface

    origin = surface.hf.origin[[0, 2]]
    tc = walls_too_close(lw.walls, origin, surface.hf.cs, surface.shape, max(surface.levels, 1), radius)
    if like is not None and like.height is not None and like.link is not None:
        return grid_from_layers(np.isfinite(like.height) & ~tc, like.height, like.link, radius, origin,
                                surface.hf.cs, runs=runs)
    return grid_from_surface(surface, radius, origin, too_close=tc, runs=runs)


def grid_components(grid: NavGrid) -> tuple[np.ndarray, int]:
    """Component labels (L, nz, nx) of a grid's valid nodes over its links (0: none)."""
    from .navgrid import layered_labels

    return layered_labels(grid.valid, grid.links())


#: spawn points prefer ground no steeper than this (degrees), and no rougher than half
#: the climb around the plane under the tank's footprint
SPAWN_SLOPE = 10.0
#: in spreading the spawn points, one on another level counts as this much farther (m)
#: from one below it than their distance across: a deck over a passage or a roof gets
#: spawns of its own, where seen from above it lies among the ground's (fort's roof,
#: stacked_floors' decks had none, and no tank went up in a match)
LEVEL_SPREAD = 30.0


def ground_under(height: np.ndarray, node: tuple[int, int, int], cell: float, radius: float) -> tuple[float, float]:
    """(slope in degrees, largest step off that slope in metres) of the ground within
    ``radius`` of a node, on its level: the least-squares plane through the heights."""
    lv, i, j = node
    r = max(1, int(math.ceil(radius / cell)))
    win = height[lv, max(0, i - r):i + r + 1, max(0, j - r):j + r + 1]
    ii, jj = np.nonzero(np.isfinite(win))
    if len(ii) < 3:
        return 0.0, 0.0
    y = win[ii, jj]
    A = np.column_stack([jj * cell, ii * cell, np.ones(len(ii))])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    slope = math.degrees(math.atan(math.hypot(coef[0], coef[1])))
    return slope, float(np.abs(A @ coef - y).max())


def focus_box(vertices: np.ndarray, faces: np.ndarray, margin: float) -> np.ndarray | None:
    """[[xmin, zmin], [xmax, zmax]] of the model's geometry other than a ground plane
    around it (flat faces spanning half the model or more: a town's 2 km plane), grown
    by ``margin``; None when there is no such plane or nothing else."""
    from ..geometry.heightfield import FACE_BLOCK

    if len(faces) == 0:
        return None
    # a block of faces at a time: the corners of every face at once took ~150 bytes a
    # face (0.3 GB on a 2 km terrain, the vehicle grids' peak); min and max are exact
    total = vertices[:, [0, 2]].max(axis=0) - vertices[:, [0, 2]].min(axis=0)
    plane = np.empty(len(faces), dtype=bool)
    for a in range(0, len(faces), FACE_BLOCK):
        tri = vertices[faces[a:a + FACE_BLOCK]]
        lo, hi = tri.min(axis=1), tri.max(axis=1)
        flat = (hi[:, 1] - lo[:, 1]) <= 1e-6
        plane[a:a + FACE_BLOCK] = flat & (hi[:, [0, 2]] - lo[:, [0, 2]] >= 0.5 * total).any(axis=1)
    if not plane.any() or plane.all():
        return None
    rlo, rhi = np.full(2, np.inf), np.full(2, -np.inf)
    for a in range(0, len(faces), FACE_BLOCK):
        rest = vertices[faces[a:a + FACE_BLOCK][~plane[a:a + FACE_BLOCK]]].reshape(-1, 3)[:, [0, 2]]
        if len(rest):
            rlo, rhi = np.minimum(rlo, rest.min(axis=0)), np.maximum(rhi, rest.max(axis=0))
    box = np.array([rlo - margin, rhi + margin])
    if np.prod(box[1] - box[0]) >= 0.5 * float(np.prod(total)):
        return None               # the other geometry covers most of it: no empty plane to avoid
    return box


def choose_spawns(lw: LevelWalls, grid: NavGrid, fleet: Fleet, bounds: np.ndarray,
                  count: int = SPAWN_COUNT, focus: np.ndarray | None = None) -> np.ndarray:
    """Spawn points ``[x, z, heading, y]`` where the largest tank fits (see the module
    docstring); the clearance is the radius plus SPAWN_MARGIN, at least SPAWN_CLEARANCE
    when that leaves ``count`` candidates.  With ``focus`` (``focus_box``), only the
    candidates inside it, when there are enough (not on the empty plane around a town)."""
    labels, k = grid_components(grid)
    if k == 0:
        raise ArenaError("no place where the largest bundled tank fits")
    best = 1   # one component (most levels): no count of every node's label (hix: ~15 ms)
    if k > 1:
        sizes = np.bincount(labels.ravel(), minlength=k + 1)
        sizes[0] = 0
        best = int(np.argmax(sizes))
    height = grid.heights()
    floor_c = fleet.radius + SPAWN_MARGIN
    chosen = None
    for c in sorted({max(SPAWN_CLEARANCE, floor_c), floor_c}, reverse=True):
        pts, ys, level = [], [], []
        for r in lw.regions:
            cand = spawn_candidates(r.free, c)
            if len(cand) == 0:
                continue
            node = grid.nodes_of(cand)
            lab = labels[r.level, node[:, 0], node[:, 1]]
            keep = lab == best
            pts.append(cand[keep])
            ys.append(height[r.level, node[keep, 0], node[keep, 1]])
            level.append(np.full(int(keep.sum()), r.level))
        pts = np.concatenate(pts) if pts else np.zeros((0, 2))
        ys = np.concatenate(ys) if ys else np.zeros(0)
        level = np.concatenate(level) if level else np.zeros(0, dtype=np.int64)
        chosen = (pts, ys, level)
        if len(pts) >= count:
            break
    pts, ys, level = chosen
    if focus is not None and len(pts):
        inside = ((pts >= focus[0]) & (pts <= focus[1])).all(axis=1)
        if inside.sum() >= min(count, len(pts)) or inside.sum() >= 2:
            pts, ys, level = pts[inside], ys[inside], level[inside]
    if len(pts) == 0:
        raise ArenaError(f"no place where the largest bundled tank fits: {fleet.radius_of} (footprint radius "
                         f"{fleet.radius:.2f} m) needs {floor_c:.2f} m from every wall for a spawn point")
    region = shapely.union_all([r.free for r in lw.regions])
    start = np.asarray(shapely.get_coordinates(shapely.centroid(region))[0])
    if focus is not None:
        start = 0.5 * (focus[0] + focus[1])
    node = grid.nodes_of(pts)
    climb = surface_climb(grid)

    def level_ground(k: int) -> bool:  # a tank spawned on a slope rolls off
        slope, rough = ground_under(height, (int(level[k]), int(node[k, 0]), int(node[k, 1])), grid.cell,
                                    fleet.radius)
        return slope <= SPAWN_SLOPE and rough <= 0.5 * climb

    # the level as a third coordinate (all 0 on one level: the same spawns as on the plane)
    at = np.column_stack([pts, level * LEVEL_SPREAD])
    start = np.append(start, 0.0)
    idx = spread(at, count, fleet.length, start, accept=level_ground)
    if len(idx) < min(count, 2):  # no level ground enough: the best there is
        idx = spread(at, count, fleet.length, start)
    p = pts[idx]
    return np.column_stack([p, facing_centre(p, bounds), ys[idx]])


def surface_climb(grid: NavGrid) -> float:
    """The climb the grid was built with (recorded on it by tank_grid), else the default."""
    from .walkable import CLIMB

    return float(getattr(grid, "climb", CLIMB))


def analyse_arena(vertices: np.ndarray, faces: np.ndarray, params: WalkableParams, fleet: Fleet,
                  cut_height: float = 1.0, tolerance: float = 0.01, spawn_count: int = SPAWN_COUNT,
                  progress: Callable[[str], None] | None = None, keep_runs: bool = True) -> ArenaLevels:
    """Everything ``import-arena`` needs to know about a model's levels (module docstring).

    ``keep_runs`` False: the tank grid is built without its run arrays (empty; 16 bytes
    a node): for a caller that reads only its nodes, links and heights
    (the import that builds the bundle's grid anew)."""
    step = progress or (lambda _s: None)
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if len(faces) == 0:
        raise ArenaError("the model has no triangles")
    if not np.isfinite(vertices).all():
        raise ArenaError("the model has non-finite vertices (NaN or inf)")
    t = {}
    t0 = time.perf_counter()
    # on the model lattice (nav/grid_window.py): the bundle's grid is this surface's, cut to the walls
    origin, shape = model_lattice(vertices, params.cell)
    surface = walkable_surface(vertices, faces, params, fleet.radius, origin_xz=origin, shape=shape)
    keep_for_analysis(surface)
    t["surface"] = time.perf_counter() - t0
    step("surface")
    if not surface.main.any():
        raise ArenaError(
            f"no surface a tank can stand on: every upward face is steeper than {params.max_slope:g} deg, "
            f"has less than {params.headroom:g} m headroom or is narrower than a cell "
            f"({_no_surface_hint(vertices, faces, params.max_slope)})")
    t0 = time.perf_counter()
    lw = level_walls(surface, vertices, faces, cut_height, params.headroom, params.climb, tolerance,
                     params.max_slope)
    t["walls"] = time.perf_counter() - t0
    step("walls")
    t0 = time.perf_counter()
    found, why, problem, tries = _largest_fit(surface, lw, params, fleet, spawn_count, vertices, faces, keep_runs)
    t["grid"] = time.perf_counter() - t0
    step("grid")
    if found is None:
        raise _refusal(surface, lw, tries, problem, (vertices, faces, params))
    grid, spawns, fleet = found
    too_big = [(n, why.get(n, "fits nowhere")) for n, r, _ in tries if r > fleet.radius]
    t["spawns"] = 0.0
    step("spawns")
    t0 = time.perf_counter()
    levels = _level_infos(surface, lw)
    report = left_out(surface, vertices, faces, params, fleet.radius)
    flat = len(lw.regions) == 1 and lw.regions[0].y_hi - lw.regions[0].y_lo <= params.cell_height + 1e-9
    floor_y = _floor_y(lw, surface)
    t["report"] = time.perf_counter() - t0
    step("report")
    return ArenaLevels(surface, params, lw, grid, spawns, levels, report, floor_y, flat, vertices, faces, t,
                       fleet, too_big)


def keep_for_analysis(surface: Surface) -> None:
    """Let go of what the analysis does not read of a finished surface: its ceilings
    and the heightfield's spans, all but those the headroom filter took away (the
    report's); the walls' flags of the surface's spans (a flat top, the rim of a steep
    obstacle) are kept as ``derived["span_flat"]``, ``["span_rim"]``.  2 B a span where
    the spans took ~20 (~0.27 GB on a 2 km terrain, under every later stage's peak)."""
    from ..geometry.heightfield import Heightfield

    hf = surface.hf
    w = hf.walkable
    surface.derived["span_flat"] = hf.flat[w]
    surface.derived["span_rim"] = ~hf.top_walkable[w]
    low = hf.low_headroom
    surface.hf = Heightfield(hf.origin, hf.cs, hf.ch, hf.shape, hf.col[low], hf.smin[low], hf.smax[low],
                             np.zeros(int(low.sum()), dtype=bool), hf.flat[low], hf.top_walkable[low],
                             dict(hf.counts), np.ones(int(low.sum()), dtype=bool))
    surface.ceil = np.zeros(0, dtype=surface.ceil.dtype)
    give_back(20 * len(surface.col))   # their pages lie between live arrays: the heap keeps them else


def _no_surface_hint(vertices: np.ndarray, faces: np.ndarray, max_slope: float) -> str:
    """What to try when nothing is walkable: flip the faces when more of the model's
    gentle area faces down than up (a floor wound the wrong way faces down, and like
    Recast we walk only on faces whose front is up), else the up axis and the scale."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1)
    gentle = np.abs(n[:, 1]) >= np.cos(np.radians(max_slope)) * length
    down, up = float(length[gentle & (n[:, 1] < 0)].sum()), float(length[gentle & (n[:, 1] > 0)].sum())
    if down > up:
        return (f"{down / 2:,.0f} m^2 of level faces face down and {up / 2:,.0f} m^2 up: are the faces wound the "
                "wrong way? flip the normals in your 3D program; or is the up axis right? try --up")
    return "is the up axis right? try --up; the scale? try --scale"


def _largest_fit(surface: Surface, lw: LevelWalls, params: WalkableParams, fleet: Fleet, spawn_count: int,
                 vertices: np.ndarray, faces: np.ndarray,
                 keep_runs: bool = True) -> tuple[tuple | None, dict[str, str], str | tuple, list]:
    """The largest vehicle that fits: the grid and spawns are made for it (an arena too
    narrow for the heavy tank still plays with the light one; play refuses the others).
    Returns ((grid, spawns, fleet) or None, vehicle -> why the arena is not for it,
    the first problem met (a message, or (vehicle, radius) that fits nowhere), the
    vehicles tried (name, radius, length))."""
    tries = [(n, r, ln) for n, r, ln in fleet.sizes] or [(fleet.radius_of, fleet.radius, fleet.length)]
    found = None  # (grid, spawns, fleet) of the largest vehicle that fits
    problem: str | tuple = ""
    why: dict[str, str] = {}
    for k, (name, radius, length) in enumerate(tries):
        if k and radius >= tries[k - 1][1]:
            continue
        fl = fleet if k == 0 else fleet.down_to(name, radius, length)
        g = tank_grid(surface, lw, radius, runs=keep_runs)
        g.climb = params.climb
        if not g.valid.any():
            problem = problem or (name, radius)   # the refusal is worked out only if it is needed
            why[name] = f"fits nowhere (it needs a circle of {2 * radius:.2f} m)"
            continue
        try:
            sp = choose_spawns(lw, g, fl, lw.walls.bounds, spawn_count, focus_box(vertices, faces, fl.length))
        except ArenaError as e:
            problem = problem or str(e)
            why[name] = "has room for no spawn point"
            continue
        if found is None or len(found[1]) < 2 <= len(sp):
            found = (g, sp, fl)
        if len(found[1]) >= 2:  # room for a duel; else a smaller vehicle may have more
            break
        why[name] = f"has room for only {len(sp)} spawn point"
    return found, why, problem, tries


def _refusal(surface: Surface, lw: LevelWalls, tries: list, problem: str | tuple, model: tuple) -> ArenaError:
    """Why no vehicle of ``tries`` fits (``problem``: the first one met, see :func:`_largest_fit`)."""
    if len(tries) == 1:
        if isinstance(problem, tuple):
            return _no_fit(surface, lw, *problem, model)
        return ArenaError(problem)
    name, radius, _ = tries[-1]
    nofit = _no_fit(surface, lw, name, radius, model)
    return NoFitError(f"no place where any bundled tank fits (the largest bundled tank, {tries[0][0]}, nor "
                      f"the smallest): {nofit}", nofit.scale)


def _level_infos(surface: Surface, lw: LevelWalls) -> list[LevelInfo]:
    """Each level's area, heights and number of regions."""
    levels = []
    cell2 = surface.hf.cs ** 2
    for lv in range(surface.levels):
        m = surface.level == lv
        ys = surface.y[m]
        levels.append(LevelInfo(lv, float(m.sum() * cell2), float(ys.min()), float(ys.max()),
                                sum(1 for r in lw.regions if r.level == lv)))
    return levels


def smaller_vehicles(result: ArenaLevels, fleet: Fleet,
                     count: int = SPAWN_COUNT) -> dict[str, tuple[float, np.ndarray]]:
    """{vehicle: (footprint radius, spawn points [x, z, heading, y])} for each bundled
    vehicle smaller than the one ``result``'s grid and spawns are for: where it fits,
    on the largest part of its own grid -- surfaces only it reaches (a deck up a ramp
    too narrow for the larger tank) included.  One with room for fewer than 2 spawn
    points is left out (it plays on the larger vehicle's spawns)."""
    big = result.fleet or fleet
    out: dict[str, tuple[float, np.ndarray]] = {}
    for name, radius, length in fleet.sizes:
        if radius >= big.radius - 1e-9 or name in out:
            continue
        g = tank_grid(result.surface, result.walls, radius, runs=False, like=result.grid)   # only its spawns are kept
        g.climb = result.params.climb
        if not g.valid.any():
            continue
        fl = fleet.down_to(name, radius, length)
        focus = focus_box(result.vertices, result.faces, fl.length) if result.vertices is not None else None
        try:
            sp = choose_spawns(result.walls, g, fl, result.walls.walls.bounds, count, focus)
        except ArenaError:
            continue
        if len(sp) >= 2:
            out[name] = (float(radius), sp)
    return out


class NoFitError(ArenaError):
    """No bundled tank fits the model; ``scale`` is the --scale at which the smallest
    fits most of its walkable surface (None: none found)."""

    def __init__(self, message: str, scale: float | None = None) -> None:
        super().__init__(message)
        self.scale = scale


#: the --scale values a refusal may suggest
SCALES = (1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0, 30.0, 40.0, 50.0, 100.0)
#: "fits most of it": the share of the walkable surface a suggested --scale gives the tank
MOST = 0.5


def widest_fit(surface: Surface, lw: LevelWalls, radius: float, steps: int = 7) -> float:
    """The largest footprint radius below ``radius`` that fits somewhere (the same test
    as the tank grid's: the surface's clearance and the exact distance to the walls),
    to ``radius / 2**steps``; 0 when not even the smallest does."""
    lo, hi = 0.0, float(radius)
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        if tank_grid(surface, lw, mid).valid.any():
            lo = mid
        else:
            hi = mid
    return lo


#: a suggested scale is tried only while its heightfield stays this small (cells)
MAX_TRY_CELLS = 4_000_000


def scale_for(vertices: np.ndarray, faces: np.ndarray, params: WalkableParams,
              radius: float) -> tuple[float, float] | None:
    """(--scale, share of the walkable surface) at which a tank of ``radius`` fits on
    most of the model's walkable surface: the smallest of ``SCALES`` whose surface,
    found again at that scale (same slope, climb and headroom), keeps ``radius`` from
    its edges on at least ``MOST`` of its area; None when none does."""
    ext = np.ptp(vertices[:, [0, 2]], axis=0) if len(vertices) else np.zeros(2)
    for s in SCALES:
        if float(np.prod(ext * s / params.cell + 1)) > MAX_TRY_CELLS:
            break
        surf = walkable_surface(vertices * s, faces, params, radius)
        clear = surf.clearance[surf.main]
        if len(clear) and float(np.mean(clear >= radius)) >= MOST:
            return s, float(np.mean(clear >= radius))
    return None


def _no_fit(surface: Surface, lw: LevelWalls, name: str, radius: float, model: tuple) -> NoFitError:
    """The refusal when no tank fits: what it needs, the widest the surface takes (by the
    same test, so always less), and the --scale at which it would fit (``model``:
    vertices, faces, params)."""
    widest = 2 * widest_fit(surface, lw, radius)
    hint = scale_for(*model, radius)
    scale = (f"at --scale {hint[0]:g} {name} fits on {100 * hint[1]:.0f} % of it" if hint is not None
             else "wrong --scale?")
    return NoFitError(f"no place where {name} fits: it needs a circle of {2 * radius:.2f} m and the widest the "
                      f"walkable surface takes is {widest:.2f} m ({scale})", hint[0] if hint is not None else None)


def _floor_y(lw: LevelWalls, surface: Surface) -> float:
    """The arena's main floor: the height of the largest exact flat floor of level 0
    (the 2002 floor on a flat arena), else the lowest walkable height."""
    flat = [(area, h) for r in lw.regions if r.level == 0 for h, area in r.flat_heights]
    if flat:
        return float(max(flat)[1])
    return float(np.min(surface.y[surface.main]))


def spawn_y_needed(result: ArenaLevels) -> bool:
    """Whether spawns need their height written (anything but one flat floor)."""
    return not (result.flat and len(result.levels) == 1)


def describe_levels(result: ArenaLevels) -> list[str]:
    """The report's lines: each level, then what was left out."""
    lines = []
    for lv in result.levels:
        span = f"y {lv.y_lo:.2f}" if math.isclose(lv.y_lo, lv.y_hi, abs_tol=0.005) else f"y {lv.y_lo:.2f} .. {lv.y_hi:.2f}"
        regions = f", {lv.regions} regions" if lv.regions > 1 else ""
        lines.append(f"  level {lv.level}: {lv.area:,.0f} m^2 at {span}{regions}")
    if result.left_out:
        lines.append("  left out: " + "; ".join(x.describe() for x in result.left_out))
    else:
        lines.append("  left out: nothing")
    return lines
