"""tanktool import-vehicle: bundles from models, conservative wrapping, bad input."""

from pathlib import Path

import numpy as np
import pytest
import trimesh
from click.testing import CliRunner

from tanktool.cli.import_vehicle import load_vehicle_source
from tanktool.cli.main import cli
from tanktool.formats.bundle import read_toml, sha256_file
from tanktool.formats.vehicle_bundle import load_vehicle
from tanktool.geometry.hull import points_in_prism
from tanktool.geometry.spheres import contains_points

DATA = Path(__file__).parent / "data" / "vehicles3ds"
#: real 3DS files and the options that make them tank-sized (they are modelled in cm or inches)
REAL = {"fels.3ds": [], "test1.3ds": ["--scale", "0.2"], "testFormatDetection": [],
        "cubes_with_alpha.3DS": ["--scale", "0.005", "--mass", "30000"], "RotatingCube.3DS": ["--scale", "0.05"]}
FILES = {"vehicle.toml", "model.glb", "hull.txt", "spheres.txt", "preview.png"}


def small_tank() -> trimesh.Trimesh:
    body = trimesh.creation.box([4.0, 1.0, 2.4])
    body.apply_translation([3.0, 10.7, -1.0])  # deliberately away from the origin
    turret = trimesh.creation.box([1.6, 0.6, 1.4])
    turret.apply_translation([2.7, 11.5, -1.0])
    barrel = trimesh.creation.cylinder(radius=0.08, height=2.0, sections=12)
    barrel.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    barrel.apply_translation([4.5, 11.5, -1.0])
    return trimesh.util.concatenate([body, turret, barrel])


@pytest.fixture
def tank_obj(tmp_path) -> Path:
    path = tmp_path / "src" / "tank.obj"
    path.parent.mkdir()
    small_tank().export(path)
    return path


