"""Fresh imports pass their own check: every level tools/make_levels.py generates (and the
third-party levels in tests/data/arenas_obj), imported with the defaults, has walls that
`check` finds nothing wrong with -- no line it cannot read, no zero-length, repeated,
overlapping or crossing walls, no normal pointing into solid (A101-A105, A201-A205)."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from tanktool.check.runner import run_check
from tanktool.cli.main import cli

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import make_levels  # noqa: E402

THIRD_PARTY = ROOT / "tests" / "data" / "arenas_obj"
#: the rules on the walls themselves (spawn and grid rules are another matter)
WALL_CODES = {"A101", "A102", "A103", "A104", "A105", "A201", "A202", "A203", "A204", "A205"}
#: a few seconds each: always run
QUICK = ["town", "junkyard", "living_room", "stacked_floors", "narrow_ramp"]
#: terrains, big grids and the levels other tests import already: a minute together
SLOW = ["terraces", "big_terrain", "rolling_terrain", "hills", "bumpy_floor", "narrow_deck", "fort", "bridge",
        "two_storeys", "ramps_and_decks", "corridor", "islands", "fence_field"]


def _import(src: Path, out: Path) -> Path:
    r = CliRunner().invoke(cli, ["-q", "import-arena", str(src), "-o", str(out)])
    assert r.exit_code == 0, r.output
    return out


def _wall_problems(bundle: Path) -> list[str]:
    report = run_check([bundle])
    return [f"{d.code} {d.path}:{d.line} {d.message}" for d in report.diagnostics if d.code in WALL_CODES]


def _check_level(tmp_path: Path, name: str) -> None:
    src = make_levels.write_obj(make_levels.level(name), tmp_path / f"{name}.obj")
    bundle = _import(src, tmp_path / name)
    assert _wall_problems(bundle) == []
    walls = (bundle / "walls.txt").read_text()
    assert len([ln for ln in walls.splitlines() if ln and not ln.startswith("#")]) > 4


@pytest.mark.parametrize("name", QUICK)
def test_generated_level_imports_with_sound_walls(tmp_path, name):
    _check_level(tmp_path, name)


@pytest.mark.slow
@pytest.mark.parametrize("name", SLOW)
def test_generated_terrain_imports_with_sound_walls(tmp_path, name):
    _check_level(tmp_path, name)


@pytest.mark.parametrize("name", ["house.obj", "dungeon.obj"])
def test_third_party_level_imports_with_sound_walls(tmp_path, name):
    src = tmp_path / name
    shutil.copyfile(THIRD_PARTY / name, src)
    assert _wall_problems(_import(src, tmp_path / "arena")) == []


def test_every_generated_level_is_listed():
    """A level added to make_levels is checked here too (tiny_room is refused by design:
    no tank fits it)."""
    assert set(make_levels.LEVELS) == set(QUICK) | set(SLOW) | {"tiny_room"}
