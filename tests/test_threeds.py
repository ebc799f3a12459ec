"""The .3ds reader and writer on real third-party files, hand-made chunks, and fuzzing."""

from __future__ import annotations

import io
import os
import struct
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from tanktool.errors import FormatError
from tanktool.formats import threeds, threeds_write
from tanktool.formats.models import detect_format
from tanktool.formats.threeds import read_3ds
from tanktool.formats.threeds_write import write_3ds

MODELS = Path(__file__).resolve().parent / "data" / "models3ds"

# The reference table of ../shared/testdata/README.md (read from the files' own
# chunks, cross-checked against assimp 5.2.5): mesh objects, raw 0x4110 vertex
# count, 0x4120 face count summed, materials, raw bounds in the file's Z-up axes.
REFERENCE = [
    ("CameraRollAnim.3ds", 1, 26, 12, 0, (-24.7863, -24.7863, 0.0), (45.8689, 23.0769, 38.7464)),
    ("CameraRollAnimWithChildObject.3ds", 2, 52, 24, 0, (-54.8899, -97.4171, 0.0), (45.8689, 23.0769, 38.7464)),
    ("RotatingCube.3DS", 1, 26, 12, 0, (-46.0925, -40.8152, -35.5429), (8.7611, 25.8876, 39.0875)),
    ("TargetCameraAnim.3ds", 1, 26, 12, 0, (-24.7863, -24.7863, 0.0), (45.8689, 23.0769, 38.7464)),
    ("cube_with_diffuse_texture.3DS", 1, 32, 12, 1, (-50.0, 32.6177, -30.5402), (0.0, 82.6177, 19.4598)),
    ("cube_with_specular_texture.3DS", 1, 32, 12, 1, (-50.0, 32.6177, -30.5402), (0.0, 82.6177, 19.4598)),
    ("cubes_with_alpha.3DS", 5, 130, 60, 5, (-856.3110, -55.1009, -268.1591), (98.8105, 1227.1409, 248.4380)),
    ("fels.3ds", 1, 386, 768, 1, (-2.2219, -3.0843, -2.5647), (1.2829, 0.1213, 2.1169)),
    ("test1.3ds", 9, 288, 108, 3, (-10.3432, -0.1942, -10.1551), (9.8509, 10.2303, 10.2476)),
    ("testFormatDetection", 1, 762, 1368, 4, (-3.1149, -4.0, -1.6493), (3.1149, 4.0, 1.6493)),
]
VALID_FILES = [row[0] for row in REFERENCE]


def chunk(cid: int, *parts: bytes) -> bytes:
    """A chunk built by hand, independently of the module's writer."""
    body = b"".join(parts)
    return struct.pack("<HI", cid, len(body) + 6) + body


def tri_object(name: bytes, vertices, faces, *face_subchunks: bytes) -> bytes:
    v = np.asarray(vertices, dtype="<f4")
    f = np.zeros((len(faces), 4), dtype="<u2")
    f[:, :3] = np.asarray(faces, dtype=int).reshape(-1, 3)
    return chunk(
        0x4000,
        name + b"\0",
        chunk(
            0x4100,
            chunk(0x4110, struct.pack("<H", len(v)), v.tobytes()),
            chunk(0x4120, struct.pack("<H", len(f)), f.tobytes(), *face_subchunks),
        ),
    )


TRIANGLE = ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])


def model_bytes(*mdata: bytes, extra: bytes = b"") -> bytes:
    return chunk(0x4D4D, chunk(0x3D3D, *mdata), extra)


# ---------------------------------------------------------------------------
# the real files


