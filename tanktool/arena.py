"""Arena bundles: build one from a model (``import-arena``) and read one back.

An arena bundle ``arenas/<name>/`` holds ``arena.toml`` (the manifest), the source
model (copied under its own name), ``model.glb`` (the model in the world frame, for
the game), ``walls.txt`` (the 2002 wall list), ``preview.png``, and later
``navgrid.npz`` / ``quadtree.npz`` written by ``build-navgrid``.  See docs/arenas.md.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from . import __version__
from .errors import ArenaError
from .formats.walls_txt import WallList

#: defaults of the [navgrid] table until build-navgrid rewrites it
NAVGRID_DEFAULTS = {"cell": 0.5, "clearance": 2.0, "quadtree_depth": 3}
MANIFEST = "arena.toml"
MIN_SPAWNS = 8


@dataclass
class ArenaBundle:
    """An arena bundle as read from disk.

    walls : the wall list (auxiliary rectangle in ``walls.aux``)
    bounds : (2, 2) ``[[xmin, zmin], [xmax, zmax]]``
    spawns : (k, 3) ``[x, z, heading_rad]``
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
    if (not isinstance(raw, list) or len(raw) > MAX_SPAWNS
            or not all(isinstance(s, list) and len(s) == 3 and all(_finite(v) for v in s) for s in raw)):
        raise ArenaError(f"{manifest}: 'spawns' must be a list of at most {MAX_SPAWNS} [x, z, heading] triples "
                         f"of finite numbers")
    spawns = np.array(raw, dtype=np.float64).reshape(-1, 3)
    raw_bounds = doc.get("bounds")
    if raw_bounds is None:
        bounds = walls.bounds
    else:
        if (not isinstance(raw_bounds, list) or len(raw_bounds) != 2
                or not all(isinstance(c, list) and len(c) == 2 and all(_finite(v) for v in c) for c in raw_bounds)):
            raise ArenaError(f"{manifest}: 'bounds' must be [[xmin, zmin], [xmax, zmax]] of finite numbers")
        bounds = np.array(raw_bounds, dtype=np.float64)
        if not (bounds[1] > bounds[0]).all():
            raise ArenaError(f"{manifest}: 'bounds' must have xmin < xmax and zmin < zmax")
    floor_y = doc.get("floor_y", 0.0)
    if not _finite(floor_y):
        raise ArenaError(f"{manifest}: 'floor_y' must be a finite number, got {floor_y!r:.60}")
    return ArenaBundle(name, path, walls, bounds, spawns, float(floor_y), doc)


# ---------------------------------------------------------------------------
# building a bundle


@dataclass
class ImportResult:
    """What :func:`import_arena` wrote, for the command's summary."""

    path: Path
    name: str
    walls: WallList
    spawns: np.ndarray
    floor_y: float
    faces: int
    thin_walls: int
    seconds: float
    warnings: list[str] = field(default_factory=list)   # non-fatal remarks (a .bzw's unknown objects)


_NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")


def _companion_files(model: Path) -> list[Path]:
    """Files a model needs beside it: an .obj's material libraries (regular files in
    the model's own folder only)."""
    from .errors import FormatError
    from .formats.bundle import bundle_file, read_input

    if model.suffix.lower() != ".obj":
        return []
    out: list[Path] = []
    try:
        data = read_input(model, "an .obj model")
    except FormatError:
        return []
    for raw in data.splitlines():
        if raw.startswith(b"mtllib"):
            for name in raw.split()[1:]:
                try:
                    p = bundle_file(model.parent, name.decode("utf-8", "replace"), "mtllib")
                except FormatError:
                    continue
                if p.is_file() and not p.is_symlink() and p.parent == model.parent and p not in out:
                    out.append(p)
    return out


