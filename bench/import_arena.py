"""The whole import-arena per stage, beside Recast's whole build of the same mesh.

Four parts, each a table (or one JSON object with ``--json``):

* **stages** (default): per level, the whole import as a match needs it --
  ``tanktool.importer.import_arena`` and then, when the import did not write the grid,
  ``build-navgrid`` on the bundle -- timed per stage by wrapping the pipeline's own
  functions (bench/stage_profile.py: exclusive times, so the stages add up): load,
  fleet, rasterise, filters, heightfield (the rest of it), links, distance, regions,
  levels, surface (the rest), walls (thin walls apart), grids, spawns, report,
  quadtree, pictures, model.glb, writing, other.  Each level runs in a fresh process
  (its peak memory is that process's high-water resident size).  Beside it, Debian's
  librecast (bench/recast_harness.cpp with ``full``) builds the same triangles at the
  import's settings through its detail mesh: ``ratio`` = our import / Recast's whole
  build.  Levels: the bundled arenas' sources (as tools/build_arenas.py imports them),
  Recast's dungeon, and terrains of 300 m and 1 km (tools/make_levels.py's rolling
  terrain, a vertex every 2 m); ``--quick`` leaves out the 1 km one; or give models.
* **scale** (``--scale``): the same import on terrains of 100 m, 300 m, 1 km and 2 km
  (``--sizes``): time and peak memory per size, the growth from each size to the next;
  ``--plot PNG`` draws it (docs/scale_series.png).
* **walls** (``--walls``): the wall extraction beside trimesh's bare cross-section of
  the same model (dungeon, the maze, a 1.3-million-face arena), best of ``--repeat``.
* **one step** (``--one-step``, bench/one_step.py): the one-step import (all outputs)
  against import + build-navgrid in the same process, CPU time, best of ``--repeat``.

    python bench/import_arena.py [MODEL ...] [--quick] [--no-kernels] [--json]
    python bench/import_arena.py --scale [--sizes 100,300,1000,2000] [--plot docs/scale_series.png] [--json]
    python bench/import_arena.py --walls [--repeat N] [--quick] [--json]
    python bench/import_arena.py --one-step [--repeat N] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(ROOT / "bench"))

from stage_profile import SURFACE_HOOKS  # noqa: E402

DUNGEON = ROOT / "tests" / "data" / "arenas_obj" / "dungeon.obj"
BUNDLED = ("box", "maze", "paper2002", "fort", "hills")
#: terrain vertex spacing (m)
TERRAIN_STEP = 2.0

#: (stage, function): every function timed, wherever the pipeline binds it
HOOKS = [
    ("load", "tanktool.formats.models:load_scene"),
    ("load", "tanktool.formats.models:load_model"),
    ("fleet", "tanktool.fleet:bundled_fleet"),
    *SURFACE_HOOKS,
    ("surface", "tanktool.nav.walkable:walkable_surface"),
    ("thin walls", "tanktool.geometry.walls:thin_walls"),
    ("walls", "tanktool.nav.level_walls:level_walls"),
    ("grids", "tanktool.nav.arena_levels:walls_too_close"),
    ("grids", "tanktool.nav.walkable:grid_from_surface"),   # the analysis' grids and the bundle's (a window)
    ("spawns", "tanktool.nav.arena_levels:choose_spawns"),
    ("report", "tanktool.nav.surface_report:left_out"),
    ("quadtree", "tanktool.nav.quadtree:WallQuadtree.build"),
    ("quadtree", "tanktool.nav.quadtree:WallQuadtree.adaptive"),
    ("pictures", "tanktool.plots.arena:render_levels"),
    ("pictures", "tanktool.plots.navgrid:render_navgrid"),
    ("model.glb", "tanktool.formats.materials:export_glb"),
    ("writing", "tanktool.formats.walls_txt:write_walls"),
    ("writing", "tanktool.formats.bundle:write_toml"),
    ("writing", "tanktool.formats.bundle:sha256_file"),
    ("writing", "tanktool.formats.bundle:atomic_write_bytes"),
    ("writing", "tanktool.formats.bundle:atomic_write_text"),
    ("writing", "tanktool.nav.navgrid:NavGrid.to_bytes"),
    ("writing", "shutil:copyfile"),
    # its own time, the picture's drawing taken off, is the wait for the grids'
    # compression in its thread (that thread's work is reported beside the stages)
    ("writing", "tanktool.grid_files:picture_and_grids"),
]
STAGES = list(dict.fromkeys(s for s, _ in HOOKS)) + ["other"]


# --------------------------------------------------------------------------- levels
def terrain(size: float, out: Path) -> Path:
    """A rolling terrain of ``size`` x ``size`` m written as OBJ (cached by size)."""
    import make_levels

    path = out / f"terrain_{size:g}m.obj"
    if not path.is_file():
        n = int(round(size / TERRAIN_STEP)) + 1
        make_levels.write_obj(make_levels.join(make_levels.rolling_terrain(size=size, n=n)), path)
    return path


def bundled_kwargs(name: str) -> tuple[Path, dict]:
    """A bundled arena's source model and the import's arguments, as tools/build_arenas.py."""
    from tanktool.formats.bundle import read_toml

    folder = ROOT / "arenas" / name
    doc = read_toml(folder / "arena.toml")
    src, walls = doc["source"], doc.get("walls", {})
    kw = dict(up=src.get("up"), scale=float(src.get("scale", 1.0)), height=float(walls.get("height", 1.0)),
              tolerance=float(walls.get("tolerance", 0.01)), navgrid=doc.get("navgrid"),
              wall_height=src.get("wall_height"), wall_thickness=src.get("wall_thickness"),
              walkable=doc.get("walkable"))
    return folder / src["file"], kw


def default_levels(work: Path, quick: bool) -> list[tuple[str, str]]:
    """(label, spec) pairs; spec is ``bundled:NAME`` or a model path."""
    out = [(n, f"bundled:{n}") for n in BUNDLED if (ROOT / "arenas" / n / "arena.toml").is_file()]
    if DUNGEON.is_file():
        out.append(("dungeon", str(DUNGEON)))
    for size in (300.0,) if quick else (300.0, 1000.0):
        out.append((f"terrain {size:g} m", str(terrain(size, work))))
    return out


# --------------------------------------------------------------------------- one import
def profile_one(spec: str, work: Path) -> dict:
    """The whole import of one level, per stage (runs in the child process)."""
    from stage_profile import Profile

    from tanktool.importer import import_arena
    from tanktool.memory import keep_freed_memory

    keep_freed_memory()  # as the tanktool command does
    if spec.startswith("bundled:"):
        model, kw = bundled_kwargs(spec.split(":", 1)[1])
    else:
        model, kw = Path(spec), {}
    out = work / "bundle"
    t_modules = preload()
    with Profile(HOOKS, memory=True) as prof:
        c0 = cpu_time()
        t0 = time.perf_counter()
        r = import_arena(model, out, name="bench", force=True, **kw)
        t_import = time.perf_counter() - t0
        two_step = not (out / "navgrid.npz").is_file()
        if two_step:
            run_build_navgrid(out)
        total = time.perf_counter() - t0
        cpu = cpu_time() - c0
    stages = {k: prof.stages.get(k, 0.0) for k in STAGES[:-1]}
    stages["other"] = max(total - sum(stages.values()), 0.0)
    p = r.params
    tank_grid = r.levels.grid if r.levels.grid is not None else r.grid.grid   # the import lets its own go
    return {"faces": int(r.faces), "walls": len(r.walls), "spawns": len(r.spawns),
            "levels": len(r.levels.levels), "nodes": int(tank_grid.valid.sum()),
            "seconds": total, "cpu_seconds": cpu, "import_seconds": t_import, "modules_seconds": t_modules, "two_step": two_step,
            "stages": stages, "thread_stages": {k: round(v, 3) for k, v in prof.thread_stages.items()},
            "stage_peak_mb": {k: round(v, 1) for k, v in prof.peak_mb.items()},
            "missing_hooks": prof.missing, "kernels": kernels_active(),
            "params": {"cell": p.cell, "cell_height": p.cell_height, "max_slope": p.max_slope,
                       "headroom": p.headroom, "climb": p.climb, "radius": float(r.levels.fleet.radius)
                       if r.levels.fleet is not None else None}}


#: modules the import loads on first use: loaded before the clock starts (a cost of
#: starting the command, reported as modules_seconds, not a stage of the work)
PRELOAD = ("trimesh", "scipy.spatial", "scipy.ndimage", "scipy.sparse.csgraph", "shapely", "matplotlib.pyplot",
           "tanktool.arena", "tanktool.importer", "tanktool.nav.arena_levels", "tanktool.plots.arena", "tanktool.plots.navgrid",
           "tanktool.formats.materials", "tanktool.formats.models", "tanktool.nav.quadtree")


def preload() -> float:
    import importlib

    import matplotlib

    matplotlib.use("Agg")
    t0 = time.perf_counter()
    for name in PRELOAD:
        try:
            importlib.import_module(name)
        except ImportError:
            pass
    import_cli()
    return time.perf_counter() - t0


def cpu_time() -> float:
    """CPU seconds of this process and of its finished children (the tile workers)."""
    import resource

    ch = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + ch.ru_utime + ch.ru_stime


def kernels_active() -> bool:
    from tanktool.geometry.kernels import active

    return active() is not None


def import_cli():
    from tanktool.cli import build_navgrid, main  # noqa: F401  (the lazy group's commands)

    return main.cli


def run_build_navgrid(bundle: Path) -> None:
    cli = import_cli()
    try:
        cli.main(["-q", "build-navgrid", str(bundle)], standalone_mode=False)
    except SystemExit as e:  # pragma: no cover - click's exit on success
        if e.code:
            raise


def child(spec: str, timeout: float) -> dict:
    """Run :func:`profile_one` in a fresh process; its row plus its peak memory."""
    with tempfile.TemporaryDirectory(prefix="import-bench-") as tmp:
        proc = subprocess.Popen([sys.executable, __file__, "--child", spec, "--work", tmp],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        t0 = time.monotonic()
        try:
            out, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
            return {"error": f"timed out after {timeout:g} s"}
        if proc.returncode != 0:
            return {"error": (err.strip().splitlines() or ["failed"])[-1], "wall_seconds": time.monotonic() - t0}
        return json.loads(out.strip().splitlines()[-1])


def peak_mb() -> float | None:
    """This process's peak resident size (MB): the kernel's high-water mark of its
    memory map (VmHWM), which starts afresh at exec -- unlike ru_maxrss, which keeps
    the size of the parent that forked it."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return round(int(line.split()[1]) / 1024, 1)
    except OSError:
        pass
    import resource  # elsewhere: the best there is

    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)


