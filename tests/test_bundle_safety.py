"""Never lose a user's files, never leave a half-written bundle (issues 18 and 21).

Only a bundle tanktool wrote is replaced; temporary folders and files never outlive a
run, not even a run killed with SIGKILL at a random moment; a bundle's derived files
and its manifest change together; files a manifest names stay inside the bundle;
a full disk or a file size limit is one ``error:`` line, exit 2.
"""

from __future__ import annotations

import os
import random
import resource
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import trimesh
from click.testing import CliRunner

from tanktool.arena import load_arena
from tanktool.cli.main import cli
from tanktool.errors import ArenaError, OutputError, VehicleError
from tanktool.formats import bundle as B
from tanktool.formats import bundle_swap
from tanktool.formats.bundle import clean_stale, read_toml, sha256_file
from tanktool.formats.bundle_swap import bundle_update, check_replaceable, staged_dir
from tanktool.formats.vehicle_bundle import load_vehicle

ROOT = Path(__file__).resolve().parent.parent
DATA = Path(__file__).resolve().parent / "data"
CLEAN = DATA / "check_clean"
LIGHT = ROOT / "vehicles" / "light" / "light.3ds"
DEFAULT_KILLS = int(os.environ.get("TANKTOOL_KILLS", "8"))


def run(*args: str):
    return CliRunner().invoke(cli, list(args))


def box_obj(path: Path) -> Path:
    trimesh.creation.box(extents=[20, 3, 20]).export(path)
    return path


def leftovers(*folders: Path) -> list[str]:
    """tanktool's temporary names (and old-style ``.x.old`` copies) in ``folders``."""
    out = []
    for f in folders:
        if f.is_dir():
            out += [f"{f}/{n}" for n in os.listdir(f) if B.is_temp_name(n) or n.endswith(".old")]
    return out


def one_error_line(r) -> str:
    assert r.exit_code == 2, r.output
    # warnings about the model (the heavy tank does not fit this small box) may come first
    lines = [ln for ln in r.output.strip().splitlines() if ln and not ln.startswith("warning: ")]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in r.output, r.output
    return lines[0]


def fresh_pid() -> int:
    """The pid of a process that has finished (so it is certainly not running)."""
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


# ------------------------------------------------------------ what --force may replace

def test_force_does_not_delete_a_folder_that_is_not_a_bundle(tmp_path):
    modder = tmp_path / "modder"
    modder.mkdir()
    box_obj(modder / "box.obj")
    (modder / "level.blend").write_text("three months of work")
    (modder / "textures").mkdir()
    line = one_error_line(run("import-arena", str(modder / "box.obj"), "-o", str(modder), "--force"))
    assert "is not a tanktool bundle" in line and str(modder) in line
    assert (modder / "level.blend").read_text() == "three months of work" and (modder / "textures").is_dir()
    assert sorted(os.listdir(tmp_path)) == ["modder"]


def test_force_does_not_replace_a_file(tmp_path):
    precious = tmp_path / "precious.txt"
    precious.write_text("mine")
    line = one_error_line(run("import-vehicle", str(LIGHT), "-o", str(precious), "--force"))
    assert "is not a folder" in line
    assert precious.read_text() == "mine"
    assert sorted(os.listdir(tmp_path)) == ["precious.txt"]  # no .precious.txt.old


def test_force_replaces_only_its_own_kind_of_bundle_with_nothing_foreign(tmp_path):
    model = box_obj(tmp_path / "box.obj")
    arena = tmp_path / "arena"
    assert run("-q", "import-arena", str(model), "-o", str(arena)).exit_code == 0
    line = one_error_line(run("import-vehicle", str(LIGHT), "-o", str(arena), "--force"))
    assert "is an arena bundle" in line
    (arena / "notes.txt").write_text("my notes")
    line = one_error_line(run("import-arena", str(model), "-o", str(arena), "--force"))
    assert "not part of the bundle (notes.txt)" in line
    (arena / "notes.txt").unlink()
    doc = read_toml(arena / "arena.toml")
    del doc["tool_version"]
    B.write_toml(arena / "arena.toml", doc)
    assert "no tool_version" in one_error_line(run("import-arena", str(model), "-o", str(arena), "--force"))
    assert leftovers(tmp_path, arena) == []


