"""``import-arena``'s pipeline: a model in, a complete arena bundle out (walls,
walkable surface, layered navigation grid, quadtree, pictures, hashes).

It reads the model (formats/), analyses its levels (nav/arena_levels.py), draws the
pictures (plots/) and writes the grid files as build-navgrid does (grid_files.py):
a front-end layer module.  Reading a bundle back is ``tanktool.arena``.
"""

from __future__ import annotations

import gc
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
from .arena import MANIFEST, MIN_SPAWNS, NAVGRID_DEFAULTS, walkable_params
from .errors import ArenaError
from .formats.limits import MAX_COORDINATE, check_cells
from .formats.walls_txt import WallList
from .memory import GIVE_BACK_MIN, frozen_heap, give_back


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
    levels: Any = None  # nav.arena_levels.ArenaLevels: levels, what was left out (its surface, model and,
    #                     with a grid built, tank grid are let go (None) once the pictures are drawn)
    params: Any = None  # the WalkableParams used
    defaults: dict[str, str] = field(default_factory=dict)  # where each default came from
    grid: Any = None    # grid_files.BuiltGrid: the navigation grid written with the bundle (None: not built)
    model_left_out: list[str] = field(default_factory=list)  # what the model file held but was not built (.bzw)


_NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")


def _companion_files(model: Path) -> list[Path]:
    """Files a model needs beside it: an .obj's material libraries, a .gltf's buffers."""
    from .formats.materials import companion_files

    return companion_files(model)


def _beside(f: Path, model: Path) -> str:
    """``f``'s name relative to the model's folder (posix), as the model names it."""
    try:
        return f.relative_to(model.parent).as_posix()
    except ValueError:
        return f.name


@frozen_heap
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
    max_slope: float | None = None,
    climb: float | None = None,
    headroom: float | None = None,
    cell: float | None = None,
    walkable: dict[str, Any] | None = None,
    max_cells: int | None = None,
    grid: bool = True,
) -> ImportResult:
    """Read ``model``, find its walkable levels, walls and spawns and write the arena
    bundle ``out``.

    ``out`` defaults to ``./<name>``; ``name`` to the model's file stem.  ``navgrid``
    overrides the [navgrid] defaults and ``walkable`` the [walkable] ones (used when
    rebuilding a bundled arena); ``grid`` (default) also builds the navigation files
    build-navgrid writes (navgrid.npz, quadtree.npz, navgrid.png: ``grid_files``) with
    the default clearance, so the bundle is ready to play; ``max_slope``, ``climb``, ``headroom`` and ``cell``
    are the command's options.  ``warn`` also receives the non-fatal remarks collected
    in ``ImportResult.warnings``.  ``wall_height`` / ``wall_thickness`` shape a .dxf/.svg
    floor plan's walls.  Everything is written into a temporary folder renamed into
    place at the end, so a failure leaves nothing behind.
    """
    from .fleet import bundled_fleet
    from .formats.bundle import write_toml
    from .formats.bundle_swap import staged_dir
    from .formats.models import default_up, detect_format

    t0 = time.perf_counter()
    model = Path(model)
    fmt = detect_format(model)
    name, target = _check_options(model, out, name, force, height, tolerance)
    warnings, remark = _collector(warn)
    fleet = bundled_fleet(warn=remark)
    nav = {**NAVGRID_DEFAULTS, **(navgrid or {})}
    params, where = walkable_params(cell if cell is not None else nav.get("cell"), max_slope, climb, headroom,
                                    fleet, walkable)
    _check_heights(params.climb, height, wall_height)
    scene, mesh = _read_mesh(model, params.cell, max_cells, progress, up=up, scale=scale, warn=remark,
                             wall_height=wall_height, wall_thickness=wall_thickness)
    result = _analyse(model, mesh, params, fleet, height, tolerance, progress, keep_runs=not grid)
    n_faces, model_left_out = len(mesh.faces), list(scene.metadata.get("left_out", []))
    del mesh   # scene.dump()'s copy: the analysis keeps the arrays it needs (vertices, faces)
    preview = _preview(name, result, keep_region=grid)   # drawn while the analysis is whole
    _before_vehicles(result, reseed=grid)
    others = _vehicle_grids(result, fleet, remark)
    if grid:
        result.grid = None   # the grid stage builds the bundle's own (ImportResult.grid holds it)
    fits = _remark_fit(model, result, fleet, remark, others)
    nav["cell"] = float(params.cell)
    companions = _companion_files(model)
    with staged_dir(target, force=force, manifest=MANIFEST) as tmp:
        textures = _stage_files(tmp, model, companions, scene, target, name, height, result, preview, remark)
        if progress:
            progress("files")
        source = {"up": up or default_up(fmt), "scale": float(scale), **_plan_source(fmt, wall_height, wall_thickness)}
        doc = _manifest(tmp, model, companions, name, source, textures, height, tolerance, params, fits,
                        result, nav)
        # one grid per smaller vehicle: grid_files builds navgrid.<vehicle>.npz from these
        write_toml(tmp / MANIFEST, {**doc, **({"grids": others} if others else {})})
        scene = None
        analysed = {"params": params, "surface": result.surface} if grid else None   # see _stage_grid
        _let_go(result)
        # the same files, built the same way, as build-navgrid on the bundle
        built = _stage_grid(tmp, fits, remark, progress, analysed) if grid else None
    return ImportResult(target, name, result.walls.walls, result.spawns, result.floor_y, n_faces,
                        result.walls.thin_walls, time.perf_counter() - t0, warnings, result, params, where, built,
                        model_left_out)


