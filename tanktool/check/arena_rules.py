"""Rules on arena bundles: the manifest and its files, the walls, the spawn points and
the free space they stand in (A3xx), and the floor of the model.

The free space holding the spawn points is the set of faces (see
:mod:`tanktool.check.freespace`) the spawns fall in.  The vehicles measured against
it are the bundled vehicles beside the arena and those checked with it; "the largest"
is the widest.  A spawn point must hold the vehicle's footprint polygon, placed with
the spawn's heading, clear of every wall.  A passage is too narrow when it is
narrower than the vehicle is wide: the free space shrunk by half that width falls
apart there (a vehicle may still need more room to turn; that is the AI grid's
business, with its own clearance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import shapely

from ..formats.limits import MAX_COORDINATE
from ..formats.walls_txt import WallList
from ..geometry.hull import min_width
from .diagnostics import Diagnostic, diag, fmt_xz
from .freespace import UNBOUNDED, FreeSpace, analyse
from .level_rules import block_wall_rules, level_rules
from .manifest import Manifest, file_rules, safe_file, vehicle_grid_files
from .walls_rules import bare_walls_leaks, check_walls, leak_diagnostics
from .walls_scan import scan_walls_file

MIN_SPAWNS = 8
FLOOR_TOLERANCE = 0.05     # m: floor faces may differ this much in height (modelling noise)
ISLAND_MIN_AREA = 0.01     # m^2: smaller faces are slivers of the wall drawing, not places


@dataclass
class VehicleSize:
    """What the arena rules need to know of a vehicle."""

    name: str
    radius: float            # footprint radius (farthest hull point from the origin), m
    path: str = ""           # its vehicle.toml, where V401 points
    line: int = 0
    footprint: np.ndarray | None = None   # (k, 2) convex footprint (x forward, z right), vehicle frame
    width: float = 0.0                    # narrowest extent of the footprint, m
    height: float = 0.0                   # hull height, m (0: unknown)

    def __post_init__(self) -> None:
        if self.footprint is not None and len(self.footprint) >= 3:
            self.width = min_width(self.footprint)
        elif not self.width:
            self.width = 2.0 * self.radius

    def placed(self, x: float, z: float, heading: float):
        """The footprint polygon at a pose (heading about +y, +x forward -> (cos, sin))."""
        if self.footprint is None or len(self.footprint) < 3:
            return shapely.Point(x, z).buffer(self.radius, quad_segs=8)
        c, s = math.cos(heading), math.sin(heading)
        fx, fz = self.footprint[:, 0], self.footprint[:, 1]
        return shapely.Polygon(np.column_stack([x + c * fx - s * fz, z + s * fx + c * fz]))


@dataclass
class ArenaInfo:
    """What the vehicle rules need from a checked arena."""

    path: Path
    name: str
    fs: FreeSpace | None = None
    spawns: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    good: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))  # spawns in free space
    faces: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    ids: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # index in the manifest


# ----------------------------------------------------------------- bare walls.txt
def check_walls_file(path: Path) -> list[Diagnostic]:
    """A bare walls.txt: syntax, wall geometry, normals, leaks of the normals' free space."""
    walls, out = scan_walls_file(path)
    fs = analyse(walls)
    return out + check_walls(walls, fs, str(path)) + bare_walls_leaks(fs, str(path))


