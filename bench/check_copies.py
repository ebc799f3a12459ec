"""`check` on walls pasted many times with tiny offsets (near-duplicates), against the
old pair search in the same process.

    python bench/check_copies.py [--json] [--sizes 100,300,1000]

A 50 m room holds one wall written N times, every copy moved by up to OFFSET in each
coordinate (far below the check's tolerance of 4 snapping grids, so each copy is an
A202 duplicate).  ``ours`` is :func:`tanktool.check.freespace.analyse` and
:func:`tanktool.check.walls_rules.pair_rules` as they are; the peer is the same code
with the copy binning (``freespace.near_copies``) switched off, which is the previous
path: every copy noded into the arrangement and every pair of copies classified, so
its cost grows with N^2.  The table also says whether both flag the same walls as
A202 (ours reports each copy once, against the first copy; the peer once per earlier
copy), and what else the peer reports (the slivers between the copies noded into
the arrangement turn the copies' normals into A205 "flipped" walls).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter
from contextlib import contextmanager
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

OFFSET = 1e-5  # m; the tolerance on a 50 m room is 4 * 5e-6 = 2e-5 m


def copies_text(n: int, seed: int = 0) -> str:
    rng = np.random.default_rng(seed)
    lines = ["0 0 0 50 -1", "0 50 50 50 -1", "50 50 50 0 -1", "50 0 0 0 -1"]   # normals inward
    for k in range(n):
        o = rng.uniform(-OFFSET, OFFSET, 4) if k else np.zeros(4)
        lines.append(f"{10 + o[0]:.9f} {10 + o[1]:.9f} {40 + o[2]:.9f} {10 + o[3]:.9f} 1")
    lines += ["# auxiliary", "-1 -1 51 -1 1", "51 -1 51 51 1", "51 51 -1 51 1", "-1 51 -1 -1 1"]
    return "\n".join(lines) + "\n"


@contextmanager
def without_binning():
    """The previous path: no wall is anybody's copy before the pair search."""
    from tanktool.check import freespace, walls_rules

    saved = freespace.near_copies

    def none(seg, direction, live, tol):
        return np.asarray(live, dtype=np.int64).copy()

    freespace.near_copies = walls_rules.near_copies = none
    try:
        yield
    finally:
        freespace.near_copies = walls_rules.near_copies = saved


def run(text: str) -> tuple[float, float, list]:
    from tanktool.check.freespace import analyse
    from tanktool.check.walls_rules import flipped_normals, pair_rules
    from tanktool.check.walls_scan import scan_walls_text

    walls, _ = scan_walls_text(text, "copies.txt")
    t = time.perf_counter()
    fs = analyse(walls)
    t_faces = time.perf_counter() - t
    t = time.perf_counter()
    diags = pair_rules(walls, fs.grid) + flipped_normals(fs, "copies.txt")
    t_pairs = time.perf_counter() - t
    return t_faces, t_pairs, diags


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    ap.add_argument("--sizes", default="100,300,1000,3000", help="copies per case (comma separated)")
    ap.add_argument("--peer-max", type=int, default=1000, help="largest N the peer runs (its cost is N^2)")
    args = ap.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    run(copies_text(10))  # imports and first-call costs out of the first row
    rows = []
    for n in sizes:
        text = copies_text(n)
        faces, pairs, diags = run(text)
        row = {"copies": n, "bytes": len(text), "faces_s": faces, "pairs_s": pairs, "diagnostics": len(diags),
               "flagged": len({(d.code, d.line) for d in diags})}
        if n <= args.peer_max:
            with without_binning():
                pf, pp, pd = run(text)
            ours_set = {(d.code, d.line) for d in diags}
            peer_set = {(d.code, d.line) for d in pd}
            row.update(peer_faces_s=pf, peer_pairs_s=pp, peer_diagnostics=len(pd),
                       same_a202={x for x in ours_set if x[0] == "A202"} == {x for x in peer_set if x[0] == "A202"},
                       ours_only=dict(Counter(c for c, _ in ours_set - peer_set)),
                       peer_only=dict(Counter(c for c, _ in peer_set - ours_set)))
        row["codes"] = dict(Counter(d.code for d in diags))
        rows.append(row)
        if not args.json:
            if len(rows) == 1:
                print(f"one wall pasted N times, each copy moved by up to {OFFSET:g} m (a 50 m room)")
                print(f"{'N':>6} {'bytes':>9} {'ours s':>8} {'(faces':>8} {'pairs)':>8} {'diags':>6} "
                      f"{'peer s':>8} {'(faces':>8} {'pairs)':>8} {'diags':>8}  A202 same  peer also")
            r = row
            ours = r["faces_s"] + r["pairs_s"]
            line = f"{n:>6} {r['bytes']:>9,} {ours:8.2f} {r['faces_s']:8.2f} {r['pairs_s']:8.2f} {r['diagnostics']:>6}"
            if "peer_faces_s" in r:
                line += (f" {r['peer_faces_s'] + r['peer_pairs_s']:8.2f} {r['peer_faces_s']:8.2f} {r['peer_pairs_s']:8.2f}"
                         f" {r['peer_diagnostics']:>8}  {'yes' if r['same_a202'] else 'NO':>9}  "
                         f"{', '.join(f'{c} x{k}' for c, k in r['peer_only'].items()) or '-'}"
                         + (f"  (ours also: {r['ours_only']})" if r["ours_only"] else ""))
            else:
                line += f" {'(not run: > --peer-max)':>37}"
            print(line, flush=True)
    if args.json:
        print(json.dumps({"offset_m": OFFSET, "rows": rows}))


if __name__ == "__main__":
    main()