# --------------------------------------------------------------------------- Recast
def recast_full(model_spec: str, params: dict, repeat: int, work: Path) -> dict | None:
    """Recast's whole build (through the detail mesh) of the level's triangles at the
    import's settings: stage times in ms, None when Recast is not available."""
    from walkable import build_harness, write_mesh

    exe = build_harness(Path(tempfile.gettempdir()) / "tanktool-bench")
    if exe is None:
        return None
    V, F = level_triangles(model_spec)
    mesh, spans = work / "mesh.bin", work / "spans.bin"
    write_mesh(mesh, V, F)
    p = params
    args = [str(exe), str(mesh), str(spans), str(p["cell"]), str(p["cell_height"]), str(p["max_slope"]),
            str(p["headroom"]), str(p["climb"]), str(p["radius"] or 0.0), str(repeat), "full"]
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        return None
    return json.loads(r.stdout)


def level_triangles(spec: str) -> tuple[np.ndarray, np.ndarray]:
    """The triangles the import works on (world frame, after up axis and scale)."""
    import trimesh

    from tanktool.formats.models import load_scene

    if spec.startswith("bundled:"):
        model, kw = bundled_kwargs(spec.split(":", 1)[1])
        scene = load_scene(model, up=kw["up"], scale=kw["scale"], wall_height=kw["wall_height"],
                           wall_thickness=kw["wall_thickness"])
    else:
        scene = load_scene(Path(spec))
    meshes = [m for m in scene.dump() if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    mesh = meshes[0] if len(meshes) == 1 else trimesh.util.concatenate(meshes)
    return np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)