@pytest.mark.parametrize("row", REFERENCE, ids=VALID_FILES)
def test_reference_table(row) -> None:
    name, n_obj, n_vert, n_face, n_mat, lo, hi = row
    model = read_3ds(MODELS / name)
    assert len(model.objects) == n_obj
    assert sum(len(o.vertices) for o in model.objects) == n_vert
    assert sum(len(o.faces) for o in model.objects) == n_face
    assert len(model.materials) == n_mat
    verts = np.vstack([o.vertices for o in model.objects])
    assert np.round(verts.min(axis=0), 4).tolist() == pytest.approx(lo, abs=1e-9)
    assert np.round(verts.max(axis=0), 4).tolist() == pytest.approx(hi, abs=1e-9)
    for obj in model.objects:
        assert obj.vertices.dtype == np.float64 and obj.vertices.shape[1] == 3
        assert obj.faces.shape == (len(obj.face_material), 3)
        assert obj.faces.max() < len(obj.vertices)
        assert obj.matrix.shape == (4, 4)


def test_format_detection_by_magic() -> None:
    path = MODELS / "testFormatDetection"
    assert path.suffix == ""
    assert detect_format(path) == "3ds"
    model = read_3ds(path)
    assert model.master_scale == 1.0  # no 0x0100 chunk in this file
    (obj,) = model.objects
    # four 0x4130 groups, one per material, covering every face
    assert sorted(np.unique(obj.face_material).tolist()) == [0, 1, 2, 3]
    assert [m.name for m in model.materials] == ["Material #1", "Material #2", "Material #3", "Material #4"]
    assert model.materials[0].diffuse == pytest.approx((0.8, 0.8, 0.8))


def test_invalid_empty_is_a_clean_format_error() -> None:
    with pytest.raises(FormatError, match=r"invalid_empty\.3ds: byte 0: empty file"):
        read_3ds(MODELS / "invalid_empty.3ds")


def test_materials_textures_and_transparency() -> None:
    alpha = read_3ds(MODELS / "cubes_with_alpha.3DS")
    by_name = {m.name: m for m in alpha.materials}
    assert by_name["Transparent"].transparency == pytest.approx(0.17)
    assert by_name["04 - Default"].transparency == 0.0
    assert by_name["01 - Default"].texture == "BERETTA_.JPG"
    # every object uses exactly one material, all faces assigned
    for obj in alpha.objects:
        assert (obj.face_material >= 0).all()

    diffuse = read_3ds(MODELS / "cube_with_diffuse_texture.3DS").materials[0]
    assert diffuse.texture == "TEST.PNG"
    assert diffuse.diffuse == pytest.approx((150 / 255,) * 3)
    specular = read_3ds(MODELS / "cube_with_specular_texture.3DS").materials[0]
    assert "specular" in specular.maps and specular.texture is None

    fels = read_3ds(MODELS / "fels.3ds")
    assert fels.nodes == []  # no keyframer in this file
    assert fels.materials[0].diffuse == pytest.approx((200 / 255,) * 3)
    assert fels.objects[0].smoothing is None and fels.objects[0].uv is None

    (cube,) = read_3ds(MODELS / "cube_with_diffuse_texture.3DS").objects
    assert cube.uv.shape == (32, 2) and cube.smoothing.shape == (12,)
    assert cube.smoothing.any()


def test_keyframer_and_matrices() -> None:
    model = read_3ds(MODELS / "test1.3ds")
    assert len(model.nodes) >= len(model.objects)
    assert {o.name for o in model.objects} <= {n.name for n in model.nodes}
    assert any(not np.allclose(o.matrix, np.eye(4)) for o in model.objects)
    for o in model.objects:
        # a rigid-ish object matrix: the axes are not degenerate
        assert abs(np.linalg.det(o.matrix[:3, :3])) > 1e-6
    child = read_3ds(MODELS / "CameraRollAnimWithChildObject.3ds")
    assert [n.name for n in child.nodes] == ["Box01", "Box02"]
    parents = {n.name: n.parent for n in child.nodes}
    ids = {n.node_id: n.name for n in child.nodes}
    assert ids == {0: "Box01", 2: "Box02"}
    # Box02 hangs below node 1, the camera node (0xB003), which is not an object node
    assert parents == {"Box01": None, "Box02": 1}


