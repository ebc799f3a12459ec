"""Rules on an arena's walkable levels and its navigation grid (A309 - A315).

An arena imported from a model with terrain, ramps or several floors has walls in
blocks, one per region of a level (formats.walls_txt).  Its walls do not close up on
their own -- a ramp's top opens onto the deck above -- so the free-space analysis of
flat arenas (leaks, islands, spawns in faces) does not apply to it; the navigation
grid, built from the model's walkable surface and measured against those walls, says
instead where a tank can stand and where it can drive:

* A309 the grid has no node a tank can use (valid and reachable from the spawns);
* A310 a level has valid nodes but none reachable from the spawns;
* A311 a spawn stands on a small island: the part of the grid it can reach is small
  beside the largest part;
* A312 the walkable surface was found for less headroom than a vehicle is tall;
* A313 the ground under a spawn is a slope of more than half the maximum slope, or
  steps more than the climb off that slope, within the largest vehicle's footprint;
* A314 a spawn is on no node where the grid's tank fits (layered arenas);
* A315 a spawn cannot be reached from the others over the grid (layered arenas).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..formats.walls_txt import WallList
from .diagnostics import Diagnostic, diag, fmt_xz
from .manifest import Manifest, safe_file
from .walls_rules import pair_rules, zero_length

#: a spawn's reachable part of the grid is an island below this share of the largest part
ISLAND_SHARE = 0.2


def block_wall_rules(walls: WallList, path: str, grid: float) -> list[Diagnostic]:
    """Zero-length walls, and duplicates / overlaps / crossings within each block (walls
    of different regions may cross: they stand at different heights)."""
    out = zero_length(walls, path)
    for r in np.unique(walls.region):
        sel = walls.region == r
        out += pair_rules(walls.select(sel), grid)
    return out


def _number(man: Manifest, table: str, key: str) -> float | None:
    v = man.get(table, key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        return None
    return float(v)


def load_grid(man: Manifest, bundle: Path, out: list[Diagnostic]):
    """The bundle's navgrid.npz, or None (with a B201 when it exists but is broken)."""
    from ..errors import FormatError
    from ..nav.navgrid import NavGrid

    path = safe_file(bundle, "navgrid.npz")
    if path is None or not path.is_file():
        return None
    try:
        return NavGrid.load(path)
    except FormatError as e:
        out.append(diag("B201", str(man.path), man.lines.table("navgrid"), f"navgrid.npz cannot be read: {e}"))
        return None


def _components(grid) -> np.ndarray:
    """Labels (L, nz, nx) of the grid's valid nodes joined by links (0: no node)."""
    from ..nav.arena_levels import grid_components as comps

    return comps(grid)[0]


def spawn_nodes(grid, spawns: np.ndarray, ys: np.ndarray) -> list[tuple[int, int, int] | None]:
    """The valid node under each spawn (level by its height, else the nearest valid
    level there), within one cell; None where there is none."""
    from ..nav.navgrid import nearest_valid_node3

    valid = grid.valid
    height = grid.heights()
    out = []
    for (x, z), y in zip(spawns[:, :2], ys):
        n = nearest_valid_node3(valid, height, grid.node_of(x, z), None if not math.isfinite(y) else float(y), 1)
        out.append(n)
    return out


def level_rules(man: Manifest, bundle: Path, spawns: np.ndarray, ys: np.ndarray, lines: list[int],
                ids: np.ndarray, vehicles: list, layered: bool) -> list[Diagnostic]:
    """A309 - A315 (see the module docstring)."""
    out: list[Diagnostic] = []
    mpath = str(man.path)
    head = _number(man, "walkable", "headroom")
    climb = _number(man, "walkable", "climb")
    if head is not None and vehicles:
        tall = max(vehicles, key=lambda v: getattr(v, "height", 0.0))
        if getattr(tall, "height", 0.0) > head + 0.01:
            out.append(diag("A312", mpath, man.lines.key("walkable", "headroom"),
                            f"the walkable surface was found for {head:g} m of headroom, but vehicle {tall.name!r} "
                            f"is {tall.height:.2f} m tall: it would drive under ceilings it hits"))
    grid = load_grid(man, bundle, out)
    if grid is None:
        return out
    valid = grid.valid
    usable = valid & grid.reachable
    if not usable.any():
        out.append(diag("A309", mpath, man.lines.table("navgrid"),
                        f"the navigation grid has no node a tank can use: {int(valid.sum()):,} valid, none reachable "
                        f"from the spawn points (clearance {grid.clearance if math.isfinite(grid.clearance) else '?'} m)"))
        return out
    for lv in range(grid.levels):
        if valid[lv].any() and not usable[lv].any():
            i, j = np.argwhere(valid[lv])[0]
            out.append(diag("A310", mpath, man.lines.table("navgrid"),
                            f"level {lv} of the navigation grid ({int(valid[lv].sum()):,} valid nodes, e.g. at "
                            f"{fmt_xz(grid.centre(int(i), int(j)))}) cannot be reached from the spawn points"))
    if len(spawns) == 0:
        return out
    labels = _components(grid)
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    largest = int(sizes.max())
    nodes = spawn_nodes(grid, spawns, ys)
    height = grid.heights()
    big = max(vehicles, key=lambda v: v.radius) if vehicles else None
    seen = []
    for k, n in enumerate(nodes):
        where = f"spawn {ids[k] if k < len(ids) else k} at {fmt_xz(spawns[k, :2])}"
        if n is None:
            if layered:
                out.append(diag("A314", mpath, lines[k],
                                f"{where} is on no node of the navigation grid where its tank fits "
                                f"(clearance {grid.clearance:g} m)"))
            continue
        lab = labels[n]
        seen.append(lab)
        if sizes[lab] < ISLAND_SHARE * largest:
            area = sizes[lab] * grid.cell * grid.cell
            out.append(diag("A311", mpath, lines[k],
                            f"{where} stands on an island of {area:,.0f} m^2 of the grid (the largest part has "
                            f"{largest * grid.cell * grid.cell:,.0f} m^2)"))
        if big is not None:
            from ..nav.arena_levels import ground_under

            slope, rough = ground_under(height, n, grid.cell, big.radius)
            max_slope = _number(man, "walkable", "max_slope")
            steep = max_slope is not None and slope > 0.5 * max_slope
            uneven = climb is not None and rough > climb
            if steep or uneven:
                what = f"a slope of {slope:.0f} deg" if steep else f"ground {rough:.2f} m off level"
                out.append(diag("A313", mpath, lines[k],
                                f"{where}: vehicle {big.name!r} spawns on {what} (max slope "
                                f"{max_slope if max_slope is not None else '?'} deg, climb {climb if climb is not None else '?'} m)"))
    if layered and len(set(seen)) > 1:
        first = seen[0]
        for k, n in enumerate(nodes):
            if n is not None and labels[n] != first:
                out.append(diag("A315", mpath, lines[k],
                                f"spawn {ids[k] if k < len(ids) else k} at {fmt_xz(spawns[k, :2])} cannot be reached "
                                f"over the navigation grid from spawn {ids[0] if len(ids) else 0}"))
    return out