# --------------------------------------------------------------------------- parts
def stages_part(levels: list[tuple[str, str]], repeat: int, timeout: float) -> list[dict]:
    rows = []
    with tempfile.TemporaryDirectory(prefix="import-bench-recast-") as tmp:
        for label, spec in levels:
            row = {"level": label, **child(spec, timeout)}
            if "error" not in row:
                rec = recast_full(spec, row["params"], repeat, Path(tmp))
                if rec is not None:
                    row["recast_ms"] = {k: rec[k] for k in ("rasterize", "filters", "compact", "erode", "distance",
                                                             "regions", "contours", "polymesh", "detail", "full")}
                    row["recast_ms"]["cpu_full"] = rec["cpu_full"]
                    row["ratio"] = round(row["seconds"] * 1000 / rec["full"], 2) if rec["full"] > 0 else None
                    row["cpu_ratio"] = (round(row["cpu_seconds"] * 1000 / rec["cpu_full"], 2)
                                        if rec["cpu_full"] > 0 else None)
                row["seconds"] = round(row["seconds"], 3)
                row["cpu_seconds"] = round(row["cpu_seconds"], 3)
                row["import_seconds"] = round(row["import_seconds"], 3)
                row["stages"] = {k: round(v, 3) for k, v in row["stages"].items()}
                top = sorted(row["stages"].items(), key=lambda kv: -kv[1])[:3]
                row["dominant"] = [k for k, _ in top]
            rows.append(row)
    return rows