# ----------------------------------------------------------------- arena bundles
def _spawns(man: Manifest, out: list[Diagnostic]) -> tuple[np.ndarray, list[int], np.ndarray]:
    """The well-formed spawn points (k, 4) ``[x, z, heading, y]`` (y NaN when the
    manifest gives only three numbers), their manifest lines and their indices in the
    manifest's list (messages name spawns by that index)."""
    raw = man.get("", "spawns")
    if raw is None:
        out.append(man.missing("", "spawns", "is missing (a list of [x, z, heading_rad])"))
        return np.zeros((0, 4)), [], np.zeros(0, np.int64)
    if not isinstance(raw, list):
        out.append(man.missing("", "spawns", f"must be a list of [x, z, heading_rad], got {raw!r}"))
        return np.zeros((0, 4)), [], np.zeros(0, np.int64)
    lines = man.lines.items("", "spawns", len(raw))
    rows, keep, ids = [], [], []
    for i, s in enumerate(raw):
        ok = (isinstance(s, list) and len(s) in (3, 4)
              and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in s)
              and all(abs(v) <= (1e3 if k == 2 else MAX_COORDINATE) for k, v in enumerate(s)))
        if not ok:
            out.append(diag("B102", str(man.path), lines[i],
                            f"spawn {i} must be [x, z, heading_rad] or [x, z, heading_rad, y] with finite numbers "
                            f"(coordinates within {MAX_COORDINATE:g} m of the origin), got {s!r:.80}"))
            continue
        rows.append([float(v) for v in s] + ([math.nan] if len(s) == 3 else []))
        keep.append(lines[i])
        ids.append(i)
    return np.array(rows, dtype=np.float64).reshape(-1, 4), keep, np.array(ids, dtype=np.int64)


def check_arena(bundle: Path, vehicles: list[VehicleSize], model_rules: bool = True) -> tuple[list[Diagnostic], ArenaInfo]:
    """Every arena rule on ``bundle``; ``model_rules=False`` skips loading the model
    (for arenas consulted only as context of a vehicle check)."""
    man = Manifest(bundle / "arena.toml")
    out = list(man.diagnostics)
    info = ArenaInfo(bundle, bundle.name)
    if man.doc is None:
        return out, info
    name = man.get("", "name")
    info.name = name if isinstance(name, str) and name else bundle.name
    # vehicles import-arena found too big for the arena ([vehicles] too_big) are refused
    # by play there: the spawns and the grid are for the others, and judged by them
    fits = man.table("vehicles")
    too_big = fits.get("too_big") if isinstance(fits, dict) else None
    if isinstance(too_big, list):
        vehicles = [v for v in vehicles if v.name not in too_big] or vehicles
    # a bundle import-arena made (its [source] and the [walkable] surface it found) plays
    # on its grid: without it a match would run as if the arena were flat (issue 25), so
    # a missing grid is an error, as in play (tanktool/freshness.py)
    imported = isinstance(man.table("source"), dict) and isinstance(man.table("walkable"), dict)
    grids = vehicle_grid_files(man, out) if imported else ()     # one grid per smaller vehicle
    out += file_rules(man, bundle, ("walls.txt",) + (("navgrid.npz",) + grids if imported else ()))

    spawns4, spawn_lines, info.ids = _spawns(man, out)
    spawns, spawn_y = spawns4[:, :3], spawns4[:, 3]
    info.spawns = spawns
    wname = man.string("walls", "file", out, default="walls.txt")
    wpath = safe_file(bundle, wname) if wname else None
    layered = False
    if wpath is None or not wpath.is_file():
        if wname and not any(d.code == "B202" and repr(wname) in d.message for d in out):
            out.append(diag("B202", str(man.path), man.lines.key("walls", "file"), f"walls file {wname!r} is missing"))
    else:
        walls, syntax = scan_walls_file(wpath)
        layered = walls.layered
        if layered:
            # walls in blocks per level and region: they do not close up on their own (a
            # ramp opens onto the deck above); the grid says where tanks go (level_rules)
            out += syntax + block_wall_rules(walls, str(wpath), 1e-6 * max(1.0, float(np.abs(walls.bounds).max())))
        else:
            fs = analyse(walls)
            info.fs = fs
            apply_spawn_vote(fs, spawns)
            out += syntax + check_walls(walls, fs, str(wpath))
            out += spawn_rules(fs, spawns, spawn_lines, man, str(wpath), vehicles, info)
    if len(spawns) < MIN_SPAWNS and man.get("", "spawns") is not None:
        out.append(diag("A305", str(man.path), man.lines.key("", "spawns"),
                        f"{len(spawns)} spawn points; a full match needs {MIN_SPAWNS}"))
    if model_rules:
        out += level_rules(man, bundle, spawns, spawn_y, spawn_lines, info.ids, vehicles, layered)
        if man.get("walkable", "headroom") is None:  # a flat 2002 arena: its floor must be flat
            region = None
            if info.fs is not None and info.good.any():
                region = info.fs.region(np.unique(info.faces[info.good]))
            out += floor_rules(man, bundle, region)
    return out, info