def _collector(warn: Callable[[str], None] | None) -> tuple[list[str], Callable[[str], None]]:
    """(the remarks so far, a function that records one and passes it to ``warn``)."""
    remarks: list[str] = []

    def remark(message: str) -> None:
        remarks.append(message)
        if warn is not None:
            warn(message)
    return remarks, remark


def _before_vehicles(result: Any, reseed: bool = False) -> None:
    """Let go of what the smaller vehicles' grids and spawns do not read, once the
    report and the preview are done: of the surface all but its spans' columns, levels,
    heights and links (its clearance, regions, floors, ceilings and the heightfield's
    spans; ``reseed``: the floors and regions stay, for the grid stage's reseed).  On a 2 km terrain ~1 GB, which the smaller vehicle's grid stacked on (the
    import's peak).  The tank grid stays: the smaller vehicles' grids share its nodes'
    heights and links (arena_levels.tank_grid ``like``), which they built again else."""
    s = result.surface
    for k in ("ceil", "main") if reseed else ("floor", "ceil", "region", "main"):   # the grids read none of these
        a = getattr(s, k)
        setattr(s, k, np.zeros(0, dtype=a.dtype))
    s.clearance = None
    s.derived.clear()
    s.hf = s.hf.geometry()
    gc.collect()   # the preview's figure is cyclic garbage holding its images (~0.1 GB on 2 km)
    give_back(GIVE_BACK_MIN)


def _preview(name: str, result: Any, keep_region: bool = False) -> bytes:
    """preview.png's bytes: the levels, walls, spawns and what was left out (the
    report's answers, kept with the surface: its clearance and regions go first;
    ``keep_region``: the regions stay, for the grid stage's reseed)."""
    from .nav.surface_report import asked
    from .plots.arena import render_levels

    s = result.surface
    if result.grid is not None and asked(s, result.grid.clearance, (result.vertices, result.faces)):
        s.clearance = None
        if not keep_region:
            s.region = np.zeros(0, dtype=s.region.dtype)
    walls, spawns, lv = result.walls.walls, result.spawns, result.levels
    bounds = walls.bounds
    title = (f"{name}: {len(lv)} level{'s' if len(lv) != 1 else ''}, {len(walls)} walls + 4 auxiliary, "
             f"{len(spawns)} spawns, {bounds[1, 0] - bounds[0, 0]:.0f} x {bounds[1, 1] - bounds[0, 1]:.0f} m")
    return render_levels(result, title)


def _let_go(result: Any) -> None:
    """Drop the analysis' large arrays once the files are staged: its surface (~100
    bytes a grid column: 0.5 GB on a 1 km terrain at 0.5 m) and the model it holds; let
    go before the grid stage (2 km terrain: ~0.9 GB).  The tank grid went already,
    once the smaller vehicles' grids no longer shared it."""
    result.surface = None
    result.vertices = result.faces = None
    give_back(GIVE_BACK_MIN)


def _check_options(model: Path, out: str | os.PathLike | None, name: str | None, force: bool, height: float,
                   tolerance: float) -> tuple[str, Path]:
    """The arena's name and folder, checked with the cut's numbers before any work."""
    from .formats.bundle_swap import check_replaceable

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
    return name, target


def _check_heights(climb: float, height: float, wall_height: float | None) -> None:
    """The climb and a floor plan's wall height against the cut height."""
    if climb >= height:
        raise ArenaError(f"--climb ({climb:g} m) must be below the cut --height ({height:g} m): "
                         "what a tank climbs cannot also be a wall")
    if wall_height is not None and not wall_height > height:
        raise ArenaError(f"--wall-height ({wall_height:g}) must be above the cut --height ({height:g}), "
                         f"or the walls would not be cut")


