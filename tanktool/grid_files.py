"""The navigation files of an arena bundle: ``navgrid.npz``, ``quadtree.npz`` and
``navgrid.png``, and the [navgrid] / [walkable] / [derived] entries that go with them.

``import-arena`` writes them into the bundle it stages (one step from a model to a
match) and ``build-navgrid`` rebuilds them with other settings; both go through
:func:`build_grid` and :func:`stage_grid_files`, so the same settings give the same
files byte for byte.
"""

from __future__ import annotations

import gc
import math
import time
import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from .errors import ArenaError
from .memory import GIVE_BACK_MIN, frozen_heap, give_back
# the smaller vehicles' grids: formats/vehicle_grids.py reads [grids] (the simulation needs it too)
from .formats.vehicle_grids import is_grid_file, vehicle_file, vehicle_grids  # noqa: F401

DEFAULTS = {"cell": 0.5, "clearance": 2.0, "quadtree_depth": 3}
#: the files written here, in the bundle's folder (and navgrid.<vehicle>.npz: vehicle_file)
FILES = ("navgrid.npz", "quadtree.npz", "navgrid.png")


#: the vehicles whose sizes set the defaults; None: the bundled ones (tests point it elsewhere)
VEHICLES_DIR: Path | None = None


def vehicles_dir() -> Path:
    """Where the vehicles live whose largest footprint sets the default clearance."""
    from .content import CHECKOUT, bundled_dir

    if VEHICLES_DIR is not None:
        return VEHICLES_DIR
    return bundled_dir("vehicles") or CHECKOUT / "vehicles"


@dataclass
class Target:
    """What a grid is built for: walls, where outputs go, and the bundle's manifest."""

    walls: Any
    out_dir: Path
    name: str
    bounds: Any = None
    spawns: Any = None
    manifest: Path | None = None
    toml: dict[str, Any] = field(default_factory=dict)
    prefix: str = ""  # output names are prefix + navgrid.npz, ...
    model: Path | None = None  # the bundle's model.glb: its walkable surface decides the levels

    def output(self, name: str) -> Path:
        return self.out_dir / f"{self.prefix}{name}"


def open_target(path: Path) -> Target:
    """An arena bundle folder (or its arena.toml), read by ``load_arena``, or a bare walls file."""
    from .arena import load_arena
    from .formats.walls_txt import read_walls

    if path.is_file() and path.name == "arena.toml":
        path = path.parent
    if not path.exists():
        raise ArenaError(f"{path}: no such arena folder or walls file")
    if path.is_file():
        if (path.parent / "arena.toml").is_file():
            raise ArenaError(f"{path} belongs to the arena bundle {path.parent}: run build-navgrid on the bundle "
                             f"folder (its grid then follows the model and arena.toml stays current)")
        from .formats.models import refuse_model

        refuse_model(path, "arena")
        walls = read_walls(path)
        if len(walls) == 0:
            raise ArenaError(f"{path}: no walls")
        # outputs next to it; named after it unless it is the usual walls.txt
        prefix = "" if path.name == "walls.txt" else f"{path.stem}."
        return Target(walls, path.parent, path.stem, walls.bounds, prefix=prefix)
    arena = load_arena(path)
    if len(arena.walls) == 0:
        raise ArenaError(f"{arena.file('walls')}: no walls")
    spawns = arena.spawns if len(arena.spawns) else None
    model = arena.file("model")
    return Target(arena.walls, arena.path, arena.name, arena.bounds, spawns, arena.path / "arena.toml", arena.toml,
                  model=model if model.is_file() and model.suffix.lower() == ".glb" else None)


