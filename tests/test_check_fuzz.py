"""Fuzzing ``tanktool check`` with mutated real walls.txt files: it must never crash.

Sources: the bundled arenas' walls.txt when there are any, and the clean corpus
arena.  A second test mutates the clean corpus bundles' manifests, hull.txt and
spheres.txt the same way.  Each case applies 1-4 random mutations (lines deleted, duplicated, swapped or
garbled; numbers replaced by huge, tiny, negative, NaN or copied values; Directions
flipped; the auxiliary marker dropped or doubled; bytes that are not UTF-8), then
checks the result both as a bare walls.txt and inside a copy of an arena bundle (so
the spawn, passage and island rules run on it too).  A crash inside a rule would
show up as X001, so the test asserts there is none.
"""

from __future__ import annotations

import os
import random
import shutil
from pathlib import Path

import pytest

from fuzz_mutators import line_op
from tanktool.check import RULES, run_check

ROOT = Path(__file__).resolve().parent.parent
CLEAN = Path(__file__).resolve().parent / "data" / "check_clean"
DEFAULT_CASES = int(os.environ.get("TANKTOOL_FUZZ_CASES", "300"))

NUMBERS = ["0", "-0", "1e300", "-1e300", "1e-300", "5e-324", "nan", "inf", "-inf", "1e15",
           "40.00000001", "39.99999999", "20", "1", "-1", "2", "0x10", "1_000", "", "--", "١٢"]


def sources() -> list[tuple[str, Path | None]]:
    """(walls text, the arena bundle it came from) for every real walls.txt."""
    out = []
    for walls in sorted((ROOT / "arenas").glob("*/walls.txt")) + [CLEAN / "arenas" / "yard" / "walls.txt"]:
        out.append((walls.read_text(encoding="utf-8", errors="replace"), walls.parent))
    return out


#: the mutations shared with every line-based format (tests/fuzz_mutators.py line_op)
COMMON = {0: "delete", 1: "duplicate", 2: "swap", 3: "field", 9: "cut_line", 10: "cut_file"}


def mutate(text: str, rng: random.Random) -> bytes:
    lines = text.splitlines()
    for _ in range(rng.randint(1, 4)):
        if not lines:
            lines = ["0 0 1 1 1"]
        i = rng.randrange(len(lines))
        op = rng.randrange(12)
        fields = lines[i].split()
        if op in COMMON:
            lines = line_op(lines, i, COMMON[op], rng, NUMBERS)
        elif op == 4 and len(fields) == 5:
            fields[4] = str(-int(float(fields[4]))) if fields[4] in ("1", "-1") else "1"
            lines[i] = " ".join(fields)
        elif op == 5 and len(fields) == 5:
            # copy an end point of another wall: makes T junctions, crossings, overlaps
            other = rng.choice(lines).split()
            if len(other) == 5:
                a, b = rng.choice([(0, 0), (0, 2), (2, 0), (2, 2)])
                fields[a:a + 2] = other[b:b + 2]
                lines[i] = " ".join(fields)
        elif op == 6 and len(fields) == 5:
            try:
                k = rng.randrange(4)
                fields[k] = repr(float(fields[k]) + rng.choice([1e-9, -1e-7, 0.5, -3.0, 17.0]))
                lines[i] = " ".join(fields)
            except ValueError:
                pass
        elif op == 7:
            lines = [ln for ln in lines if not ln.startswith("# auxiliary")]
        elif op == 8:
            lines.insert(rng.randrange(len(lines) + 1), "# auxiliary")
        elif op == 11 and len(fields) == 5:
            fields[2:4] = fields[0:2]  # zero length
            lines[i] = " ".join(fields)
    data = ("\n".join(lines) + "\n").encode()
    if rng.random() < 0.05:
        k = rng.randrange(len(data) + 1)
        data = data[:k] + bytes([0xFF, 0xFE]) + data[k:]
    return data


