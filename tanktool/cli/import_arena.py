"""``tanktool import-arena``: an arena model in, an arena bundle out."""

from __future__ import annotations

from pathlib import Path

import click

from .options import force_option, name_option, out_option, progress, up_option

#: models with more faces than this get a progress bar
PROGRESS_FACES = 100_000
#: floor plans bigger than this get one (a 37 KB plan of 800 pillars takes seconds)
PROGRESS_PLAN_BYTES = 16_000
#: the stages import_arena reports (floor plans report PLAN_STAGES while being read),
#: then nav.arena_levels.STAGES, then the files
STAGES = ("read", "surface", "walls", "grid", "spawns", "report", "files", "navgrid")


def _face_count_guess(model: Path) -> int:
    """A cheap over-estimate of the face count from the file size (no parsing)."""
    try:
        size = model.stat().st_size
    except OSError:
        return 0
    # ~40 bytes a face in .obj text, ~14 in .3ds; either way a big file is a big model
    return size // 20


def _stages(model: Path) -> tuple[str, ...] | None:
    """The progress bar's stages for ``model``, or None when it imports in a moment."""
    from ..formats.floorplan import PLAN_EXTENSIONS, PLAN_STAGES

    if model.suffix.lower() in PLAN_EXTENSIONS:
        big = _face_count_guess(model) * 20 > PROGRESS_PLAN_BYTES
        return PLAN_STAGES + STAGES if big else None
    return STAGES if _face_count_guess(model) > PROGRESS_FACES else None


@click.command("import-arena")
@click.argument("model", type=click.Path(path_type=Path))
@out_option
@name_option
@up_option
@click.option("--scale", "scale_text", default="1", show_default=True, metavar="S|auto",
              help="Multiply the model's coordinates (after the axis conversion) to get metres; 'auto': the "
                   "scale at which the smallest bundled tank fits most of the walkable surface, when none fits "
                   "at 1.")
@click.option("--height", type=float, default=1.0, show_default=True,
              help="Cut height above a flat floor, in metres: what crosses it is a wall.")
@click.option("--cell", type=float, default=None, metavar="M",
              help="Voxel and navigation-grid cell size in metres (default 0.5).")
@click.option("--max-slope", type=float, default=None, metavar="DEG",
              help="Steepest walkable slope in degrees (default 35).")
@click.option("--climb", type=float, default=None, metavar="M",
              help="Highest step a tank drives up or down, in metres (default 0.9).")
@click.option("--headroom", type=float, default=None, metavar="M",
              help="Free height a tank needs above the surface, in metres (default: the tallest bundled vehicle).")
@click.option("--tolerance", type=float, default=0.01, show_default=True,
              help="Shortest wall kept and snapping grid, in metres.")
@click.option("--wall-height", type=float, default=None, metavar="H",
              help="Floor plans (.dxf .svg): wall height in metres (default 3).")
@click.option("--wall-thickness", type=float, default=None, metavar="T",
              help="Floor plans (.dxf .svg): wall thickness in metres (default 0.5).")
@click.option("--max-cells", type=click.IntRange(1), default=None, metavar="N",
              help="Most heightfield cells the import may use (default: 4,000,000 + 200 per byte of the "
                   "model file, at most 40,000,000).")