def default_clearance(target: Target, warn: Callable[[str], None] | None = None) -> tuple[float, str]:
    """The footprint radius of the largest bundled vehicle (of those that fit in the
    arena, when import-arena found the larger ones fit nowhere: arena.toml
    [vehicles]), else arena.toml's value."""
    from .formats.bundle import read_toml

    fits = target.toml.get("vehicles", {})
    r = fits.get("radius") if isinstance(fits, dict) else None
    if fits.get("too_big") and isinstance(r, (int, float)) and not isinstance(r, bool) and math.isfinite(r) and r > 0:
        return float(r), f"footprint radius of vehicle '{fits.get('largest')}', the largest that fits"
    best: tuple[float, str] | None = None
    for vt in sorted(vehicles_dir().glob("*/vehicle.toml")):
        try:
            r = read_toml(vt).get("footprint_radius")
            if not isinstance(r, (int, float)) or isinstance(r, bool):
                from .formats.vehicle_bundle import load_vehicle

                r = load_vehicle(vt.parent).footprint_radius
        except Exception as e:  # a broken vehicle must not stop the arena tools
            if warn is not None:
                warn(f"{vt}: skipped for the default clearance ({e})")
            continue
        if math.isfinite(r) and r > 0 and (best is None or r > best[0]):
            best = (float(r), f"footprint radius of vehicle '{vt.parent.name}'")
    if best is not None:
        return best
    r = target.toml.get("navgrid", {}).get("clearance")
    if isinstance(r, (int, float)) and not isinstance(r, bool) and math.isfinite(r) and r >= 0:
        return float(r), "arena.toml [navgrid] clearance"
    return DEFAULTS["clearance"], "built-in default"


@dataclass
class BuiltGrid:
    """A grid built in memory, with how it was built."""

    grid: Any                 # nav.navgrid.NavGrid
    tree: Any                 # nav.quadtree.WallQuadtree
    free: Any                 # mask of nodes in free space / on the surface (the picture's background)
    cell: float
    clearance: float
    clearance_source: str
    quadtree_depth: int
    params: Any = None        # nav.walkable.WalkableParams, None for a bare walls file
    seconds: float = 0.0
    #: the smaller vehicles' grids stage_grid_files built with it ({vehicle: BuiltGrid})
    vehicles: dict[str, Any] = field(default_factory=dict)


def _number(name: str, value: float | None, lo: float, lo_open: bool) -> None:
    if value is None:
        return
    bad = not math.isfinite(value) or (value <= lo if lo_open else value < lo)
    if bad:
        raise ArenaError(f"--{name} must be {'>' if lo_open else '>='} {lo:g}, got {value:g}")


def settings(target: Target, cell: float | None, quadtree_depth: int | None) -> tuple[float, int]:
    """--cell and --quadtree-depth, else the manifest's [navgrid] values, else the defaults."""
    nav_t = target.toml.get("navgrid", {})
    if not isinstance(nav_t, dict):
        raise ArenaError(f"{target.manifest}: [navgrid] must be a table")
    if cell is None:
        cell = nav_t.get("cell", DEFAULTS["cell"])
        if isinstance(cell, bool) or not isinstance(cell, (int, float)) or not (math.isfinite(cell) and cell > 0):
            raise ArenaError(f"{target.manifest}: [navgrid] cell must be a number > 0, got {cell!r}")
    if quadtree_depth is None:
        quadtree_depth = nav_t.get("quadtree_depth", DEFAULTS["quadtree_depth"])
        if isinstance(quadtree_depth, bool) or not isinstance(quadtree_depth, int) or not 0 <= quadtree_depth <= 10:
            raise ArenaError(f"{target.manifest}: [navgrid] quadtree_depth must be an integer 0..10, "
                             f"got {quadtree_depth!r}")
    return float(cell), int(quadtree_depth)


