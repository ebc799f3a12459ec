"""Rules on vehicle bundles: hull points, sphere tree, mass and drive figures, posture
and size, and whether the vehicle fits the bundled arenas.

hull.txt and spheres.txt are scanned line by line with the same field rules as
:mod:`tanktool.formats.vehicle_bundle` and :mod:`tanktool.geometry.spheres`, so every
bad line is reported, not only the first.  The geometric rules use the vertices of
the bundle's model (``model.glb``, already in the vehicle frame) and, for the sphere
tree, points sampled over its surface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import numpy as np

from ..formats.bundle import data_lines
from ..formats.vehicle_bundle import DRIVE_KEYS, HULL_MAX, HULL_MIN
from ..geometry.hull import convex_hull_2d, points_in_prism
from ..geometry.spheres import SphereTree
from .arena_rules import ArenaInfo, VehicleSize, blocked_spawns, narrow_passages
from .diagnostics import Diagnostic, diag, fmt_xz
from .manifest import Manifest, file_rules, safe_file

#: hull.txt and spheres.txt hold 4 decimals; the tools round so the written shapes still
#: enclose, float32 storage in model.glb adds ~1e-7 relative: 0.2 mm covers both
GEOM_TOL = 2e-4
#: m: hull points and spheres farther out than this are typos, not vehicles
MAX_SIZE = 1000.0
#: points sampled over the model's surface for V202/V203 (0.005 % of the surface each
#: for 20,000), and the seed that makes them the same every run
SURFACE_SAMPLES = 20_000
SURFACE_SEED = 2002


def _data_lines(path: Path) -> Iterator[tuple[int, str, list[str]]]:
    """(line number, text without its comment, fields) of each line of ``path`` that
    holds data (undecodable bytes read as U+FFFD, so such a line is a bad one)."""
    yield from data_lines(path.read_bytes().decode("utf-8", errors="replace"))


def scan_hull(path: Path) -> tuple[np.ndarray, list[Diagnostic]]:
    out: list[Diagnostic] = []
    rows: list[list[float]] = []
    for no, line, parts in _data_lines(path):
        try:
            xyz = [float(p) for p in parts]
        except ValueError:
            xyz = []
        if len(parts) != 3 or len(xyz) != 3:
            out.append(diag("V101", str(path), no, f"expected 3 numbers 'x y z', got {line!r}"))
            continue
        if not all(math.isfinite(c) for c in xyz):
            out.append(diag("V101", str(path), no, f"coordinates must be finite numbers, got {line!r}"))
            continue
        if max(abs(c) for c in xyz) > MAX_SIZE:
            out.append(diag("V101", str(path), no, f"a point beyond +-{MAX_SIZE:g} m: {line!r}",
                            "check the number: hull points are in metres, vehicle frame"))
            continue
        rows.append(xyz)
    if not HULL_MIN <= len(rows) <= HULL_MAX and not out:
        out.append(diag("V102", str(path), 0, f"{len(rows)} hull points; expected {HULL_MIN} to {HULL_MAX}"))
    return np.array(rows, dtype=np.float64).reshape(-1, 3), out


def scan_spheres(path: Path) -> tuple[SphereTree | None, np.ndarray, list[Diagnostic]]:
    """The sphere tree (None when any line is bad), each sphere's line, diagnostics."""
    out: list[Diagnostic] = []
    rows: list[tuple[int, int, int, float, float, float, float]] = []
    lines: list[int] = []
    for no, line, parts in _data_lines(path):
        where = (str(path), no)
        n = len(rows)
        try:
            if len(parts) != 7:
                raise ValueError(f"expected 7 fields 'id parent level cx cy cz r', got {len(parts)}")
            sid, par, lev = int(parts[0]), int(parts[1]), int(parts[2])
            cx, cy, cz, r = (float(v) for v in parts[3:])
        except ValueError as e:
            msg = str(e) if str(e).startswith("expected 7") else \
                f"expected integers id parent level then 4 numbers, got {line!r}"
            out.append(diag("V201", *where, msg))
            # the line was meant to be sphere n: keep its place so later ids still line up
            rows.append((n, -2, -1, math.nan, math.nan, math.nan, math.nan))
            lines.append(no)
            continue
        problem = None
        if not all(math.isfinite(v) for v in (cx, cy, cz, r)):
            problem = "centre and radius must be finite numbers"
        elif r < 0:
            problem = f"radius must not be negative, got {r:g}"
        elif max(abs(cx), abs(cy), abs(cz), r) > MAX_SIZE:
            problem = f"centre or radius beyond {MAX_SIZE:g} m: a vehicle is not that big"
        elif sid != n:
            problem = f"expected sphere id {n} (ids count up from 0), got {sid}"
        elif n == 0 and (par != -1 or lev != 1):
            problem = "the first sphere must be the root (parent -1, level 1)"
        elif n > 0 and not 0 <= par < n:
            problem = f"parent {par} must be an earlier sphere id (0..{n - 1})"
        elif n > 0 and rows[par][2] >= 1 and lev != rows[par][2] + 1:
            problem = f"level {lev} must be one more than its parent's ({rows[par][2]})"
        if problem:
            out.append(diag("V201", *where, problem))
        rows.append((n, par, lev, cx, cy, cz, r))
        lines.append(no)
    if not rows and not out:
        out.append(diag("V201", str(path), 0, "no spheres (expected at least the root line)"))
    if out or not rows:
        return None, np.array(lines), out
    arr = np.array(rows, dtype=np.float64)
    tree = SphereTree(arr[:, 3:6], arr[:, 6], arr[:, 1].astype(np.int64), arr[:, 2].astype(np.int64))
    return tree, np.array(lines), out


