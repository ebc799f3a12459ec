"""No silent fallback (issue 25): an arena bundle whose derived files are missing or
stale is rebuilt before a match uses it, or refused with the command that fixes it.

What a match reads of a bundle -- ``walls.txt``, ``model.glb``, ``navgrid.npz``,
``quadtree.npz`` -- must be there and have the sha256 its ``arena.toml`` records in
``[derived]`` (a bundle import-arena made, one with ``[source]`` and ``[walkable]``, must have its grid:
without it the match would run as if the arena were flat).  :func:`problems` says
what is wrong; :func:`ensure_fresh` mends it where it can:

* only the navigation files wrong: they are rebuilt as ``build-navgrid`` would with
  the settings the manifest records (cell, clearance, quadtree depth), swapped into
  the bundle with the manifest in one atomic exchange;
* a missing walls.txt or model.glb: the bundle is imported again from its source
  model with the recorded parameters (staged and swapped in: one step);
* a walls.txt or model.glb that is there but not what was imported: refused, never
  overwritten (someone edited it; re-importing would throw their work away).

Where it cannot (a read-only folder, the source model gone or changed, an edit), it
raises ArenaError: one line naming the command that fixes it.
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path
from typing import Any, Callable

from .errors import ArenaError
from .formats.vehicle_grids import is_grid_file

#: the navigation files: build-navgrid rebuilds them (and the smaller vehicles' navgrid.<vehicle>.npz)
GRID_FILES = ("navgrid.npz", "quadtree.npz")
#: the other files a match reads: import-arena makes them
MODEL_FILES = ("walls.txt", "model.glb")


def problems(folder: Path, doc: dict[str, Any]) -> dict[str, str]:
    """{file: "missing" | "stale"} for the files a match reads of the bundle."""
    from .formats.bundle import sha256_file

    derived = doc.get("derived") if isinstance(doc.get("derived"), dict) else {}
    # a bundle import-arena made: its [source] and the [walkable] surface it found
    imported = isinstance(doc.get("source"), dict) and isinstance(doc.get("walkable"), dict)
    out: dict[str, str] = {}
    for name in MODEL_FILES + GRID_FILES + _vehicle_files(folder, doc):
        path = folder / name
        if name not in derived:
            # a hand-made bundle (walls.txt only) has no grid to miss; an imported one must
            if imported and (name == "walls.txt" or is_grid_file(name) and name != "quadtree.npz") \
                    and not path.is_file():
                out[name] = "missing"
            continue
        if not path.is_file():
            out[name] = "missing"
        elif sha256_file(path) != derived[name]:
            out[name] = "stale"
    return out


def _vehicle_files(folder: Path, doc: dict[str, Any]) -> tuple[str, ...]:
    """The smaller vehicles' grid files, navgrid.<vehicle>.npz of [grids.<vehicle>]."""
    from .formats.vehicle_grids import vehicle_file, vehicle_grids

    return tuple(str(vehicle_file(n)) for n in vehicle_grids(doc, folder / "arena.toml"))


def _say_files(bad: dict[str, str]) -> str:
    parts = [f"{n} {w}" for n, w in bad.items()]
    return ", ".join(parts)


def _number(v: Any) -> float | None:
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) else None


def _import_command(folder: Path, doc: dict[str, Any]) -> str:
    src = doc.get("source", {})
    cmd = f"tanktool import-arena {folder / str(src.get('file', 'MODEL'))} -o {folder} --force"
    if src.get("up"):
        cmd += f" --up {src['up']}"
    if _number(src.get("scale")) not in (None, 1.0):
        cmd += f" --scale {src['scale']:g}"
    return cmd


def _writable(folder: Path) -> bool:
    return os.access(folder, os.W_OK) and os.access(folder.parent, os.W_OK)


def _source_ok(folder: Path, doc: dict[str, Any]) -> bool:
    from .formats.bundle import sha256_file

    src = doc.get("source")
    if not isinstance(src, dict) or not isinstance(src.get("file"), str):
        return False
    path = folder / src["file"]
    return path.is_file() and sha256_file(path) == src.get("sha256")


def rebuild_grid(folder: Path, doc: dict[str, Any]) -> None:
    """The navigation files again, with the manifest's settings, swapped in atomically."""
    from .formats.bundle import atomic_write_text, dumps_toml
    from .formats.bundle_swap import bundle_update
    from .grid_files import build_grid, open_target, picture_and_grids, stage_grid_files

    nav = doc.get("navgrid") if isinstance(doc.get("navgrid"), dict) else {}
    derived = doc.get("derived") if isinstance(doc.get("derived"), dict) else {}
    # the clearance a grid was built with, when there was one (else the default's)
    clearance = _number(nav.get("clearance")) if "navgrid.npz" in derived else None
    target = open_target(folder)
    built = build_grid(target, clearance=clearance)
    picture, packed = picture_and_grids(built, target)
    with bundle_update(folder) as stage:
        atomic_write_text(stage / "arena.toml", dumps_toml(stage_grid_files(stage, target, built, picture, packed)))


def reimport(folder: Path, doc: dict[str, Any]) -> None:
    """The bundle imported again from its source with the recorded parameters."""
    from .importer import import_arena

    src, walls = doc["source"], doc.get("walls", {}) if isinstance(doc.get("walls"), dict) else {}
    import_arena(folder / src["file"], folder, name=doc.get("name"), up=src.get("up"),
                 scale=_number(src.get("scale")) or 1.0, height=_number(walls.get("height")) or 1.0,
                 tolerance=_number(walls.get("tolerance")) or 0.01, force=True, navgrid=doc.get("navgrid"),
                 wall_height=_number(src.get("wall_height")), wall_thickness=_number(src.get("wall_thickness")),
                 walkable=doc.get("walkable"))


def ensure_fresh(folder: Path, say: Callable[[str], None] | None = None) -> str | None:
    """Make the bundle at ``folder`` fit for a match (see the module docstring).
    Returns the line saying what was rebuilt (also given to ``say``), None when
    nothing was wrong; raises ArenaError when it cannot be mended here."""
    from .formats.bundle import read_toml

    manifest = folder / "arena.toml"
    if not manifest.is_file():
        return None            # not a bundle: load_arena says so
    doc = read_toml(manifest)
    bad = problems(folder, doc)
    if not bad:
        return None
    what = f"{folder}: {_say_files(bad)}"
    grid_only = all(is_grid_file(n) for n in bad)
    edited = [n for n, w in bad.items() if w == "stale" and not is_grid_file(n)]
    fix = f"tanktool build-navgrid {folder}" if grid_only else _import_command(folder, doc)
    if edited:
        raise ArenaError(f"{folder}: {' and '.join(edited)} changed since the import (not the sha256 arena.toml "
                         f"records); re-import to play it: {fix}")
    if not _writable(folder):
        raise ArenaError(f"{what} and the folder is read-only: run {fix} on a writable copy")
    if not grid_only and not _source_ok(folder, doc):
        raise ArenaError(f"{what} and the source model is missing or changed: re-import it with {fix}")
    t0 = time.perf_counter()
    if grid_only:
        rebuild_grid(folder, doc)
    else:
        reimport(folder, doc)
    line = f"{what}: rebuilt ({'build-navgrid' if grid_only else 'import-arena'}, {time.perf_counter() - t0:.1f} s)"
    if say is not None:
        say(line)
    return line