def run(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def test_import_obj_writes_a_loadable_conservative_bundle(tmp_path, tank_obj):
    out = tmp_path / "vehicles" / "tank"
    r = run("import-vehicle", tank_obj, "-o", out)
    assert r.exit_code == 0, r.output
    # the footprint's convex hull has 6 corners, so 12 points wrap it exactly
    assert "hull     12 points" in r.output and "1.000 x convex hull" in r.output and "kg" in r.output
    assert FILES | {"tank.obj"} <= {p.name for p in out.iterdir()}
    doc = read_toml(out / "vehicle.toml")
    assert doc["source"]["sha256"] == sha256_file(tank_obj)
    for name, digest in doc["derived"].items():
        assert sha256_file(out / name) == digest
    b = load_vehicle(out)
    assert b.mass > 0 and b.inertia > 0 and b.top_speed > 0 and b.shell_speed == 200
    assert doc["mass"]["method"] == "mesh"
    # the vehicle frame: footprint box centred on the origin, lowest point at y = 0
    mesh = load_vehicle_source(out)
    v = mesh.vertices
    assert v[:, 1].min() == pytest.approx(0)
    assert (v[:, 0].min() + v[:, 0].max()) == pytest.approx(0)
    assert (v[:, 2].min() + v[:, 2].max()) == pytest.approx(0)
    assert points_in_prism(b.hull, v, tol=0).all()
    assert contains_points(b.spheres, v, tol=0).all()
    assert b.footprint_radius == pytest.approx(doc["footprint_radius"], abs=1e-4)
    assert doc["hull"]["footprint_area"] <= 1.15 * doc["hull"]["convex_area"]


def test_default_output_folder_is_the_name(tmp_path, tank_obj, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = run("import-vehicle", tank_obj, "--name", "scout", "--hull-points", "8", "--sphere-levels", "2",
            "--branching", "3")
    assert r.exit_code == 0, r.output
    b = load_vehicle(tmp_path / "scout")
    assert b.name == "scout" and len(b.hull) == 8 and b.spheres.levels == 2
    assert len(b.spheres.children(0)) == 3


def test_mass_option_and_scale(tmp_path, tank_obj):
    r1 = run("import-vehicle", tank_obj, "-o", tmp_path / "a")
    r2 = run("import-vehicle", tank_obj, "-o", tmp_path / "b", "--mass", "5000", "--scale", "2")
    assert r1.exit_code == 0 and r2.exit_code == 0, r2.output
    a, b = load_vehicle(tmp_path / "a"), load_vehicle(tmp_path / "b")
    assert b.mass == 5000
    # inertia ~ mass x length^2: same shape, twice the size
    assert b.inertia / b.mass == pytest.approx(4 * a.inertia / a.mass, rel=1e-3)
    assert b.spheres.radii[0] == pytest.approx(2 * a.spheres.radii[0], abs=2e-4)
    assert b.engine_force < a.engine_force


def test_existing_bundle_needs_force(tmp_path, tank_obj):
    out = tmp_path / "t"
    assert run("import-vehicle", tank_obj, "-o", out).exit_code == 0
    r = run("import-vehicle", tank_obj, "-o", out, "--hull-points", "8")
    assert r.exit_code == 2 and "already exists" in r.output
    assert len(load_vehicle(out).hull) == 12
    r = run("import-vehicle", tank_obj, "-o", out, "--hull-points", "8", "--force")
    assert r.exit_code == 0 and len(load_vehicle(out).hull) == 8
    assert sorted(p.name for p in tmp_path.iterdir()) == ["src", "t"]  # no leftovers


@pytest.mark.parametrize("args, message", [
    (["--hull-points", "5"], "--hull-points must be an even number from 8 to 16"),
    (["--hull-points", "9"], "--hull-points must be an even number"),
    (["--hull-points", "18"], "--hull-points must be an even number"),
    (["--branching", "0"], "--branching must be from 2 to 8"),
    (["--sphere-levels", "0"], "--sphere-levels must be from 1 to 5"),
    (["--mass", "-3"], "--mass must be from 1 to 1e+06 kg"),
    (["--mass", "1e12"], "--mass must be from"),
    (["--mass", "nan"], "--mass must be from"),
    (["--name", "a b"], "use letters, digits"),
])
def test_bad_options_one_line_exit_2_nothing_written(tmp_path, tank_obj, args, message):
    out = tmp_path / "out"
    r = run("import-vehicle", tank_obj, "-o", out, *args)
    assert r.exit_code == 2
    assert message in r.output
    assert r.output.startswith("error: ") and r.output.count("\n") == 1
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["src"]


def _nan_obj(p: Path) -> Path:
    p.write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    return p


@pytest.mark.parametrize("make, message", [
    (lambda d: d / "missing.obj", "no such file"),
    (lambda d: (d / "notes.txt").write_text("hello") and d / "notes.txt", "not a model file"),
    (lambda d: _nan_obj(d / "nan.obj"), "not finite"),
    (lambda d: (d / "empty.obj").write_text("# nothing\n") and d / "empty.obj", ""),
    (lambda d: DATA / "invalid_empty.3ds", "invalid_empty.3ds"),
])
def test_bad_models_one_line_exit_2(tmp_path, make, message):
    model = make(tmp_path)
    out = tmp_path / "out"
    r = run("import-vehicle", model, "-o", out)
    assert r.exit_code == 2, r.output
    assert r.output.startswith("error: ") and r.output.count("\n") == 1 and message in r.output
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_absurd_mass_from_volume_is_refused(tmp_path, tank_obj):
    r = run("import-vehicle", tank_obj, "-o", tmp_path / "out", "--scale", "100")
    assert r.exit_code == 2 and "wrong --scale? or give --mass" in r.output
    assert not (tmp_path / "out").exists()


def test_flat_model_is_refused(tmp_path):
    tri = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])  # a wall: no width in z
    tri.export(tmp_path / "flat.stl")
    r = run("import-vehicle", tmp_path / "flat.stl", "-o", tmp_path / "out")
    assert r.exit_code == 2 and "flat seen from above" in r.output