def sphere_rules(tree: SphereTree, lines: np.ndarray, vertices: np.ndarray, path: str,
                 surface: np.ndarray | None = None) -> list[Diagnostic]:
    """V202: every vertex, and every point sampled over the surface, in some leaf;
    V203: in every ancestor of a leaf holding it.

    The vertices alone are not enough: a triangle whose corners lie in two leaves can
    bulge out between them.  ``surface`` is (m, 3) points spread over the triangles by
    area (:func:`surface_points`), so the share of them outside is the share of the
    surface outside.  Points are tested a block at a time, so memory stays bounded
    whatever the tree's size.
    """
    v = vertices if surface is None else np.vstack([vertices, surface])
    nv, ns = len(vertices), 0 if surface is None else len(surface)
    leaves = tree.leaves()
    chains = [tree.ancestors(int(leaf)) for leaf in leaves]
    lost_v = lost_s = 0
    worst: tuple[float, np.ndarray] | None = None       # (outside by, point)
    culprits: dict[int, list[int]] = {}
    block = max(1, 2_000_000 // max(len(tree), 1))
    for start in range(0, len(v), block):
        p = v[start:start + block]
        inside = np.empty((len(p), len(tree)), dtype=bool)
        for s in range(len(tree)):
            inside[:, s] = np.sum((p - tree.centers[s]) ** 2, axis=1) <= (tree.radii[s] + GEOM_TOL) ** 2
        in_leaf = inside[:, leaves].any(axis=1)
        in_chain = np.zeros(len(p), dtype=bool)
        for chain in chains:
            in_chain |= inside[:, chain].all(axis=1)
        lost = np.flatnonzero(~in_leaf)
        if len(lost):
            is_vertex = start + lost < nv
            lost_v += int(is_vertex.sum())
            lost_s += int((~is_vertex).sum())
            q = p[lost]
            by = np.min(np.sqrt(((q[:, None, :] - tree.centers[leaves][None]) ** 2).sum(axis=2))
                        - tree.radii[leaves][None], axis=1)
            k = int(np.argmax(by))
            if worst is None or by[k] > worst[0]:
                worst = (float(by[k]), q[k])
        # points some leaf holds but whose every chain breaks: name the parent that lets go
        for i in np.flatnonzero(in_leaf & ~in_chain):
            for leaf, chain in zip(leaves, chains):
                if inside[i, leaf]:
                    miss = [a for a in chain if not inside[i, a]]
                    culprits.setdefault(int(miss[0]), []).append(int(leaf))
                    break
    out = []
    if worst is not None:
        by, pt = worst
        # name the leaf whose centre is nearest: the one that most likely should hold it
        dc = np.sqrt(np.sum((tree.centers[leaves] - pt) ** 2, axis=1))
        near = int(leaves[int(np.argmin(dc))])
        what = []
        if lost_v:
            what.append(f"{lost_v} of {nv} model vertices")
        if lost_s:
            what.append(f"about {100.0 * lost_s / ns:.2g} % of the model's surface ({lost_s} of {ns} points "
                        "sampled over it)")
        out.append(diag("V202", path, int(lines[near]),
                        f"{' and '.join(what)} {'is' if not lost_v else 'are'} in no leaf sphere; the farthest, "
                        f"({pt[0]:.3f}, {pt[1]:.3f}, {pt[2]:.3f}), is {by:.3f} m outside, nearest leaf {near}"))
    for parent, kids in sorted(culprits.items()):
        out.append(diag("V203", path, int(lines[parent]),
                        f"sphere {parent} does not enclose the part of the model in its descendant leaf "
                        f"{kids[0]} ({len(kids)} points of the model outside it)"))
    return out


def surface_points(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(SURFACE_SAMPLES, 3) points spread over the model's triangles by area, the same
    ones every run (a fixed seed, not the one the sphere tree was built with)."""
    from ..geometry.sphere_build import surface_samples

    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    f = f[((f >= 0) & (f < len(v))).all(axis=1)]   # a damaged model's stray indices name nothing
    return surface_samples(v, f, SURFACE_SAMPLES, seed=SURFACE_SEED)


def proportion_rules(hull: np.ndarray, man: Manifest) -> list[Diagnostic]:
    """V105 on its side, V106 facing sideways, V107 an absurd size, from the hull (which
    encloses the model): the same tests import-vehicle warns with."""
    from ..geometry.proportions import on_its_side, proportions, sideways, size_problem

    mpath = str(man.path)
    p = proportions(hull)
    up = man.get("source", "up")
    out = []
    why = on_its_side(p, "the vehicle")
    if why:
        other = {"y": "z", "z": "y"}.get(up) if isinstance(up, str) else None
        hint = f"re-import it with --up {other}: it was imported with --up {up}" if other else None
        out.append(diag("V105", mpath, man.lines.key("source", "up"), why, hint))
    why = sideways(p, "the vehicle")
    if why:
        key = "forward" if man.get("source", "forward") is not None else "up"
        line = man.lines.key("source", key)
        out.append(diag("V106", mpath, line, why))
    why = size_problem(p, "the vehicle")
    if why:
        out.append(diag("V107", mpath, man.lines.key("", "footprint_radius"), why))
    return out


def _why_drive(key: str, v: float, mass: float | None) -> tuple[str, str] | None:
    """(code, why) when a [drive] value is impossible (V302) or implausible (V303)."""
    if key in ("engine_force", "turn_torque", "strafe_force") and v < 0:
        return "V302", "a negative force or torque drives the tank backwards from the controls"
    if key == "friction" and v < 0:
        return "V302", "negative drag would speed the tank up by itself"
    if key == "restitution" and not 0 <= v <= 1:
        return "V302", "restitution must be in [0, 1]: above 1 a collision creates energy, below 0 is meaningless"
    if key == "top_speed" and v <= 0:
        return "V302", "the tank could not move"
    if key == "top_speed" and v > 50:
        return "V303", "over 50 m/s (180 km/h) is unrealistic: real tanks top out near 20 m/s"
    if key == "fire_interval" and v <= 0:
        return "V302", "the interval between shots must be positive"
    if key == "fire_interval" and v < 0.1:
        return "V303", "more than 10 shots a second: no tank gun reloads that fast"
    if key == "shell_speed" and v <= 0:
        return "V302", "shells must leave the barrel"
    if key == "shell_speed" and v > 2000:
        return "V303", "faster than any tank gun (about 1,800 m/s)"
    if key == "hit_points" and v < 1:
        return "V302", "a vehicle with no hit points is destroyed before it is hit"
    if key == "engine_force" and mass and v / mass > 20:
        return "V303", f"{v / mass:.0f} m/s^2 of acceleration is over 2 g"
    return None


def check_vehicle(bundle: Path, model_rules: bool = True) -> tuple[list[Diagnostic], VehicleSize | None]:
    """Every vehicle rule on ``bundle`` and the vehicle's size; ``model_rules=False``
    skips loading the model (for vehicles consulted only for their size)."""
    man = Manifest(bundle / "vehicle.toml")
    out = list(man.diagnostics)
    if man.doc is None:
        return out, None
    mpath = str(man.path)
    name = man.get("", "name")
    name = name if isinstance(name, str) and name else bundle.name
    out += file_rules(man, bundle, ("hull.txt", "spheres.txt"))
    mass, inertia, com = _mass_rules(man, out)
    _drive_rules(man, mass, out)
    shapes = _Shapes.read(man, bundle, out)
    hull = shapes.hull
    if hull is not None and com is not None and inertia is not None and mass is not None and mass > 0 and inertia > 0:
        _inertia_rules(man, hull, com, mass, inertia, out)
    model = man.get("model", "file")
    mfile = safe_file(bundle, model) if isinstance(model, str) and model else None
    if model_rules and mfile is not None and mfile.is_file() and (hull is not None or shapes.tree is not None):
        _model_rules(man, mfile, shapes, out)
    if hull is not None:
        return out, VehicleSize(name, float(np.max(np.hypot(hull[:, 0], hull[:, 2]))), mpath,
                                man.lines.key("", "footprint_radius") or man.lines.key("hull", "file"),
                                footprint=convex_hull_2d(hull[:, [0, 2]]), height=float(np.ptp(hull[:, 1])))
    r = man.get("", "footprint_radius")
    if isinstance(r, (int, float)) and not isinstance(r, bool) and math.isfinite(r) and r > 0:
        return out, VehicleSize(name, float(r), mpath, man.lines.key("", "footprint_radius"))
    return out, None


def _mass_rules(man: Manifest, out: list[Diagnostic]) -> tuple[float | None, float | None, list | None]:
    """[mass]: mass and inertia positive, a plausible mass, the centre of mass 3 finite
    numbers; returns (mass, inertia, centre of mass), None for what is unusable."""
    mpath = str(man.path)
    mass = man.number("mass", "mass", out)
    inertia = man.number("mass", "inertia", out)
    for key, val in (("mass", mass), ("inertia", inertia)):
        if val is not None and val <= 0:
            out.append(diag("V301", mpath, man.lines.key("mass", key),
                            f"[mass] {key} = {val:g} must be positive"))
    if mass is not None and mass > 0:
        from ..geometry.proportions import mass_problem

        why = mass_problem(mass)
        if why:
            out.append(diag("V303", mpath, man.lines.key("mass", "mass"), f"[mass] mass = {mass:g} kg: {why}"))
    com = man.get("mass", "centre_of_mass")
    if not (isinstance(com, list) and len(com) == 3
            and all(isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c) for c in com)):
        out.append(man.missing("mass", "centre_of_mass", f"must be 3 finite numbers [x, y, z], got {com!r}"))
        com = None
    return mass, inertia, com


def _drive_rules(man: Manifest, mass: float | None, out: list[Diagnostic]) -> None:
    """[drive]: present, each figure plausible, shells faster than the tank."""
    mpath = str(man.path)
    if man.table("drive") is None:
        out.append(diag("B102", mpath, 0, "table [drive] is missing"))
        return
    for key in DRIVE_KEYS:
        val = man.number("drive", key, out)
        if val is None:
            continue
        why = _why_drive(key, val, mass if mass and mass > 0 else None)
        if why:
            out.append(diag(why[0], mpath, man.lines.key("drive", key), f"[drive] {key} = {val:g}: {why[1]}"))
    top, shell = man.get("drive", "top_speed"), man.get("drive", "shell_speed")
    if (isinstance(top, (int, float)) and isinstance(shell, (int, float)) and 0 < shell <= top):
        out.append(diag("V303", mpath, man.lines.key("drive", "shell_speed"),
                        f"[drive] shell_speed = {shell:g} m/s is not faster than top_speed = {top:g} m/s: "
                        "the tank would drive into its own shells"))


@dataclass
class _Shapes:
    """The hull and the sphere tree of a bundle, when their files read without fault."""

    hull: np.ndarray | None = None
    hull_path: Path | None = None
    tree: SphereTree | None = None
    sphere_lines: np.ndarray | None = None
    spheres_path: Path | None = None

    @classmethod
    def read(cls, man: Manifest, bundle: Path, out: list[Diagnostic]) -> "_Shapes":
        """Scan hull.txt (and its proportions) and spheres.txt, naming missing ones."""

        def named(table: str, default: str) -> Path | None:
            file = man.string(table, "file", out, default=default)
            path = safe_file(bundle, file) if file else None
            if file and (path is None or not path.is_file()) and not any(
                    d.code == "B202" and repr(file) in d.message for d in out):
                out.append(diag("B202", str(man.path), man.lines.key(table, "file"),
                                f"derived file {file!r} is missing"))
            return path if path is not None and path.is_file() else None

        shapes = cls()
        shapes.hull_path = named("hull", "hull.txt")
        if shapes.hull_path is not None:
            pts, hd = scan_hull(shapes.hull_path)
            out += hd
            if not hd:
                shapes.hull = pts
                out += proportion_rules(pts, man)
        shapes.spheres_path = named("spheres", "spheres.txt")
        if shapes.spheres_path is not None:
            shapes.tree, shapes.sphere_lines, sd = scan_spheres(shapes.spheres_path)
            out += sd
        return shapes


def _inertia_rules(man: Manifest, hull: np.ndarray, com: list, mass: float, inertia: float,
                   out: list[Diagnostic]) -> None:
    """The centre of mass inside the hull, and no more inertia than all the mass on its rim."""
    mpath = str(man.path)
    with np.errstate(all="ignore"):  # a degenerate hull (repeated corners) makes 0/0: outside
        com_inside = points_in_prism(hull, np.array([com], dtype=np.float64), tol=GEOM_TOL)[0]
    if not com_inside:
        out.append(diag("V104", mpath, man.lines.key("mass", "centre_of_mass"),
                        f"centre of mass ({com[0]:g}, {com[1]:g}, {com[2]:g}) is outside the hull"))
        return
    # no body has more inertia than with all its mass on the hull's farthest rim
    with np.errstate(all="ignore"):  # absurd figures overflow to inf, and are then reported
        r2 = float(np.max((hull[:, 0] - com[0]) ** 2 + (hull[:, 2] - com[2]) ** 2))
        too_much = inertia > mass * r2 * (1 + 1e-6)
    if too_much:
        out.append(diag("V302", mpath, man.lines.key("mass", "inertia"),
                        f"[mass] inertia = {inertia:g} kg m^2 is more than the {mass * r2:.4g} kg m^2 "
                        "of all the mass on the hull's rim: impossible"))


def _model_rules(man: Manifest, mfile: Path, shapes: _Shapes, out: list[Diagnostic]) -> None:
    """The model inside the hull (V103) and inside the spheres (sphere_rules)."""
    from ..errors import FormatError
    from .glb import load_triangles

    try:
        verts, faces = load_triangles(mfile)
    except FormatError as e:
        out.append(diag("B201", str(man.path), man.lines.key("model", "file"), f"model file cannot be read: {e}"))
        return
    v = np.unique(verts, axis=0)
    if shapes.hull is not None:
        with np.errstate(all="ignore"):
            outside = np.flatnonzero(~points_in_prism(shapes.hull, v, tol=GEOM_TOL))
        if len(outside):
            p = v[outside[0]]
            out.append(diag("V103", str(shapes.hull_path), 0,
                            f"{len(outside)} of {len(v)} model vertices are outside the hull, e.g. "
                            f"({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f})"))
    if shapes.tree is not None:
        out += sphere_rules(shapes.tree, shapes.sphere_lines, v, str(shapes.spheres_path),
                            surface_points(verts, faces))


def vehicle_fit(size: VehicleSize, arena: ArenaInfo) -> list[Diagnostic]:
    """V401: the vehicle does not fit at a spawn point or through a passage of ``arena``
    (one diagnostic per arena, naming the worst place)."""
    fs = arena.fs
    if fs is None or not arena.good.any():
        return []
    out = []
    where = f"arena {arena.name!r} ({arena.path})"
    blocked = blocked_spawns(fs, arena.spawns, arena.good, size)
    if blocked:
        i = blocked[0]
        more = f" and {len(blocked) - 1} more" if len(blocked) > 1 else ""
        out.append(diag("V401", size.path, size.line,
                        f"vehicle {size.name!r} placed at spawn {arena.ids[i] if i < len(arena.ids) else i} {fmt_xz(arena.spawns[i, :2])}{more} of {where} "
                        "touches a wall"))
    passages = narrow_passages(fs, np.unique(arena.faces[arena.good]), size)
    if passages:
        width, mid, _ = passages[0]
        n = len(passages)
        out.append(diag("V401", size.path, size.line,
                        f"vehicle {size.name!r} ({size.width:.2f} m wide) does not fit through "
                        f"{n} passage{'s' if n > 1 else ''} of {where}; the narrowest is about {width:.2f} m "
                        f"wide at {fmt_xz(mid)}"))
    return out
