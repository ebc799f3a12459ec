"""No silent fallback (issue 25): a bundle whose grid is missing or stale is rebuilt
before `play` uses it (one line says so), or refused with one error line naming the
command that fixes it; `check` calls a missing or stale grid an error."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from tanktool import freshness
from tanktool.cli.main import cli
from tanktool.formats.bundle import read_toml, sha256_file

ROOT = Path(__file__).resolve().parent.parent


def run(*args: str):
    return CliRunner().invoke(cli, [str(a) for a in args])


@pytest.fixture
def box(tmp_path: Path) -> Path:
    out = tmp_path / "box"
    shutil.copytree(ROOT / "arenas" / "box", out)
    return out


def _play(bundle: Path):
    return run("play", "--headless", "--arena", bundle, "--seconds", "1", "--bots", "2", "--seed", "1")


def _error_lines(output: str) -> list[str]:
    return [ln for ln in output.splitlines() if ln.startswith("error:")]


def test_deleted_grid_fails_check_and_play_rebuilds_it(box: Path):
    grid = (box / "navgrid.npz").read_bytes()
    (box / "navgrid.npz").unlink()
    r = run("check", box)
    assert r.exit_code == 1 and "B202" in r.output and "navgrid.npz" in r.output, r.output
    r = _play(box)
    assert r.exit_code == 0, r.output
    said = [ln for ln in r.output.splitlines() if "rebuilt" in ln]
    assert len(said) == 1 and "navgrid.npz missing" in said[0] and "build-navgrid" in said[0]
    # the same grid as before, its hash in the manifest: check is clean again
    assert (box / "navgrid.npz").read_bytes() == grid
    assert sha256_file(box / "navgrid.npz") == read_toml(box / "arena.toml")["derived"]["navgrid.npz"]
    assert run("check", box).exit_code == 0
    assert "rebuilt" not in _play(box).output        # nothing to do the second time


def test_stale_grid_is_rebuilt(box: Path):
    shutil.copyfile(ROOT / "arenas" / "maze" / "navgrid.npz", box / "navgrid.npz")
    assert "B203" in run("check", box).output
    r = _play(box)
    assert r.exit_code == 0 and "navgrid.npz stale: rebuilt" in r.output, r.output
    assert (box / "navgrid.npz").read_bytes() == (ROOT / "arenas" / "box" / "navgrid.npz").read_bytes()


def test_an_import_without_its_grid_is_an_error_in_check(tmp_path: Path):
    # a bundle imported before the one-step import had no grid and no hash of one
    from tanktool.importer import import_arena

    out = tmp_path / "maze"
    import_arena(ROOT / "arenas" / "maze" / "maze.obj", out, grid=False)
    assert not (out / "navgrid.npz").exists()
    r = run("check", out)
    assert r.exit_code == 1 and "'navgrid.npz' is missing" in r.output, r.output
    # and the light tank's own grid ([grids.light]: its clearance and spawns are recorded)
    assert freshness.problems(out, read_toml(out / "arena.toml")) == {"navgrid.npz": "missing",
                                                                      "navgrid.light.npz": "missing"}
    assert _play(out).exit_code == 0
    assert run("check", out).exit_code == 0


def test_read_only_bundle_is_refused_with_the_fixing_command(box: Path, monkeypatch):
    (box / "navgrid.npz").unlink()
    monkeypatch.setattr(freshness, "_writable", lambda folder: False)   # root writes anywhere
    r = _play(box)
    assert r.exit_code == 2
    (line,) = _error_lines(r.output)
    assert "navgrid.npz missing" in line and f"tanktool build-navgrid {box}" in line
    assert "Traceback" not in r.output


def test_edited_walls_are_never_overwritten(box: Path):
    walls = box / "walls.txt"
    walls.write_text(walls.read_text() + "# my edit\n")
    r = _play(box)
    assert r.exit_code == 2
    (line,) = _error_lines(r.output)
    assert "walls.txt changed since the import" in line and "tanktool import-arena" in line
    assert walls.read_text().endswith("# my edit\n")


def test_missing_walls_without_the_source_is_refused(box: Path):
    (box / "walls.txt").unlink()
    (box / "box.obj").unlink()
    r = _play(box)
    assert r.exit_code == 2
    (line,) = _error_lines(r.output)
    assert "walls.txt missing" in line and "source model is missing" in line and "import-arena" in line


def test_missing_walls_with_the_source_are_imported_again(box: Path):
    (box / "walls.txt").unlink()
    r = _play(box)
    assert r.exit_code == 0 and "walls.txt missing: rebuilt (import-arena" in r.output, r.output
    assert (box / "walls.txt").read_bytes() == (ROOT / "arenas" / "box" / "walls.txt").read_bytes()
