"""Textures from the model: what .3ds, .obj/.mtl and .gltf files name, where the files
are found, the warning for a missing or broken one, model.glb with the images
embedded, and the files copied into the bundle by import-arena and import-vehicle."""

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from tanktool.cli.main import cli
from tanktool.formats.materials import (
    _mtl_map_name, find_texture, model_textures, textured_scene,
)


def png(path: Path, rgb=(200, 40, 40), size=8) -> Path:
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.full((size, size, 3), rgb, dtype=np.uint8)).save(path)
    return path


def box_parts(s: float = 40.0, h: float = 3.0):
    """A walled yard as (name, material, vertices, faces) boxes, Y up."""
    import trimesh

    def box(x0, z0, x1, z1, y0, y1):
        b = trimesh.creation.box(extents=[x1 - x0, y1 - y0, z1 - z0])
        b.apply_translation([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
        return b

    parts = [("floor", "ground", box(0, 0, s, s, -0.5, 0))]
    for k, (a, b, c, d) in enumerate([(0, 0, s, 1), (0, s - 1, s, s), (0, 1, 1, s - 1), (s - 1, 1, s, s - 1)]):
        parts.append((f"wall{k}", "brick", box(a, b, c, d, 0, h)))
    return [(n, m, np.asarray(b.vertices), np.asarray(b.faces)) for n, m, b in parts]


def write_obj(folder: Path, maps: dict[str, str], name: str = "yard") -> Path:
    """An .obj with texture coordinates and an .mtl naming ``maps`` (material -> map_Kd line)."""
    lines = [f"mtllib {name}.mtl"]
    base = 1
    for obj, mat, v, f in box_parts():
        lines += [f"o {obj}", f"usemtl {mat}"]
        lines += [f"v {x:g} {y:g} {z:g}" for x, y, z in v]
        lines += [f"vt {x / 4:g} {z / 4 + y / 4:g}" for x, y, z in v]
        lines += [f"f {a + base}/{a + base} {b + base}/{b + base} {c + base}/{c + base}" for a, b, c in f]
        base += len(v)
    (folder / f"{name}.obj").write_text("\n".join(lines) + "\n")
    mtl = "".join(f"newmtl {m}\nKd 0.5 0.5 0.5\n" + (f"map_Kd {maps[m]}\n" if m in maps else "") + "\n"
                  for m in ("ground", "brick"))
    (folder / f"{name}.mtl").write_text(mtl)
    return folder / f"{name}.obj"


def test_mtl_options_before_the_file_name():
    assert _mtl_map_name("map_Kd -s 2 2 1 -o 0 0 0 -bm 0.5 tex/a b.png") == "tex/a b.png"
    assert _mtl_map_name("map_Kd brick.png") == "brick.png"
    assert _mtl_map_name("map_Kd -clamp on") == ""


def test_find_texture_beside_in_subfolders_any_case_and_in_the_bundle(tmp_path):
    model = tmp_path / "m" / "model.3ds"
    model.parent.mkdir()
    model.write_bytes(b"")
    a = png(tmp_path / "m" / "Brick.PNG")
    b = png(tmp_path / "m" / "maps" / "grass.png")
    c = png(tmp_path / "bundle" / "textures" / "stone.png")
    assert find_texture("brick.png", model) == a                     # letter case does not matter
    assert find_texture("C:\\art\\MAPS\\GRASS.PNG", model) == b       # a Windows path from the artist's machine
    assert find_texture("textures/stone.png", model) is None
    assert find_texture("textures/stone.png", model, [tmp_path / "bundle"]) == c
    assert find_texture("data:image/png;base64,AAAA", model) is None


def test_obj_textures_copied_into_the_arena_bundle(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    png(src / "tex" / "ground.png", (90, 80, 60))
    png(src / "brick.png", (170, 60, 40))
    model = write_obj(src, {"ground": "-s 1 1 1 tex/ground.png", "brick": "BRICK.png"})
    out = tmp_path / "yard"
    r = CliRunner().invoke(cli, ["import-arena", str(model), "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert "warning" not in r.output                               # nothing missing, nothing to say
    assert (out / "tex" / "ground.png").is_file()                   # as the .mtl names it: its copy finds it
    assert (out / "textures" / "brick.png").is_file()               # "BRICK.png" was found as brick.png
    from tanktool.formats.bundle import read_toml

    doc = read_toml(out / "arena.toml")
    assert doc["model"]["textures"] == ["tex/ground.png", "textures/brick.png"]
    # the game's model carries both images and their texture coordinates
    from tanktool.game.meshes import load_model

    m = load_model(str(out / "model.glb"))
    colours = sorted(tuple(int(c) for c in b.image.reshape(-1, b.image.shape[-1])[0, :3]) for b in m.batches
                     if b.image is not None)
    assert colours == [(90, 80, 60), (170, 60, 40)]
    assert all(np.ptp(b.vertices[:, 9:11]) > 0 for b in m.batches)   # real UVs
    # rebuilding the bundle from its own copy of the model finds the copied textures
    r = CliRunner().invoke(cli, ["import-arena", str(out / "yard.obj"), "--out", str(out), "--force"])
    assert r.exit_code == 0, r.output
    assert read_toml(out / "arena.toml")["model"]["textures"] == ["tex/ground.png", "textures/brick.png"]


def test_missing_and_broken_textures_warn_and_keep_the_colour(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    (src / "broken.png").write_bytes(b"\x89PNG not really")
    model = write_obj(src, {"ground": "missing.png", "brick": "broken.png"})
    out = tmp_path / "yard"
    r = CliRunner().invoke(cli, ["import-arena", str(model), "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert "material 'ground': texture 'missing.png' not found" in r.output
    assert "material 'brick': texture 'broken.png'" in r.output and "not a readable image" in r.output
    assert "keep the material's colour" in r.output
    assert not (out / "textures").exists()
    from tanktool.formats.bundle import read_toml
    from tanktool.game.meshes import load_model

    assert "textures" not in read_toml(out / "arena.toml")["model"]
    m = load_model(str(out / "model.glb"))
    assert all(b.image is None for b in m.batches)
    rgb = np.unique(np.round(np.concatenate([b.vertices[:, 6:9] for b in m.batches]), 2), axis=0)
    assert rgb.tolist() == [[0.5, 0.5, 0.5]]                        # the Kd of the .mtl


def test_3ds_map_chunks_and_uvs(tmp_path):
    from tanktool.formats.models import load_scene
    from tanktool.formats.threeds_write import write_3ds
    from tanktool.game.meshes import model_from_meshes

    png(tmp_path / "CAMO.PNG", (30, 120, 40))
    parts = box_parts(20.0)
    objects = []
    for i, (name, mat, v, f) in enumerate(parts):
        zup = np.column_stack([v[:, 0], -v[:, 2], v[:, 1]])
        uv = v[:, [0, 2]] / 5.0
        if i == 0:
            objects.append((name, zup, f, (0.4, 0.4, 0.4), uv, "camo.png"))       # textured
        elif i == 1:
            objects.append((name, zup, f, (0.8, 0.2, 0.2), None, "camo.png"))     # a map but no UVs
        else:
            objects.append((name, zup, f, (0.2, 0.2, 0.8)))
    model = tmp_path / "yard.3ds"
    write_3ds(model, objects)
    found = model_textures(model)
    # two materials (two colours) name the same file: one use each, one file
    assert [(u.name, u.path.name) for u in found.found] == [("camo.png", "CAMO.PNG")] * 2
    said = []
    scene, _ = textured_scene(model, load_scene(model), warn=said.append)
    assert any("object 'wall0'" in s and "no texture coordinates" in s for s in said)
    m = model_from_meshes([g for g in scene.dump()])
    textured = [b for b in m.batches if b.image is not None]
    assert len(textured) == 1 and textured[0].image[0, 0, :3].tolist() == [30, 120, 40]
    assert textured[0].triangles == 12                              # the floor box, and only it
    # the floor's texture coordinates are the ones written (x/5, z/5), in the world frame
    tv = textured[0].vertices
    assert np.allclose(tv[:, 9], tv[:, 0] / 5.0, atol=1e-5) and np.allclose(tv[:, 10], tv[:, 2] / 5.0, atol=1e-5)
    untextured = np.concatenate([b.vertices for b in m.batches if b.image is None])
    assert {tuple(round(float(x), 2) for x in c) for c in untextured[:, 6:9]} == {(0.8, 0.2, 0.2), (0.2, 0.2, 0.8)}


def test_vehicle_textures_go_into_the_vehicle_bundle(tmp_path, root_dir):
    # the bundled light tank's source names its textures in textures/; imported from a
    # copy that has them beside it, the new bundle gets them too
    import shutil

    src = tmp_path / "src"
    shutil.copytree(root_dir / "vehicles" / "light" / "textures", src / "textures")
    shutil.copyfile(root_dir / "vehicles" / "light" / "light.3ds", src / "light.3ds")
    out = tmp_path / "light"
    r = CliRunner().invoke(cli, ["import-vehicle", str(src / "light.3ds"), "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in (out / "textures").iterdir()) == ["camo_green.png", "steel.png", "tracks.png"]
    from tanktool.game.meshes import load_model

    assert sum(b.image is not None for b in load_model(str(out / "model.glb")).batches) == 3


def test_gltf_external_image_missing(tmp_path):
    import json

    doc = {"asset": {"version": "2.0"}, "images": [{"uri": "skin.png"}, {"uri": "data:image/png;base64,AA=="}]}
    model = tmp_path / "m.gltf"
    model.write_text(json.dumps(doc))
    found = model_textures(model)
    assert [u.name for u in found.missing] == ["skin.png"]          # the data URI is inside the file
    png(tmp_path / "skin.png")
    assert [u.name for u in model_textures(model).found] == ["skin.png"]


@pytest.mark.parametrize("bundle", ["arenas/box", "arenas/maze", "arenas/paper2002", "vehicles/light",
                                    "vehicles/heavy"])
def test_bundled_content_is_textured(root_dir, bundle):
    # tools/make_textures.py painted them; the models name them; model.glb carries them
    from tanktool.formats.bundle import read_toml
    from tanktool.game.meshes import load_model

    folder = root_dir / bundle
    doc = read_toml(next(folder.glob("*.toml")))
    names = doc["model"]["textures"]
    assert names and all((folder / n).is_file() for n in names)
    from PIL import Image

    assert all("CC0" in Image.open(folder / n).info.get("License", "") for n in names)
    m = load_model(str(folder / "model.glb"))
    assert sum(b.triangles for b in m.batches if b.image is not None) == m.triangles   # every face textured


def test_glb_embedded_textures_kept(tmp_path):
    # a .glb carries its images: they reach the bundle's model.glb, nothing to copy
    import trimesh
    from PIL import Image

    from tanktool.game.meshes import load_model

    scene = trimesh.Scene()
    for obj, mat, v, f in box_parts():
        uv = np.column_stack([v[:, 0] / 4, v[:, 2] / 4])
        img = Image.fromarray(np.full((4, 4, 3), (20, 140, 60) if mat == "ground" else (160, 50, 40), np.uint8))
        vis = trimesh.visual.TextureVisuals(uv=uv, material=trimesh.visual.material.PBRMaterial(
            name=mat, baseColorTexture=img))
        scene.add_geometry(trimesh.Trimesh(v, f, visual=vis, process=False), geom_name=obj)
    model = tmp_path / "yard.glb"
    model.write_bytes(scene.export(file_type="glb"))
    out = tmp_path / "yard"
    r = CliRunner().invoke(cli, ["import-arena", str(model), "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert "warning" not in r.output and not (out / "textures").exists()
    m = load_model(str(out / "model.glb"))
    colours = {tuple(int(c) for c in b.image[0, 0, :3]) for b in m.batches if b.image is not None}
    assert colours == {(20, 140, 60), (160, 50, 40)}