def test_cameras_are_skipped() -> None:
    data = (MODELS / "TargetCameraAnim.3ds").read_bytes()
    assert b"\x00\x47" in data  # the file does hold a camera chunk (0x4700)
    model = read_3ds(data)
    assert [o.name for o in model.objects] == ["Box01"]


# ---------------------------------------------------------------------------
# hand-made chunks


def test_linear_colour_preferred_over_gamma() -> None:
    def material(*color_subchunks: bytes) -> bytes:
        return chunk(0xAFFF, chunk(0xA000, b"m\0"), chunk(0xA020, *color_subchunks))

    gamma24 = chunk(0x0011, bytes([255, 0, 0]))
    lin24 = chunk(0x0012, bytes([0, 255, 0]))
    gammaf = chunk(0x0010, struct.pack("<3f", 0.0, 0.0, 1.0))
    linf = chunk(0x0013, struct.pack("<3f", 0.25, 0.5, 0.75))
    cases = [
        ((gamma24, lin24), (0.0, 1.0, 0.0)),
        ((lin24, gamma24), (0.0, 1.0, 0.0)),
        ((gammaf, linf), (0.25, 0.5, 0.75)),
        ((gamma24,), (1.0, 0.0, 0.0)),
        ((gammaf,), (0.0, 0.0, 1.0)),
    ]
    for subchunks, expected in cases:
        model = read_3ds(model_bytes(material(*subchunks)))
        assert model.materials[0].diffuse == pytest.approx(expected)


def test_percentages_and_master_scale() -> None:
    mat = chunk(
        0xAFFF,
        chunk(0xA000, b"glass\0"),
        chunk(0xA040, chunk(0x0030, struct.pack("<h", 40))),
        chunk(0xA050, chunk(0x0031, struct.pack("<f", 62.5))),
        chunk(0xA200, chunk(0x0030, struct.pack("<h", 100)), chunk(0xA300, b"wall.png\0")),
    )
    group = chunk(0x4130, b"glass\0", struct.pack("<HH", 1, 0))
    data = model_bytes(chunk(0x0100, struct.pack("<f", 2.5)), mat, tri_object(b"tri", *TRIANGLE, group))
    model = read_3ds(data)
    m = model.materials[0]
    assert m.shininess == pytest.approx(0.40)
    assert m.transparency == pytest.approx(0.625)
    assert m.texture == "wall.png" and m.maps["diffuse"].strength == pytest.approx(1.0)
    assert model.master_scale == 2.5
    assert model.objects[0].face_material.tolist() == [0]


def test_materials_may_follow_objects_and_unknown_names_are_grey(tmp_path: Path) -> None:
    group = chunk(0x4130, b"later\0", struct.pack("<HH", 1, 0))
    other = chunk(0x4130, b"missing\0", struct.pack("<HH", 1, 0))
    mat = chunk(0xAFFF, chunk(0xA000, b"later\0"), chunk(0xA020, chunk(0x0011, bytes([10, 20, 30]))))
    data = model_bytes(tri_object(b"a", *TRIANGLE, group), tri_object(b"b", *TRIANGLE, other), mat)
    model = read_3ds(data)
    assert model.objects[0].face_material.tolist() == [0]
    assert model.objects[1].face_material.tolist() == [-1]
    path = tmp_path / "m.3ds"
    path.write_bytes(data)
    scene = threeds.load_scene(path)
    assert scene.geometry["a"].visual.face_colors[0].tolist() == [10, 20, 30, 255]
    assert scene.geometry["b"].visual.face_colors[0].tolist() == list(threeds.DEFAULT_COLOR)


