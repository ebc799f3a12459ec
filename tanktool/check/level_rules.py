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

Each smaller vehicle's own grid (``navgrid.<vehicle>.npz``, arena.toml ``[grids.<vehicle>]``)
gets the same rules with its own spawns, A314 and A315 on flat arenas too (no free-space
rule looks at those spawns).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
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


def load_grid(man: Manifest, bundle: Path, out: list[Diagnostic], name: str = "navgrid.npz"):
    """The bundle's navgrid.npz (or a vehicle's ``name``), or None (with a B201 when it
    exists but is broken)."""
    from ..errors import FormatError
    from ..nav.navgrid import NavGrid

    path = safe_file(bundle, name)
    if path is None or not path.is_file():
        return None
    try:
        return NavGrid.load(path)
    except FormatError as e:
        out.append(diag("B201", str(man.path), man.lines.table("navgrid"), f"{name} cannot be read: {e}"))
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
    """A309 - A315 (see the module docstring), on navgrid.npz with the arena's spawns and
    on each smaller vehicle's navgrid.<vehicle>.npz with its own ([grids.<vehicle>])."""
    out: list[Diagnostic] = []
    mpath = str(man.path)
    head = _number(man, "walkable", "headroom")
    if head is not None and vehicles:
        tall = max(vehicles, key=lambda v: getattr(v, "height", 0.0))
        if getattr(tall, "height", 0.0) > head + 0.01:
            out.append(diag("A312", mpath, man.lines.key("walkable", "headroom"),
                            f"the walkable surface was found for {head:g} m of headroom, but vehicle {tall.name!r} "
                            f"is {tall.height:.2f} m tall: it would drive under ceilings it hits"))
    grid = load_grid(man, bundle, out)
    if grid is not None:
        big = max(vehicles, key=lambda v: v.radius) if vehicles else None
        out += _grid_rules(man, grid, _Spawns(spawns, ys, lines, ids, "spawn"), big, layered, "the navigation grid")
    for name, (clearance, own) in _vehicle_grids(man).items():
        from ..formats.vehicle_grids import vehicle_file

        file = str(vehicle_file(name))
        g = load_grid(man, bundle, out, file)
        if g is None:
            continue        # missing: B202 (check/manifest.py)
        if not math.isfinite(g.clearance):     # the file does not keep it: the manifest does
            g.clearance = clearance
        line = man.lines.key(f"grids.{name}", "spawns")
        sp = _Spawns(own[:, :3], own[:, 3], [line] * len(own), np.arange(len(own)), f"{name}'s spawn")
        vehicle = next((v for v in vehicles if v.name == name), None)
        # no free-space spawn rules cover these spawns on a flat arena: A314/A315 always
        out += _grid_rules(man, g, sp, vehicle, True, file)
    return out


def _vehicle_grids(man: Manifest) -> dict:
    """[grids.<vehicle>] of the manifest ({} when malformed: vehicle_grid_files reports it)."""
    from ..errors import ArenaError
    from ..formats.vehicle_grids import vehicle_grids

    try:
        return vehicle_grids(man.doc or {}, man.path)
    except ArenaError:
        return {}


@dataclass
class _Spawns:
    """Spawn points checked against a grid: (k, 3) [x, z, heading], heights, manifest
    lines, ids, and what to call one in a message."""

    xz: np.ndarray
    ys: np.ndarray
    lines: list[int]
    ids: np.ndarray
    noun: str

    def where(self, k: int) -> str:
        return f"{self.noun} {self.ids[k] if k < len(self.ids) else k} at {fmt_xz(self.xz[k, :2])}"


def _grid_rules(man: Manifest, grid, sp: _Spawns, big, layered: bool, what: str) -> list[Diagnostic]:
    """A309 - A311, A313 - A315 of one grid and the spawns it is for."""
    out: list[Diagnostic] = []
    mpath = str(man.path)
    valid = grid.valid
    usable = valid & grid.reachable
    if not usable.any():
        out.append(diag("A309", mpath, man.lines.table("navgrid"),
                        f"{what} has no node a tank can use: {int(valid.sum()):,} valid, none reachable "
                        f"from the spawn points (clearance {grid.clearance if math.isfinite(grid.clearance) else '?'} m)"))
        return out
    for lv in range(grid.levels):
        if valid[lv].any() and not usable[lv].any():
            i, j = np.argwhere(valid[lv])[0]
            out.append(diag("A310", mpath, man.lines.table("navgrid"),
                            f"level {lv} of {what} ({int(valid[lv].sum()):,} valid nodes, e.g. at "
                            f"{fmt_xz(grid.centre(int(i), int(j)))}) cannot be reached from the spawn points"))
    if len(sp.xz) == 0:
        return out
    labels = _components(grid)
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    largest = int(sizes.max())
    nodes = spawn_nodes(grid, sp.xz, sp.ys)
    seen = []
    for k, n in enumerate(nodes):
        if n is None:
            if layered:
                out.append(diag("A314", mpath, sp.lines[k],
                                f"{sp.where(k)} is on no node of {what} where its tank fits "
                                f"(clearance {grid.clearance:g} m)"))
            continue
        seen.append(labels[n])
        if sizes[labels[n]] < ISLAND_SHARE * largest:
            area = sizes[labels[n]] * grid.cell * grid.cell
            out.append(diag("A311", mpath, sp.lines[k],
                            f"{sp.where(k)} stands on an island of {area:,.0f} m^2 of {what} (the largest part has "
                            f"{largest * grid.cell * grid.cell:,.0f} m^2)"))
        if big is not None:
            out += _ground_rule(man, grid, n, big, sp.where(k), sp.lines[k])
    if layered and len(set(seen)) > 1:
        first = seen[0]
        for k, n in enumerate(nodes):
            if n is not None and labels[n] != first:
                out.append(diag("A315", mpath, sp.lines[k],
                                f"{sp.where(k)} cannot be reached over {what} from "
                                f"{sp.noun} {sp.ids[0] if len(sp.ids) else 0}"))
    return out


def _ground_rule(man: Manifest, grid, n: tuple[int, int, int], big, where: str, line: int) -> list[Diagnostic]:
    """A313: the ground under a spawn's node, within vehicle ``big``'s footprint."""
    from ..nav.arena_levels import ground_under

    climb = _number(man, "walkable", "climb")
    slope, rough = ground_under(grid.heights(), n, grid.cell, big.radius)
    max_slope = _number(man, "walkable", "max_slope")
    steep = max_slope is not None and slope > 0.5 * max_slope
    uneven = climb is not None and rough > climb
    if not (steep or uneven):
        return []
    what = f"a slope of {slope:.0f} deg" if steep else f"ground {rough:.2f} m off level"
    return [diag("A313", str(man.path), line,
                 f"{where}: vehicle {big.name!r} spawns on {what} (max slope "
                 f"{max_slope if max_slope is not None else '?'} deg, climb {climb if climb is not None else '?'} m)")]