@frozen_heap
def build_grid(target: Target, cell: float | None = None, clearance: float | None = None,
               max_slope: float | None = None, climb: float | None = None, headroom: float | None = None,
               quadtree_depth: int | None = None, warn: Callable[[str], None] | None = None,
               progress: Callable[[int], None] | None = None, fleet: Any = None,
               base: Any = None, analysed: dict[str, Any] | None = None) -> BuiltGrid:
    """The navigation grid and wall quadtree of ``target``: on a bundle with its model,
    the layered grid of the model's walkable surface; on a bare walls file, the flat
    2002 grid.  Options left None come from the manifest, then the defaults.

    ``fleet`` (import-arena's ``fleet.Fleet``, the vehicles the arena was made for)
    gives the default clearance, its largest footprint radius, when its largest
    vehicle is not the one build-navgrid would take from the vehicles on disk.

    On a bundle with its model and [grids] tables, the smaller vehicles' grids are
    built too (``BuiltGrid.vehicles``), of the same walkable surface reseeded
    (``base``: the larger grid's, see :func:`_smaller_vehicles`) where each built it again.

    ``analysed`` ({"params", "surface"}: import-arena's analysed surface of the bundle's
    model, on the model lattice, the import's only reference) is reseeded instead of
    rasterising model.glb again: the same surface by construction (nav/grid_window.py)."""
    import numpy as np

    from .nav.navgrid import build_navgrid as build, free_space, grid_shape
    from .nav.quadtree import WallQuadtree

    _number("cell", cell, 0.0, True)
    _number("clearance", clearance, 0.0, False)
    if quadtree_depth is not None and not 0 <= quadtree_depth <= 10:
        raise ArenaError(f"--quadtree-depth must be 0..10, got {quadtree_depth}")
    cell, quadtree_depth = settings(target, cell, quadtree_depth)
    source = "--clearance"
    if clearance is None:
        clearance, source = default_clearance(target, warn)
        # import-arena's vehicles are not those on disk (a test's, a broken bundle skipped)
        if fleet is not None and fleet.radius_of != "built-in default" and f"'{fleet.radius_of}'" not in source:
            clearance, source = float(fleet.radius), f"footprint radius of vehicle '{fleet.radius_of}'"
    bounds = target.bounds
    shape = grid_shape(bounds, cell)  # refuses absurd grids before any work
    ext = np.asarray(bounds)[1] - np.asarray(bounds)[0]
    if min(shape) < 3:
        raise ArenaError(f"--cell {cell:g} m leaves {shape[1]} x {shape[0]} nodes over the {ext[0]:g} x {ext[1]:g} m "
                         f"arena: use a cell of at most {min(ext) / 3:g} m")
    params = None
    if target.model is not None:
        from .arena import walkable_params
        from .fleet import bundled_fleet

        wk = target.toml.get("walkable", {})
        fleet = bundled_fleet(vehicles_dir(), warn=warn)
        params, _ = walkable_params(cell, max_slope, climb, headroom, fleet, wk if isinstance(wk, dict) else {})
    elif any(v is not None for v in (max_slope, climb, headroom)):
        raise ArenaError(f"{target.out_dir}: --max-slope, --climb and --headroom need an arena bundle with its "
                         "model (a bare walls file has no surface)")
    import scipy.ndimage  # noqa: F401  (imported before the clock starts: regions use it)

    t0 = time.perf_counter()
    if params is not None:
        reuse = base if base is not None and base["params"] == params else None
        if reuse is None and analysed is not None and analysed["params"] == params:
            # import-arena's surface of this model on the same lattice: not built again
            reuse = {"surface": _handed_over(analysed)}
        grid, free, surface = _layered(target, params, clearance, bounds, reuse)
        analysed = reuse = None
    else:
        surface = None
        grid = build(target.walls, cell, clearance, spawns=target.spawns, bounds=bounds, progress=progress)
        free = free_space(target.walls, grid.origin, cell, shape)
    tree = WallQuadtree.build(target.walls.segments, bounds, depth=quadtree_depth)
    built = BuiltGrid(grid, tree, free, cell, float(clearance), source, quadtree_depth, params)
    if surface is not None and base is None:  # while the surface is alive; stage_grid_files writes them
        shared = {"params": params, "surface": surface}
        del surface  # the vehicles' grids let go of it as soon as they can
        _smaller_vehicles(target, built, shared)
    built.seconds = time.perf_counter() - t0
    return built


def _handed_over(analysed: dict[str, Any]) -> Any:
    """import-arena's analysed surface, taken out of ``analysed`` (the caller's last
    reference), without its played region and levels: the reseed finds them anew, and
    the old levels beside the new ones were +0.13 GB at a 2 km terrain's peak."""
    import numpy as np

    s = analysed.pop("surface")
    s.main, s.level = np.zeros(0, dtype=bool), np.zeros(0, dtype=s.level.dtype)
    return s


def _smaller_vehicles(target: Target, built: BuiltGrid, shared: dict[str, Any]) -> None:
    """The grids of the smaller vehicles of ``target``'s [grids] into ``built.vehicles``,
    each of ``shared["surface"]`` (the larger grid's, its only reference) reseeded.
    Its played region and levels are the larger grid's, done with: they go first; the
    last vehicle takes the surface out of ``shared``, so what its grid does not read
    goes before that grid is built (~0.4 GB on a 2 km terrain)."""
    import numpy as np

    vehicles = list(vehicle_grids(target.toml, target.manifest).items())
    if not vehicles:
        return
    surface = shared["surface"]
    # the larger grid's levels, a byte a span: a reseed that finds them again gives a
    # grid of the same nodes, heights and links (_layered shares them)
    shared["levels"] = surface.level.astype(np.int8) if surface.levels < 127 else None
    shared["grid"] = built.grid
    surface.main, surface.level = np.zeros(0, dtype=bool), np.zeros(0, dtype=surface.level.dtype)
    del surface
    for k, (name, (c, spawns)) in enumerate(vehicles):
        shared["last"] = k == len(vehicles) - 1
        built.vehicles[name] = build_grid(dataclasses.replace(target, spawns=spawns), cell=built.cell, clearance=c,
                                          quadtree_depth=built.quadtree_depth, base=shared,
                                          **_surface_options(built.params))