def _read_mesh(model: Path, cell: float, max_cells: int | None, progress: Callable[[str], None] | None,
               **load: Any) -> tuple[Any, Any]:
    """(scene, its triangles as one mesh, rounded as model.glb stores them): ``load``
    goes to load_scene."""
    from .formats.models import load_scene

    scene = load_scene(model, progress=progress, **load)
    if progress:
        progress("read")
    mesh = _one_mesh(model, scene, cell, max_cells)
    _as_stored(mesh)
    give_back(GIVE_BACK_MIN)   # the parser's temporaries (2 km terrain: ~0.36 GB of free heap kept)
    return scene, mesh


def _one_mesh(model: Path, scene: Any, cell: float, max_cells: int | None) -> Any:
    """The scene's triangles as one mesh, its grid size checked."""
    import trimesh

    meshes = _as_placed(scene)
    if meshes is None:
        meshes = [m for m in scene.dump() if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    if not meshes:
        raise ArenaError(f"{model}: the model has no triangles")
    mesh = meshes[0] if len(meshes) == 1 else trimesh.util.concatenate(meshes)
    lo, hi = mesh.bounds
    far = float(np.abs(mesh.bounds).max())
    if far > MAX_COORDINATE:   # walls.txt and the grids could not hold it (not a temporary file's error)
        raise ArenaError(f"{model}: the model reaches {far:,.0f} m from the origin, and an arena's files hold "
                         f"coordinates within {MAX_COORDINATE:,.0f} m: move it near the origin in your 3D program "
                         "(or check --scale and the file's units)")
    check_cells(str(model), float(hi[0] - lo[0]), float(hi[2] - lo[2]), cell, model.stat().st_size,
                max_cells)  # before the heightfield: its cost follows the cells
    return mesh


def _as_stored(mesh: Any) -> None:
    """The mesh's vertices rounded, in place, to the float32 model.glb stores them in:
    the analysis' surface is then the one build-navgrid rasterises from model.glb
    (a vertex on the other side of a cell or step line moved a span else)."""
    v = mesh.vertices
    stored = np.asarray(v, dtype=np.float64).astype(np.float32)
    if getattr(v, "flags", None) is not None and v.flags.writeable:
        v[...] = stored
    else:   # a loader's read-only view of its file's bytes
        mesh.vertices = stored.astype(np.float64)


def _as_placed(scene: Any) -> list[Any] | None:
    """The scene's one mesh itself when it is placed once, untransformed: scene.dump()
    copies it (~80 bytes a face and vertex: 0.15 GB on a 2 km terrain) only to apply an
    identity matrix.  None: dump the scene."""
    import trimesh

    nodes = scene.graph.nodes_geometry
    if len(nodes) != 1:
        return None
    transform, name = scene.graph[nodes[0]]
    g = scene.geometry.get(name)
    if not isinstance(g, trimesh.Trimesh) or not np.array_equal(transform, np.eye(4)):
        return None
    return [g] if len(g.faces) else []


def _analyse(model: Path, mesh: Any, params: Any, fleet: Any, height: float, tolerance: float,
             progress: Callable[[str], None] | None, keep_runs: bool = True) -> Any:
    """analyse_arena on the mesh, its errors naming the file (``keep_runs``: see there;
    False with the grid stage: the tank grid is only the spawns', the bundle's is built
    anew from the same surface)."""
    from .nav.arena_levels import analyse_arena

    try:
        return analyse_arena(mesh.vertices, mesh.faces, params, fleet, cut_height=height, tolerance=tolerance,
                             progress=progress, keep_runs=keep_runs)
    except ArenaError as e:
        # the same kind (a NoFitError keeps the --scale it suggests), the file named
        err = ArenaError(f"{model}: {e}")
        if hasattr(e, "scale"):
            err = type(e)(f"{model}: {e}", e.scale)
        raise err from None


def _remark_fit(model: Path, result: Any, fleet: Any, remark: Callable[[str], None],
                others: dict[str, Any] | None = None) -> Any:
    """Remark on repaired walls, vehicles too big and too few spawns; the fleet the arena is for."""
    for line in result.walls.repairs.remarks():   # repaired walls, and what check would still find
        remark(f"{model}: {line}")
    spawns = result.spawns
    fits = result.fleet or fleet
    if result.too_big:
        remark(f"{model}: {'; '.join(f'{n} {w}' for n, w in result.too_big)}: the spawns and the navigation "
               f"grid are for {fits.radius_of} (footprint radius {fits.radius:.2f} m), and play refuses the "
               f"larger vehicles here")
    if len(spawns) < MIN_SPAWNS:
        own = "".join(f"; {n} has {len(t['spawns'])} of its own" for n, t in (others or {}).items())
        remark(f"{model}: room for only {len(spawns)} spawn point(s) where the largest bundled tank that fits "
               f"({fits.radius_of}) fits, at least {fits.length:.1f} m apart{own}")
    return fits


def _vehicle_grids(result: Any, fleet: Any, remark: Callable[[str], None]) -> dict[str, Any]:
    """arena.toml's [grids.<vehicle>] (clearance, spawns) of the bundled vehicles smaller
    than the one navgrid.npz is for (nav.arena_levels.smaller_vehicles)."""
    from .formats.vehicle_grids import vehicle_file
    from .nav.arena_levels import smaller_vehicles

    out: dict[str, Any] = {}
    for name, (radius, spawns) in smaller_vehicles(result, fleet).items():
        if result.flat:   # the 2002 case keeps its spawns for every vehicle: flat arenas play as they did
            spawns = result.spawns
        if vehicle_file(name) is None:
            remark(f"vehicle {name!r}: no grid of its own (its name cannot be part of a file name)")
            continue
        out[name] = {"clearance": _r(radius), "spawns": [[_r(x), _r(z), _r(h, 6), _r(y)] for x, z, h, y in spawns]}
    return out


def _stage_files(tmp: Path, model: Path, companions: list[Path], scene: Any, target: Path, name: str,
                 height: float, result: Any, preview: bytes, remark: Callable[[str], None]) -> Any:
    """Copy the model in and write model.glb, walls.txt and preview.png (``preview``:
    its bytes, :func:`_preview`); the textures export_glb copied."""
    from .formats.bundle import atomic_write_bytes
    from .formats.materials import export_glb
    from .formats.walls_txt import write_walls

    walls = result.walls.walls
    for f in [model, *companions]:  # where the model looks for it: a .gltf's "data/scene.bin" stays there
        (tmp / _beside(f, model)).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(f, tmp / _beside(f, model))
    glb, textures = export_glb(model, scene, tmp, extra=[target], warn=remark)   # textures copied in
    (tmp / "model.glb").write_bytes(glb)
    header = (f"arena {name}: walls of {model.name}, the boundaries of its walkable surface "
              f"(flat floors: cut {height:g} m above them)\n"
              f"made by tanktool {__version__} import-arena; normals point into free space")
    write_walls(tmp / "walls.txt", walls, header=header)
    atomic_write_bytes(tmp / "preview.png", preview)
    return textures


def _manifest(tmp: Path, model: Path, companions: list[Path], name: str, source: dict[str, Any], textures: Any,
              height: float, tolerance: float, params: Any, fits: Any, result: Any,
              nav: dict[str, Any]) -> dict[str, Any]:
    """The bundle's arena.toml document, hashing the files staged in ``tmp``."""
    from .formats.bundle import sha256_file
    from .nav.arena_levels import spawn_y_needed

    walls, bounds, with_y = result.walls.walls, result.walls.walls.bounds, spawn_y_needed(result)
    return {
        "name": name,
        "tool_version": __version__,
        "bounds": [[_r(bounds[0, 0]), _r(bounds[0, 1])], [_r(bounds[1, 0]), _r(bounds[1, 1])]],
        "floor_y": _r(result.floor_y),
        "spawns": [[_r(x), _r(z), _r(h, 6), _r(y)] if with_y else [_r(x), _r(z), _r(h, 6)]
                   for x, z, h, y in result.spawns],
        "source": {"file": model.name, "sha256": sha256_file(tmp / model.name), **source,
                   **({"companions": [_beside(f, model) for f in companions]} if companions else {})},
        "model": {"file": "model.glb", **({"textures": textures} if textures else {})},
        "walls": {"file": "walls.txt", "height": float(height), "tolerance": float(tolerance),
                  "count": len(walls)},
        "walkable": params.as_toml(),
        "vehicles": {"largest": fits.radius_of, "radius": _r(fits.radius),
                     "too_big": [n for n, _ in result.too_big]},
        "levels": [{"level": x.level, "area": _r(x.area, 1), "y": [_r(x.y_lo, 3), _r(x.y_hi, 3)],
                    "regions": x.regions} for x in result.levels],
        "navgrid": nav,
        "derived": {f: sha256_file(tmp / f) for f in ("walls.txt", "model.glb", "preview.png")},
    }


def _stage_grid(tmp: Path, fits: Any, remark: Callable[[str], None],
                progress: Callable[[str], None] | None, analysed: dict[str, Any] | None = None) -> Any:
    """navgrid.npz, quadtree.npz and navgrid.png as build-navgrid writes them, recorded
    in the manifest.  ``analysed`` ({"params", "surface"}: the analysis' surface, on the
    model lattice as build-navgrid's from model.glb, its only reference) is reseeded
    instead of rasterising model.glb again (grid_files.build_grid)."""
    from .formats.bundle import write_toml
    from .grid_files import build_grid, open_target, picture_and_grids, stage_grid_files

    staged = open_target(tmp)
    built = build_grid(staged, warn=remark, fleet=fits, analysed=analysed)
    write_toml(tmp / MANIFEST, stage_grid_files(tmp, staged, built, *picture_and_grids(built, staged)))
    if progress:
        progress("navgrid")
    return built


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
