"""Walkable surfaces beside the real Recast library, in one run.

For each mesh (default: Recast's dungeon and the levels tools/make_levels.py
generates: rolling terrain, ramps and decks, a bridge over a passage, a floor with
10 cm bumps, two storeys), at Recast's demo settings (cell 0.3 m, cell height 0.2 m,
max slope 45 deg, headroom 2.0 m, climb 0.9 m, clearance 0.6 m):

* **ours**: the time in this process from the loaded triangles to the finished
  layered navigation grid -- heightfield (rasterise, merge, the three filters),
  open spans and links, chamfer clearance, regions, levels, the grid with its links
  and per-level run numbers (tanktool.nav.walkable: ``walkable_surface`` then
  ``grid_from_surface``);
* **recast**: Debian's librecast (``-lRecast``, headers in ``recastnavigation``) on the
  same triangles through bench/recast_harness.cpp, compiled here with g++ -O2: the
  same work as RecastDemo's solo mesh up to its regions (rasterise, the three span
  filters, compact heightfield, erode, distance field, watershed regions).  "not
  available" when g++ or the library is missing.

Both are the fastest of ``--repeat`` runs (each program timing itself, warm): the
ratio ours / recast is the figure (<= 1: ours is as fast).  Agreement: our walkable
nodes (every surface span at least the clearance from an edge, in any region) against
Recast's eroded walkable spans: a node matches a span in the same or an adjacent
column with |dy| <= 0.5 m; precision = our nodes that match, recall = Recast's spans
that do.

    python bench/walkable.py [MESH.obj ...] [--repeat N] [--json]

``--json`` prints one object: ``{"meshes": [{"mesh", "tris", "ms_ours", "ms_recast",
"nodes", "levels", "precision", "recall", ...}]}`` (null where Recast is missing).
"""

from __future__ import annotations

import argparse
import json
import shutil
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

from tanktool.errors import TanktoolError  # noqa: E402
from tanktool.memory import keep_freed_memory  # noqa: E402
from tanktool.nav.walkable import WalkableParams, grid_from_surface, walkable_surface  # noqa: E402

DUNGEON = ROOT / "tests" / "data" / "arenas_obj" / "dungeon.obj"
GENERATED = ("rolling_terrain", "ramps_and_decks", "bridge", "bumpy_floor", "two_storeys")
#: Recast's demo settings
SETTINGS = {"cell": 0.3, "cell_height": 0.2, "max_slope": 45.0, "headroom": 2.0, "climb": 0.9, "clearance": 0.6}
HARNESS = ROOT / "bench" / "recast_harness.cpp"
INCLUDE = Path("/usr/include/recastnavigation")
#: a node matches a Recast span this close in height (m)
DY = 0.5


def build_harness(cache: Path) -> Path | None:
    """Compile the harness once (into ``cache``); None when it cannot be built."""
    exe = cache / "recast_harness"
    if exe.is_file() and exe.stat().st_mtime >= HARNESS.stat().st_mtime:
        return exe
    gxx = shutil.which("g++")
    if gxx is None or not (INCLUDE / "Recast.h").is_file():
        return None
    cache.mkdir(parents=True, exist_ok=True)
    r = subprocess.run([gxx, "-O2", f"-I{INCLUDE}", str(HARNESS), "-lRecast", "-o", str(exe)],
                       capture_output=True, text=True)
    return exe if r.returncode == 0 else None


def write_mesh(path: Path, V: np.ndarray, F: np.ndarray) -> None:
    """The triangles as recast_harness reads them: counts, float32 vertices, int32 faces."""
    with open(path, "wb") as f:
        f.write(np.array([len(V), len(F)], np.int32).tobytes())
        f.write(np.asarray(V, np.float32).tobytes())
        f.write(np.asarray(F, np.int32).tobytes())


def run_recast(exe: Path, V: np.ndarray, F: np.ndarray, repeat: int, work: Path) -> tuple[dict, np.ndarray]:
    """Recast's timings (ms) and its eroded walkable spans (k, 3): column x, row z, floor y."""
    mesh, spans = work / "mesh.bin", work / "spans.bin"
    write_mesh(mesh, V, F)
    s = SETTINGS
    args = [str(exe), str(mesh), str(spans), str(s["cell"]), str(s["cell_height"]), str(s["max_slope"]),
            str(s["headroom"]), str(s["climb"]), str(s["clearance"]), str(repeat)]
    r = subprocess.run(args, capture_output=True, text=True, check=True)
    data = np.fromfile(spans, dtype=np.dtype([("x", "<i4"), ("z", "<i4"), ("y", "<f4")]))
    return json.loads(r.stdout), np.column_stack([data["x"], data["z"], data["y"]]).astype(np.float64)


