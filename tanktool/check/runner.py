"""Find what to check under the given paths, run the rules, collect one report.

A path may be an arena bundle, a vehicle bundle (the folder or its manifest), a bare
walls file, or a folder holding any of them at any depth.  Rules that relate arenas
and vehicles (clearance, passages, V401) see the bundles being checked plus the
bundled ones beside them: for ``X/arenas/<name>`` the vehicles in ``X/vehicles/``,
and the other way round.  An arena with no vehicle named or beside it is checked
against tanktool's bundled vehicles (and a vehicle with no arena, against the
bundled arenas), and the report's ``notes`` say so: an arena is never checked
against no vehicle at all without a word.
"""

from __future__ import annotations

import os
import traceback
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..formats.models import BUILT_EXTENSIONS, MESH_EXTENSIONS
from .arena_rules import ArenaInfo, VehicleSize, check_arena, check_walls_file
from .diagnostics import ERROR, WARNING, Diagnostic, diag
from .vehicle_rules import check_vehicle, vehicle_fit

ARENA_MANIFEST = "arena.toml"
VEHICLE_MANIFEST = "vehicle.toml"


@dataclass
class Report:
    files: list[str] = field(default_factory=list)
    diagnostics: list[Diagnostic] = field(default_factory=list)
    unreadable: list[str] = field(default_factory=list)   # one message per path that cannot be read
    #: what the rules were measured against, when the user did not say (one line each)
    notes: list[str] = field(default_factory=list)

    @property
    def errors(self) -> int:
        return sum(d.severity == ERROR for d in self.diagnostics)

    @property
    def warnings(self) -> int:
        return sum(d.severity == WARNING for d in self.diagnostics)

    def exit_code(self, strict: bool = False) -> int:
        if self.unreadable:
            return 2
        if self.errors or (strict and self.warnings):
            return 1
        return 0

    def summary(self) -> str:
        def n(k: int, word: str) -> str:
            return f"{k} {word}{'' if k == 1 else 's'}"
        unread = n(len(self.unreadable), "path")
        if self.unreadable and not self.files:  # "0 errors in 0 files" would contradict the errors above
            return f"nothing checked: {unread} could not be read"
        text = f"{n(self.errors, 'error')}, {n(self.warnings, 'warning')} in {n(len(self.files), 'file')}"
        return f"{text}; {unread} could not be read" if self.unreadable else text

    def to_dict(self) -> dict:
        return {"files": self.files,
                "diagnostics": [d.to_dict() for d in self.diagnostics],
                "notes": self.notes,
                "summary": {"errors": self.errors, "warnings": self.warnings}}


@dataclass
class Targets:
    arenas: list[Path] = field(default_factory=list)
    vehicles: list[Path] = field(default_factory=list)
    walls: list[Path] = field(default_factory=list)
    unreadable: list[str] = field(default_factory=list)

    def add(self, kind: str, p: Path) -> None:
        lst = getattr(self, kind)
        if p not in lst:
            lst.append(p)


#: model files: check reads bundles and walls files, not models
MODEL_SUFFIXES = MESH_EXTENSIONS | BUILT_EXTENSIONS


def _is_walls_file(p: Path) -> bool:
    return p.name == "walls.txt" or p.name.endswith(".walls.txt") or p.name.endswith("_walls.txt")


def _bundled_hint(p: Path) -> str:
    """For a bare name that is a bundled arena or vehicle (``check fort``): where it is."""
    if len(p.parts) != 1:
        return ""
    from ..content import bundled_dir

    for kind in ("arenas", "vehicles"):
        folder = bundled_dir(kind)
        if folder is not None and (folder / p.name).is_dir():
            return f" (the bundled {kind[:-1]} {p.name} is {folder / p.name}: give that path)"
    return ""


def discover(paths: list[Path]) -> Targets:
    t = Targets()
    for p in paths:
        if not p.exists():
            t.unreadable.append(f"{p}: no such file or folder{_bundled_hint(p)}")
        elif p.is_file():
            if not os.access(p, os.R_OK):
                t.unreadable.append(f"{p}: cannot be read (permission denied)")
            elif p.name == ARENA_MANIFEST:
                t.add("arenas", p.parent)
            elif p.name == VEHICLE_MANIFEST:
                t.add("vehicles", p.parent)
            elif p.suffix.lower() in MODEL_SUFFIXES:
                t.unreadable.append(f"{p} is a model: import it first with `tanktool import-arena {p}` "
                                    f"(or import-vehicle), then check the bundle")
            else:
                t.add("walls", p)  # any other file is taken as a wall list
        elif not os.access(p, os.R_OK | os.X_OK):
            t.unreadable.append(f"{p}: folder cannot be read (permission denied)")
        else:
            _walk(p, t)
    return t


