"""The one-step import against the two steps it replaced (issue 25), in one process.

One step: ``tanktool.importer.import_arena`` writing every file a match needs (walls,
surface, layered navigation grid, quadtree, pictures, hashes).  Two steps: the same
import without the grid (``grid=False``), then the ``build-navgrid`` command on the
bundle.  Best of ``--repeat`` each, the two ways taking turns (so a change in the
machine's load falls on both), CPU time of this process (every thread) and its
finished children (the machine is shared, so wall time is shown too but not judged) and the ratio one / two.
``grid surface``: the CPU seconds the one step spends computing the grid's walkable
surface a second time (``walkable_surface`` called from the grid build, on model.glb):
the most that handing the import's surface over could save.  It is not handed over:
the grid's surface is not the import's (model.glb's float32 vertices, the walls'
bounds for origin and extent, vehicle.toml's radius as the clearance cap, the spawns
as seeds), and build-navgrid alone must give the same bytes.
Levels: the bundled arenas' sources (their recorded settings), Recast's dungeon and a
300 m rolling terrain (bench/import_arena.py's helpers).  Goal: the one step is not
slower than the two together (ratio <= 1, with 5 % for noise).

    python bench/import_arena.py --one-step [--repeat N] [--json]
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any, Callable

#: a bit of slack for "not slower": two runs of the same work differ by a few per cent
NOISE = 1.05


def cpu() -> float:
    """CPU seconds of this process and of its finished children (the import's tile
    workers run in child processes)."""
    import resource

    ch = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + ch.ru_utime + ch.ru_stime


def best_both(fn: Callable[[], Any], repeat: int) -> tuple[float, float, Any]:
    """Best wall-clock and best CPU time of ``repeat`` runs, and the last result."""
    return best_turns([fn], repeat)[0]


def best_turns(fns: list[Callable[[], Any]], repeat: int) -> list[tuple[float, float, Any]]:
    """:func:`best_both` of each of ``fns``, run in turns (one round of each, ``repeat``
    rounds): all of one way after all of the other would judge the machine's load."""
    best = [[float("inf"), float("inf"), None] for _ in fns]
    for _ in range(repeat):
        for fn, b in zip(fns, best):
            t0, c0 = time.perf_counter(), cpu()
            b[2] = fn()
            b[0] = min(b[0], time.perf_counter() - t0)
            b[1] = min(b[1], cpu() - c0)
    return [(t, c, r) for t, c, r in best]


class GridSurfaceClock:
    """CPU seconds spent in ``walkable_surface`` called from the grid build (which
    imports it when it runs; the import's own analysis bound it at import time)."""

    def __init__(self) -> None:
        self.seconds = 0.0

    def __enter__(self) -> "GridSurfaceClock":
        import tanktool.nav.walkable as walkable

        self._module, self._real = walkable, walkable.walkable_surface

        def timed(*args: Any, **kw: Any) -> Any:
            c0 = cpu()
            try:
                return self._real(*args, **kw)
            finally:
                self.seconds += cpu() - c0

        walkable.walkable_surface = timed
        return self

    def __exit__(self, *exc: Any) -> None:
        self._module.walkable_surface = self._real


def cases(work: Path) -> list[tuple[str, Path, dict]]:
    """(label, model, import_arena keyword arguments) of the levels compared."""
    import import_arena as bench

    out = []
    for name in bench.BUNDLED:
        if (bench.ROOT / "arenas" / name / "arena.toml").is_file():
            model, kw = bench.bundled_kwargs(name)
            out.append((f"arenas/{name}", model, {**kw, "name": name}))
    if bench.DUNGEON.is_file():
        out.append(("dungeon.obj", bench.DUNGEON, {}))
    out.append(("terrain 300 m", bench.terrain(300.0, work), {}))
    return out


def run(repeat: int) -> list[dict]:
    """One row per level: CPU and wall seconds of each way, their ratios, the grid."""
    import import_arena as bench

    from tanktool.importer import import_arena

    bench.import_cli()
    rows = []
    with tempfile.TemporaryDirectory(prefix="one-step-bench-") as d:
        work = Path(d)
        for label, model, kw in cases(work):
            out = work / "bundle"

            def one() -> Any:
                return import_arena(model, out, force=True, **kw)

            def two() -> None:
                import_arena(model, out, force=True, grid=False, **kw)
                bench.run_build_navgrid(out)

            (t_two, c_two, _), (t_one, c_one, res) = best_turns([two, one], repeat)
            with GridSurfaceClock() as clock:  # one more run: the share the grid's own surface takes
                one()
            g = res.grid.grid
            rows.append({"model": label, "one_step_cpu_s": round(c_one, 3), "two_steps_cpu_s": round(c_two, 3),
                         "ratio": round(c_one / c_two, 3), "grid_surface_cpu_s": round(clock.seconds, 3),
                         "grid_surface_share": round(clock.seconds / c_one, 3), "one_step_wall_s": round(t_one, 3),
                         "two_steps_wall_s": round(t_two, 3), "wall_ratio": round(t_one / t_two, 3),
                         "levels": int(g.levels), "valid": int(g.valid.sum())})
    return rows


def report(rows: list[dict], as_json: bool) -> dict | None:
    """Print the table (or return the JSON object)."""
    goal = all(r["ratio"] <= NOISE for r in rows)
    if as_json:
        return {"part": "one_step", "rows": rows, "noise": NOISE, "goals": {"one_step_not_slower": goal}}
    print(f"{'one step vs import + build-navgrid':<24} {'CPU s: one':>10} {'two':>6} {'ratio':>6} "
          f"{'grid surface s':>14} {'share':>6} {'wall s: one':>11} {'two':>6} {'ratio':>6} "
          f"{'levels':>6} {'valid nodes':>11}")
    for r in rows:
        print(f"{r['model']:<24} {r['one_step_cpu_s']:>10.2f} {r['two_steps_cpu_s']:>6.2f} {r['ratio']:>6.2f} "
              f"{r['grid_surface_cpu_s']:>14.3f} {r['grid_surface_share']:>6.1%} "
              f"{r['one_step_wall_s']:>11.2f} {r['two_steps_wall_s']:>6.2f} {r['wall_ratio']:>6.2f} "
              f"{r['levels']:>6} {r['valid']:>11,}")
    print(f"goal: one step not slower than the two (CPU ratio <= {NOISE}): {goal}")
    return None
