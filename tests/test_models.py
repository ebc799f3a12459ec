"""models.load_scene / load_model: every format into the world frame (Y up, metres)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from tanktool.errors import FormatError
from tanktool.formats import models
from tanktool.formats.threeds import read_3ds
from tanktool.formats.threeds_write import write_3ds

MODELS = Path(__file__).resolve().parent / "data" / "models3ds"


def raw_vertices(path: Path) -> np.ndarray:
    return np.vstack([o.vertices for o in read_3ds(path).objects if len(o.faces)])


def test_3ds_axes_converted_to_y_up() -> None:
    path = MODELS / "cubes_with_alpha.3DS"
    raw = raw_vertices(path)
    mesh = models.load_model(path)
    assert len(mesh.faces) == 60
    # (x, y, z) -> (x, z, -y), vertex for vertex (objects joined in file order)
    np.testing.assert_allclose(mesh.vertices, np.column_stack([raw[:, 0], raw[:, 2], -raw[:, 1]]), rtol=1e-12)
    # per-face colours survive, including the transparent material's alpha
    assert (mesh.visual.face_colors[:, 3] == 212).sum() == 12


def test_3ds_scale_and_up_override() -> None:
    path = MODELS / "testFormatDetection"  # no extension: found by its magic
    raw = raw_vertices(path)
    scaled = models.load_model(path, scale=0.25)
    np.testing.assert_allclose(scaled.vertices, 0.25 * np.column_stack([raw[:, 0], raw[:, 2], -raw[:, 1]]))
    as_is = models.load_model(path, up="y")  # taken as already Y up: no rotation
    np.testing.assert_allclose(as_is.vertices, raw)
    assert len(np.unique(as_is.visual.face_colors, axis=0)) == 4  # four materials


def test_master_scale_applied(tmp_path: Path) -> None:
    path = tmp_path / "scaled.3ds"
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 2]], dtype=float)
    write_3ds(path, [("t", v, [[0, 1, 2]], (1, 1, 1))], master_scale=0.01)
    mesh = models.load_model(path, scale=2.0)
    np.testing.assert_allclose(mesh.vertices, 0.02 * np.column_stack([v[:, 0], v[:, 2], -v[:, 1]]), atol=1e-9)


@pytest.mark.parametrize("ext", ["obj", "stl", "ply", "off", "glb"])
def test_other_formats_through_trimesh(tmp_path: Path, ext: str) -> None:
    box = trimesh.creation.box(extents=(2.0, 1.0, 3.0))
    box.apply_translation((5.0, 0.5, -1.0))
    path = tmp_path / f"box.{ext}"
    box.export(path)
    mesh = models.load_model(path)
    assert len(mesh.faces) == 12
    # Y-up formats are taken as they are
    np.testing.assert_allclose(mesh.bounds, box.bounds, atol=1e-6)
    scaled = models.load_model(path, scale=3.0)
    np.testing.assert_allclose(scaled.bounds, 3.0 * box.bounds, atol=1e-5)
    z_up = models.load_model(path, up="z")
    np.testing.assert_allclose(z_up.bounds, [[4.0, -2.5, -1.0], [6.0, 0.5, 0.0]], atol=1e-6)


def test_refuses_non_models(tmp_path: Path) -> None:
    text = tmp_path / "notes.txt"
    text.write_text("hello\n")
    with pytest.raises(FormatError, match=r"notes\.txt: not a model file"):
        models.load_model(text)
    noext = tmp_path / "blob"
    noext.write_bytes(b"\x00\x01 random")
    with pytest.raises(FormatError, match="not a model file"):
        models.load_model(noext)
    with pytest.raises(FormatError, match="no such file"):
        models.load_model(tmp_path / "absent.obj")
    with pytest.raises(FormatError, match="is a folder"):
        models.load_model(tmp_path)


def test_refuses_empty_files(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match=r"invalid_empty\.3ds: byte 0: empty file"):
        models.load_model(MODELS / "invalid_empty.3ds")
    for ext in ("obj", "stl", "ply", "off", "glb"):
        empty = tmp_path / f"empty.{ext}"
        empty.write_bytes(b"")
        with pytest.raises(FormatError, match=rf"empty\.{ext}"):
            models.load_model(empty)


def test_refuses_models_without_triangles(tmp_path: Path) -> None:
    path = tmp_path / "points.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    with pytest.raises(FormatError, match="no triangles"):
        models.load_model(path)
    lonely = tmp_path / "lonely.3ds"
    write_3ds(lonely, [("p", np.zeros((3, 3)), np.zeros((0, 3), dtype=int), (0, 0, 0))])
    with pytest.raises(FormatError, match="no triangles"):
        models.load_model(lonely)


def test_refuses_nan_vertices(tmp_path: Path) -> None:
    path = tmp_path / "nan.obj"
    path.write_text("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(FormatError, match=r"nan\.obj: .*vertex 1 is not finite"):
        models.load_model(path)
    ply = tmp_path / "inf.ply"
    ply.write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n"
    )
    with pytest.raises(FormatError, match="not finite"):
        models.load_model(ply)


def test_refuses_bad_up_and_scale() -> None:
    path = MODELS / "fels.3ds"
    with pytest.raises(FormatError, match="--up"):
        models.load_model(path, up="x")
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(FormatError, match="--scale"):
            models.load_model(path, scale=bad)


@pytest.mark.parametrize("case", ["empty", "truncated"])
def test_cli_reports_a_bad_3ds_in_one_line(tmp_path: Path, case: str) -> None:
    """Through the real command line: one ``error:`` line naming the file and byte,
    exit status 2, no traceback, nothing written."""
    import subprocess
    import sys

    if case == "empty":
        model = MODELS / "invalid_empty.3ds"
    else:
        model = tmp_path / "cut.3ds"
        model.write_bytes((MODELS / "test1.3ds").read_bytes()[:3000])
    out = tmp_path / "bundle"
    proc = subprocess.run(
        [sys.executable, "-m", "tanktool", "import-vehicle", str(model), "-o", str(out)],
        capture_output=True, text=True, timeout=120,
    )
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {model}: byte 0: ")
    assert not out.exists()


def test_truncated_files_are_format_errors(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(2.0, 1.0, 3.0))
    for ext in ("stl", "ply", "glb", "off", "obj"):
        data = box.export(file_type=ext)
        data = data.encode() if isinstance(data, str) else data
        path = tmp_path / f"cut.{ext}"
        path.write_bytes(data[: len(data) // 2])
        with pytest.raises(FormatError, match=rf"cut\.{ext}: "):
            models.load_model(path)
    stl = tmp_path / "cut.stl"
    with pytest.raises(FormatError, match=r"byte 80: binary STL says 12 triangles \(684 bytes\) but the file has 342"):
        models.load_model(stl)
    # an ASCII STL is left to trimesh
    ascii_stl = tmp_path / "ascii.stl"
    ascii_stl.write_text(box.export(file_type="stl_ascii"))
    assert len(models.load_model(ascii_stl).faces) == 12


def test_gltf_with_its_buffers(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(2.0, 1.0, 3.0))
    path = tmp_path / "box.gltf"
    box.export(path)
    assert len(models.load_model(path).faces) == 12
    for buffer in tmp_path.glob("*.bin"):
        buffer.unlink()
    with pytest.raises(FormatError, match=r"box\.gltf: buffers\[0\]\.uri .*: no such file"):
        models.load_model(path)