def test_repeated_face_array_replaces_the_first_and_empty_groups() -> None:
    first = np.array([[0, 1, 2], [2, 1, 0]], dtype="<u2")
    arr1 = chunk(
        0x4120,
        struct.pack("<H", 2),
        np.column_stack([first, np.zeros(2, "<u2")]).astype("<u2").tobytes(),
        chunk(0x4130, b"m\0", struct.pack("<HHH", 2, 0, 1)),
        chunk(0x4150, b"\1\0\0\0\2\0\0\0"),
    )
    arr2 = chunk(0x4120, struct.pack("<HHHHH", 1, 0, 2, 1, 7), chunk(0x4130, b"m\0", b"\0\0"))
    obj = chunk(
        0x4000,
        b"o\0",
        chunk(0x4100, chunk(0x4110, struct.pack("<H9f", 3, 0, 0, 0, 1, 0, 0, 0, 1, 0)), arr1, arr2),
    )
    mat = chunk(0xAFFF, chunk(0xA000, b"m\0"))
    model = read_3ds(model_bytes(mat, obj))
    (o,) = model.objects
    assert o.faces.tolist() == [[0, 2, 1]] and o.face_flags.tolist() == [7]
    assert o.face_material.tolist() == [-1] and o.smoothing is None


@pytest.mark.parametrize(
    "data, message",
    [
        (b"\x4d\x4d\x06", "too short for a 3DS header"),
        (chunk(0x1234, b"xx"), "expected magic 0x4D4D, found 0x1234"),
        (struct.pack("<HI", 0x4D4D, 4000), r"byte 0: chunk 0x4D4D claims 4000 bytes .* the file ends at byte 6"),
        (struct.pack("<HI", 0x4D4D, 3), "less than its 6-byte header"),
        (chunk(0x4D4D, struct.pack("<HI", 0x3D3D, 50)), r"byte 6: chunk 0x3D3D claims 50 bytes .* parent chunk 0x4D4D ends at byte 12"),
        (chunk(0x4D4D, b"abc"), r"byte 6: 3 stray byte\(s\) at the end of chunk 0x4D4D"),
        (model_bytes(chunk(0x4000, b"no-nul")), "name not terminated by a NUL byte"),
        (
            model_bytes(chunk(0x4000, b"o\0", chunk(0x4100, chunk(0x4110, struct.pack("<H", 60000), b"\0" * 24)))),
            r"chunk 0x4110: 60000 vertices: 720000 bytes needed but only 24 left",
        ),
        (
            model_bytes(chunk(0x4000, b"o\0", chunk(0x4100, chunk(0x4120, struct.pack("<H", 9), b"\0" * 8)))),
            r"chunk 0x4120: 9 faces: 72 bytes needed but only 8 left",
        ),
        (model_bytes(tri_object(b"o", [[0, 0, 0]], [[0, 1, 0]])), r"object 'o': face 0 uses vertex 1 but the object has 1 vertices"),
        # byte 38 = 3 headers (18) + name (2) + 0x4100 and 0x4110 headers (12) + count (2) + x (4)
        (model_bytes(tri_object(b"o", [[0, np.nan, 0]], [])), r"byte 38: chunk 0x4110: 1 vertices: value not finite"),
        (
            model_bytes(tri_object(b"o", *TRIANGLE, chunk(0x4130, b"m\0", struct.pack("<HH", 1, 5)))),
            "material group 'm' names face 5 but the object has 1 faces",
        ),
        (model_bytes(tri_object(b"o", *TRIANGLE, chunk(0x4150, b"\0" * 8))), "smoothing groups chunk has 8 bytes, expected 4 per face = 4"),
        (model_bytes(chunk(0x0100, struct.pack("<f", 0.0))), "master scale must be positive"),
    ],
    ids=[
        "short", "magic", "main-past-eof", "tiny-length", "child-past-parent", "stray-bytes",
        "unterminated-name", "vertex-count", "face-count", "face-index", "nan-vertex",
        "group-face-index", "smoothing-length", "master-scale",
    ],
)
def test_bad_files_give_one_format_error_with_offset(data: bytes, message: str) -> None:
    pattern = message if message.startswith("byte") else r"byte \d+: .*" + message
    with pytest.raises(FormatError, match=r"^<bytes>: " + pattern):
        read_3ds(data)


