"""``tanktool build-navgrid ARENA``: the wall quadtree and the AI navigation grid.

ARENA is an arena bundle folder (outputs go into it and their sha256 into its
``arena.toml``) or a bare ``walls.txt`` (outputs go next to it).  Everything is
computed and rendered in memory first; only then are the files written, each through
a temporary file and a rename, ``arena.toml`` last.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import click

from ..errors import ArenaError
from .main import echo, is_quiet
from .options import progress

#: where bundled vehicles live (the largest footprint sets the default clearance)
def _vehicles_dir() -> Path:
    from ..content import CHECKOUT, bundled_dir

    return bundled_dir("vehicles") or CHECKOUT / "vehicles"


VEHICLES_DIR = _vehicles_dir()
DEFAULTS = {"cell": 0.5, "clearance": 2.0, "quadtree_depth": 3}
#: show a progress bar from this many nodes up
PROGRESS_NODES = 1_000_000


@dataclass
class Target:
    """What build-navgrid works on: walls, where outputs go, and the bundle's manifest."""

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
    from ..arena import load_arena
    from ..formats.walls_txt import read_walls

    if path.is_file() and path.name == "arena.toml":
        path = path.parent
    if not path.exists():
        raise ArenaError(f"{path}: no such arena folder or walls file")
    if path.is_file():
        if (path.parent / "arena.toml").is_file():
            raise ArenaError(f"{path} belongs to the arena bundle {path.parent}: run build-navgrid on the bundle "
                             f"folder (its grid then follows the model and arena.toml stays current)")
        from ..formats.models import refuse_model

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


def _layered(target: Target, params, clearance: float, bounds, shape):
    """The layered grid of a bundle: its model's walkable surface on the grid over the
    bounds, valid where a node keeps ``clearance`` from the walls of its level.
    Returns (grid, mask of nodes that exist, for the picture)."""
    import numpy as np

    from ..formats.models import load_model
    from ..nav.arena_levels import walls_too_close
    from ..nav.walkable import grid_from_surface, walkable_surface

    mesh = load_model(target.model, up="y")
    origin = np.asarray(bounds, dtype=np.float64)[0]
    seeds = None
    if target.spawns is not None:  # [x, z] and the spawn's height when the manifest has it
        sp = np.asarray(target.spawns, dtype=np.float64)
        seeds = sp[:, [0, 1, 3]] if sp.shape[1] >= 4 else sp[:, :2]
    surface = walkable_surface(mesh.vertices, mesh.faces, params, clearance, origin_xz=origin, shape=shape,
                               seeds=seeds)
    if not surface.main.any():
        raise ArenaError(f"{target.model}: no walkable surface (max slope {params.max_slope:g} deg, "
                         f"headroom {params.headroom:g} m)")
    levels = max(surface.levels, 1)
    tc = walls_too_close(target.walls, origin, params.cell, shape, levels, clearance)
    grid = grid_from_surface(surface, clearance, origin, seeds=target.spawns, too_close=tc)
    from ..nav.walkable import surface_layers

    exists = surface_layers(surface)[0]
    return grid, (exists[0] if grid.levels == 1 else None)


def default_clearance(target: Target) -> tuple[float, str]:
    """The footprint radius of the largest bundled vehicle (of those that fit in the
    arena, when import-arena found the larger ones fit nowhere: arena.toml
    [vehicles]), else arena.toml's value."""
    from ..formats.bundle import read_toml

    fits = target.toml.get("vehicles", {})
    r = fits.get("radius") if isinstance(fits, dict) else None
    if fits.get("too_big") and isinstance(r, (int, float)) and not isinstance(r, bool) and math.isfinite(r) and r > 0:
        return float(r), f"footprint radius of vehicle '{fits.get('largest')}', the largest that fits"
    best: tuple[float, str] | None = None
    for vt in sorted(VEHICLES_DIR.glob("*/vehicle.toml")):
        try:
            r = read_toml(vt).get("footprint_radius")
            if not isinstance(r, (int, float)) or isinstance(r, bool):
                from ..formats.vehicle_bundle import load_vehicle

                r = load_vehicle(vt.parent).footprint_radius
        except Exception as e:  # a broken vehicle must not stop the arena tools
            click.echo(f"warning: {vt}: skipped for the default clearance ({e})", err=True)
            continue
        if math.isfinite(r) and r > 0 and (best is None or r > best[0]):
            best = (float(r), f"footprint radius of vehicle '{vt.parent.name}'")
    if best is not None:
        return best
    r = target.toml.get("navgrid", {}).get("clearance")
    if isinstance(r, (int, float)) and not isinstance(r, bool) and math.isfinite(r) and r >= 0:
        return float(r), "arena.toml [navgrid] clearance"
    return DEFAULTS["clearance"], "built-in default"