def ours(V: np.ndarray, F: np.ndarray, repeat: int):
    """The fastest of ``repeat`` runs of our pipeline (wall clock and process CPU time,
    ms), and its last result."""
    s = SETTINGS
    params = WalkableParams(s["cell"], s["cell_height"], s["max_slope"], s["climb"], s["headroom"])
    best, best_cpu, out = float("inf"), float("inf"), None
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        surface = walkable_surface(V, F, params, s["clearance"])
        grid = grid_from_surface(surface, s["clearance"], surface.hf.origin[[0, 2]])
        best = min(best, time.perf_counter() - t0)
        best_cpu = min(best_cpu, time.process_time() - c0)
        out = (surface, grid)
    return best * 1000, best_cpu * 1000, out


#: our stages, timed by wrapping the pipeline's functions (bench/stage_profile.py)
STAGE_HOOKS = [
    *SURFACE_HOOKS,
    ("heights", "tanktool.nav.walkable:snap_heights"),
    ("heights", "tanktool.geometry.heightfield:flat_heights"),
    ("grid", "tanktool.nav.navgrid:layered_runs"),
]


def our_stages(V: np.ndarray, F: np.ndarray, repeat: int) -> dict:
    """Exclusive ms per stage, the fastest of ``repeat`` profiled runs for each stage
    (the grid's own work is what the hooks leave over): on a shared machine a mean
    of a few runs moved a stage by 2x between runs."""
    from stage_profile import Profile

    s = SETTINGS
    params = WalkableParams(s["cell"], s["cell_height"], s["max_slope"], s["climb"], s["headroom"])
    best: dict[str, float] = {}
    for _ in range(repeat):
        with Profile(STAGE_HOOKS) as prof:
            t0 = time.perf_counter()
            surface = walkable_surface(V, F, params, s["clearance"])
            grid_from_surface(surface, s["clearance"], surface.hf.origin[[0, 2]])
            total = time.perf_counter() - t0
        out = dict(prof.stages)
        out["grid"] = out.get("grid", 0.0) + total - sum(prof.stages.values())
        # work done in the heightfield's band threads, inside the main thread's stage
        out.update({f"{k} in threads": v for k, v in prof.thread_stages.items()})
        for k, v in out.items():
            best[k] = min(best.get(k, float("inf")), v)
    return {k: round(v * 1000, 2) for k, v in best.items()}


def match_share(a: np.ndarray, b: np.ndarray, width: int) -> float:
    """Share of points ``a`` (k, 3: column, row, y) with a point of ``b`` in the same or
    an adjacent column and within DY in height."""
    if len(a) == 0:
        return float("nan")
    if len(b) == 0:
        return 0.0
    key_b = b[:, 1].astype(np.int64) * width + b[:, 0].astype(np.int64)
    order = np.argsort(key_b, kind="stable")
    key_b, yb = key_b[order], b[order, 2]
    hit = np.zeros(len(a), dtype=bool)
    for dz in (-1, 0, 1):
        for dx in (-1, 0, 1):
            k = (a[:, 1].astype(np.int64) + dz) * width + a[:, 0].astype(np.int64) + dx
            lo = np.searchsorted(key_b, k, side="left")
            hi = np.searchsorted(key_b, k, side="right")
            depth = int((hi - lo).max()) if len(lo) else 0
            for m in range(depth):
                idx = np.minimum(lo + m, len(yb) - 1)
                hit |= (lo + m < hi) & (np.abs(yb[idx] - a[:, 2]) <= DY)
    return float(hit.mean())


def load(path: Path) -> tuple[np.ndarray, np.ndarray]:
    import trimesh

    m = trimesh.load(str(path), force="mesh", process=False)
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)