def _layered(target: Target, params: Any, clearance: float, bounds: Any, base: Any = None) -> tuple[Any, Any, Any]:
    """The layered grid of a bundle: its model's walkable surface on the model lattice,
    the nodes cut to the walls' bounds (nav/grid_window.py: the rule both commands
    follow), valid where a node keeps ``clearance`` from the walls of its level
    (``base``: {"surface": a surface of the same model and settings, "last": ...,
    "levels", "grid"}, reseeded; see :func:`_smaller_vehicles`).
    Returns (grid, mask of nodes that exist, for the picture, the surface or None)."""
    import numpy as np

    from .nav.arena_levels import walls_too_close
    from .nav.grid_window import grid_window, model_lattice, window_nodes
    from .nav.walkable import grid_from_layers, grid_from_surface, level_nodes, reseed, walkable_surface

    seeds = None
    if target.spawns is not None:  # [x, z] and the spawn's height when the manifest has it
        sp = np.asarray(target.spawns, dtype=np.float64)
        seeds = sp[:, [0, 1, 3]] if sp.shape[1] >= 4 else sp[:, :2]
    old = base["surface"] if base is not None else None
    if old is not None:
        surface = reseed(old, clearance, seeds)
        del old
        if base.get("last"):  # its only reference: what the grid does not read goes now
            base["surface"] = None
            surface.floor = np.zeros(0, dtype=surface.floor.dtype)
            surface.region = np.zeros(0, dtype=surface.region.dtype)
    else:
        del old
        vertices, faces = _model_triangles(target.model)
        gc.collect()   # the scene read is cyclic garbage (~0.2 GB on a 2 km terrain) the surface would stack on
        origin, shape = model_lattice(vertices, params.cell)
        surface = walkable_surface(vertices, faces, params, clearance, origin_xz=origin, shape=shape,
                                   seeds=seeds, lean=True)   # its grid reads the walls' distance (too_close)
        del vertices, faces
    if not surface.main.any():
        raise ArenaError(f"{target.model}: no walkable surface (max slope {params.max_slope:g} deg, "
                         f"headroom {params.headroom:g} m)")
    w = grid_window(surface.hf.origin[[0, 2]], params.cell, bounds)
    levels = max(surface.levels, 1)
    tc = walls_too_close(target.walls, w.origin, params.cell, w.shape, levels, clearance)
    if base is not None and base.get("levels") is not None and np.array_equal(surface.level, base["levels"]):
        # the larger grid's levels again: its nodes (a finite height), heights and links
        # are this grid's; the surface (~0.75 GB on a 2 km terrain) goes before it is built
        g0, cell = base["grid"], surface.hf.cs
        del surface
        if base.get("last"):
            base["surface"] = None
            give_back(GIVE_BACK_MIN)
        nodes = np.isfinite(g0.height)
        grid = grid_from_layers(nodes & ~tc, g0.height, g0.link, clearance, w.origin, cell, seeds=target.spawns)
        return grid, (nodes[0] if grid.levels == 1 else None), None
    grid = grid_from_surface(surface, clearance, w.origin, seeds=target.spawns, too_close=tc, window=w)
    return grid, (window_nodes(level_nodes(surface), w) if grid.levels == 1 else None), surface