def test_error_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "broken.3ds"
    path.write_bytes(struct.pack("<HI", 0x4D4D, 100))
    with pytest.raises(FormatError, match=r"broken\.3ds: byte 0: "):
        read_3ds(path)
    with pytest.raises(FormatError, match="no such file"):
        read_3ds(tmp_path / "absent.3ds")


# ---------------------------------------------------------------------------
# writer


def test_writer_round_trip(tmp_path: Path) -> None:
    box_v = np.array([[0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 3, 0], [0, 0, 4]], dtype=float)
    box_f = np.array([[0, 1, 2], [0, 2, 3], [0, 1, 4]])
    tri_v = np.array([[5, 5, 5], [6, 5, 5], [5, 6.5, 5]])
    objects = [
        ("box", box_v, box_f, (1.0, 0.0, 0.0)),
        ("tri", tri_v, [[0, 2, 1]], (0.2, 0.4, 0.6)),
        ("box2", box_v + 10, box_f, (1.0, 0.0, 0.0)),  # same colour: same material
    ]
    path = tmp_path / "out.3ds"
    write_3ds(path, objects, master_scale=0.5)
    model = read_3ds(path)
    assert model.master_scale == 0.5
    assert [o.name for o in model.objects] == ["box", "tri", "box2"]
    assert len(model.materials) == 2
    for (name, v, f, rgb), obj in zip(objects, model.objects):
        np.testing.assert_allclose(obj.vertices, v, rtol=1e-6)
        np.testing.assert_array_equal(obj.faces, f)
        (mat,) = np.unique(obj.face_material)
        assert model.materials[mat].diffuse == pytest.approx(rgb, abs=1e-7)
    # the 24-bit gamma copy is written too, for readers that only know it
    assert model.materials[1].ambient == pytest.approx((0.2, 0.4, 0.6), abs=1e-7)

    scene = threeds.load_scene(path)  # master scale applied, colours per face
    np.testing.assert_allclose(scene.geometry["tri"].vertices, tri_v * 0.5, rtol=1e-6)
    assert scene.geometry["tri"].visual.face_colors[0].tolist() == [51, 102, 153, 255]


def test_writer_splits_big_meshes(tmp_path: Path) -> None:
    # a 200 x 200 grid: 40401 vertices, 80000 faces -> more than one object
    n = 201
    x, y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    verts = np.column_stack([x.ravel(), y.ravel(), np.zeros(n * n)])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    faces = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    path = tmp_path / "grid.3ds"
    write_3ds(path, [("grid", verts, faces, (0.5, 0.5, 0.5))])
    model = read_3ds(path)
    assert [o.name for o in model.objects] == ["grid_0", "grid_1"]
    assert all(len(o.faces) <= 65535 and len(o.vertices) <= 65535 for o in model.objects)
    got = np.vstack([o.vertices[o.faces] for o in model.objects])
    np.testing.assert_array_equal(got, verts[faces])

    # separate triangles: the vertex limit binds first, at 65535 // 3 faces a part
    soup = np.random.default_rng(2).random((90000, 3))
    write_3ds(path, [("soup", soup, np.arange(90000).reshape(-1, 3), (1, 1, 1))])
    parts = read_3ds(path).objects
    assert [len(o.faces) for o in parts] == [21845, 8155]
    assert [len(o.vertices) for o in parts] == [65535, 24465]
    got = np.vstack([o.vertices[o.faces] for o in parts])
    np.testing.assert_allclose(got, soup.reshape(-1, 3, 3), rtol=1e-6)

    # random sharing: every part is as long as the limits allow
    faces = np.random.default_rng(3).integers(0, 100000, (150000, 3))
    pts = np.random.default_rng(4).random((100000, 3))
    write_3ds(path, [("mix", pts, faces, (1, 1, 1))])
    parts = read_3ds(path).objects
    assert sum(len(o.faces) for o in parts) == len(faces)
    start = 0
    for o in parts[:-1]:
        stop = start + len(o.faces)
        assert len(o.vertices) == len(np.unique(faces[start:stop])) <= 65535
        assert len(o.faces) == 65535 or len(np.unique(faces[start : stop + 1])) > 65535
        start = stop
    np.testing.assert_allclose(np.vstack([o.vertices[o.faces] for o in parts]), pts[faces], rtol=1e-6)

    # many vertices, few faces: the unused vertices are dropped when splitting
    many = np.random.default_rng(1).random((70000, 3))
    write_3ds(path, [("cloud", many, [[0, 1, 69999]], (0, 0, 0))])
    (obj,) = read_3ds(path).objects
    np.testing.assert_allclose(obj.vertices[obj.faces], many[[[0, 1, 69999]]], rtol=1e-6)