@force_option
def import_arena(model: Path, out: Path | None, name: str | None, up: str | None, scale_text: str,
                 height: float, cell: float | None, max_slope: float | None, climb: float | None,
                 headroom: float | None, tolerance: float, wall_height: float | None, wall_thickness: float | None,
                 max_cells: int | None, force: bool) -> None:
    """Turn an arena MODEL (.3ds .obj .glb .stl .ply .off, BZFlag .bzw, floor plan
    .dxf .svg) into an arena bundle.

    Finds where a tank can stand as Recast does (a voxel heightfield: faces no steeper
    than --max-slope, --headroom free above, neighbours within --climb), stacks it into
    levels (a deck over a passage is level 1), draws each level's walls (exact on flat
    floors) and places spawns where the largest bundled tank fits.  Prints each
    level's area and height range and what was left out and why.

    Writes everything a match needs, so `tanktool play --arena OUT` follows at once:
    build-navgrid is only for rebuilding the grid with other settings.

    \b
    Writes arena.toml, the model, model.glb, walls.txt, preview.png, navgrid.npz,
    quadtree.npz, navgrid.png, and navgrid.<vehicle>.npz for each smaller bundled vehicle:
      tanktool import-arena castle.3ds -o arenas/castle --height 1.2
      tanktool import-arena hills.obj --max-slope 30 --climb 0.5
      tanktool import-arena plan.dxf --wall-height 3 --wall-thickness 0.4
    """
    from ..importer import import_arena as run
    from .main import echo

    def warn(message: str) -> None:
        # non-fatal remarks (a .bzw's unknown objects) go to stderr, even under -q
        click.echo(f"warning: {message}", err=True)

    from ..nav.arena_levels import NoFitError, describe_levels

    kw = dict(warn=warn, wall_height=wall_height, wall_thickness=wall_thickness, max_slope=max_slope,
              climb=climb, headroom=headroom, cell=cell, max_cells=max_cells)
    auto = scale_text.strip().lower() == "auto"
    scale = 1.0 if auto else _scale(scale_text)
    try:
        result = _run(run, model, out, name, up, scale, height, tolerance, force, kw)
    except NoFitError as e:
        if not auto or e.scale is None:
            raise
        echo(f"--scale auto: no bundled tank fits at scale 1; importing at --scale {e.scale:g}")
        result = _run(run, model, out, name, up, e.scale, height, tolerance, force, kw)
    (x0, z0), (x1, z1) = result.walls.bounds
    thin = f" ({result.thin_walls} from thin walls)" if result.thin_walls else ""
    nlev = len(result.levels.levels)
    echo(f"arena {result.name!r}: {nlev} level{'s' if nlev != 1 else ''}, {len(result.walls)} walls{thin} "
         f"+ 4 auxiliary, {len(result.spawns)} spawns")
    for line in describe_levels(result.levels):
        if line.startswith("  left out: ") and result.model_left_out:
            # what the model file held but was not built is left out too: never "nothing" then
            model = "; ".join(result.model_left_out) + f" of {model.name} not built"
            line = f"  left out: {model}" if line == "  left out: nothing" else f"{line}; {model}"
        echo(line)
    echo(f"  walkable: {_describe_params(result.params, result.defaults)}")
    echo(f"  bounds x {x0:g}..{x1:g}, z {z0:g}..{z1:g} m ({x1 - x0:.1f} x {z1 - z0:.1f} m), "
         f"floor y={result.floor_y:.3f}, {result.faces} faces")
    if result.grid is not None:
        g = result.grid
        valid = int(g.grid.valid.sum())
        echo(f"  navgrid: {g.grid.nz} x {g.grid.nx} nodes{f' on {g.grid.levels} levels' if g.grid.levels > 1 else ''} "
             f"at {g.cell:g} m, clearance {g.clearance:g} m ({g.clearance_source}): {valid:,} valid")
        for name, own in g.vehicles.items():     # a grid of its own for each smaller vehicle
            og = own.grid
            echo(f"  navgrid.{name}.npz: clearance {own.clearance:g} m (footprint radius of vehicle '{name}'): "
                 f"{int(og.valid.sum()):,} valid, {int((og.valid & og.reachable).sum()):,} reachable from its "
                 f"{len(og.spawn_nodes)} spawns")
        echo(f"  holds at once: {_holds(result)}")
    echo(f"  wrote {result.path} in {result.seconds:.2f} s")


def _scale(text: str) -> float:
    """--scale S: a number in (0, 1e6]."""
    import math

    from ..errors import ArenaError

    try:
        v = float(text)
    except ValueError:
        v = math.nan
    if not (math.isfinite(v) and 0 < v <= 1e6):
        raise ArenaError(f"--scale must be a number in (0, 1e6] or 'auto', got {text!r}")
    return v


def _run(run, model, out, name, up, scale, height, tolerance, force, kw):
    """One import, with a progress bar when the model is big."""
    stages = _stages(model)
    if stages:
        with progress(length=len(stages), label=f"importing {model.name}") as bar:
            return run(model, out, name, up, scale, height, tolerance, force, progress=lambda _s: bar.update(1), **kw)
    return run(model, out, name, up, scale, height, tolerance, force, **kw)


#: play's largest --bots: the count of tanks an arena holds is given up to this
HOLDS_LIMIT = 64


def _holds(result) -> str:
    """How many tanks of each bundled vehicle the arena holds at once (its spawn points
    and free places of its ground a tank's length apart: sim/extra_spawns.py)."""
    from ..errors import TanktoolError
    from ..sim.extra_spawns import holds
    from ..sim.match import load_match_arena, load_tank_spec

    info = load_match_arena(result.path)
    parts = []
    too_big = {n for n, _ in (getattr(result.levels, "too_big", None) or [])}
    for name in _vehicle_names():
        if name in too_big:
            parts.append(f"{name} 0 (too big)")
            continue
        try:
            (_, n), = holds(info, [load_tank_spec(name)], HOLDS_LIMIT)
        except TanktoolError:
            n = 0
        parts.append(f"{name} {n}{'+' if n >= HOLDS_LIMIT else ''}")
    return ", ".join(parts) if parts else "no bundled vehicle"


def _vehicle_names() -> list[str]:
    from ..content import bundled_names

    return sorted(bundled_names("vehicles"))


def _describe_params(params, where: dict[str, str]) -> str:
    """The walkable parameters, each default saying where it came from."""
    def one(label: str, key: str, value: float, unit: str) -> str:
        src = where.get(key, "default")
        note = "" if src == "option" else f" ({src})" if src not in ("default",) else ""
        return f"{label} {value:g}{unit}{note}"
    return ", ".join([
        one("cell", "cell", params.cell, " m"), one("cell height", "cell_height", params.cell_height, " m"),
        one("max slope", "max_slope", params.max_slope, " deg"), one("climb", "climb", params.climb, " m"),
        one("headroom", "headroom", params.headroom, " m"),
    ])
