"""How long `tanktool check` takes: the bundled content, and wall lists of growing size.

    python bench/check.py

Prints two tables.  The first times checking every bundled arena and vehicle, both
in-process (median of 5) and as the command a user types (median of 3, including
Python's start-up and imports).  The second times the stages of checking bare wall
lists (block mazes from tanktool.nav.synthetic) next to the strict parser
``parse_walls``, which stops at the first problem and does no geometry: the
peer that shows what the linter's scanning and geometry cost on top of reading.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def median_time(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def bundled() -> None:
    from tanktool.check import run_check

    paths = [p for p in (ROOT / "arenas", ROOT / "vehicles") if p.is_dir()]
    report = run_check(paths)
    inproc = median_time(lambda: run_check(paths), 5)
    exe = Path(sys.executable).with_name("tanktool")
    cmd = [str(exe), "check", *map(str, paths)] if exe.exists() else [sys.executable, "-m", "tanktool", "check", *map(str, paths)]
    cli = median_time(lambda: subprocess.run(cmd, capture_output=True, check=False), 3)
    print("bundled content:", ", ".join(p.name for p in paths), f"({len(report.files)} bundles, {report.summary()})")
    print(f"{'what':<40} {'seconds':>8}")
    print(f"{'run_check in-process (median of 5)':<40} {inproc:8.3f}")
    print(f"{'tanktool check arenas vehicles (median of 3)':<40} {cli:8.3f}")
    print()


def walls_sizes() -> None:
    from tanktool.check.freespace import analyse
    from tanktool.check.walls_rules import bare_walls_leaks, check_walls
    from tanktool.check.walls_scan import scan_walls_text
    from tanktool.formats.walls_txt import format_walls, parse_walls
    from tanktool.nav.synthetic import block_maze

    print(f"{'maze n':>6} {'walls':>6} {'parse_walls':>12} {'scan':>8} {'faces':>8} {'rules':>8} {'total':>8}  (ms)")
    with tempfile.TemporaryDirectory():
        for n in (5, 10, 20, 30):
            text = format_walls(block_maze(0, n=n))
            t_parse = median_time(lambda: parse_walls(text), 3)
            t_scan = median_time(lambda: scan_walls_text(text, "w"), 3)
            walls, _ = scan_walls_text(text, "w")
            t_faces = median_time(lambda: analyse(walls), 3)
            fs = analyse(walls)
            t_rules = median_time(lambda: (check_walls(walls, fs, "w"), bare_walls_leaks(fs, "w")), 3)
            total = t_scan + t_faces + t_rules
            print(f"{n:>6} {len(walls):>6} {1e3 * t_parse:>12.1f} {1e3 * t_scan:>8.1f} {1e3 * t_faces:>8.1f} "
                  f"{1e3 * t_rules:>8.1f} {1e3 * total:>8.1f}")


if __name__ == "__main__":
    bundled()
    walls_sizes()