def test_writer_refuses_bad_objects_and_writes_nothing(tmp_path: Path) -> None:
    path = tmp_path / "bad.3ds"
    v = np.zeros((3, 3))
    bad = [
        [("o", np.zeros((3, 2)), [[0, 1, 2]], (0, 0, 0))],
        [("o", v, [[0, 1, 3]], (0, 0, 0))],
        [("o", v, [[0, 1, 2]], (0, 0, 2))],
        [("o", [[0, 0, np.nan]] * 3, [[0, 1, 2]], (0, 0, 0))],
        [("o\0", v, [[0, 1, 2]], (0, 0, 0))],
        [("o", v, [[0, 1, 2]])],
    ]
    for objects in bad:
        with pytest.raises(ValueError):
            write_3ds(path, objects)
    assert list(tmp_path.iterdir()) == []


def test_scene_to_3ds_objects_round_trip(tmp_path: Path) -> None:
    import trimesh

    from tanktool.formats.models import load_scene

    box = trimesh.creation.box(extents=(2.0, 1.0, 4.0))
    box.apply_translation((0.0, 0.5, 0.0))  # standing on the floor, Y up
    colors = np.tile([200, 10, 10, 255], (len(box.faces), 1)).astype(np.uint8)
    colors[:4] = [10, 200, 10, 255]
    box.visual.face_colors = colors
    plain = trimesh.creation.icosphere(subdivisions=1, radius=0.5)  # no colours
    scene = trimesh.Scene()
    scene.add_geometry(box, node_name="hull")
    scene.add_geometry(plain, node_name="turret", transform=trimesh.transformations.translation_matrix([0, 2, 0]))

    objects = threeds_write.scene_to_3ds_objects(scene)
    assert sorted(o[0] for o in objects) == ["hull_0", "hull_1", "turret"]
    hull_z_up = np.vstack([o[1] for o in objects if o[0].startswith("hull")])
    # Y-up (x, y, z) -> Z-up (x, -z, y): the box's height (Y 0..1) becomes file Z
    assert hull_z_up[:, 2].min() == pytest.approx(0.0) and hull_z_up[:, 2].max() == pytest.approx(1.0)
    assert np.ptp(hull_z_up[:, 1]) == pytest.approx(4.0)

    path = tmp_path / "tank.3ds"
    write_3ds(path, objects)
    back = load_scene(path)  # world frame again (Y up), in the scene graph
    meshes = {m.metadata["name"]: m for m in back.dump()}
    assert sum(len(m.faces) for m in meshes.values()) == len(box.faces) + len(plain.faces)
    np.testing.assert_allclose(back.bounds, [[-1.0, 0.0, -2.0], [1.0, 2.5, 2.0]], atol=1e-6)
    turret = meshes["turret"]
    assert turret.visual.face_colors[0].tolist() == list(threeds.DEFAULT_COLOR)
    np.testing.assert_allclose(turret.vertices.mean(axis=0), plain.vertices.mean(axis=0) + [0, 2, 0], atol=1e-6)
    hull_colors = np.vstack([meshes[k].visual.face_colors for k in ("hull_0", "hull_1")])
    assert sorted(map(tuple, np.unique(hull_colors, axis=0).tolist())) == [(10, 200, 10, 255), (200, 10, 10, 255)]