def _largest(vehicles: list[VehicleSize]) -> VehicleSize | None:
    return max(vehicles, key=lambda v: (v.width, v.radius)) if vehicles else None


def spawn_rules(fs: FreeSpace, spawns: np.ndarray, lines: list[int], man: Manifest, wpath: str,
                vehicles: list[VehicleSize], info: ArenaInfo) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    mpath = str(man.path)
    walls = fs.walls
    k = len(spawns)
    if k == 0:
        return out
    xz = spawns[:, :2]
    face = fs.face_of(xz)
    info.faces = face
    n = info.ids if len(info.ids) == k else np.arange(k)

    good = np.zeros(k, dtype=bool)
    leaking = False
    dist, wall = fs.nearest_wall(xz)
    for i in range(k):
        f = int(face[i])
        if f == UNBOUNDED and len(fs.dangling):
            leaking = True
            continue
        if f == UNBOUNDED:
            out.append(diag("A302", mpath, lines[i], f"spawn {n[i]} at {fmt_xz(xz[i])} is outside the arena's walls"))
        elif not fs.free[f]:
            out.append(diag("A302", mpath, lines[i], f"spawn {n[i]} at {fmt_xz(xz[i])} is inside solid material"))
        elif dist[i] <= 4 * fs.grid:
            out.append(diag("A302", mpath, lines[i],
                            f"spawn {n[i]} at {fmt_xz(xz[i])} is on the wall at {wpath}:{_wl(walls, wall[i])}"))
        else:
            good[i] = True
    if leaking:
        out += leak_diagnostics(fs, wpath, "the free space holding the spawn points")
    info.good = good

    big = _largest(vehicles)
    half = 0.5 * big.width if big else 0.0
    placed = good.copy()
    if big:
        for i in blocked_spawns(fs, spawns, good, big):
            out.append(diag("A303", mpath, lines[i],
                            f"spawn {n[i]} at {fmt_xz(xz[i])}: vehicle {big.name!r} placed there touches the wall at "
                            f"{wpath}:{_wl(walls, wall[i])} ({dist[i]:.2f} m from the spawn point)"))
            placed[i] = False

    out += reachability(fs, xz, face, placed, lines, mpath, half, big, n)
    if big:
        out += passage_diagnostics(fs, np.unique(face[good]), big, wpath)
    out += islands(fs, set(int(f) for f in face[good]), wpath)
    return out


def apply_spawn_vote(fs: FreeSpace, spawns: np.ndarray) -> None:
    """A room holding most spawn points is free space, whatever its normals say: if they
    all point out of it, A205 then names each of its walls instead of every spawn
    being reported inside solid material."""
    if not len(spawns):
        return
    face = fs.face_of(spawns[:, :2])
    bounded = face[face >= 0]
    if len(bounded):
        counts = np.bincount(bounded, minlength=len(fs.faces))
        top = int(np.argmax(counts))
        if counts[top] * 2 > len(spawns):
            fs.free[top] = True


def blocked_spawns(fs: FreeSpace, spawns: np.ndarray, good: np.ndarray, size: VehicleSize) -> list[int]:
    """Spawn points where the vehicle's footprint, placed with the spawn's heading,
    touches or overlaps a wall."""
    out = []
    if fs.noded is None:
        return out
    for i in np.flatnonzero(good):
        x, z, h = spawns[i]
        if shapely.intersects(size.placed(x, z, h), fs.noded):
            out.append(int(i))
    return out