def test_force_replaces_a_bundle_and_leaves_nothing_behind(tmp_path):
    model = box_obj(tmp_path / "box.obj")
    out = tmp_path / "b"
    assert run("-q", "import-arena", str(model), "-o", str(out)).exit_code == 0
    assert run("-q", "build-navgrid", str(out)).exit_code == 0
    first = sha256_file(out / "arena.toml")
    assert run("-q", "import-arena", str(model), "-o", str(out), "--force", "--height", "1.2").exit_code == 0
    assert sha256_file(out / "arena.toml") != first
    assert sorted(os.listdir(tmp_path)) == ["b", "box.obj"]
    assert leftovers(out) == []
    # an .obj's material library is part of the bundle it was copied into: rebuild allowed
    (tmp_path / "m.mtl").write_text("newmtl a\nKd 1 0 0\n")
    (tmp_path / "m.obj").write_text("mtllib m.mtl\nusemtl a\n" + (tmp_path / "box.obj").read_text())
    assert run("-q", "import-arena", str(tmp_path / "m.obj"), "-o", str(out), "--force").exit_code == 0
    assert read_toml(out / "arena.toml")["source"]["companions"] == ["m.mtl"]
    assert run("-q", "import-arena", str(tmp_path / "m.obj"), "-o", str(out), "--force").exit_code == 0


def test_bad_output_places_are_clean_errors(tmp_path, monkeypatch):
    model = box_obj(tmp_path / "box.obj")
    line = one_error_line(run("import-arena", str(model), "-o", "/proc/nope"))
    assert line.startswith("error: /proc/nope: cannot make a folder in /proc")
    monkeypatch.chdir(tmp_path)
    line = one_error_line(run("import-arena", "box.obj", "-o", ".", "--force"))
    assert "is not a tanktool bundle" in line
    assert sorted(os.listdir(tmp_path)) == ["box.obj"]
    with pytest.raises(OutputError, match="root of the file system"):
        with staged_dir("/", force=True):
            pass


def test_absurd_scale_is_refused_before_any_work(tmp_path):
    model = box_obj(tmp_path / "box.obj")
    line = one_error_line(run("import-arena", str(model), "-o", str(tmp_path / "a4"), "--scale", "1000000"))
    assert "more than 100 km" in line and "--scale" in line
    line = one_error_line(run("import-arena", str(model), "-o", str(tmp_path / "a5"), "--scale", "0.00001"))
    assert "less than 1 mm" in line
    assert sorted(os.listdir(tmp_path)) == ["box.obj"]


# ------------------------------------------------------------ what killed runs leave

def test_stale_staging_and_temporary_files_are_cleaned_at_the_next_run(tmp_path):
    dead = fresh_pid()
    stage = tmp_path / f".b.tanktool-{dead}-00ab"
    stage.mkdir()
    (stage / "walls.txt").write_text("half")
    tmp_file = tmp_path / f".report.json.tanktool-{dead}-0f.tmp"
    tmp_file.write_text("half")
    alive = tmp_path / f".c.tanktool-{os.getppid()}-0a"   # a running process's: kept
    alive.mkdir()
    user = tmp_path / ".b.backup"                         # not ours: kept
    user.mkdir()
    model = box_obj(tmp_path / "box.obj")
    assert run("-q", "import-arena", str(model), "-o", str(tmp_path / "b")).exit_code == 0
    assert not stage.exists()
    B.atomic_write_text(tmp_path / "report.json", "{}")
    assert not tmp_file.exists() and alive.is_dir() and user.is_dir()