def import_arena(
    model: str | os.PathLike,
    out: str | os.PathLike | None = None,
    name: str | None = None,
    up: str | None = None,
    scale: float = 1.0,
    height: float = 1.0,
    tolerance: float = 0.01,
    force: bool = False,
    navgrid: dict[str, Any] | None = None,
    progress: Callable[[str], None] | None = None,
    warn: Callable[[str], None] | None = None,
    wall_height: float | None = None,
    wall_thickness: float | None = None,
) -> ImportResult:
    """Read ``model``, extract walls and spawns and write the arena bundle ``out``.

    ``out`` defaults to ``./<name>``; ``name`` to the model's file stem.  ``navgrid``
    overrides the [navgrid] defaults (used when rebuilding a bundled arena).
    ``warn`` also receives the non-fatal remarks collected in ``ImportResult.warnings``.
    ``wall_height`` / ``wall_thickness`` shape a .dxf/.svg floor plan's walls.
    Everything is written into a temporary folder renamed into place at the end,
    so a failure leaves nothing behind.
    """
    import trimesh

    from .formats.bundle import check_replaceable, sha256_file, staged_dir, write_toml
    from .formats.models import default_up, detect_format, load_scene
    from .formats.walls_txt import write_walls
    from .geometry.spawns import place_spawns
    from .geometry.walls import extract_walls
    from .plots.arena import save_preview

    t0 = time.perf_counter()
    model = Path(model)
    fmt = detect_format(model)
    if name is None:  # from the file stem, made a safe folder name ("my arena" -> "my_arena")
        name = re.sub(r"[^A-Za-z0-9._-]+", "_", model.stem).strip("._-") or "arena"
    if not _NAME_RE.match(name):
        raise ArenaError(f"arena name {name!r}: use letters, digits, '.', '_' or '-'")
    target = Path(out) if out is not None else Path.cwd() / name
    check_replaceable(target, force, MANIFEST)  # before any work: only a bundle tanktool wrote is replaced
    if not (math.isfinite(height) and height > 0):
        raise ArenaError(f"--height must be a positive number of metres, got {height}")
    if not (math.isfinite(tolerance) and 0 < tolerance < height):
        raise ArenaError(f"--tolerance must be positive and below --height, got {tolerance}")

    warnings: list[str] = []

    def remark(message: str) -> None:
        warnings.append(message)
        if warn is not None:
            warn(message)

    if wall_height is not None and not wall_height > height:
        raise ArenaError(f"--wall-height ({wall_height:g}) must be above the cut --height ({height:g}), "
                         f"or the walls would not be cut")
    scene = load_scene(model, up=up, scale=scale, warn=remark, wall_height=wall_height,
                       wall_thickness=wall_thickness, progress=progress)
    if progress:
        progress("read")
    meshes = [m for m in scene.dump() if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    mesh = meshes[0] if len(meshes) == 1 else trimesh.util.concatenate(meshes)
    try:
        ex = extract_walls(mesh.vertices, mesh.faces, height=height, tolerance=tolerance, progress=progress)
    except ArenaError as e:
        raise ArenaError(f"{model}: {e}") from None
    try:
        spawns = place_spawns(ex.free, ex.walls.bounds)
    except ArenaError as e:
        raise ArenaError(f"{model}: {e}") from None
    if progress:
        progress("spawns")

    src_up = up or default_up(fmt)
    nav = dict(NAVGRID_DEFAULTS)
    nav.update(navgrid or {})
    bounds = ex.walls.bounds
    companions = _companion_files(model)
    with staged_dir(target, force=force, manifest=MANIFEST) as tmp:
        copied = [model, *companions]
        for f in copied:
            shutil.copyfile(f, tmp / f.name)
        glb = scene.export(file_type="glb")
        (tmp / "model.glb").write_bytes(glb)
        header = (f"arena {name}: walls of {model.name} cut {height:g} m above the floor (y={ex.floor_y:.4g})\n"
                  f"made by tanktool {__version__} import-arena; normals point into free space")
        write_walls(tmp / "walls.txt", ex.walls, header=header)
        title = (f"{name}: {len(ex.walls)} walls + 4 auxiliary, {len(spawns)} spawns, "
                 f"{bounds[1, 0] - bounds[0, 0]:.0f} x {bounds[1, 1] - bounds[0, 1]:.0f} m")
        save_preview(tmp / "preview.png", ex.walls, spawns, title, ex.free)
        if progress:
            progress("files")
        doc = {
            "name": name,
            "tool_version": __version__,
            "bounds": [[_r(bounds[0, 0]), _r(bounds[0, 1])], [_r(bounds[1, 0]), _r(bounds[1, 1])]],
            "floor_y": _r(ex.floor_y),
            "spawns": [[_r(x), _r(z), _r(h, 6)] for x, z, h in spawns],
            "source": {"file": model.name, "sha256": sha256_file(tmp / model.name), "up": src_up,
                       "scale": float(scale), **_plan_source(fmt, wall_height, wall_thickness),
                       **({"companions": [f.name for f in companions]} if companions else {})},
            "model": {"file": "model.glb"},
            "walls": {"file": "walls.txt", "height": float(height), "tolerance": float(tolerance),
                      "count": len(ex.walls)},
            "navgrid": nav,
            "derived": {f: sha256_file(tmp / f) for f in ("walls.txt", "model.glb", "preview.png")},
        }
        write_toml(tmp / MANIFEST, doc)
    return ImportResult(target, name, ex.walls, spawns, ex.floor_y, len(mesh.faces), ex.thin_walls,
                        time.perf_counter() - t0, warnings)


def _plan_source(fmt: str, wall_height: float | None, wall_thickness: float | None) -> dict[str, float]:
    """[source] keys of a floor plan: the wall height and thickness it was built with."""
    from .formats.models import PLAN_FORMATS

    if fmt not in PLAN_FORMATS:
        return {}
    from .formats.floorplan import DEFAULT_WALL_HEIGHT, DEFAULT_WALL_THICKNESS

    return {"wall_height": float(DEFAULT_WALL_HEIGHT if wall_height is None else wall_height),
            "wall_thickness": float(DEFAULT_WALL_THICKNESS if wall_thickness is None else wall_thickness)}


def _r(v: float, nd: int = 4) -> float:
    v = round(float(v), nd)
    return 0.0 if v == 0.0 else v  # no "-0.0" in the manifest