@pytest.mark.parametrize("name", REAL)
def test_real_3ds_models_are_wrapped_conservatively(tmp_path, name):
    out = tmp_path / "v"
    r = run("-q", "import-vehicle", DATA / name, "-o", out, "--name", "real", *REAL[name])
    assert r.exit_code == 0, r.output
    b = load_vehicle(out)
    v = load_vehicle_source(out).vertices
    assert points_in_prism(b.hull, v, tol=0).all()
    assert contains_points(b.spheres, v, tol=0).all()
    doc = read_toml(out / "vehicle.toml")
    assert doc["hull"]["footprint_area"] <= 1.15 * doc["hull"]["convex_area"]


# ------------------------------------------------------------------ facing, posture, sanity, precision
@pytest.mark.parametrize("up", ["y", "z"])
@pytest.mark.parametrize("forward", ["+x", "-x", "+y", "-y", "+z", "-z"])
def test_forward_rotation_turns_the_file_axis_to_plus_x(up, forward):
    from tanktool.cli.import_vehicle import forward_rotation
    from tanktool.errors import VehicleError
    from tanktool.formats.models import Z_UP_TO_Y_UP

    if forward[1] == up:
        with pytest.raises(VehicleError, match="is the model's up axis"):
            forward_rotation(forward, up)
        return
    m = forward_rotation(forward, up)
    assert np.allclose(m[:3, :3] @ m[:3, :3].T, np.eye(3)) and np.linalg.det(m[:3, :3]) == pytest.approx(1)
    axis = np.zeros(4)
    axis["xyz".index(forward[1])] = 1.0 if forward[0] == "+" else -1.0
    world = (Z_UP_TO_Y_UP if up == "z" else np.eye(4)) @ axis      # what load_scene made of it
    assert np.allclose(m @ world, [1, 0, 0, 0])
    assert np.allclose(m @ [0, 1, 0, 0], [0, 1, 0, 0])              # up stays up


def test_forward_option_turns_a_model_facing_z(tmp_path):
    """A tank modelled along +z comes in sideways without --forward (and says so);
    with --forward +z it is the same vehicle as the one modelled along +x."""
    along_x = tmp_path / "x.obj"
    small_tank().export(along_x)
    along_z = tmp_path / "z.obj"
    turned = small_tank()
    turned.apply_transform(trimesh.transformations.rotation_matrix(-np.pi / 2, [0, 1, 0]))  # +x -> +z
    turned.export(along_z)
    r = run("import-vehicle", along_z, "-o", tmp_path / "sideways")
    assert r.exit_code == 0, r.output
    assert "warning: " in r.output and "along its forward axis" in r.output
    assert "(--forward +z or --forward -z)" in r.output
    r = run("import-vehicle", along_z, "--forward", "+z", "-o", tmp_path / "z")
    assert r.exit_code == 0 and "warning" not in r.output, r.output
    assert run("import-vehicle", along_x, "-o", tmp_path / "x").exit_code == 0
    vz = np.unique(np.round(load_vehicle_source(tmp_path / "z").vertices, 6), axis=0)
    vx = np.unique(np.round(load_vehicle_source(tmp_path / "x").vertices, 6), axis=0)
    assert vz.shape == vx.shape and np.allclose(vz, vx, atol=1e-5)
    assert read_toml(tmp_path / "z" / "vehicle.toml")["source"]["forward"] == "+z"
    assert np.allclose(load_vehicle(tmp_path / "z").hull, load_vehicle(tmp_path / "x").hull, atol=2e-4)
    # facing backwards: the barrel (the long thin end) ends up at -x
    assert run("import-vehicle", along_x, "--forward", "-x", "-o", tmp_path / "back").exit_code == 0
    back = load_vehicle_source(tmp_path / "back").vertices
    front = load_vehicle_source(tmp_path / "x").vertices
    assert np.allclose(np.sort(back[:, 0]), np.sort(-front[:, 0]), atol=1e-5)
    # the check agrees: the sideways bundle gets V106, the turned one nothing
    from tanktool.check import run_check

    assert {d.code for d in run_check([tmp_path / "sideways"]).diagnostics} == {"V106"}
    assert run_check([tmp_path / "z"]).diagnostics == []
    r = run("import-vehicle", along_x, "--forward", "+y", "-o", tmp_path / "bad")
    assert r.exit_code == 2 and "--forward +y is the model's up axis (--up y)" in r.output
    assert not (tmp_path / "bad").exists()


