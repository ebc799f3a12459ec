"""Hostile inputs for every reader: the harness that makes mutated files of every kind
and runs them (the hand-made cases are in :mod:`fuzz_files`, the mutators in
:mod:`fuzz_mutators`).

Each *kind* of input has seed files (real ones from tests/data, the bundled arenas and
vehicles, and small files made here), a mutator and a target: the function that reads
such a file the way the tools do (``models.load_scene`` for models, ``run_check`` and
play's loaders for bundles, ``read_replay`` for replays, ...).  A target may succeed or
raise a :class:`TanktoolError`; anything else is a failure, and so is an input whose
reading takes more than ``TIME_LIMIT`` seconds of CPU time.

Generators by kind of attack: byte mutations (flips, extreme integers, truncation,
splices), structure mutations (glTF JSON: counts, strides, offsets, self-referencing
and cyclic node graphs; 3DS chunk lengths; TOML values of the wrong type and deep
nesting; replay headers), paths (files named in manifests pointing out of the bundle,
at /etc/passwd, /dev/zero, through symbolic links), bombs (zlib, huge arcs and
counts), and many objects.
"""

from __future__ import annotations

import base64
import json
import random
import shutil
import time
import traceback
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from fuzz_files import (TEXTURED_OBJ, box_glb, box_gltf, dxf_circle_bomb, glb_bytes, jpeg_bytes, make_replay,
                        named_glb_cases, png_bytes, replay_with, svg_arc_bomb, textured_box_gltf, threeds_objects)
from fuzz_mutators import (mutate_bytes, mutate_glb, mutate_image_pixels, mutate_json_doc, mutate_plan_coordinates,
                           mutate_replay, mutate_replay_fields, mutate_text, mutate_textured_glb, mutate_toml,
                           textured_obj_companions)

ROOT = Path(__file__).resolve().parent.parent
DATA = Path(__file__).resolve().parent / "data"
CLEAN = DATA / "check_clean"

#: seconds of CPU time one input may take (issue 18)
TIME_LIMIT = 2.0


def _textured_glb_seeds(_tmp: Path) -> list[bytes]:
    return [glb_bytes(*textured_box_gltf(png_bytes(8, 8), "image/png")),
            glb_bytes(*textured_box_gltf(jpeg_bytes(), "image/jpeg"))]


def _textured_import(path: Path) -> None:
    """What import does with a textured model: load it, then the game's model.glb
    with the textures attached and embedded, the texture files copied."""
    from tanktool.formats.materials import export_glb
    from tanktool.formats.models import load_scene

    export_glb(path, load_scene(path), path.parent / "bundle", warn=lambda _m: None)


def _plan_work(path: Path) -> None:
    """What import-arena does with a plan before the heavy work: read it (the overlap
    limit), then check the cells it asks for against the file's budget."""
    from tanktool.formats.limits import check_cells
    from tanktool.formats.models import load_scene

    scene = load_scene(path)
    lo, hi = scene.bounds
    check_cells(str(path), float(hi[0] - lo[0]), float(hi[2] - lo[2]), 0.5, path.stat().st_size)


def _load_scene(path: Path) -> None:
    from tanktool.formats.models import load_scene

    load_scene(path)


def _check_triangles(path: Path) -> None:
    from tanktool.check.glb import load_triangles

    load_triangles(path)


def _walls(path: Path) -> None:
    from tanktool.formats.walls_txt import read_walls

    read_walls(path)


def _hull(path: Path) -> None:
    from tanktool.formats.vehicle_bundle import read_hull

    read_hull(path)


def _spheres(path: Path) -> None:
    from tanktool.geometry.spheres import read_spheres

    read_spheres(path)


def _bindings(path: Path) -> None:
    from tanktool.game.input import load_bindings

    load_bindings(path)


def _quadtree(path: Path) -> None:
    from tanktool.nav.quadtree import WallQuadtree

    WallQuadtree.load(path)


def _replay(path: Path) -> None:
    from tanktool.sim.match import load_match_arena, load_tank_spec
    from tanktool.sim.replay import play_replay, read_replay

    tape = read_replay(path)
    # what play does next: the bundles the tape names, then the playback itself
    arena = load_match_arena(tape.header.get("arena_ref") or "box")
    spec = load_tank_spec(tape.header.get("vehicle_ref") or "light")
    if int(tape.header["steps"]) <= 240:   # a long valid recording is long to play: that is no bug
        play_replay(tape, arena, spec)


