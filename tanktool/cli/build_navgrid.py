"""``tanktool build-navgrid ARENA``: the wall quadtree and the AI navigation grid.

ARENA is an arena bundle folder (outputs go into it and their sha256 into its
``arena.toml``) or a bare ``walls.txt`` (outputs go next to it).  Everything is
computed and rendered in memory first; only then are the files written, each through
a temporary file and a rename, ``arena.toml`` last.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from ..errors import ArenaError
from .main import echo, is_quiet
from .options import progress

#: show a progress bar from this many nodes up
PROGRESS_NODES = 1_000_000


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
    from ..grid_files import open_target, render_picture
    from ..nav.navgrid import format_table

    def warn(message: str) -> None:
        click.echo(f"warning: {message}", err=True)

    target = open_target(arena)
    reg = parse_region(region, target.bounds)
    plot_path = plot_path or target.output("navgrid.png")
    fmt = plot_path.suffix.lower().lstrip(".")
    if fmt not in ("png", "svg"):
        raise ArenaError(f"--plot {plot_path}: the picture must be .png or .svg")
    for p in [plot_path, table_path]:
        if p is not None and not p.parent.is_dir():
            raise ArenaError(f"{p}: folder {p.parent} does not exist")

    _warn_open_ends(target)
    kw = dict(cell=cell, clearance=clearance, max_slope=max_slope, climb=climb, headroom=headroom,
              quadtree_depth=quadtree_depth, warn=warn)
    built = _build(target, cell, kw)
    grid, tree = built.grid, built.tree

    # everything rendered in memory first: a failure here writes nothing
    picture = render_picture(built, target, fmt, annotate, reg)
    table = format_table(grid, reg) if table_path is not None else None
    tree_path = target.output("quadtree.npz")
    grid_path = target.output("navgrid.npz")

    _write_files(target, built, picture, table, table_path, plot_path, grid_path, tree_path)
    _report(target, built)
    wrote = [str(grid_path), f"{tree_path} ({len(tree.leaves)} leaves, depth {tree.max_depth})", str(plot_path)]
    for name, own in built.vehicles.items():     # one grid per smaller vehicle ([grids] of arena.toml)
        g = own.grid
        echo(f"  {name}: clearance {own.clearance:g} m, {int(g.valid.sum()):,} valid, "
             f"{int((g.valid & g.reachable).sum()):,} reachable from its own spawns ({own.seconds * 1000:.0f} ms)")
        wrote.append(str(target.out_dir / f"navgrid.{name}.npz"))
    if table_path is not None:
        wrote.append(str(table_path))
    if target.manifest is not None:
        wrote.append(f"{target.manifest} (hashes)")
    echo("wrote " + ", ".join(wrote))


def _warn_open_ends(target: Any) -> None:
    """Warn when a flat walls file's walls leave ends open."""
    from ..nav.navgrid import open_ends

    # walls in blocks per level open onto each other (a ramp's top onto the deck): their
    # ends need not close up, the surface says where the free space is
    loose = open_ends(target.walls) if not target.walls.layered else []
    if len(loose) and not is_quiet():
        x, z = loose[0]
        click.echo(
            f"warning: {target.walls.path}: {len(loose)} wall end(s) do not close up (first at {x:g}, {z:g}); "
            "free space near them depends on the direction it is scanned", err=True,
        )


def _build(target: Any, cell: float | None, kw: dict[str, Any]) -> Any:
    """build_grid, with a progress bar on a large flat grid."""
    from ..grid_files import build_grid, settings
    from ..nav.navgrid import grid_shape

    nodes = 0
    if target.model is None and (cell is None or (math.isfinite(cell) and cell > 0)):
        shape0 = grid_shape(target.bounds, settings(target, cell, None)[0])
        nodes = shape0[0] * shape0[1]
    if nodes >= PROGRESS_NODES:
        with progress(length=shape0[0], label=f"classifying {nodes:,} nodes") as bar:
            built = build_grid(target, progress=bar.update, **kw)
    else:
        built = build_grid(target, **kw)
    return built


def _write_files(target: Any, built: Any, picture: bytes, table: str | None, table_path: Path | None,
                 plot_path: Path, grid_path: Path, tree_path: Path) -> None:
    """Write the table, grid, quadtree and picture (in a bundle: with its manifest, in one swap)."""
    from ..formats.bundle import atomic_write_bytes, atomic_write_text, dumps_toml
    from ..grid_files import stage_grid_files

    grid, tree = built.grid, built.tree
    if table is not None:
        atomic_write_text(table_path, table)
    if target.manifest is None:
        atomic_write_bytes(grid_path, grid.to_bytes())
        tree.save(tree_path)
        atomic_write_bytes(plot_path, picture)
    else:
        # the grid files and the manifest that hashes them change together, in one
        # atomic swap of the bundle folder (formats/bundle.py bundle_update)
        from ..formats.bundle_swap import bundle_update

        in_bundle = plot_path.resolve().parent == target.out_dir.resolve() and plot_path.name == "navgrid.png"
        if not in_bundle:
            atomic_write_bytes(plot_path, picture)
        with bundle_update(target.out_dir) as stage:
            doc = stage_grid_files(stage, target, built, picture if in_bundle else None)
            atomic_write_text(stage / target.manifest.name, dumps_toml(doc))


def _report(target: Any, built: Any) -> None:
    """The summary line, the per-level counts and heights, and the warnings on valid nodes and spawns."""
    grid, params = built.grid, built.params
    cell, clearance, source, t_build = built.cell, built.clearance, built.clearance_source, built.seconds
    shape = grid.shape
    n_valid = int(grid.valid.sum())
    n_reach = int((grid.valid & grid.reachable).sum())
    levels = f" on {grid.levels} levels" if grid.levels > 1 else ""
    echo(
        f"{target.name}: {shape[0]} x {shape[1]} nodes{levels} at {cell:g} m, clearance {clearance:g} m ({source}): "
        f"{n_valid:,} valid, {n_reach:,} reachable, {n_valid - n_reach:,} unreachable "
        f"({t_build * 1000:.0f} ms)"
    )
    if params is not None:
        hv = grid.heights()[grid.valid]
        if grid.levels > 1:
            per = ", ".join(f"level {k}: {int(v.sum()):,}" for k, v in enumerate(grid.valid))
            echo(f"  {per}")
        if len(hv):
            echo(f"  heights y {hv.min():.2f} .. {hv.max():.2f}; walkable: {params.describe()}")
    if n_valid == 0 and not is_quiet():
        click.echo(f"warning: {target.name}: no valid node: no tank of clearance {clearance:g} m fits anywhere", err=True)
    if target.spawns is not None and len(grid.spawn_nodes) < len(target.spawns) and not is_quiet():
        click.echo(f"warning: {len(target.spawns) - len(grid.spawn_nodes)} spawn point(s) have no valid node nearby", err=True)