def _wl(walls: WallList, i: int) -> int:
    return int(walls.lines[i]) if i >= 0 and walls.lines is not None and i < len(walls.lines) else 0


def components(fs: FreeSpace, face_ids, radius: float) -> list:
    """Connected pieces of the free space a vehicle of ``radius`` can stand in."""
    region = fs.clear_region(face_ids, radius)
    parts = [p for p in shapely.get_parts(region) if p.area > 1e-9 * max(1.0, radius * radius)]
    return parts


def _component_of(parts: list, xz: np.ndarray) -> np.ndarray:
    out = np.full(len(xz), -1, dtype=np.int64)
    if not parts or not len(xz):
        return out
    tree = shapely.STRtree(parts)
    pi, ci = tree.query(shapely.points(xz), predicate="intersects")
    out[pi] = ci
    return out


def reachable_groups(fs: FreeSpace, xz: np.ndarray, face: np.ndarray, placed: np.ndarray,
                     radius: float) -> np.ndarray:
    """(k,) group label per spawn (-1 when not placed); equal labels reach each other."""
    label = np.full(len(xz), -1, dtype=np.int64)
    idx = np.flatnonzero(placed)
    if not len(idx):
        return label
    if radius <= 0:
        label[idx] = face[idx]
        return label
    parts = components(fs, np.unique(face[idx]), radius)
    comp = _component_of(parts, xz[idx])
    # a spawn on the very edge of the clear region (distance == radius) still counts:
    # fall back to its face so it is not reported as cut off
    label[idx] = np.where(comp >= 0, comp, -2 - face[idx])
    return label


def reachability(fs: FreeSpace, xz: np.ndarray, face: np.ndarray, placed: np.ndarray, lines: list[int],
                 mpath: str, radius: float, big: VehicleSize | None, n: np.ndarray) -> list[Diagnostic]:
    label = reachable_groups(fs, xz, face, placed, radius)
    idx = np.flatnonzero(placed)
    if len(idx) < 2:
        return []
    vals, counts = np.unique(label[idx], return_counts=True)
    # the biggest group is the arena; ties go to the group of the first spawn
    main = vals[np.argmax(counts)] if counts.max() > counts[vals == label[idx[0]]][0] else label[idx[0]]
    first = int(idx[label[idx] == main][0])
    out = []
    for i in idx[label[idx] != main]:
        if face[i] != face[first]:
            why = "walls close it off"
        else:
            why = f"a passage on the way is too narrow for vehicle {big.name!r}" if big else "walls close it off"
        out.append(diag("A304", mpath, lines[i],
                        f"spawn {n[i]} at {fmt_xz(xz[i])} cannot be reached from spawn {n[first]}: {why}"))
    return out


def narrow_passages(fs: FreeSpace, face_ids, size: VehicleSize) -> list[tuple[float, np.ndarray, int]]:
    """Passages of the given faces narrower than ``size`` is wide, narrowest first.

    Shrinking a face's free space by half the vehicle's width splits it into pieces
    exactly where a passage is too narrow; between two pieces the shortest line runs
    through the passage, and the walls on either side of its middle give the width.
    Returns ``(width, centre, wall index next to it)``, one per passage.
    """
    found: dict[tuple[int, int], tuple[float, np.ndarray, int]] = {}
    half = 0.5 * size.width
    for f in face_ids:
        if f < 0:
            continue
        parts = components(fs, [f], half)
        if len(parts) < 2:
            continue
        parts.sort(key=lambda p: -p.area)
        for p in parts[1:50]:
            others = shapely.union_all([q for q in parts if q is not p])
            c = np.asarray(shapely.shortest_line(p, others).coords, dtype=np.float64)
            width, mid = fs.passage(c.mean(axis=0), 2.0 * size.width)
            width = min(width, size.width)  # the split proves it; the measure is approximate
            _, w = fs.nearest_wall(mid[None])
            key = (int(round(mid[0] / max(half, 1e-6))), int(round(mid[1] / max(half, 1e-6))))
            if key not in found:
                found[key] = (float(width), mid, int(w[0]))
    return sorted(found.values(), key=lambda t: t[0])