def print_stages(rows: list[dict]) -> None:
    shown = [s for s in STAGES if any(r.get("stages", {}).get(s, 0) >= 0.005 for r in rows)]
    head = f"{'level':<16}{'faces':>9}{'total s':>9}{'peak MB':>9}{'recast ms':>10}{'ratio':>7}{'cpu':>6}  "
    print(head + "".join(f"{s[:9]:>10}" for s in shown))
    for r in rows:
        if "error" in r:
            print(f"{r['level']:<16} error: {r['error']}")
            continue
        rec = r.get("recast_ms", {}).get("full")
        print(f"{r['level']:<16}{r['faces']:>9,}{r['seconds']:>9.2f}{r['peak_mb'] or 0:>9.0f}"
              f"{rec if rec is not None else float('nan'):>10.1f}{r.get('ratio') or float('nan'):>7.1f}"
              f"{r.get('cpu_ratio') or float('nan'):>6.1f}  "
              + "".join(f"{r['stages'].get(s, 0):>10.3f}" for s in shown))
    print("stage columns: exclusive seconds; ratio: our whole import / Recast's whole build (detail mesh),"
          " wall clock; cpu: the same in process CPU time")
    for r in rows:
        if "dominant" in r:
            share = sum(r["stages"][k] for k in r["dominant"]) / max(r["seconds"], 1e-9)
            print(f"  {r['level']}: dominated by {', '.join(r['dominant'])} ({100 * share:.0f} % of the import)")
        if r.get("thread_stages"):  # beside the main thread's stages, not added to them
            print(f"  {r['level']}: in worker threads, within the stages above: "
                  + ", ".join(f"{k} {v:.3f} s" for k, v in r["thread_stages"].items()))


def scale_part(sizes: list[float], timeout: float) -> list[dict]:
    rows = []
    with tempfile.TemporaryDirectory(prefix="import-bench-scale-") as tmp:
        for size in sizes:
            ok = [r for r in rows if "error" not in r]
            if ok:  # a size the machine cannot hold is skipped, not run into the OOM killer
                need = ok[-1]["peak_mb"] * (size / ok[-1]["size_m"]) ** 2
                have = available_mb()
                if have is not None and need > 0.8 * have:
                    rows.append({"size_m": size, "error": f"skipped: would need about {need / 1024:.1f} GB, "
                                                          f"{have / 1024:.1f} GB available"})
                    continue
            path = terrain(size, Path(tmp))
            row = {"size_m": size, **child(str(path), timeout)}
            if "error" not in row:
                row = {k: row[k] for k in ("size_m", "faces", "seconds", "cpu_seconds", "peak_mb", "stages", "thread_stages",
                                           "stage_peak_mb", "nodes", "walls", "kernels")}
                row["seconds"] = round(row["seconds"], 3)
                row["cpu_seconds"] = round(row["cpu_seconds"], 3)
                row["stages"] = {k: round(v, 3) for k, v in row["stages"].items()}
            rows.append(row)
            path.unlink(missing_ok=True)
    ok = [r for r in rows if "error" not in r]
    for a, b in zip(ok, ok[1:]):
        b["time_growth"] = round(b["seconds"] / a["seconds"], 2)
        b["area_growth"] = round((b["size_m"] / a["size_m"]) ** 2, 2)
    return rows