# ---------------------------------------------------------------------------
# trimesh registration


def test_trimesh_load_registration() -> None:
    import trimesh

    assert "3ds" in trimesh.available_formats()
    scene = trimesh.load(str(MODELS / "test1.3ds"))
    assert isinstance(scene, trimesh.Scene)
    assert len(scene.geometry) == 9
    assert sum(len(g.faces) for g in scene.geometry.values()) == 108
    # file's own axes (Z up), exactly the raw vertices
    lo = np.min([g.bounds[0] for g in scene.geometry.values()], axis=0)
    assert np.round(lo, 4).tolist() == pytest.approx([-10.3432, -0.1942, -10.1551])
    # upper-case extension and a file object both go through the same loader
    alpha = trimesh.load_scene(str(MODELS / "cubes_with_alpha.3DS"))
    assert alpha.geometry["Quader05"].visual.face_colors[0].tolist() == [178, 8, 0, 212]
    with open(MODELS / "fels.3ds", "rb") as f:
        fels = trimesh.load_scene(f, file_type="3ds")
    (mesh,) = fels.geometry.values()
    assert mesh.faces.shape == (768, 3)
    assert mesh.visual.face_colors[0].tolist() == [200, 200, 200, 255]
    with pytest.raises(FormatError, match="empty file"):
        trimesh.load(str(MODELS / "invalid_empty.3ds"))


# ---------------------------------------------------------------------------
# fuzzing

CONTAINERS = {0x4D4D, 0x3D3D, 0x4000, 0x4100, 0x4120, 0xAFFF, 0xA010, 0xA020, 0xA030, 0xA040, 0xA050, 0xA200, 0xB000, 0xB002}


def chunk_spans(data: bytes) -> list[tuple[int, int]]:
    """(offset, end) of every chunk that can hold children, walked independently of
    the reader (names and fixed arrays before the children are skipped by hand)."""
    spans = []

    def walk(start: int, end: int) -> None:
        pos = start
        while pos + 6 <= end:
            cid, length = struct.unpack_from("<HI", data, pos)
            if length < 6 or pos + length > end:
                return
            if cid in CONTAINERS:
                spans.append((pos, pos + length))
                body = pos + 6
                if cid == 0x4000:
                    body = data.index(b"\0", body) + 1
                elif cid == 0x4120:
                    body += 2 + 8 * struct.unpack_from("<H", data, body)[0]
                walk(body, pos + length)
            pos += length

    walk(0, len(data))
    return spans


def truncated(data: bytes, cut: int, spans: list[tuple[int, int]]) -> bytes:
    """``data[:cut]`` with every chunk around the cut shortened to end there, so the
    damage is found deep inside the tree rather than at the top chunk."""
    out = bytearray(data[:cut])
    for start, end in spans:
        if start < cut < end and start + 6 <= cut:
            struct.pack_into("<I", out, start + 2, cut - start)
    return bytes(out)


