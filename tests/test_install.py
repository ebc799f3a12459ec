"""A real install: the bundled arenas and vehicles ship inside the wheel and are found
from it (tanktool/content.py); the package list in pyproject.toml is complete.

The full round trip (build the wheel, install it into a fresh virtual environment
outside the checkout, play and check there) is in .ci/run; the slow test below
builds the wheel and looks inside it.
"""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from tanktool import content
from tanktool.formats.bundle import tomllib

ROOT = Path(__file__).resolve().parent.parent


def _setuptools() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]


def test_every_package_is_listed_and_the_content_is_mapped_in():
    conf = _setuptools()
    on_disk = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "tanktool").rglob("__init__.py")}
    listed = set(conf["packages"])
    assert on_disk - listed == set(), "add these packages to [tool.setuptools] packages in pyproject.toml"
    assert conf["package-dir"] == {"tanktool.bundled.arenas": "arenas", "tanktool.bundled.vehicles": "vehicles"}
    assert listed - on_disk == {"tanktool.bundled.arenas", "tanktool.bundled.vehicles"}
    for pkg in ("tanktool.bundled.arenas", "tanktool.bundled.vehicles"):
        assert conf["package-data"][pkg] == ["**/*"]


def test_the_checkout_is_the_fallback():
    # here (a checkout, editable install) there is no tanktool/bundled: the top-level folders
    assert not (ROOT / "tanktool" / "bundled").exists()
    assert content.bundled_dir("arenas") == ROOT / "arenas"
    assert content.bundled_dir("vehicles") == ROOT / "vehicles"
    assert {"box", "maze", "paper2002"} <= set(content.bundled_names("arenas"))
    assert {"light", "heavy"} <= set(content.bundled_names("vehicles"))
    with pytest.raises(ValueError):
        content.bundled_dir("tanks")


def _installed_layout(tmp_path: Path, monkeypatch) -> Path:
    """A package folder shaped as the wheel installs it, with one arena and one vehicle
    (copies of the bundled ones), and no checkout beside it."""
    import shutil

    pkg = tmp_path / "site-packages" / "tanktool"
    shutil.copytree(ROOT / "arenas" / "box", pkg / "bundled" / "arenas" / "box")
    shutil.copytree(ROOT / "vehicles" / "light", pkg / "bundled" / "vehicles" / "light")
    monkeypatch.setattr(content.importlib.resources, "files", lambda name: pkg)
    monkeypatch.setattr(content, "CHECKOUT", tmp_path / "no-checkout")
    return pkg


def test_an_installed_package_finds_its_own_content(tmp_path, monkeypatch):
    pkg = _installed_layout(tmp_path, monkeypatch)
    assert content.bundled_dir("arenas") == pkg / "bundled" / "arenas"
    assert content.bundled_names("vehicles") == ["light"]
    from tanktool.sim.match import _bundle_dir, default_arena, default_vehicle

    assert default_arena() == "box" and default_vehicle() == "light"
    assert _bundle_dir("box", "arenas", ()) == pkg / "bundled" / "arenas" / "box"
    from tanktool.game.app import bundled

    assert bundled("arenas") == ["box"]
    # `tanktool play` with nothing named plays there (it said "none bundled" before)
    from click.testing import CliRunner

    from tanktool.cli.main import cli

    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(cli, ["play", "--headless", "--seconds", "1", "--bots", "2"])
    assert r.exit_code == 0, r.output
    assert r.output.startswith("box: 2 bots, 1 s")
    r = CliRunner().invoke(cli, ["check", "--strict"])
    assert r.exit_code == 0, r.output
    assert f"checking the bundled content ({pkg / 'bundled' / 'arenas'}, {pkg / 'bundled' / 'vehicles'})" in r.output
    assert r.output.strip().endswith("0 errors, 0 warnings in 2 files")


def test_without_any_content_the_messages_say_so(tmp_path, monkeypatch):
    monkeypatch.setattr(content.importlib.resources, "files", lambda name: tmp_path / "empty")
    monkeypatch.setattr(content, "CHECKOUT", tmp_path / "no-checkout")
    monkeypatch.chdir(tmp_path)
    assert content.bundled_dir("arenas") is None and content.bundled_names("vehicles") == []
    from click.testing import CliRunner

    from tanktool.cli.main import cli

    r = CliRunner().invoke(cli, ["play", "--headless", "--seconds", "1"])
    assert r.exit_code == 2 and "no arena given and none bundled" in r.output
    r = CliRunner().invoke(cli, ["check"])
    assert r.exit_code == 2 and "no PATH given and no bundled content found" in r.output


@pytest.mark.slow
def test_the_wheel_carries_every_bundled_file(tmp_path):
    """Build the wheel (pip, as `pip install .` does) from a copy of the checkout (the
    build leaves a build/ folder behind) and look inside."""
    import shutil

    src = tmp_path / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, src / name)
    for name in ("tanktool", "arenas", "vehicles"):
        shutil.copytree(ROOT / name, src / name, ignore=shutil.ignore_patterns("__pycache__"))
    out = subprocess.run([sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "--wheel-dir",
                          str(tmp_path), str(src)], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    (wheel,) = tmp_path.glob("tanktool-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for kind in ("arenas", "vehicles"):
        for f in (ROOT / kind).rglob("*"):
            if f.is_file() and "__pycache__" not in f.parts:
                assert f"tanktool/bundled/{kind}/{f.relative_to(ROOT / kind).as_posix()}" in names
    assert "tanktool/content.py" in names and "tanktool/cli/main.py" in names