def _check_bundle(path: Path) -> None:
    """``tanktool check`` on the bundle, then play's loaders on it."""
    from tanktool.check import run_check
    from tanktool.errors import TanktoolError
    from tanktool.sim.match import load_match_arena, load_tank_spec

    report = run_check([path])
    crashes = [d.format() for d in report.diagnostics if d.code == "X001"]
    if crashes:
        raise AssertionError(f"check crashed: {crashes[0]}")
    try:
        if (path / "arena.toml").exists():
            load_match_arena(path)
        else:
            load_tank_spec(path)
        failed = None
    except TanktoolError as e:
        failed = e
    errors = [d for d in report.diagnostics if d.severity == "error"]
    if failed is not None and not errors and not report.unreadable:
        raise AssertionError(f"check found no error but play stops: {failed}")
    if failed is not None:
        raise failed


@dataclass
class Kind:
    """One kind of input: where its seeds come from, how to mutate, what reads it."""

    name: str
    suffix: str
    seeds: Callable[[Path], list[bytes]]
    mutate: Callable[[bytes, random.Random, list[bytes] | None], bytes]
    target: Callable[[Path], None]
    bundle: Path | None = None     # a bundle the file is put into (as ``suffix``), else a bare file
    share: int = 1                 # relative number of cases in a run
    companions: Callable[[Path, random.Random], None] | None = None   # more files beside a bare one


def _files(*globs: str) -> Callable[[Path], list[bytes]]:
    def seeds(_tmp: Path) -> list[bytes]:
        out = []
        for g in globs:
            for p in sorted(ROOT.glob(g)):
                if p.is_file() and p.stat().st_size < 400_000:
                    out.append(p.read_bytes())
        return out
    return seeds


def _trimesh_seeds(ext: str) -> Callable[[Path], list[bytes]]:
    def seeds(_tmp: Path) -> list[bytes]:
        import trimesh

        out = []
        for mesh in (trimesh.creation.box(extents=(2, 1, 3)), trimesh.creation.icosphere(1)):
            for ft in ([ext] if ext != "stl" else ["stl", "stl_ascii"]) if ext != "ply" else ["ply"]:
                data = mesh.export(file_type=ft)
                out.append(data.encode() if isinstance(data, str) else data)
        if ext == "ply":
            data = trimesh.creation.box().export(file_type="ply", encoding="ascii")
            out.append(data.encode() if isinstance(data, str) else data)
        return out
    return seeds


def _glb_seeds(_tmp: Path) -> list[bytes]:
    return [box_glb(False), box_glb(True), (ROOT / "arenas/box/model.glb").read_bytes(),
            (CLEAN / "vehicles/tank/model.glb").read_bytes(), *named_glb_cases().values()]


def _3ds_seeds(tmp: Path) -> list[bytes]:
    return _files("tests/data/models3ds/*.3ds", "tests/data/models3ds/*.3DS", "arenas/paper2002/*.3ds")(tmp) + \
        [threeds_objects(40), threeds_objects(300)]


def _gltf_seeds(_tmp: Path) -> list[bytes]:
    doc, binary = box_gltf(True)
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(binary).decode()
    return [json.dumps(doc).encode()]


def _replay_seeds(tmp: Path) -> list[bytes]:
    data = make_replay(tmp)
    return [data, replay_with(data, integrator="../../../../etc/passwd"), replay_with(data, dt=0.0),
            replay_with(data, steps=365 * 86400 * 120, seconds=365 * 86400.0), replay_with(data, bots="4")]


def _bindings_seeds(_tmp: Path) -> list[bytes]:
    from tanktool.formats.bundle import dumps_toml
    from tanktool.game.input import Bindings

    return [dumps_toml(Bindings().to_dict()).encode()]