def parse_region(text: str | None, bounds) -> Any:
    """``x0,z0,x1,z1`` -> [[x0, z0], [x1, z1]], checked against the grid's bounds."""
    import numpy as np

    if text is None:
        return None
    parts = text.replace(" ", "").split(",")
    try:
        v = [float(p) for p in parts]
    except ValueError:
        raise ArenaError(f"--region: expected four numbers x0,z0,x1,z1, got {text!r}") from None
    if len(v) != 4 or not all(math.isfinite(a) for a in v):
        raise ArenaError(f"--region: expected four numbers x0,z0,x1,z1, got {text!r}")
    x0, z0, x1, z1 = v
    if not (x1 > x0 and z1 > z0):
        raise ArenaError(f"--region: need x0 < x1 and z0 < z1, got {text}")
    if x1 < bounds[0][0] or x0 > bounds[1][0] or z1 < bounds[0][1] or z0 > bounds[1][1]:
        raise ArenaError(f"--region {text} lies outside the arena bounds {np.asarray(bounds).tolist()}")
    return np.array([[x0, z0], [x1, z1]])


def _number_option(name: str, value: float | None, lo: float, lo_open: bool) -> None:
    if value is None:
        return
    bad = not math.isfinite(value) or (value <= lo if lo_open else value < lo)
    if bad:
        raise ArenaError(f"--{name} must be {'>' if lo_open else '>='} {lo:g}, got {value:g}")


@click.command("build-navgrid")
@click.argument("arena", type=click.Path(path_type=Path))
@click.option("--cell", type=float, default=None, help="Node spacing in metres (default: arena.toml [navgrid] cell, else 0.5).")
@click.option("--clearance", type=float, default=None,
              help="Minimum distance from a valid node to every wall, metres (default: the largest bundled vehicle's footprint radius).")
@click.option("--max-slope", type=float, default=None, metavar="DEG",
              help="Steepest walkable slope in degrees (default: arena.toml [walkable], else 35).")
@click.option("--climb", type=float, default=None, metavar="M",
              help="Highest step between neighbouring nodes, metres (default: arena.toml [walkable], else 0.9).")
@click.option("--headroom", type=float, default=None, metavar="M",
              help="Free height a node needs, metres (default: arena.toml [walkable], else the tallest bundled vehicle).")
@click.option("--quadtree-depth", type=int, default=None, help="Levels below the root (default 3: 64 leaves).")
@click.option("--plot", "plot_path", type=click.Path(path_type=Path), default=None,
              help="Picture to write, .png or .svg (default: navgrid.png in the bundle, or NAME.navgrid.png beside a walls file).")
@click.option("--annotate", type=click.Choice(["rows", "cols", "both", "none"]), default="both", show_default=True,
              help="Run numbers printed on the nodes when they are readable.")
@click.option("--region", default=None, metavar="X0,Z0,X1,Z1", help="Zoom the picture (and --table) to this rectangle.")
@click.option("--table", "table_path", type=click.Path(path_type=Path), default=None,
              help="Also write the 2002-style text table, one node a line.")