def test_a_bundle_moved_aside_by_a_killed_swap_is_put_back(tmp_path):
    """Without RENAME_EXCHANGE the old bundle is renamed aside first; a kill then
    leaves no bundle, and the next run puts the old one back."""
    model = box_obj(tmp_path / "box.obj")
    out = tmp_path / "b"
    assert run("-q", "import-arena", str(model), "-o", str(out)).exit_code == 0
    before = sha256_file(out / "arena.toml")
    dead = fresh_pid()
    out.rename(tmp_path / f".b.tanktool-{dead}-0c.old")
    (tmp_path / f".b.tanktool-{dead}-0c").mkdir()           # its half-made replacement
    assert load_arena(out).name == "box"                    # the next run finds it again
    assert sha256_file(out / "arena.toml") == before
    assert leftovers(tmp_path, out) == []


def test_replacing_without_rename_exchange(tmp_path, monkeypatch):
    monkeypatch.setattr(bundle_swap, "_exchange", lambda a, b: False)
    model = box_obj(tmp_path / "box.obj")
    out = tmp_path / "b"
    for height in ("1", "1.2"):
        assert run("-q", "import-arena", str(model), "-o", str(out), "--force", "--height", height).exit_code == 0
    assert read_toml(out / "arena.toml")["walls"]["height"] == 1.2
    assert leftovers(tmp_path, out) == []


def test_build_navgrid_changes_grid_and_manifest_together(tmp_path, monkeypatch):
    model = box_obj(tmp_path / "box.obj")
    out = tmp_path / "b"
    assert run("-q", "import-arena", str(model), "-o", str(out)).exit_code == 0
    assert run("-q", "build-navgrid", str(out)).exit_code == 0
    snapshot = {p.name: sha256_file(p) for p in out.iterdir()}

    from tanktool.nav.quadtree import WallQuadtree

    def boom(self, path):
        raise OSError(28, "No space left on device", str(path))
    monkeypatch.setattr(WallQuadtree, "save", boom)
    line = one_error_line(run("build-navgrid", str(out), "--cell", "0.7"))
    assert "no space left on the disk" in line
    assert {p.name: sha256_file(p) for p in out.iterdir()} == snapshot   # nothing changed
    assert leftovers(tmp_path, out) == []
    monkeypatch.undo()
    assert run("-q", "build-navgrid", str(out), "--cell", "0.7").exit_code == 0
    doc = read_toml(out / "arena.toml")
    assert doc["navgrid"]["cell"] == 0.7
    for name in ("navgrid.npz", "quadtree.npz", "navgrid.png"):
        assert doc["derived"][name] == sha256_file(out / name)


def test_bundle_update_is_all_or_nothing(tmp_path):
    b = tmp_path / "b"
    b.mkdir()
    (b / "arena.toml").write_text("x = 1\n")
    (b / "keep.txt").write_text("keep")
    with pytest.raises(RuntimeError):
        with bundle_update(b) as stage:
            B.atomic_write_text(stage / "arena.toml", "x = 2\n")
            raise RuntimeError
    assert (b / "arena.toml").read_text() == "x = 1\n"
    with bundle_update(b) as stage:
        B.atomic_write_text(stage / "arena.toml", "x = 3\n")
    assert (b / "arena.toml").read_text() == "x = 3\n" and (b / "keep.txt").read_text() == "keep"
    assert leftovers(tmp_path, b) == []


KILL_CHILD = textwrap.dedent("""
    import sys
    from pathlib import Path
    from tanktool.importer import import_arena
    from tanktool.cli.main import cli
    model, out = Path(sys.argv[1]), Path(sys.argv[2])
    print("ready", flush=True)
    k = 0
    while True:
        k += 1
        import_arena(model, out, force=True, height=0.9 + 0.01 * (k % 5))
        try:
            cli.main(["-q", "build-navgrid", str(out), "--cell", str(0.5 + 0.1 * (k % 3))], standalone_mode=False)
        except SystemExit:
            pass
""")


