"""What one grid per vehicle size costs the import (issue 25), in one process.

``import_arena`` as it is (navgrid.npz for the largest vehicle that fits, and
navgrid.<vehicle>.npz with its own spawns for each smaller one) against the same import
with the smaller vehicles' grids left out (``importer._vehicle_grids`` returning none,
the import before them), best of ``--repeat`` CPU seconds each, the two ways taking
turns, with the ratio.  Levels: the bundled fort and hills (their sources), and the
generated narrow_ramp (tools/make_levels.py: a deck only the light tank reaches), with
what each grid reaches.

    python bench/vehicle_grids.py [--repeat N] [--json]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "tools"))

from one_step import best_turns  # noqa: E402


def levels(tmp: Path) -> list[tuple[str, Path]]:
    import make_levels

    ramp = make_levels.write_obj(make_levels.level("narrow_ramp"), tmp / "narrow_ramp.obj")
    return [("fort", ROOT / "arenas" / "fort" / "fort.obj"), ("hills", ROOT / "arenas" / "hills" / "hills.obj"),
            ("narrow_ramp", ramp)]


def reach(bundle: Path) -> dict[str, int]:
    """Reachable nodes of each grid file of a bundle."""
    from tanktool.nav.navgrid import NavGrid

    return {f.name: int((g.valid & g.reachable).sum()) for f in sorted(bundle.glob("navgrid*.npz"))
            for g in [NavGrid.load(f)]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    from tanktool import importer

    rows = []
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for name, model in levels(tmp):
            out = tmp / name
            real = importer._vehicle_grids

            def per_vehicle() -> None:
                importer._vehicle_grids = real
                importer.import_arena(model, out, force=True, warn=lambda m: None)

            def one_grid() -> None:
                importer._vehicle_grids = lambda *args: {}
                try:
                    importer.import_arena(model, tmp / f"{name}-one", force=True, warn=lambda m: None)
                finally:
                    importer._vehicle_grids = real

            (_, c_per, _), (_, c_one, _) = best_turns([per_vehicle, one_grid], a.repeat)
            rows.append({"level": name, "per_vehicle_cpu_s": round(c_per, 3), "one_grid_cpu_s": round(c_one, 3),
                         "ratio": round(c_per / c_one, 3), "reachable": reach(out)})
    if a.json:
        print(json.dumps(rows, indent=2))
        return 0
    print(f"{'level':<12} {'per vehicle':>12} {'one grid':>9} {'ratio':>6}  reachable nodes per grid")
    for r in rows:
        grids = ", ".join(f"{k} {v:,}" for k, v in r["reachable"].items())
        print(f"{r['level']:<12} {r['per_vehicle_cpu_s']:>10.2f} s {r['one_grid_cpu_s']:>7.2f} s {r['ratio']:>6.2f}  {grids}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
