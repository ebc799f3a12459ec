"""Rules on arena bundles: the manifest and its files, the walls, the spawn points and
the free space they stand in (A3xx), and the floor of the model.

The free space holding the spawn points is the set of faces (see
:mod:`tanktool.check.freespace`) the spawns fall in.  Clearance, reachability and
passages are measured with one disc: the footprint radius of the largest vehicle
known (the bundled vehicles beside the arena, or those being checked with it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import shapely

from ..formats.walls_txt import WallList
from .diagnostics import Diagnostic, diag, fmt_xz
from .freespace import UNBOUNDED, FreeSpace, analyse
from .manifest import Manifest, file_rules, safe_file
from .walls_rules import bare_walls_leaks, check_walls, leak_diagnostics
from .walls_scan import scan_walls_file

MIN_SPAWNS = 8
FLOOR_TOLERANCE = 0.05     # m: floor faces may differ this much in height (modelling noise)
ISLAND_MIN_AREA = 0.01     # m^2: smaller faces are slivers of the wall drawing, not places


@dataclass
class VehicleSize:
    name: str
    radius: float            # footprint radius, m
    path: str = ""           # its vehicle.toml, where V401 points
    line: int = 0


@dataclass
class ArenaInfo:
    """What the vehicle rules need from a checked arena."""

    path: Path
    name: str
    fs: FreeSpace | None = None
    spawns: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    good: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))  # spawns in free space
    faces: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


# ----------------------------------------------------------------- bare walls.txt
def check_walls_file(path: Path) -> list[Diagnostic]:
    """A bare walls.txt: syntax, wall geometry, normals, leaks of the normals' free space."""
    walls, out = scan_walls_file(path)
    fs = analyse(walls)
    return out + check_walls(walls, fs, str(path)) + bare_walls_leaks(fs, str(path))


# ----------------------------------------------------------------- arena bundles
def _spawns(man: Manifest, out: list[Diagnostic]) -> tuple[np.ndarray, list[int]]:
    raw = man.get("", "spawns")
    if raw is None:
        out.append(man.missing("", "spawns", "is missing (a list of [x, z, heading_rad])"))
        return np.zeros((0, 3)), []
    if not isinstance(raw, list):
        out.append(man.missing("", "spawns", f"must be a list of [x, z, heading_rad], got {raw!r}"))
        return np.zeros((0, 3)), []
    lines = man.lines.items("", "spawns", len(raw))
    rows, keep = [], []
    for i, s in enumerate(raw):
        ok = (isinstance(s, list) and len(s) == 3
              and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in s))
        if not ok:
            out.append(diag("B102", str(man.path), lines[i],
                            f"spawn {i} must be [x, z, heading_rad] with 3 finite numbers, got {s!r}"))
            continue
        rows.append([float(v) for v in s])
        keep.append(lines[i])
    return np.array(rows, dtype=np.float64).reshape(-1, 3), keep


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
    out += file_rules(man, bundle, ("walls.txt",))

    spawns, spawn_lines = _spawns(man, out)
    info.spawns = spawns
    wname = man.string("walls", "file", out, default="walls.txt")
    wpath = safe_file(bundle, wname) if wname else None
    if wpath is None or not wpath.is_file():
        if wname and not any(d.code == "B202" and repr(wname) in d.message for d in out):
            out.append(diag("B202", str(man.path), man.lines.key("walls", "file"), f"walls file {wname!r} is missing"))
    else:
        walls, syntax = scan_walls_file(wpath)
        fs = analyse(walls)
        info.fs = fs
        apply_spawn_vote(fs, spawns)
        out += syntax + check_walls(walls, fs, str(wpath))
        out += spawn_rules(fs, spawns, spawn_lines, man, str(wpath), vehicles, info)
    if len(spawns) < MIN_SPAWNS and man.get("", "spawns") is not None:
        out.append(diag("A305", str(man.path), man.lines.key("", "spawns"),
                        f"{len(spawns)} spawn points; a full match needs {MIN_SPAWNS}"))
    if model_rules:
        out += floor_rules(man, bundle)
    return out, info