KINDS: dict[str, Kind] = {k.name: k for k in [
    Kind("3ds", ".3ds", _3ds_seeds, mutate_bytes, _load_scene, share=4),
    Kind("obj", ".obj", lambda t: _files("arenas/box/box.obj", "arenas/maze/maze.obj")(t) + _trimesh_seeds("obj")(t),
         mutate_text, _load_scene, share=2),
    Kind("stl", ".stl", _trimesh_seeds("stl"), mutate_bytes, _load_scene, share=2),
    Kind("ply", ".ply", _trimesh_seeds("ply"), mutate_bytes, _load_scene),
    Kind("off", ".off", _trimesh_seeds("off"), mutate_text, _load_scene),
    Kind("glb", ".glb", _glb_seeds, mutate_glb, _load_scene, share=4),
    Kind("glb-check", ".glb", _glb_seeds, mutate_glb, _check_triangles, share=3),
    Kind("glb-images", ".glb", _textured_glb_seeds, mutate_textured_glb, _textured_import, share=3),
    Kind("obj-textured", ".obj", lambda t: [TEXTURED_OBJ.encode()],
         lambda d, r, p: mutate_text(d, r, p) if r.random() < 0.3 else d, _textured_import, share=3,
         companions=textured_obj_companions),
    Kind("gltf", ".gltf", _gltf_seeds, lambda d, r, p: json.dumps(mutate_json_doc(json.loads(d), r)).encode(),
         _load_scene),
    Kind("bzw", ".bzw", _files("tests/data/bzw/*.bzw"), mutate_text, _load_scene, share=2),
    Kind("dxf", ".dxf", lambda t: _files("tests/data/plans/*.dxf")(t) + [dxf_circle_bomb()], mutate_text,
         _load_scene, share=2),
    Kind("svg", ".svg", lambda t: _files("tests/data/plans/*.svg")(t) + [svg_arc_bomb()], mutate_text,
         _load_scene, share=2),
    Kind("walls", ".txt", _files("arenas/*/walls.txt"), mutate_text, _walls, share=2),
    Kind("hull", ".txt", _files("vehicles/*/hull.txt"), mutate_text, _hull),
    Kind("spheres", ".txt", _files("vehicles/*/spheres.txt"), mutate_text, _spheres),
    Kind("bindings", ".toml", _bindings_seeds, mutate_toml, _bindings),
    Kind("replay", ".ttr", _replay_seeds, mutate_replay, _replay, share=3),
    Kind("replay-fields", ".ttr", lambda t: _replay_seeds(t)[:1], mutate_replay_fields, _replay),
    Kind("glb-pixels", ".glb", _textured_glb_seeds, mutate_image_pixels, _textured_import, share=2),
    Kind("plan-coords-dxf", ".dxf", _files("tests/data/plans/room.dxf"), mutate_plan_coordinates, _plan_work,
         share=2),
    Kind("plan-coords-svg", ".svg", _files("tests/data/plans/yard.svg"), mutate_plan_coordinates, _plan_work,
         share=2),
    Kind("quadtree", ".npz", _files("arenas/*/quadtree.npz"), mutate_bytes, _quadtree),
    Kind("arena", "arena.toml", _files("arenas/box/arena.toml"), mutate_toml, _check_bundle,
         bundle=ROOT / "arenas" / "box", share=3),
    Kind("arena-walls", "walls.txt", _files("arenas/box/walls.txt"), mutate_text, _check_bundle,
         bundle=ROOT / "arenas" / "box"),
    Kind("arena-glb", "model.glb", _files("arenas/box/model.glb"), mutate_glb, _check_bundle,
         bundle=ROOT / "arenas" / "box"),
    Kind("arena-npz", "quadtree.npz", _files("arenas/box/quadtree.npz"), mutate_bytes, _check_bundle,
         bundle=ROOT / "arenas" / "box"),
    Kind("arena-navgrid", "navgrid.npz", _files("arenas/box/navgrid.npz"), mutate_bytes, _check_bundle,
         bundle=ROOT / "arenas" / "box"),
    Kind("vehicle", "vehicle.toml", _files("tests/data/check_clean/vehicles/tank/vehicle.toml"), mutate_toml,
         _check_bundle, bundle=CLEAN / "vehicles" / "tank", share=3),
    Kind("vehicle-hull", "hull.txt", _files("tests/data/check_clean/vehicles/tank/hull.txt"), mutate_text,
         _check_bundle, bundle=CLEAN / "vehicles" / "tank"),
    Kind("vehicle-spheres", "spheres.txt", _files("tests/data/check_clean/vehicles/tank/spheres.txt"), mutate_text,
         _check_bundle, bundle=CLEAN / "vehicles" / "tank"),
]}


def _navgrid(path: Path) -> None:
    from tanktool.nav.navgrid import NavGrid

    NavGrid.load(path)


def _import_arena(path: Path) -> None:
    """The whole import (formats, then the wall geometry of geometry/walls.py)."""
    from tanktool.importer import import_arena

    import_arena(path, path.parent / "bundle")


def _import_vehicle(path: Path) -> None:
    from tanktool.cli.import_vehicle import build_vehicle_bundle

    build_vehicle_bundle(path, path.parent / "bundle", "v")


def _any_model(tmp: Path) -> list[bytes]:
    return _3ds_seeds(tmp)[:8]