def default_meshes(work: Path) -> list[Path]:
    import make_levels

    out = [DUNGEON] if DUNGEON.is_file() else []
    for name in GENERATED:
        out.append(make_levels.write_obj(make_levels.level(name), work / f"{name}.obj"))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("meshes", nargs="*", type=Path)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--no-kernels", action="store_true", help="force the numpy code (no tanktool._kernels)")
    a = ap.parse_args(argv)
    keep_freed_memory()  # as the tanktool command does (tanktool/memory.py)
    from tanktool.geometry import kernels

    with kernels.use_kernels(not a.no_kernels):
        return run(a, kernels.active() is not None)


def run(a: argparse.Namespace, compiled: bool) -> int:
    rows = []
    with tempfile.TemporaryDirectory(prefix="walkable-bench-") as tmp:
        work = Path(tmp)
        exe = build_harness(Path(tempfile.gettempdir()) / "tanktool-bench")
        for path in a.meshes or default_meshes(work):
            try:
                V, F = load(path)
                ms_ours, cpu_ours, (surface, grid) = ours(V, F, a.repeat)
            except TanktoolError as e:  # a mesh over the column limit, an unreadable file: one line
                print(f"error: {path}: {' '.join(str(e).split())}", file=sys.stderr)
                return 2
            row = {"mesh": str(path), "tris": int(len(F)), "ms_ours": round(ms_ours, 2), "ms_recast": None,
                   "cpu_ms_ours": round(cpu_ours, 2), "kernels": compiled,
                   "ours_stages_ms": our_stages(V, F, a.repeat),
                   "nodes": int(grid.valid.sum()), "levels": int(grid.levels), "precision": None, "recall": None}
            if exe is not None:
                rec, spans = run_recast(exe, V, F, a.repeat, work)
                row["ms_recast"] = round(rec["total"], 2)
                row["ratio"] = round(ms_ours / rec["total"], 2) if rec["total"] > 0 else None
                row["cpu_ms_recast"] = round(rec["cpu_total"], 2)
                row["cpu_ratio"] = round(cpu_ours / rec["cpu_total"], 2) if rec["cpu_total"] > 0 else None
                row["recast_stages_ms"] = {k: rec[k] for k in ("rasterize", "filters", "compact", "erode",
                                                                "distance", "regions")}
                i, j = surface.ij()
                mine = surface.clearance >= SETTINGS["clearance"]
                pts = np.column_stack([j[mine], i[mine], surface.y[mine]])
                width = surface.shape[1] + 2
                row["precision"] = round(match_share(pts, spans, width), 4)
                row["recall"] = round(match_share(spans, pts, width), 4)
                row["recast_spans"] = int(len(spans))
            rows.append(row)
    if a.json:
        print(json.dumps({"settings": SETTINGS, "kernels": compiled, "meshes": rows}))
        return 0
    print(f"walkable surfaces at Recast's demo settings: {SETTINGS}; compiled kernels: {compiled}")
    print(f"{'mesh':<22}{'tris':>7}{'ours ms':>10}{'recast ms':>11}{'ratio':>7}{'cpu ratio':>10}{'nodes':>8}"
          f"{'levels':>7}{'precision':>11}{'recall':>8}")
    for r in rows:
        rec = f"{r['ms_recast']:.1f}" if r["ms_recast"] is not None else "not available"
        ratio = f"{r['ratio']:.2f}" if r.get("ratio") is not None else "-"
        cpu = f"{r['cpu_ratio']:.2f}" if r.get("cpu_ratio") is not None else "-"
        prec = f"{r['precision']:.3f}" if r["precision"] is not None else "-"
        recall = f"{r['recall']:.3f}" if r["recall"] is not None else "-"
        print(f"{Path(r['mesh']).stem:<22}{r['tris']:>7}{r['ms_ours']:>10.1f}{rec:>11}{ratio:>7}{cpu:>10}"
              f"{r['nodes']:>8}{r['levels']:>7}{prec:>11}{recall:>8}")
    print("ratio: ours / Recast through regions, wall clock; cpu ratio: the same in process CPU time")
    for r in rows:
        if r.get("recast_stages_ms"):
            print(f"  {Path(r['mesh']).stem}: ours " + ", ".join(f"{k} {v:.1f}" for k, v in r["ours_stages_ms"].items())
                  + " | recast " + ", ".join(f"{k} {v:.1f}" for k, v in r["recast_stages_ms"].items()))
    if exe is None:
        print("recast: not available (needs g++ and Debian's librecast-dev)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
