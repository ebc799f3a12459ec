"""Wall extraction speed beside trimesh's bare cross-section of the same model.

Per model: the bare cut, ``trimesh.Trimesh.section(plane_origin, plane_normal)`` at
the same height on a fresh mesh (so no cached adjacency helps it), and our whole
extraction (``tanktool.geometry.walls.extract_walls``: floor, cut, solid
cross-sections, free space, outline, thin walls).  Best of ``--repeat`` runs each,
in the same process.  Models: the real dungeon.obj (10k faces), the bundled maze,
and a 1.3-million-face arena: dungeon.obj subdivided three times (every triangle
into 64), two copies side by side.

Goals: extraction within 3x the bare cut; under 1 s for a million faces.

    python bench/import_arena.py [--json] [--repeat N] [--quick]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

DUNGEON = ROOT / "tests" / "data" / "arenas_obj" / "dungeon.obj"


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


def run(repeat: int, quick: bool) -> list[dict]:
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


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="a 160k-face model instead of 1.3M")
    args = ap.parse_args()
    rows = run(args.repeat, args.quick)
    big = [r for r in rows if r["faces"] >= 1_000_000]
    goals = {
        "ratio_within_3x": all(r["ratio"] <= 3.0 for r in rows),
        "million_faces_under_1s": all(r["extraction_ms"] < 1000 for r in big) if big else None,
    }
    if args.json:
        print(json.dumps({"repeat": args.repeat, "models": rows, "goals": goals}, indent=1))
        return 0
    print(f"{'model':<36} {'faces':>10} {'bare cut ms':>12} {'ours ms':>9} {'ratio':>6} {'walls':>6}")
    for r in rows:
        print(f"{r['model']:<36} {r['faces']:>10,} {r['bare_cut_ms']:>12.1f} {r['extraction_ms']:>9.1f} "
              f"{r['ratio']:>6.2f} {r['walls']:>6}")
    print()
    for r in rows:
        print(f"{r['model']}: " + ", ".join(f"{k} {v:.1f} ms" for k, v in r["stages_ms"].items()))
    print(f"goals: within 3x of the bare cut: {goals['ratio_within_3x']}; "
          f"1M+ faces under 1 s: {goals['million_faces_under_1s']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