#: readers owned elsewhere (nav/navgrid.py, geometry/walls.py): run on request
#: (``python tests/fuzz_inputs.py N navgrid import-3ds``), not by the tests
EXTRA_KINDS: dict[str, Kind] = {k.name: k for k in [
    Kind("navgrid", ".npz", _files("arenas/*/navgrid.npz"), mutate_bytes, _navgrid),
    Kind("import-3ds", ".3ds", _any_model, mutate_bytes, _import_arena),
    Kind("import-obj", ".obj", _files("arenas/box/box.obj"), mutate_text, _import_arena),
    Kind("import-bzw", ".bzw", _files("tests/data/bzw/*.bzw"), mutate_text, _import_arena),
    Kind("import-svg", ".svg", _files("tests/data/plans/*.svg"), mutate_text, _import_arena),
    Kind("import-stl", ".stl", _trimesh_seeds("stl"), mutate_bytes, _import_arena),
    Kind("import-vehicle", ".3ds", _files("vehicles/*/*.3ds"), mutate_bytes, _import_vehicle),
]}


@dataclass
class Outcome:
    kind: str
    seed: int
    status: str          # "ok", "error" (a TanktoolError), "crash" (anything else)
    seconds: float       # CPU time
    message: str = ""


def case_file(kind: Kind, seed: int, tmp: Path, seeds: list[bytes]) -> Path:
    """Write case ``seed`` of ``kind`` under ``tmp`` and return what the target reads."""
    rng = random.Random(seed * 7919 + zlib.crc32(kind.name.encode()))
    base = seeds[rng.randrange(len(seeds))]
    data = kind.mutate(base, rng, seeds) if rng.random() < 0.95 else base
    case = tmp / f"{kind.name}-{seed}"
    if case.exists():
        shutil.rmtree(case)
    case.mkdir(parents=True)
    if kind.bundle is not None:
        bundle = case / kind.bundle.parent.name / kind.bundle.name
        shutil.copytree(kind.bundle, bundle)
        (bundle / kind.suffix).write_bytes(data)
        manifest = bundle / ("arena.toml" if (bundle / "arena.toml").exists() else "vehicle.toml")
        if kind.suffix != manifest.name and rng.random() < 0.7:
            # the manifest made to agree with the damaged file: no "stale" error to stop at
            from tanktool.formats.bundle import dumps_toml, read_toml, sha256_file

            doc = read_toml(manifest)
            doc.setdefault("derived", {})[kind.suffix] = sha256_file(bundle / kind.suffix)
            manifest.write_text(dumps_toml(doc))
        if rng.random() < 0.05:
            # a file the manifest names replaced by a link out of the bundle
            victim = rng.choice([p for p in bundle.iterdir() if p.name != kind.suffix])
            if victim.is_dir() and not victim.is_symlink():   # the bundle's textures/
                shutil.rmtree(victim)
            else:
                victim.unlink()
            victim.symlink_to(rng.choice(["/etc/passwd", "/dev/zero", "../../../../etc"]))
        return bundle
    f = case / f"case{kind.suffix}"
    f.write_bytes(data)
    if kind.companions is not None:
        kind.companions(case, rng)
    if kind.name == "obj" and rng.random() < 0.3:
        (case / "box.mtl").write_bytes((ROOT / "arenas/box/box.mtl").read_bytes())
    return f


def run_one(kind: Kind, seed: int, tmp: Path, seeds: list[bytes]) -> Outcome:
    from tanktool.errors import TanktoolError

    target = case_file(kind, seed, tmp, seeds)
    t0 = time.process_time()
    try:
        kind.target(target)
        status, msg = "ok", ""
    except TanktoolError as e:
        status, msg = "error", str(e)
        if "\n" in msg.strip():
            status, msg = "crash", f"a multi-line error message: {msg[:300]!r}"
    except Exception as e:  # noqa: BLE001 - that is what the fuzzer looks for
        tb = traceback.extract_tb(e.__traceback__)[-1]
        status, msg = "crash", f"{type(e).__name__}: {str(e)[:300]} ({Path(tb.filename).name}:{tb.lineno})"
    seconds = time.process_time() - t0
    shutil.rmtree(target.parent if kind.bundle is None else target.parent.parent, ignore_errors=True)
    return Outcome(kind.name, seed, status, seconds, msg)


def plan(total: int) -> list[tuple[str, int]]:
    """(kind, seed) pairs: ``total`` cases shared between the kinds by their ``share``."""
    weight = sum(k.share for k in KINDS.values())
    out = []
    for k in KINDS.values():
        n = max(1, round(total * k.share / weight))
        out += [(k.name, s) for s in range(n)]
    return out


