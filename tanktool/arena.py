"""Arena bundles read back: ``load_arena`` (what play, check and the tools read), and
the walkable-surface parameters a bundle records (``walkable_params``).

An arena bundle ``arenas/<name>/`` holds ``arena.toml`` (the manifest), the source
model (copied under its own name), ``model.glb`` (the model in the world frame, for
the game), ``walls.txt`` (the 2002 wall list), ``preview.png``, ``navgrid.npz``,
``quadtree.npz`` and ``navgrid.png``.  See docs/arenas.md.  Building one from a model
(``import-arena``) is ``tanktool.importer``: it draws pictures (plots/), so it sits
with the front ends, above the simulation that loads bundles through this module.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .errors import ArenaError
from .formats.walls_txt import WallList
from .formats.limits import MAX_COORDINATE

#: defaults of the [navgrid] table until build-navgrid rewrites it
NAVGRID_DEFAULTS = {"cell": 0.5, "clearance": 2.0, "quadtree_depth": 3}
MANIFEST = "arena.toml"
MIN_SPAWNS = 8


@dataclass
class ArenaBundle:
    """An arena bundle as read from disk.

    walls : the wall list (auxiliary rectangle in ``walls.aux``)
    bounds : (2, 2) ``[[xmin, zmin], [xmax, zmax]]``
    spawns : (k, 3) ``[x, z, heading_rad]``, or (k, 4) with the height y of the
             surface under each (arenas of several levels or with relief)
    toml : the whole manifest
    """

    name: str
    path: Path
    walls: WallList
    bounds: np.ndarray
    spawns: np.ndarray
    floor_y: float
    toml: dict[str, Any] = field(default_factory=dict)

    def file(self, key: str) -> Path:
        """Path of a file the manifest names in table ``key`` (e.g. "walls", "model"),
        inside the bundle (``load_arena`` refused names that lead out of it); the
        bundle folder itself when the table names none."""
        from .formats.bundle import bundle_file

        t = self.toml.get(key)
        name = t.get("file") if isinstance(t, dict) else None
        if name is None:
            return self.path / ""
        return bundle_file(self.path, name, f"{self.path / MANIFEST}: [{key}] file")


#: spawn points an arena may list (a match uses at most 64 tanks)
MAX_SPAWNS = 4096


def _finite(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _table(doc: dict[str, Any], key: str, manifest: Path) -> dict[str, Any]:
    t = doc.get(key, {})
    if not isinstance(t, dict):
        raise ArenaError(f"{manifest}: [{key}] must be a table, got {key} = {t!r:.60}")
    return t


def _within_limits(spawns: np.ndarray, manifest: Path) -> None:
    """Refuse a spawn point whose coordinate is finite but absurd (±1e308 overflowed
    the grid's index arithmetic in check and play): name the spawn and the field."""
    far = np.abs(spawns[:, [0, 1] + ([3] if spawns.shape[1] == 4 else [])]) > MAX_COORDINATE
    headings = np.abs(spawns[:, 2]) > 1e3  # radians; a larger turn is a mistake
    bad = np.flatnonzero(far.any(axis=1) | headings)
    if len(bad):
        k = int(bad[0])
        raise ArenaError(f"{manifest}: spawns[{k}] = {spawns[k].tolist()}: a coordinate beyond "
                         f"{MAX_COORDINATE:g} m from the origin or a heading beyond 1000 rad (the limits of an arena)")


def load_arena(path: str | os.PathLike) -> ArenaBundle:
    """Read an arena bundle folder (or its ``arena.toml``) the way ``play`` uses it.

    Every value play needs is checked for its type and range, and every file the
    manifest names must lie inside the bundle.  Raises ArenaError / FormatError
    naming the file and the key.
    """
    from .errors import FormatError
    from .formats.bundle import bundle_file, clean_stale, read_toml
    from .formats.walls_txt import read_walls

    path = Path(path)
    if path.name == MANIFEST and path.is_file():
        path = path.parent
    if not path.is_dir():
        clean_stale(path.parent, path.name)  # a replacement killed half-way: put the bundle back
    if not path.is_dir():
        from .formats.models import refuse_model

        refuse_model(path, "arena")
        raise ArenaError(f"{path}: no such arena folder")
    manifest = path / MANIFEST
    if not manifest.is_file():
        raise ArenaError(f"{path}: not an arena bundle (no {MANIFEST})")
    doc = read_toml(manifest)
    name = doc.get("name", path.name)
    if not isinstance(name, str) or not name:
        raise ArenaError(f"{manifest}: 'name' must be a non-empty string, got {name!r:.60}")
    walls_t = _table(doc, "walls", manifest)
    model_t = _table(doc, "model", manifest)
    try:
        walls_path = bundle_file(path, walls_t.get("file", "walls.txt"), f"{manifest}: [walls] file")
        if "file" in model_t:
            bundle_file(path, model_t["file"], f"{manifest}: [model] file")
    except FormatError as e:  # a name that leads out of the bundle: the manifest is wrong
        raise ArenaError(str(e)) from None
    walls = read_walls(walls_path)
    raw = doc.get("spawns", [])
    width = len(raw[0]) if isinstance(raw, list) and raw and isinstance(raw[0], list) else 3
    if (not isinstance(raw, list) or len(raw) > MAX_SPAWNS or width not in (3, 4)
            or not all(isinstance(s, list) and len(s) == width and all(_finite(v) for v in s) for s in raw)):
        raise ArenaError(f"{manifest}: 'spawns' must be a list of at most {MAX_SPAWNS} [x, z, heading] or "
                         f"[x, z, heading, y] lists of finite numbers, all of one length")
    spawns = np.array(raw, dtype=np.float64).reshape(-1, width)
    _within_limits(spawns, manifest)
    raw_bounds = doc.get("bounds")
    if raw_bounds is None:
        bounds = walls.bounds
    else:
        if (not isinstance(raw_bounds, list) or len(raw_bounds) != 2
                or not all(isinstance(c, list) and len(c) == 2 and all(_finite(v) for v in c) for c in raw_bounds)):
            raise ArenaError(f"{manifest}: 'bounds' must be [[xmin, zmin], [xmax, zmax]] of finite numbers")
        bounds = np.array(raw_bounds, dtype=np.float64)
        if np.abs(bounds).max() > MAX_COORDINATE:
            raise ArenaError(f"{manifest}: 'bounds' {raw_bounds} lie beyond {MAX_COORDINATE:g} m from the origin "
                             f"(the limit of an arena coordinate)")
        if not (bounds[1] > bounds[0]).all():
            raise ArenaError(f"{manifest}: 'bounds' must have xmin < xmax and zmin < zmax")
    floor_y = doc.get("floor_y", 0.0)
    if not (_finite(floor_y) and abs(floor_y) <= MAX_COORDINATE):
        raise ArenaError(f"{manifest}: 'floor_y' must be a finite number within {MAX_COORDINATE:g} m of the origin, "
                         f"got {floor_y!r:.60}")
    return ArenaBundle(name, path, walls, bounds, spawns, float(floor_y), doc)


def walkable_params(cell: float | None = None, max_slope: float | None = None, climb: float | None = None,
                    headroom: float | None = None, fleet: Any = None,
                    recorded: dict[str, Any] | None = None) -> tuple[Any, dict[str, str]]:
    """The walkable-surface parameters: each given value, else the one ``recorded`` in
    an arena.toml, else the default (headroom: the tallest bundled vehicle).  Returns
    (params, where each value came from)."""
    from .nav.walkable import CELL_HEIGHT, CLIMB, MAX_SLOPE, WalkableParams

    rec = recorded or {}
    where: dict[str, str] = {}

    def pick(name: str, given: float | None, default: float, default_src: str) -> float:
        if given is not None:
            where[name] = "option"
            return float(given)
        v = rec.get(name)
        if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
            where[name] = "arena.toml"
            return float(v)
        where[name] = default_src
        return float(default)

    height_default = fleet.height if fleet is not None else 2.0
    height_src = f"height of vehicle '{fleet.height_of}'" if fleet is not None else "built-in default"
    params = WalkableParams(
        cell=pick("cell", cell, NAVGRID_DEFAULTS["cell"], "default"),
        cell_height=pick("cell_height", None, CELL_HEIGHT, "default"),
        max_slope=pick("max_slope", max_slope, MAX_SLOPE, "default"),
        climb=pick("climb", climb, CLIMB, "default"),
        headroom=pick("headroom", headroom, height_default, height_src),
    )
    return params.check(), where