def _walk(root: Path, t: Targets) -> None:
    """Bundles and walls files under ``root``; a bundle's own folder is not searched further."""
    def onerror(e: OSError) -> None:
        t.unreadable.append(f"{e.filename}: folder cannot be read ({e.strerror})")

    for here, dirs, files in os.walk(root, onerror=onerror):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))  # staged or hidden bundles
        d = Path(here)
        if ARENA_MANIFEST in files:
            t.add("arenas", d)
            dirs[:] = []
        elif VEHICLE_MANIFEST in files:
            t.add("vehicles", d)
            dirs[:] = []
        else:
            for f in sorted(files):
                if _is_walls_file(d / f):
                    t.add("walls", d / f)


def _shown(p: Path) -> Path:
    """``p`` relative to the working folder when it is inside it (for messages)."""
    try:
        return p.resolve().relative_to(Path.cwd().resolve())
    except (ValueError, OSError):
        return p


def _siblings(bundle: Path, kind: str, manifest: str) -> list[Path]:
    """Bundled ``kind`` ('arenas'/'vehicles') next to the collection holding ``bundle``."""
    folder = bundle.resolve().parent.parent / kind
    if not folder.is_dir():
        return []
    try:
        return sorted(_shown(p.parent) for p in folder.glob(f"*/{manifest}"))
    except OSError:
        return []


def _guard(report: Report, path: Path, fn, *args):
    """Run one bundle's rules; a crash becomes X001 (so check itself never crashes)."""
    try:
        return fn(*args)
    except OSError as e:
        report.unreadable.append(f"{e.filename or path}: cannot be read ({e.strerror or e})")
    except Exception as e:  # a bug in a rule: report it and go on with the other files
        where = traceback.extract_tb(e.__traceback__)[-1]
        report.diagnostics.append(diag("X001", str(path), 0,
                                       f"{type(e).__name__}: {e} (in {Path(where.filename).name}:{where.lineno})"))
    return None


def _bundled(kind: str) -> list[Path]:
    from ..content import bundled_paths

    return [_shown(p) for p in bundled_paths(kind)]


def _names(paths) -> str:
    return ", ".join(sorted(f"'{Path(p).name}'" for p in paths))


def _context(bundle: Path, kind: str, named: list[Path], lonely: list[Path]) -> list[Path]:
    """The ``kind`` bundles ("arenas"/"vehicles") that ``bundle`` meets besides the ones
    named: those beside it; when there are none and none of that kind were named,
    tanktool's bundled ones (and ``bundle`` joins ``lonely``, for the note)."""
    near = _siblings(bundle, kind, ARENA_MANIFEST if kind == "arenas" else VEHICLE_MANIFEST)
    if not named and not near:
        near = _bundled(kind)
        lonely.append(bundle)
    return near


def _consult(paths: list[Path], cache: dict, measure) -> set[Path]:
    """Keys of the bundles in ``paths`` that ``measure(path) -> (diagnostics, what)``
    can measure, filling ``cache`` (key -> what); their own diagnostics are not reported."""
    keys = set()
    for p in paths:
        key = p.resolve()
        if key not in cache:
            res = _guard(Report(), p, measure, p)
            if not res or not res[1]:
                continue
            cache[key] = res[1]
        keys.add(key)
    return keys


def _fallback_note(what: list[Path], kind: str, used: list[Path]) -> str:
    """The note saying that ``what`` (arenas or vehicles) met tanktool's bundled ``kind``."""
    one = "arena" if kind == "vehicles" else "vehicle"
    other = kind[:-1]
    subject = f"{one} {_names(what)}" if len(what) == 1 else f"{len(what)} {one}s"
    if not used:
        return (f"note: {subject} checked against no {other}: none named, none beside "
                f"{'it' if len(what) == 1 else 'them'}, none bundled (the rules that need a {other} were skipped)")
    return (f"note: {subject} checked against the bundled {kind} {_names(used)} in "
            f"{Path(used[0]).parent}/: no {other} named or beside {'it' if len(what) == 1 else 'them'} "
            f"(name {other} bundles to check against others)")


def _key_line(man_path: Path, message: str) -> int:
    """The manifest line of the key a loader's message names (``[hull] file``,
    ``'spawns'``, ``[walls]``), or 0."""
    import re

    from .manifest import Manifest

    try:
        lines = Manifest(man_path).lines
    except OSError:
        return 0
    for m in re.finditer(r"\[(\w+)\](?: (\w+))?", message):
        line = (m.group(2) and lines.key(m.group(1), m.group(2))) or lines.table(m.group(1)) \
            or lines.key("", m.group(1))
        if line:
            return line
    for m in re.finditer(r"'(\w+)'|\b(\w+) must\b", message):
        line = lines.key("", m.group(1) or m.group(2))
        if line:
            return line
    return 0