def run_case(seed: int, tmp: Path, pool: list[tuple[str, Path | None]]) -> None:
    rng = random.Random(seed)
    text, bundle = pool[rng.randrange(len(pool))]
    data = mutate(text, rng)
    if bundle is not None and rng.random() < 0.5:
        target = tmp / f"case{seed}" / "arenas" / "a"
        shutil.copytree(bundle, target)
        (target / "walls.txt").write_bytes(data)
        if (CLEAN / "vehicles").is_dir():
            shutil.copytree(CLEAN / "vehicles", tmp / f"case{seed}" / "vehicles")
    else:
        target = tmp / f"case{seed}.walls.txt"
        target.write_bytes(data)
    report = run_check([target])
    crashes = [d.format() for d in report.diagnostics if d.code == "X001"]
    assert not crashes, (seed, data[:2000], crashes)
    assert not report.unreadable
    for d in report.diagnostics:
        assert d.code in RULES and d.severity == RULES[d.code].severity and d.line >= 0
    assert report.exit_code() in (0, 1)


def _fuzz(cases: int, tmp_path: Path, first_seed: int = 0) -> None:
    pool = sources()
    for seed in range(first_seed, first_seed + cases):
        run_case(seed, tmp_path, pool)


def test_fuzz_mutated_walls_never_crash(tmp_path):
    _fuzz(DEFAULT_CASES, tmp_path)


@pytest.mark.slow
def test_fuzz_mutated_walls_never_crash_long(tmp_path):
    _fuzz(10 * DEFAULT_CASES, tmp_path, first_seed=100_000)


# ------------------------------------------------------------------ bundle files
VALUES = ["nan", "inf", "-1", "0", "1e308", '"text"', "[]", "[1, 2]", "true", "{}", "-0.0", "1e-300", "3"]


def mutate_bundle_file(text: str, rng: random.Random) -> str:
    """Line mutations for TOML manifests, hull.txt and spheres.txt."""
    lines = text.splitlines()
    for _ in range(rng.randint(1, 3)):
        if not lines:
            break
        i = rng.randrange(len(lines))
        op = rng.randrange(5)
        if op == 0:
            del lines[i]
        elif op == 1 and "=" in lines[i]:
            key = lines[i].split("=", 1)[0]
            lines[i] = f"{key}= {rng.choice(VALUES)}"
        elif op == 2:
            fields = lines[i].split()
            if fields:
                fields[rng.randrange(len(fields))] = rng.choice(VALUES + ["-5", "0.1", "99"])
                lines[i] = " ".join(fields)
        elif op == 3:
            lines.insert(i, lines[rng.randrange(len(lines))])
        else:
            lines = lines[: rng.randrange(len(lines) + 1)]
    return "\n".join(lines) + "\n"


def _fuzz_bundles(cases: int, tmp_path: Path, first_seed: int = 0) -> None:
    for seed in range(first_seed, first_seed + cases):
        rng = random.Random(seed)
        case = tmp_path / f"b{seed}"
        shutil.copytree(CLEAN, case)
        kind = rng.choice(["arenas/yard/arena.toml", "vehicles/tank/vehicle.toml",
                           "vehicles/tank/hull.txt", "vehicles/tank/spheres.txt"])
        f = case / kind
        f.write_text(mutate_bundle_file(f.read_text(), rng))
        report = run_check([case])
        crashes = [d.format() for d in report.diagnostics if d.code == "X001"]
        assert not crashes, (seed, kind, f.read_text()[:3000], crashes)
        assert report.exit_code() in (0, 1)


def test_fuzz_mutated_bundles_never_crash(tmp_path):
    _fuzz_bundles(max(30, DEFAULT_CASES // 3), tmp_path)


@pytest.mark.slow
def test_fuzz_mutated_bundles_never_crash_long(tmp_path):
    _fuzz_bundles(10 * DEFAULT_CASES, tmp_path, first_seed=100_000)