def fuzz_cases(count: int, seed: int = 2024) -> list[bytes]:
    rng = np.random.default_rng(seed)
    files = [(MODELS / n).read_bytes() for n in VALID_FILES]
    file_spans = [chunk_spans(f) for f in files]
    cases: list[bytes] = []
    # truncations: plain ones (the top chunk then overruns the file) and ones with
    # the enclosing lengths patched, at every offset of test1.3ds when asked for
    # enough cases, else at evenly spread offsets
    base = (MODELS / "test1.3ds").read_bytes()
    spans = chunk_spans(base)
    # (the 20,000-case run cuts at every one of its 10,654 offsets)
    n_cut = len(base) if count >= 2 * len(base) else count // 2
    for i, cut in enumerate(np.linspace(0, len(base) - 1, n_cut).astype(int)):
        cases.append(truncated(base, int(cut), spans) if i % 4 else base[: int(cut)])
    # random damage anywhere in any file: flipped bits, random bytes, and random
    # values written over a chunk's length or first count (where damage matters most)
    while len(cases) < count:
        k = int(rng.integers(len(files)))
        data = bytearray(files[k])
        kind = rng.integers(3)
        for _ in range(rng.integers(1, 5)):
            if kind == 0:
                data[int(rng.integers(len(data)))] ^= 1 << int(rng.integers(8))
            elif kind == 1:
                data[int(rng.integers(len(data)))] = int(rng.integers(256))
            else:
                start, end = file_spans[k][int(rng.integers(len(file_spans[k])))]
                where = start + 2 + 4 * int(rng.integers(2))  # the length, or what follows it
                value = [0, 5, 6, 7, end - start + 1, 0xFFFF, 0xFFFFFFFF, int(rng.integers(1 << 32))]
                struct.pack_into("<I", data, min(where, len(data) - 4), value[int(rng.integers(len(value)))])
        cases.append(bytes(data))
    return cases


def check_case(data: bytes) -> bool:
    """Parse ``data``: it either works or raises FormatError, and never holds more
    memory than a small multiple of the file (counts are checked before arrays).
    Returns whether it was refused."""
    import trimesh

    tracemalloc.start()
    try:
        model = read_3ds(data)
        _, peak = tracemalloc.get_traced_memory()
        largest = max((t.size for t in tracemalloc.take_snapshot().traces), default=0)
    except FormatError:
        _, peak = tracemalloc.get_traced_memory()
        model, largest = None, 0
    finally:
        tracemalloc.stop()
    # arrays are at most twice the bytes they come from (float32 -> float64); per
    # chunk bookkeeping is a few hundred bytes.  A count trusted without a check
    # would allocate up to 65535 x 24 bytes and break this bound.
    assert peak <= 3 * len(data) + 64 * 1024, (peak, len(data))
    assert largest <= len(data) + 4096, (largest, len(data))
    if model is None:
        return True
    # what parsed also converts to a trimesh scene without any exception
    scene = trimesh.load_scene(io.BytesIO(data), file_type="3ds")
    assert len(scene.geometry) == sum(1 for o in model.objects if len(o.faces))
    return False


def test_memory_stays_proportional_to_many_tiny_chunks() -> None:
    """Per-chunk bookkeeping is bounded: 10,000 empty objects / materials / nodes."""
    units = [
        chunk(0x3D3D, chunk(0x4000, b"\0", chunk(0x4100, chunk(0x4120, b"\0\0"))) * 10_000),
        chunk(0x3D3D, chunk(0xAFFF) * 10_000),
        chunk(0xB000, chunk(0xB002) * 10_000),
    ]
    for unit in units:
        data = chunk(0x4D4D, unit)
        tracemalloc.start()
        try:
            read_3ds(data)
            _, peak = tracemalloc.get_traced_memory()
        finally:
            tracemalloc.stop()
        assert peak < 40 * len(data), (peak, len(data))


def test_chunk_spans_cover_the_tree() -> None:
    spans = chunk_spans((MODELS / "test1.3ds").read_bytes())
    assert spans[0][0] == 0 and len(spans) > 30


def test_fuzz_truncation_and_flips() -> None:
    cases = fuzz_cases(int(os.environ.get("TANKTOOL_FUZZ_CASES", "300")))
    assert len(cases) >= 300 or "TANKTOOL_FUZZ_CASES" in os.environ
    refused = sum(check_case(data) for data in cases)
    # the cases do exercise the error paths, and not only them
    assert 0.2 * len(cases) < refused < len(cases)


@pytest.mark.slow
def test_fuzz_long() -> None:
    cases = fuzz_cases(20_000, seed=7)
    for data in cases:
        check_case(data)
