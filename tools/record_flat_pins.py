"""Record the flat-arena pins: replays and 2002 grid numbers that later changes must keep.

    .venv/bin/python tools/record_flat_pins.py          # write tests/data/flat_pins/
    .venv/bin/python tools/record_flat_pins.py --check  # say whether today's code still matches

The bundled flat arenas (box, maze, paper2002) were played by the 2002 model of the
world (a plane floor, walls infinitely tall) before issue 25 gave every arena a
ground.  To hold that change to "flat arenas keep their behaviour", this tool records,
with the code of the day:

* ``<arena>_<bot>_s<seed>.ttr``: headless matches (4 tanks of the light vehicle, agent
  and scripted bots) as replays; each carries its rules, fingerprints and the digest
  of the final state, so tests/test_flat_pins.py plays them back and asks for the
  same state bit for bit;
* ``paper2002_grid.npz``: the 2002 arena's walls (every segment with its direction,
  the auxiliary rectangle included) and its navigation grid's valid mask and
  row/column run numbers (``row_index``, ``row_total``, ``col_index``, ``col_total``),
  as the one-level (nz, nx) arrays of the paper.

Run it only to re-pin on purpose (a deliberate change of the simulation): the point
of the files is that they do not follow the code.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

OUT = ROOT / "tests" / "data" / "flat_pins"
ARENAS = ("box", "maze", "paper2002")
#: (bot kind, seed, seconds): agents long enough to fire, hit and respawn
MATCHES = (("agent", 1, 40.0), ("agent", 7, 40.0), ("scripted", 3, 20.0))
BOTS = 4
VEHICLE = "light"
GRID_KEYS = ("valid", "row_index", "row_total", "col_index", "col_total")


def pin_name(arena: str, bot: str, seed: int) -> str:
    return f"{arena}_{bot}_s{seed}.ttr"


def grid_numbers(arena: str = "paper2002") -> dict[str, np.ndarray]:
    """The arena's walls and its grid's 2002 numbers, as (nz, nx) arrays of level 0."""
    from tanktool.arena import load_arena
    from tanktool.nav.navgrid import NavGrid
    from tanktool.sim.match import load_match_arena

    path = load_match_arena(arena).path
    bundle = load_arena(path)
    grid = NavGrid.load(path / "navgrid.npz")
    out = {"walls": np.asarray(bundle.walls.all_segments(), dtype=np.float64),
           "origin": np.asarray(grid.origin, dtype=np.float64), "cell": np.float64(grid.cell)}
    for key in GRID_KEYS:
        out[key] = np.asarray(getattr(grid, key))[0]     # level 0 (a NavGrid is (L, nz, nx))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare with the recorded pins, write nothing")
    args = ap.parse_args(argv)
    from tanktool.sim.match import load_match_arena, load_tank_spec
    from tanktool.sim.replay import play_replay, read_replay, record_match, write_replay

    spec = load_tank_spec(VEHICLE)
    bad = 0
    if not args.check:
        OUT.mkdir(parents=True, exist_ok=True)
    for arena in ARENAS:
        info = load_match_arena(arena)
        for bot, seed, seconds in MATCHES:
            path = OUT / pin_name(arena, bot, seed)
            if args.check:
                ok = play_replay(read_replay(path), info, spec).matches
                bad += not ok
                print(f"{path.name}: {'same' if ok else 'DIFFERENT'}")
                continue
            result, tape = record_match(info, spec, bots=BOTS, seconds=seconds, seed=seed, arena_ref=arena,
                                        vehicle_ref=VEHICLE, bot=bot)
            write_replay(path, tape)
            r = result.report
            print(f"{path.name}: {len(tape)} changes, shots {sum(t['shots'] for t in r['tanks'])}, "
                  f"kills {sum(t['kills'] for t in r['tanks'])}")
    numbers = grid_numbers()
    path = OUT / "paper2002_grid.npz"
    if args.check:
        pinned = np.load(path)
        same = all(np.array_equal(pinned[k], numbers[k]) for k in pinned.files)
        bad += not same
        print(f"{path.name}: {'same' if same else 'DIFFERENT'}")
    else:
        np.savez_compressed(path, **numbers)
        print(f"{path.name}: {len(numbers['walls'])} walls, {int(numbers['valid'].sum())} valid nodes")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