def available_mb() -> float | None:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return None


def print_scale(rows: list[dict]) -> None:
    print(f"{'terrain':>9}{'faces':>11}{'seconds':>9}{'peak MB':>9}{'x time':>8}{'x area':>8}")
    for r in rows:
        if "error" in r:
            print(f"{r['size_m']:>7g} m  error: {r['error']}")
            continue
        print(f"{r['size_m']:>7g} m{r['faces']:>11,}{r['seconds']:>9.2f}{r['peak_mb'] or 0:>9.0f}"
              f"{r.get('time_growth', float('nan')):>8.2f}{r.get('area_growth', float('nan')):>8.2f}")


def plot_scale(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in rows if "error" not in r]
    area = np.array([(r["size_m"] / 1000) ** 2 for r in ok])
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1.25, 1]})
    sec = np.array([r["seconds"] for r in ok])
    bottom = np.zeros(len(ok))
    names = [s for s in STAGES if any(r["stages"].get(s, 0) > 0.03 * r["seconds"] for r in ok)]
    x = np.arange(len(ok))
    colours = plt.get_cmap("tab20").colors
    for k, s in enumerate(names):  # each stage's share of its import
        v = 100 * np.array([r["stages"].get(s, 0) for r in ok]) / sec
        a1.bar(x, v, bottom=bottom, label=s, color=colours[(2 * k) % 20 + (2 * k) // 20])
        bottom += v
    a1.bar(x, 100 - bottom, bottom=bottom, label="the rest", color="0.8")
    a1.set_xticks(x, [f"{r['size_m']:g} m\n{r['seconds']:.1f} s" for r in ok])
    a1.set_ylabel("share of the import (%)")
    a1.set_title("where the time goes, per terrain size")
    a1.legend(fontsize=7, ncol=1, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    a2.loglog(area, sec, "o-", label="wall time (s)")
    a2.loglog(area, [r["cpu_seconds"] for r in ok], "^-", label="CPU time (s)")
    a2.loglog(area, [r["peak_mb"] / 1000 for r in ok], "s-", label="peak memory (GB)")
    if len(ok) >= 2:  # through the second largest: small imports are mostly fixed costs
        k = len(ok) - 2
        cpu = np.array([r["cpu_seconds"] for r in ok])
        a2.loglog(area[k:], cpu[k] * area[k:] / area[k], "k:", label="linear in area")
    a2.set_xlabel("area (km²)")
    a2.set_title("growth with the area")
    a2.legend(fontsize=8)
    a2.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


# --------------------------------------------------------------------------- walls
def models(quick: bool) -> list[tuple[str, np.ndarray, np.ndarray]]:
    import trimesh

    from tanktool.formats.models import load_model

    out = []
    d = trimesh.load(DUNGEON, force="mesh", process=False)
    out.append(("dungeon.obj", np.asarray(d.vertices), np.asarray(d.faces)))
    maze = load_model(ROOT / "arenas" / "maze" / "maze.obj")
    out.append(("arenas/maze", np.asarray(maze.vertices), np.asarray(maze.faces)))
    v, f = np.asarray(d.vertices), np.asarray(d.faces)
    for _ in range(2 if quick else 3):
        v, f = trimesh.remesh.subdivide(v, f)
    width = v[:, 0].max() - v[:, 0].min() + 10.0
    v2 = np.concatenate([v, v + [width, 0, 0]])
    f2 = np.concatenate([f, f + len(v)])
    out.append((f"dungeon subdivided x{4 ** (2 if quick else 3)}, 2 copies", v2, f2))
    return out


def best(fn, repeat: int) -> tuple[float, object]:
    t_best, result = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        t_best = min(t_best, time.perf_counter() - t0)
    return t_best, result


def walls_part(repeat: int, quick: bool) -> list[dict]:
    import trimesh

    from tanktool.geometry.walls import extract_walls, find_floor

    rows = []
    for name, v, f in models(quick):
        cut_y = find_floor(v, f).y + 1.0

        def bare():
            mesh = trimesh.Trimesh(v, f, process=False)  # fresh: no cached adjacency
            return mesh.section(plane_origin=[0, cut_y, 0], plane_normal=[0, 1, 0])

        t_bare, sec = best(bare, repeat)
        t_ours, ex = best(lambda: extract_walls(v, f, height=1.0, tolerance=0.01), repeat)
        rows.append({
            "model": name, "faces": int(len(f)), "bare_cut_ms": round(t_bare * 1000, 1),
            "extraction_ms": round(t_ours * 1000, 1), "ratio": round(t_ours / t_bare, 2),
            "bare_polylines": int(len(sec.entities)) if sec is not None else 0,
            "walls": int(len(ex.walls)), "stages_ms": {k: round(s * 1000, 1) for k, s in ex.timings.items()},
        })
    return rows


def print_walls(rows: list[dict]) -> None:
    print(f"{'model':<36} {'faces':>10} {'bare cut ms':>12} {'ours ms':>9} {'ratio':>6} {'walls':>6}")
    for r in rows:
        print(f"{r['model']:<36} {r['faces']:>10,} {r['bare_cut_ms']:>12.1f} {r['extraction_ms']:>9.1f} "
              f"{r['ratio']:>6.2f} {r['walls']:>6}")
    print()
    for r in rows:
        print(f"{r['model']}: " + ", ".join(f"{k} {v:.1f} ms" for k, v in r["stages_ms"].items()))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("models", nargs="*", type=Path, help="models to profile (default: see the docstring)")
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    ap.add_argument("--quick", action="store_true", help="leave out the 1 km terrain (--walls: a 160k-face model)")
    ap.add_argument("--repeat", type=int, default=3, help="Recast's runs (fastest kept); --walls: best of N")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds one level's import may take")
    ap.add_argument("--scale", action="store_true", help="the scale series on terrains")
    ap.add_argument("--sizes", default="100,300,1000,2000", help="--scale: terrain sizes in metres")
    ap.add_argument("--plot", type=Path, default=None, help="--scale: draw the series into this PNG")
    ap.add_argument("--walls", action="store_true", help="the wall extraction beside trimesh's bare cut")
    ap.add_argument("--one-step", action="store_true",
                    help="the one-step import against import + build-navgrid (bench/one_step.py)")
    ap.add_argument("--no-kernels", action="store_true", help="force the numpy code (no tanktool._kernels)")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--work", type=Path, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        row = profile_one(a.child, a.work)
        row["peak_mb"] = peak_mb()
        print(json.dumps(row))
        return 0
    if a.one_step:
        import one_step

        out = one_step.report(one_step.run(a.repeat), a.json)
        if out is not None:
            print(json.dumps(out, indent=1))
        return 0
    if a.walls:
        rows = walls_part(a.repeat, a.quick)
        big = [r for r in rows if r["faces"] >= 1_000_000]
        goals = {"ratio_within_3x": all(r["ratio"] <= 3.0 for r in rows),
                 "million_faces_under_1s": all(r["extraction_ms"] < 1000 for r in big) if big else None}
        if a.json:
            print(json.dumps({"part": "walls", "repeat": a.repeat, "models": rows, "goals": goals}, indent=1))
        else:
            print_walls(rows)
            print(f"goals: within 3x of the bare cut: {goals['ratio_within_3x']}; "
                  f"1M+ faces under 1 s: {goals['million_faces_under_1s']}")
        return 0
    if a.no_kernels:  # the children read it (tanktool/geometry/kernels.py)
        os.environ["TANKTOOL_NO_KERNELS"] = "1"
    if a.scale:
        sizes = [float(s) for s in a.sizes.split(",") if s.strip()]
        rows = scale_part(sizes, a.timeout)
        if a.plot:
            plot_scale(rows, a.plot)
        if a.json:
            print(json.dumps({"part": "scale", "terrain_step_m": TERRAIN_STEP, "sizes": rows}))
        else:
            print_scale(rows)
            if a.plot:
                print(f"wrote {a.plot}")
        return 0
    with tempfile.TemporaryDirectory(prefix="import-bench-levels-") as tmp:
        levels = [(m.stem, str(m)) for m in a.models] or default_levels(Path(tmp), a.quick)
        rows = stages_part(levels, a.repeat, a.timeout)
    if a.json:
        print(json.dumps({"part": "stages", "stages": STAGES, "levels": rows}))
    else:
        print_stages(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