def run_inline(cases: list[tuple[str, int]], tmp: Path) -> list[Outcome]:
    """Run the cases in this process (the quick version in the default suite)."""
    seeds: dict[str, list[bytes]] = {}
    out = []
    for name, seed in cases:
        kind = KINDS[name]
        if name not in seeds:
            seeds[name] = kind.seeds(tmp)
        out.append(run_one(kind, seed, tmp, seeds[name]))
    return out


def _worker(conn, cases: list[tuple[str, int]], tmp: str, memory: int) -> None:
    """Child process: bounded address space, one message before and after each case."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    seeds: dict[str, list[bytes]] = {}
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for i, (name, seed) in enumerate(cases):
        conn.send(("start", i))
        kind = KINDS[name]
        try:
            if name not in seeds:
                seeds[name] = kind.seeds(Path(tmp))
            o = run_one(kind, seed, Path(tmp), seeds[name])
        except MemoryError:
            o = Outcome(name, seed, "crash", 0.0, "MemoryError (more memory than the limit)")
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        if peak - base > 600_000:  # KB: a case took over 600 MB more than the first cases
            o = Outcome(name, seed, "crash", o.seconds, f"peak memory grew to {peak // 1024} MB ({o.message})")
            base = peak
        conn.send(("done", i, o.__dict__))
    conn.send(("end", len(cases)))


def run_isolated(cases: list[tuple[str, int]], tmp: Path, hang: float = 30.0,
                 memory: int = 6 << 30) -> list[Outcome]:
    """Run the cases in child processes with an address-space limit; a case that hangs
    (no answer in ``hang`` s of wall time) or kills the interpreter (a segmentation
    fault) is recorded as a crash and the run goes on with the next case."""
    import multiprocessing as mp

    ctx = mp.get_context("fork")
    out: list[Outcome] = []
    start = 0
    while start < len(cases):
        parent, child = ctx.Pipe()
        p = ctx.Process(target=_worker, args=(child, cases[start:], str(tmp), memory), daemon=True)
        p.start()
        child.close()
        current = None
        while True:
            if not parent.poll(hang):
                name, seed = cases[start + (current or 0)]
                out.append(Outcome(name, seed, "crash", hang, f"no answer in {hang:g} s (a hang)"))
                p.kill()
                p.join()
                start += (current or 0) + 1
                break
            try:
                msg = parent.recv()
            except EOFError:
                p.join()
                name, seed = cases[start + (current or 0)]
                out.append(Outcome(name, seed, "crash", 0.0, f"the interpreter died (exit {p.exitcode})"))
                start += (current or 0) + 1
                break
            if msg[0] == "start":
                current = msg[1]
            elif msg[0] == "done":
                out.append(Outcome(**msg[2]))
            else:
                p.join()
                start = len(cases)
                break
    return out


def failures(outcomes: list[Outcome], limit: float = TIME_LIMIT) -> list[str]:
    return [f"{o.kind} #{o.seed}: {o.message}" if o.status == "crash"
            else f"{o.kind} #{o.seed}: took {o.seconds:.2f} s of CPU ({o.status}: {o.message[:120]})"
            for o in outcomes if o.status == "crash" or o.seconds > limit]


def summary(outcomes: list[Outcome]) -> str:
    rows = {}
    for o in outcomes:
        r = rows.setdefault(o.kind, [0, 0, 0, 0.0])
        r[{"ok": 0, "error": 1, "crash": 2}[o.status]] += 1
        r[3] = max(r[3], o.seconds)
    lines = [f"{'kind':<16}{'ok':>7}{'error':>7}{'crash':>7}{'max s':>8}"]
    lines += [f"{k:<16}{a:>7}{b:>7}{c:>7}{m:>8.2f}" for k, (a, b, c, m) in sorted(rows.items())]
    return "\n".join(lines)


if __name__ == "__main__":  # a manual run: python tests/fuzz_inputs.py [N [KIND...]]
    import sys
    import tempfile

    sys.path.insert(0, str(ROOT))

    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    with tempfile.TemporaryDirectory() as d:
        t0 = time.time()
        asked = sys.argv[2:]
        if asked and all(a in EXTRA_KINDS for a in asked):
            KINDS.update(EXTRA_KINDS)
            todo = [(a, s) for a in asked for s in range(n)]
        else:
            todo = [c for c in plan(n) if not asked or c[0] in asked]
        res = run_isolated(todo, Path(d))
        print(summary(res))
        for line in failures(res)[:60]:
            print("FAIL", line)
        print(f"{len(res)} inputs in {time.time() - t0:.0f} s")