def passage_diagnostics(fs: FreeSpace, face_ids, big: VehicleSize, wpath: str) -> list[Diagnostic]:
    return [diag("A306", wpath, _wl(fs.walls, w),
                 f"a passage about {width:.2f} m wide at {fmt_xz(mid)} is narrower than vehicle "
                 f"{big.name!r} ({big.width:.2f} m wide)")
            for width, mid, w in narrow_passages(fs, face_ids, big)]


def islands(fs: FreeSpace, spawn_faces: set[int], wpath: str) -> list[Diagnostic]:
    if not spawn_faces:
        return []
    out = []
    for f in np.flatnonzero(fs.free):
        if int(f) in spawn_faces or fs.faces[f].area < ISLAND_MIN_AREA:
            continue
        walls_of = np.sort(fs.piece_wall[fs.piece_front == f])
        line = _wl(fs.walls, int(walls_of[0])) if len(walls_of) else 0
        p = shapely.point_on_surface(fs.faces[f])
        out.append(diag("A307", wpath, line,
                        f"free space of {fs.faces[f].area:.2f} m^2 around {fmt_xz((p.x, p.y))} "
                        "cannot be reached from the spawn points"))
    return out


# ----------------------------------------------------------------- the floor
def floor_rules(man: Manifest, bundle: Path, region=None) -> list[Diagnostic]:
    """A308: the upward faces below the wall slice height over the free space (what
    tanks drive on, since no wall stands there) must all be at one height.

    ``region`` is the free space holding the spawn points (a shapely geometry); without
    one (an arena that leaks) every such face counts.
    """
    floor_y = man.get("", "floor_y")
    mfile = man.get("model", "file")
    if isinstance(floor_y, bool) or not isinstance(floor_y, (int, float)) or not math.isfinite(floor_y):
        return [man.missing("", "floor_y", f"must be a finite number (m), got {floor_y!r}")]
    if not isinstance(mfile, str):
        return []
    mpath = safe_file(bundle, mfile)
    if mpath is None or not mpath.is_file():
        return []  # B201 already said so
    height = man.get("walls", "height")
    height = float(height) if isinstance(height, (int, float)) and not isinstance(height, bool) and height > 0 else 1.0
    from ..errors import FormatError
    from .glb import load_triangles

    try:
        v, f = load_triangles(mpath)
    except FormatError as e:
        return [diag("B201", str(man.path), man.lines.key("model", "file"), f"model file cannot be read: {e}")]
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    nl = np.linalg.norm(n, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        up = np.where(nl > 0, n[:, 1] / nl, 0.0)
    floor = (up > 0.7) & (tri[:, :, 1].max(axis=1) < float(floor_y) + height)
    if region is not None and not region.is_empty and floor.any():
        c = tri[floor].mean(axis=1)
        floor[np.flatnonzero(floor)[~shapely.contains_xy(region, c[:, 0], c[:, 2])]] = False
    if not floor.any():
        return []
    ys = tri[floor][:, :, 1]
    lo, hi = float(ys.min()), float(ys.max())
    if hi - lo <= FLOOR_TOLERANCE:
        return []
    top = tri[floor][np.argmax(ys.max(axis=1))].mean(axis=0)
    return [diag("A308", str(man.path), man.lines.key("", "floor_y"),
                 f"the floor's upward faces span y = {lo:.2f} .. {hi:.2f} m ({hi - lo:.2f} m, more than "
                 f"{FLOOR_TOLERANCE} m); highest near {fmt_xz((top[0], top[2]))}")]