def _model_triangles(model: Path) -> tuple[Any, Any]:
    """The bundle model's vertices and faces in the world frame, all objects joined as
    ``load_model`` joins them (in order, faces offset), without joining their materials:
    packing the textures into one atlas took more time than the surface on a textured arena."""
    import numpy as np
    import trimesh

    from .formats.models import load_scene

    meshes = [m for m in load_scene(model, up="y").dump() if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    if not meshes:
        raise ArenaError(f"{model}: the model has no triangles")
    starts = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    vertices = np.vstack([np.asarray(m.vertices, dtype=np.float64) for m in meshes])
    faces = np.vstack([np.asarray(m.faces, dtype=np.int64) + k for m, k in zip(meshes, starts)])
    return vertices, faces


def render_picture(built: BuiltGrid, target: Target, fmt: str = "png", annotate: str = "both",
                   region: Any = None) -> bytes:
    """The grid's picture (plots/navgrid.py), rendered in memory."""
    from .plots.navgrid import render_navgrid

    return render_navgrid(built.grid, target.walls, fmt=fmt, quadtree=built.tree, free=built.free,
                          spawns=target.spawns, annotate=annotate, region=region, title=target.name)


def _surface_options(params: Any) -> dict[str, float]:
    """build_grid's max_slope / climb / headroom of a grid's walkable surface."""
    if params is None:
        return {}
    return {"max_slope": params.max_slope, "climb": params.climb, "headroom": params.headroom}


def packed_grids(built: BuiltGrid) -> dict[str, bytes]:
    """The npz bytes of ``built``'s grid and of its smaller vehicles' ({file name: bytes})."""
    out = {"navgrid.npz": built.grid.to_bytes()}
    for name, own in built.vehicles.items():
        file = vehicle_file(name)
        if file is not None:
            out[str(file)] = own.grid.to_bytes()
    return out


def picture_and_grids(built: BuiltGrid, target: Target) -> tuple[bytes, dict[str, bytes]]:
    """(:func:`render_picture`, :func:`packed_grids`), the grids compressed in a thread
    while the picture is drawn: zlib lets go of the GIL, so on a second core the
    writing's compression (~0.2 s of CPU a grid on hix) costs no wall time."""
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1) as pool:
        packed = pool.submit(packed_grids, built)
        picture = render_picture(built, target)
        return picture, packed.result()


def stage_grid_files(stage: Path, target: Target, built: BuiltGrid, picture: bytes | None,
                     packed: dict[str, bytes] | None = None) -> dict[str, Any]:
    """Write navgrid.npz, quadtree.npz (and navgrid.png when ``picture`` is given) into
    the folder ``stage`` and return ``target``'s manifest with its [navgrid],
    [walkable] and [derived] entries updated for them (the caller writes it).
    ``packed``: the grids' bytes already made (:func:`picture_and_grids`)."""
    from .formats.bundle import atomic_write_bytes, sha256_file

    packed = dict(packed or {})
    atomic_write_bytes(stage / "navgrid.npz", packed.pop("navgrid.npz", None) or built.grid.to_bytes())
    built.tree.save(stage / "quadtree.npz")
    if picture is not None:
        atomic_write_bytes(stage / "navgrid.png", picture)
    doc = dict(target.toml)
    derived = {k: v for k, v in doc.get("derived", {}).items() if not (is_grid_file(k) and k not in FILES)}
    grids, own_hashes = {}, {}
    for name, (clearance, spawns) in vehicle_grids(doc, target.manifest).items():
        # the same surface and settings, the vehicle's clearance, reachable from its own spawns
        own = built.vehicles.get(name)
        file = str(vehicle_file(name))
        if own is None or own.clearance != clearance:   # a bare walls file's (build_grid made a bundle's)
            own = build_grid(dataclasses.replace(target, spawns=spawns), cell=built.cell, clearance=clearance,
                             quadtree_depth=built.quadtree_depth, **_surface_options(built.params))
            built.vehicles[name] = own
            packed.pop(file, None)   # the grid packed was another's
        atomic_write_bytes(stage / file, packed.pop(file, None) or own.grid.to_bytes())
        own_hashes[file] = sha256_file(stage / file)
        grids[name] = {**doc["grids"][name], "file": file}
    if grids:
        doc["grids"] = grids
    doc["navgrid"] = {**doc.get("navgrid", {}), "cell": float(built.cell), "clearance": float(built.clearance),
                      "quadtree_depth": int(built.quadtree_depth)}
    if built.params is not None:  # the surface this grid was built from
        doc["walkable"] = built.params.as_toml()
    for name in FILES:
        if name != "navgrid.png" or picture is not None:
            derived[name] = sha256_file(stage / name)
    doc["derived"] = {**derived, **own_hashes}     # after the others: a rebuild writes the same manifest
    return doc