def _largest(vehicles: list[VehicleSize]) -> VehicleSize | None:
    return max(vehicles, key=lambda v: v.radius) if vehicles else None


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

    good = np.zeros(k, dtype=bool)
    leaking = False
    dist, wall = fs.nearest_wall(xz)
    for i in range(k):
        f = int(face[i])
        if f == UNBOUNDED and len(fs.dangling):
            leaking = True
            continue
        if f == UNBOUNDED:
            out.append(diag("A302", mpath, lines[i], f"spawn {i} at {fmt_xz(xz[i])} is outside the arena's walls"))
        elif not fs.free[f]:
            out.append(diag("A302", mpath, lines[i], f"spawn {i} at {fmt_xz(xz[i])} is inside solid material"))
        elif dist[i] <= 4 * fs.grid:
            out.append(diag("A302", mpath, lines[i],
                            f"spawn {i} at {fmt_xz(xz[i])} is on the wall at {wpath}:{_wl(walls, wall[i])}"))
        else:
            good[i] = True
    if leaking:
        out += leak_diagnostics(fs, wpath, "the free space holding the spawn points")
    info.good = good

    big = _largest(vehicles)
    radius = big.radius if big else 0.0
    if big:
        for i in np.flatnonzero(good & (dist < radius)):
            out.append(diag("A303", mpath, lines[i],
                            f"spawn {i} at {fmt_xz(xz[i])} is {dist[i]:.2f} m from the wall at "
                            f"{wpath}:{_wl(walls, wall[i])}; vehicle {big.name!r} needs {radius:.2f} m"))
        placed = good & (dist >= radius)
    else:
        placed = good

    out += reachability(fs, xz, face, placed, lines, mpath, radius, big)
    if big:
        out += narrow_passages(fs, np.unique(face[good]), big, wpath)
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
                 mpath: str, radius: float, big: VehicleSize | None) -> list[Diagnostic]:
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
                        f"spawn {i} at {fmt_xz(xz[i])} cannot be reached from spawn {first}: {why}"))
    return out


def narrow_passages(fs: FreeSpace, face_ids, big: VehicleSize, wpath: str, code: str = "A306",
                    where: str | None = None) -> list[Diagnostic]:
    """Places where the free space of one face falls apart for a disc of the vehicle's radius."""
    out = []
    for f in face_ids:
        if f < 0:
            continue
        parts = components(fs, [f], big.radius)
        if len(parts) < 2:
            continue
        parts.sort(key=lambda p: -p.area)
        for p in parts[1:20]:
            others = shapely.union_all([q for q in parts if q is not p])
            line = shapely.shortest_line(p, others)
            c = np.asarray(line.coords, dtype=np.float64)
            width, mid = fs.passage(c.mean(axis=0), 2.0 * big.radius)
            _, w = fs.nearest_wall(mid[None])
            msg = (f"a passage about {width:.2f} m wide at {fmt_xz(mid)} is narrower than vehicle "
                   f"{big.name!r} ({2 * big.radius:.2f} m across)")
            if code == "A306":
                out.append(diag("A306", wpath, _wl(fs.walls, int(w[0])), msg))
            else:
                out.append(diag(code, where or big.path, big.line, f"{msg} in arena {wpath}"))
    return out


def islands(fs: FreeSpace, spawn_faces: set[int], wpath: str) -> list[Diagnostic]:
    if not spawn_faces:
        return []
    out = []
    for f in np.flatnonzero(fs.free):
        if int(f) in spawn_faces or fs.faces[f].area < ISLAND_MIN_AREA:
            continue
        walls_of = np.flatnonzero(fs.front == f)
        line = _wl(fs.walls, int(walls_of[0])) if len(walls_of) else 0
        p = shapely.point_on_surface(fs.faces[f])
        out.append(diag("A307", wpath, line,
                        f"free space of {fs.faces[f].area:.2f} m^2 around {fmt_xz((p.x, p.y))} "
                        "cannot be reached from the spawn points"))
    return out


# ----------------------------------------------------------------- the floor
def floor_rules(man: Manifest, bundle: Path) -> list[Diagnostic]:
    """A308: upward faces below the wall slice height (what tanks drive on) at one height."""
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
    from ..formats.models import load_model

    try:
        mesh = load_model(mpath, up="y", scale=1.0)
    except FormatError as e:
        return [diag("B201", str(man.path), man.lines.key("model", "file"), f"model file cannot be read: {e}")]
    v = np.asarray(mesh.vertices, dtype=np.float64)
    tri = v[np.asarray(mesh.faces, dtype=np.int64)]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    nl = np.linalg.norm(n, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        up = np.where(nl > 0, n[:, 1] / nl, 0.0)
    floor = (up > 0.7) & (tri[:, :, 1].max(axis=1) < float(floor_y) + height)
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