def play_rules(kind: str, bundle: Path) -> list[Diagnostic]:
    """B301: load the bundle the way ``play`` does (sim/match.py's loaders, the world,
    the files the game window reads: model.glb, quadtree.npz, navgrid.npz), so that
    anything that would stop ``play`` is an error here too."""
    from ..errors import TanktoolError

    manifest = bundle / (ARENA_MANIFEST if kind == "arenas" else VEHICLE_MANIFEST)
    try:
        _play_load(kind, bundle)
    except TanktoolError as e:
        msg = str(e)
        return [diag("B301", str(manifest), _key_line(manifest, msg), f"play cannot load this bundle: {msg}")]
    except (ValueError, TypeError, KeyError, IndexError, ArithmeticError) as e:
        return [diag("B301", str(manifest), 0, f"play would stop with an internal error: {type(e).__name__}: {e}")]
    return []


def _play_load(kind: str, bundle: Path) -> None:
    from ..formats.bundle import read_input
    from ..formats.gltf import read_gltf
    from ..sim.body import TankSpec
    from ..sim.match import load_match_arena, load_tank_spec
    from ..sim.world import World

    if kind == "arenas":
        from ..arena import load_arena
        from ..nav.navgrid import NavGrid
        from ..nav.quadtree import WallQuadtree

        info = load_match_arena(bundle)
        model = load_arena(bundle).file("model")
        model = model if model.name else bundle / "model.glb"
        if model.suffix.lower() == ".glb" and model.is_file():  # what the 3D view draws
            read_gltf(read_input(model, "a .glb model"), str(model))
        from ..formats.npz import read_npz

        for name, reader in (("quadtree.npz", WallQuadtree.load), ("navgrid.npz", NavGrid.load)):
            if (bundle / name).is_file():  # what the top view's overlays read
                read_npz(bundle / name, f"a {name} file")  # a damaged archive: one clear line
                reader(bundle / name)
        World(info.walls, [TankSpec.box("check")], info.spawns, bounds=info.bounds)  # a match needs a spawn
    else:
        spec = load_tank_spec(bundle)
        model = bundle / "model.glb"
        if model.is_file():
            read_gltf(read_input(model, "a .glb model"), str(model))
        World(np.array([[[0.0, 0.0], [100.0, 0.0]]]), [spec], [[50.0, 50.0, 0.0]],
              bounds=np.array([[0.0, 0.0], [100.0, 100.0]]))


def _with_play_rules(report: Report, kind: str, bundle: Path) -> None:
    """Add B301 for ``bundle`` unless its rules already found an error (which stops
    play as well and says more precisely what to fix)."""
    root = bundle.resolve()
    for d in report.diagnostics:
        if d.severity == ERROR and (Path(d.path).resolve() == root or root in Path(d.path).resolve().parents):
            return
    report.diagnostics += _guard(report, bundle, play_rules, kind, bundle) or []


def run_check(paths: list[str | os.PathLike]) -> Report:
    targets = discover([Path(p) for p in paths])
    report = Report(unreadable=list(targets.unreadable))
    lonely_arenas: list[Path] = []      # arenas that met the bundled vehicles (for the note)
    lonely_vehicles: list[Path] = []

    # vehicles first: their sizes feed the arena rules
    sizes: dict[Path, VehicleSize] = {}
    for v in targets.vehicles:
        report.files.append(str(v))
        res = _guard(report, v, check_vehicle, v)
        if res:
            report.diagnostics += res[0]
            if res[1]:
                sizes[v.resolve()] = res[1]
        _with_play_rules(report, "vehicles", v)
    checked_vehicles = set(sizes)
    infos: dict[Path, ArenaInfo] = {}
    for a in targets.arenas:
        report.files.append(str(a))
        # each arena meets the vehicles being checked and the bundled ones beside it
        near = _context(a, "vehicles", targets.vehicles, lonely_arenas)
        mine = checked_vehicles | _consult(near, sizes, lambda v: check_vehicle(v, False))  # only its size
        res = _guard(report, a, check_arena, a, [sizes[k] for k in sorted(mine, key=str)])
        if res:
            report.diagnostics += res[0]
            infos[a.resolve()] = res[1]
        _with_play_rules(report, "arenas", a)
    for w in targets.walls:
        report.files.append(str(w))
        res = _guard(report, w, check_walls_file, w)
        if res:
            report.diagnostics += res

    if targets.vehicles:
        # each vehicle meets the arenas being checked and the bundled ones beside it
        checked = set(infos)
        for v in targets.vehicles:
            size = sizes.get(v.resolve())
            if size is None:
                continue
            near = _context(v, "arenas", targets.arenas, lonely_vehicles)
            mine = checked | _consult(near, infos, lambda a: check_arena(a, [], False))
            for key in sorted(mine, key=str):
                res = _guard(report, v, vehicle_fit, size, infos[key])
                if res:
                    report.diagnostics += res
    if lonely_arenas:
        report.notes.append(_fallback_note(lonely_arenas, "vehicles", _bundled("vehicles")))
    if lonely_vehicles:
        report.notes.append(_fallback_note(lonely_vehicles, "arenas", _bundled("arenas")))
    # a compiler's order: file by file, top to bottom (stable, so rules keep their order on a line)
    report.diagnostics.sort(key=lambda d: (d.path, d.line))
    return report