def build_navgrid(arena: Path, cell: float | None, clearance: float | None, max_slope: float | None,
                  climb: float | None, headroom: float | None, quadtree_depth: int | None,
                  plot_path: Path | None, annotate: str, region: str | None, table_path: Path | None) -> None:
    """Build ARENA's wall quadtree and AI navigation grid, save them, and plot them.

    ARENA is an arena bundle folder or a bare walls.txt file.  In a bundle the grid
    follows the model's walkable surface: nodes on every level (a deck over a passage
    has two), each with its height, linked to its neighbours across ramps and steps
    within --climb; a node is valid where it keeps --clearance from the walls of its
    level.  A bare walls file gives the flat 2002 grid of its walls.
    """
    import time

    from ..formats.bundle import atomic_write_bytes, atomic_write_text, dumps_toml, sha256_file
    from ..nav.navgrid import build_navgrid as build, format_table, free_space, grid_shape, open_ends
    from ..nav.quadtree import WallQuadtree
    from ..plots.navgrid import render_navgrid

    _number_option("cell", cell, 0.0, True)
    _number_option("clearance", clearance, 0.0, False)
    if quadtree_depth is not None and not 0 <= quadtree_depth <= 10:
        raise ArenaError(f"--quadtree-depth must be 0..10, got {quadtree_depth}")
    target = open_target(arena)
    nav_t = target.toml.get("navgrid", {})
    if not isinstance(nav_t, dict):
        raise ArenaError(f"{target.manifest}: [navgrid] must be a table")
    if cell is None:
        cell = nav_t.get("cell", DEFAULTS["cell"])
        if isinstance(cell, bool) or not isinstance(cell, (int, float)) or not (math.isfinite(cell) and cell > 0):
            raise ArenaError(f"{target.manifest}: [navgrid] cell must be a number > 0, got {cell!r}")
        cell = float(cell)
    if quadtree_depth is None:
        quadtree_depth = nav_t.get("quadtree_depth", DEFAULTS["quadtree_depth"])
        if isinstance(quadtree_depth, bool) or not isinstance(quadtree_depth, int) or not 0 <= quadtree_depth <= 10:
            raise ArenaError(f"{target.manifest}: [navgrid] quadtree_depth must be an integer 0..10, got {quadtree_depth!r}")
    source = "--clearance"
    if clearance is None:
        clearance, source = default_clearance(target)
    bounds = target.bounds
    shape = grid_shape(bounds, cell)  # refuses absurd grids before any work
    ext = bounds[1] - bounds[0]
    if min(shape) < 3:
        raise ArenaError(f"--cell {cell:g} m leaves {shape[1]} x {shape[0]} nodes over the {ext[0]:g} x {ext[1]:g} m "
                         f"arena: use a cell of at most {min(ext) / 3:g} m")
    params = None
    if target.model is not None:
        from ..arena import walkable_params
        from ..fleet import bundled_fleet

        wk = target.toml.get("walkable", {})
        fleet = bundled_fleet(VEHICLES_DIR, warn=lambda m: click.echo(f"warning: {m}", err=True))
        params, _ = walkable_params(cell, max_slope, climb, headroom, fleet, wk if isinstance(wk, dict) else {})
    elif any(v is not None for v in (max_slope, climb, headroom)):
        raise ArenaError(f"{arena}: --max-slope, --climb and --headroom need an arena bundle with its model "
                         "(a bare walls file has no surface)")
    reg = parse_region(region, bounds)
    plot_path = plot_path or target.output("navgrid.png")
    fmt = plot_path.suffix.lower().lstrip(".")
    if fmt not in ("png", "svg"):
        raise ArenaError(f"--plot {plot_path}: the picture must be .png or .svg")
    for p in [plot_path, table_path]:
        if p is not None and not p.parent.is_dir():
            raise ArenaError(f"{p}: folder {p.parent} does not exist")

    # walls in blocks per level open onto each other (a ramp's top onto the deck): their
    # ends need not close up, the surface says where the free space is
    loose = open_ends(target.walls) if not target.walls.layered else []
    if len(loose) and not is_quiet():
        x, z = loose[0]
        click.echo(
            f"warning: {target.walls.path}: {len(loose)} wall end(s) do not close up (first at {x:g}, {z:g}); "
            "free space near them depends on the direction it is scanned", err=True,
        )

    import scipy.ndimage  # noqa: F401  (imported before the clock starts: regions use it)

    t0 = time.perf_counter()
    nodes = shape[0] * shape[1]
    if params is not None:
        grid, free = _layered(target, params, clearance, bounds, shape)
    elif nodes >= PROGRESS_NODES:
        with progress(length=shape[0], label=f"classifying {nodes:,} nodes") as bar:
            grid = build(target.walls, cell, clearance, spawns=target.spawns, bounds=bounds, progress=bar.update)
    else:
        grid = build(target.walls, cell, clearance, spawns=target.spawns, bounds=bounds)
    tree = WallQuadtree.build(target.walls.segments, bounds, depth=quadtree_depth)
    t_build = time.perf_counter() - t0

    # everything rendered in memory first: a failure here writes nothing
    if params is None:
        free = free_space(target.walls, grid.origin, cell, shape)
    picture = render_navgrid(
        grid, target.walls, fmt=fmt, quadtree=tree, free=free, spawns=target.spawns,
        annotate=annotate, region=reg, title=target.name,
    )
    table = format_table(grid, reg) if table_path is not None else None
    tree_path = target.output("quadtree.npz")
    grid_path = target.output("navgrid.npz")

    if table is not None:
        atomic_write_text(table_path, table)
    if target.manifest is None:
        atomic_write_bytes(grid_path, grid.to_bytes())
        tree.save(tree_path)
        atomic_write_bytes(plot_path, picture)
    else:
        # the grid files and the manifest that hashes them change together, in one
        # atomic swap of the bundle folder (formats/bundle.py bundle_update)
        from ..formats.bundle import bundle_update

        in_bundle = plot_path.resolve().parent == target.out_dir.resolve()
        if not in_bundle:
            atomic_write_bytes(plot_path, picture)
        with bundle_update(target.out_dir) as stage:
            atomic_write_bytes(stage / grid_path.name, grid.to_bytes())
            tree.save(stage / tree_path.name)
            if in_bundle:
                atomic_write_bytes(stage / plot_path.name, picture)
            doc = dict(target.toml)
            doc["navgrid"] = {**doc.get("navgrid", {}), "cell": float(cell), "clearance": float(clearance),
                              "quadtree_depth": int(quadtree_depth)}
            if params is not None:  # the surface this grid was built from
                doc["walkable"] = params.as_toml()
            derived = dict(doc.get("derived", {}))
            derived["navgrid.npz"] = sha256_file(stage / grid_path.name)
            derived["quadtree.npz"] = sha256_file(stage / tree_path.name)
            if in_bundle and plot_path.name == "navgrid.png":
                derived["navgrid.png"] = sha256_file(stage / plot_path.name)
            doc["derived"] = derived
            atomic_write_text(stage / target.manifest.name, dumps_toml(doc))

    n_valid = int(grid.valid.sum())
    n_reach = int((grid.valid & grid.reachable).sum())
    levels = f" on {grid.levels} levels" if grid.levels > 1 else ""
    echo(
        f"{target.name}: {shape[0]} x {shape[1]} nodes{levels} at {cell:g} m, clearance {clearance:g} m ({source}): "
        f"{n_valid:,} valid, {n_reach:,} reachable, {n_valid - n_reach:,} unreachable "
        f"({t_build * 1000:.0f} ms)"
    )
    if params is not None:
        hv = grid.heights()[grid.layered("valid")]
        if grid.levels > 1:
            per = ", ".join(f"level {k}: {int(v.sum()):,}" for k, v in enumerate(grid.layered("valid")))
            echo(f"  {per}")
        if len(hv):
            echo(f"  heights y {hv.min():.2f} .. {hv.max():.2f}; walkable: {params.describe()}")
    if n_valid == 0 and not is_quiet():
        click.echo(f"warning: {target.name}: no valid node: no tank of clearance {clearance:g} m fits anywhere", err=True)
    if target.spawns is not None and len(grid.spawn_nodes) < len(target.spawns) and not is_quiet():
        click.echo(f"warning: {len(target.spawns) - len(grid.spawn_nodes)} spawn point(s) have no valid node nearby", err=True)
    wrote = [str(grid_path), f"{tree_path} ({len(tree.leaves)} leaves, depth {tree.max_depth})", str(plot_path)]
    if table_path is not None:
        wrote.append(str(table_path))
    if target.manifest is not None:
        wrote.append(f"{target.manifest} (hashes)")
    echo("wrote " + ", ".join(wrote))