def bundle_is_whole(out: Path) -> list[str]:
    """What is wrong with the bundle: unreadable manifest, files whose sha256 is not the
    one the manifest records (a partial or stale bundle)."""
    doc = read_toml(out / "arena.toml")
    wrong = [f"{name}: sha256 differs" for name, digest in doc["derived"].items()
             if not (out / name).is_file() or sha256_file(out / name) != digest]
    wrong += [f"{n}: not in the manifest" for n in os.listdir(out)
              if n not in bundle_swap.bundle_files(out, doc, "arena.toml")]
    return wrong


def kill_at_random_moments(tmp_path: Path, kills: int, seed: int = 0) -> None:
    model = box_obj(tmp_path / "box.obj")
    out = tmp_path / "b"
    assert run("-q", "import-arena", str(model), "-o", str(out)).exit_code == 0
    rng = random.Random(seed)
    problems = []
    for k in range(kills):
        p = subprocess.Popen([sys.executable, "-c", KILL_CHILD, str(model), str(out)], stdout=subprocess.PIPE,
                             text=True, cwd=tmp_path)
        assert p.stdout.readline().strip() == "ready"
        time.sleep(rng.uniform(0.0, 2.0))
        p.send_signal(signal.SIGKILL)
        p.wait()
        # the next run: it finds the bundle (put back if need be) and tidies up
        load_arena(out)
        clean_stale(tmp_path)
        problems += [f"kill {k}: {w}" for w in bundle_is_whole(out)]
        problems += [f"kill {k}: left {n}" for n in leftovers(tmp_path, out)]
    assert not problems, problems[:20]


def test_sigkill_at_random_moments_leaves_a_whole_bundle_and_no_leftovers(tmp_path):
    kill_at_random_moments(tmp_path, DEFAULT_KILLS)


@pytest.mark.slow
def test_sigkill_at_random_moments_long(tmp_path):
    kill_at_random_moments(tmp_path, 200, seed=1)


# ------------------------------------------------------------ the disk says no

def _limited(limit: int, *args: str, cwd: Path) -> subprocess.CompletedProcess:
    def preexec():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return subprocess.run([sys.executable, "-m", "tanktool", *args], cwd=cwd, capture_output=True, text=True,
                          preexec_fn=preexec, timeout=300)


def test_file_size_limit_is_one_error_line_and_leaves_nothing(tmp_path):
    model = box_obj(tmp_path / "box.obj")
    p = _limited(16_000, "import-arena", "box.obj", "-o", "small", cwd=tmp_path)
    assert p.returncode == 2, p.stderr
    lines = [ln for ln in p.stderr.strip().splitlines() if not ln.startswith("warning: ")]
    assert len(lines) == 1 and lines[0].startswith("error: "), p.stderr
    assert "small/" in lines[0] and ".tanktool-" not in lines[0] and "file size limit reached" in lines[0], p.stderr
    assert sorted(os.listdir(tmp_path)) == ["box.obj"]
    # build-navgrid on a bundle: the bundle is left as it was
    assert run("-q", "import-arena", str(model), "-o", str(tmp_path / "b")).exit_code == 0
    snapshot = {f.name: sha256_file(f) for f in (tmp_path / "b").iterdir()}
    p = _limited(3_000, "build-navgrid", "b", cwd=tmp_path)
    assert p.returncode == 2 and "file size limit reached" in p.stderr and p.stderr.count("\n") == 1, p.stderr
    assert {f.name: sha256_file(f) for f in (tmp_path / "b").iterdir()} == snapshot
    assert leftovers(tmp_path, tmp_path / "b") == []
    p = _limited(64, "play", "--headless", "--seconds", "1", "--bots", "2", "--report", "r.json", cwd=tmp_path)
    assert p.returncode == 2 and p.stderr.strip().splitlines()[-1].startswith("error: r.json: cannot write"), p.stderr
    assert not (tmp_path / "r.json").exists() and leftovers(tmp_path) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_folder_is_one_error_line(tmp_path):
    model = box_obj(tmp_path / "box.obj")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        line = one_error_line(run("import-arena", str(model), "-o", str(ro / "x")))
        assert "permission denied" in line
    finally:
        ro.chmod(0o755)