def test_a_vehicle_on_its_side_is_a_warning_then_a_check_error(tmp_path, tank_obj):
    # an OBJ (Y up) read as Z up: the tank lies on its side
    r = run("import-vehicle", tank_obj, "--up", "z", "-o", tmp_path / "side")
    assert r.exit_code == 0, r.output
    assert "lies on its side" in r.output and "(--up y; it was read as --up z)" in r.output
    from tanktool.check import run_check

    report = run_check([tmp_path / "side"])
    assert [d.code for d in report.diagnostics] == ["V105"]
    assert report.exit_code() == 1 and "--up y" in report.diagnostics[0].hint


def test_absurd_sizes_and_masses_are_warned_and_figures_keep_their_digits(tmp_path, tank_obj):
    from tanktool.check import run_check

    # the 32 m, 794 t "vehicle"
    r = run("import-vehicle", tank_obj, "--scale", "7", "--mass", "794000", "-o", tmp_path / "huge")
    assert r.exit_code == 0, r.output
    assert "m long at its longest, outside the 1 .. 15 m" in r.output
    assert "a mass of 794 t is outside" in r.output
    assert {d.code for d in run_check([tmp_path / "huge"]).diagnostics} >= {"V107", "V303"}
    # a toy: figures written with significant digits, never rounded to zero
    r = run("import-vehicle", tank_obj, "--scale", "0.01", "--mass", "2", "-o", tmp_path / "toy")
    assert r.exit_code == 0, r.output
    assert r.output.count("warning: ") == 2 and "inertia 0.000" in r.output
    doc = read_toml(tmp_path / "toy" / "vehicle.toml")
    b = load_vehicle(tmp_path / "toy")
    assert doc["drive"]["turn_torque"] > 0 and doc["mass"]["inertia"] > 0
    assert doc["drive"]["turn_torque"] == pytest.approx(1.5 * b.inertia, rel=1e-5)
    assert doc["footprint_radius"] == pytest.approx(b.footprint_radius, rel=1e-4)
    com = np.array(doc["mass"]["centre_of_mass"])
    assert np.abs(com).max() > 0 and np.all((com == 0) | (np.abs(com) > 1e-5))
    assert {d.code for d in run_check([tmp_path / "toy"]).diagnostics} == {"V107", "V303"}


def test_sphere_trees_hold_the_whole_surface(tmp_path, tank_obj):
    """Not only the vertices: points sampled over the surface (the check's own, not the
    builder's) are all inside a leaf and its ancestors."""
    from tanktool.check.glb import load_triangles
    from tanktool.check.vehicle_rules import GEOM_TOL, surface_points

    out = tmp_path / "t"
    assert run("import-vehicle", tank_obj, "-o", out, "--sphere-levels", "3", "--branching", "5").exit_code == 0
    tree = load_vehicle(out).spheres
    v, f = load_triangles(out / "model.glb")
    p = np.vstack([v, surface_points(v, f)])
    held = np.zeros(len(p), dtype=bool)
    for leaf in tree.leaves():
        chain = tree.ancestors(int(leaf))
        inside = np.ones(len(p), dtype=bool)
        for s in chain:
            inside &= np.linalg.norm(p - tree.centers[s], axis=1) <= tree.radii[s] + GEOM_TOL
        held |= inside
    assert held.all()