# ------------------------------------------------------------ files stay inside their bundle

def _vehicle(tmp_path: Path) -> Path:
    import shutil

    v = tmp_path / "vehicles" / "tank"
    shutil.copytree(CLEAN / "vehicles" / "tank", v)
    return v


@pytest.mark.parametrize("table,name", [("hull", "/etc/passwd"), ("spheres", "/dev/zero"),
                                        ("hull", "../../../../etc/passwd"), ("spheres", "../tank/../../x")])
def test_vehicle_files_outside_the_bundle_are_refused(tmp_path, table, name):
    v = _vehicle(tmp_path)
    text = (v / "vehicle.toml").read_text().replace(f'file = "{table}.txt"', f'file = "{name}"')
    (v / "vehicle.toml").write_text(text)
    with pytest.raises(VehicleError, match=rf"\[{table}\] file must be a file name inside the bundle"):
        load_vehicle(v)
    r = run("check", str(v))
    assert r.exit_code == 1 and "error" in r.output and "X001" not in r.output, r.output


@pytest.mark.parametrize("target", ["/dev/zero", "/etc/passwd"])
def test_links_out_of_the_bundle_are_refused(tmp_path, target):
    v = _vehicle(tmp_path)
    (v / "spheres.txt").unlink()
    (v / "spheres.txt").symlink_to(target)
    with pytest.raises(VehicleError, match="leads outside the bundle"):
        load_vehicle(v)
    t0 = time.process_time()
    report = __import__("tanktool.check", fromlist=["run_check"]).run_check([v])
    assert time.process_time() - t0 < 30 and report.errors >= 1
    assert not any(d.code == "X001" for d in report.diagnostics)


def test_arena_model_outside_the_bundle_is_refused(tmp_path):
    import shutil

    a = tmp_path / "arenas" / "yard"
    shutil.copytree(CLEAN / "arenas" / "yard", a)
    for name in ("/etc/passwd", "/dev/zero", "../../model.glb"):
        doc = read_toml(a / "arena.toml")
        doc["model"]["file"] = name
        B.write_toml(a / "arena.toml", doc)
        with pytest.raises(ArenaError, match=r"\[model\] file must be a file name inside the bundle"):
            load_arena(a)
        assert check_cli_errors(a)


def check_cli_errors(path: Path) -> bool:
    r = run("check", str(path))
    return r.exit_code == 1 and "error" in r.output


def test_check_replaceable_refuses_links(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "link").symlink_to(real)
    with pytest.raises(OutputError, match="symbolic link"):
        check_replaceable(tmp_path / "link", True, "arena.toml")


def test_obj_materials_reads_mtllib_lines_only(tmp_path):
    """The .obj's material libraries a bundle holds: only lines starting with mtllib, at
    any line ending (\\n, \\r\\n, \\r), never a comment or another keyword."""
    from tanktool.formats.bundle_swap import _obj_materials

    cases = {b"mtllib a.mtl\nv 1 2 3\n": {"a.mtl"},
             b"v 1\r\nmtllib b.mtl c.mtl\r\n": {"b.mtl", "c.mtl"},
             b"v 1\rmtllib d.mtl": {"d.mtl"},
             b"# mtllib x.mtl\n  mtllib y.mtl\nusemtl z\nxmtllib q\n": set(),
             b"": set(), b"mtllib": set()}
    for data, expected in cases.items():
        (tmp_path / "m.obj").write_bytes(data)
        assert _obj_materials(tmp_path / "m.obj") == expected, data
