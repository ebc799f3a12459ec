"""Paint the bundled arenas' and vehicles' textures, procedurally, from fixed seeds.

    .venv/bin/python tools/make_textures.py [--out DIR] [--only NAME]

Every image is made here from numpy noise (no photograph, no third-party asset), so
the same command always writes the same pixels.  **Licence: CC0 1.0 (public domain
dedication)**: the images may be used for anything without asking; each PNG says so
in its ``License`` text chunk, beside ``Software: tanktool tools/make_textures.py``.

All are seamless (they tile): noise is made periodic by filtering white noise in the
frequency domain, and every pattern (brick courses, planks, plates, treads) has a
whole number of repeats across the image.  Where each one goes:

=============  ===============================================  ==========================
texture        what                                             used by
=============  ===============================================  ==========================
brick          red-brown brick courses, grey-brown mortar       box, hills walls
dirt           packed earth with gravel and tyre ruts           box floor, fort ground
planks         weathered wooden planks with nails               box crates, fort decks
stone          grey-beige ashlar blocks                         maze, fort walls
grass          short dry grass over earth                       maze floor, hills
concrete       cast concrete panels with form-tie holes         paper2002 walls, fort ramps
tarmac         worn asphalt with patched cracks                 paper2002 floor
rock           craggy grey rock with cracks and lichen          hills and fort rock
camo_green     woodland camouflage over riveted plates          light tank
camo_sand      desert camouflage over riveted plates            heavy tank
tracks         track links with grousers                        both tanks' tracks
steel          dark gun steel, slightly scuffed                 wheels, barrels
=============  ===============================================  ==========================

``ARENA_TEXTURES`` says which material of which arena gets which texture.  The .obj
sources get their texture coordinates from :func:`texture_obj` (``--models``: a box
projection per face, ``TILE`` metres per repeat, positions untouched, so walls and
grids stay the same), the .3ds one from tools/make_arena_models.py, the tanks from
tools/make_vehicle_models.py; import-arena and import-vehicle embed the images in
``model.glb`` and copy them into the bundles' ``textures/`` folders.  After a new
bundled arena: add it to ``ARENA_TEXTURES``, then ``python tools/make_textures.py
--models`` and ``make arenas``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Callable

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

SIZE = 256
LICENSE = "CC0-1.0 (public domain dedication): https://creativecommons.org/publicdomain/zero/1.0/"


# ---------------------------------------------------------------- noise
from tanktool.game.noise import fbm, periodic_noise  # noqa: E402  (shared with the sky's clouds)


def colourise(value: np.ndarray, low, high) -> np.ndarray:
    """(h, w) in [0, 1] -> (h, w, 3) floats between two RGB colours (0..255)."""
    lo, hi = np.asarray(low, float), np.asarray(high, float)
    return lo + value[..., None] * (hi - lo)


def _grid(size: int) -> tuple[np.ndarray, np.ndarray]:
    y, x = np.mgrid[0:size, 0:size]
    return x.astype(float), y.astype(float)


def courses(size: int, rows: int, cols: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Running bond (each course shifted half a block): per pixel its course, its block
    in the course and its distance to the nearest joint [px]."""
    x, y = _grid(size)
    rh, cw = size / rows, size / cols
    row = (y // rh).astype(int)
    shifted = (x + (row % 2) * cw / 2) % size
    col = (shifted // cw).astype(int) % cols
    joint = np.minimum(np.minimum(y % rh, rh - y % rh), np.minimum(shifted % cw, cw - shifted % cw))
    return row, col, joint


# ---------------------------------------------------------------- textures
def brick(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    rows, cols = 8, 4                    # a 3 m tile: 0.375 m courses, 0.75 m bricks
    row, col, joint = courses(size, rows, cols)
    mortar = joint < 2.2
    tone = rng.uniform(0.75, 1.15, (rows, cols))[row, col]
    grain = fbm(rng, size, (18, 6, 2), (0.5, 0.3, 0.2))
    img = colourise(grain, (120, 52, 36), (178, 86, 58)) * tone[..., None]
    soot = periodic_noise(rng, size, 50)
    img *= (0.82 + 0.25 * soot)[..., None]
    mortar_c = colourise(fbm(rng, size, (8, 2), (0.6, 0.4)), (92, 80, 70), (132, 118, 104))
    img[mortar] = mortar_c[mortar]
    return img


def dirt(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    base = fbm(rng, size)
    img = colourise(base, (92, 78, 56), (148, 126, 92))
    gravel = periodic_noise(rng, size, 1.2)
    img[gravel > 0.8] *= 0.7
    img[gravel < 0.12] = img[gravel < 0.12] * 0.6 + np.array([170, 160, 140]) * 0.4
    x, y = _grid(size)
    ruts = 0.5 + 0.5 * np.sin(2 * np.pi * x / size * 2)   # two faint ruts across a tile
    img *= (0.93 + 0.07 * ruts)[..., None]
    return img


def planks(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    n = 5
    x, y = _grid(size)
    w = size / n
    k = (y // w).astype(int)
    offset = rng.uniform(0, size, n)[k]
    grain_src = periodic_noise(rng, size, 3)
    streak = 0.5 + 0.5 * np.sin((y % w) / w * np.pi * 6 + 8 * grain_src + offset * 0.01)
    tone = rng.uniform(0.8, 1.1, n)[k]
    img = colourise(0.6 * streak + 0.4 * fbm(rng, size, (16, 4), (0.6, 0.4)), (112, 80, 44), (170, 128, 76))
    img *= tone[..., None]
    gap = np.minimum(y % w, w - y % w) < 1.6
    img[gap] = (46, 32, 20)
    # nails near both ends of each plank (two per end, periodic across the tile)
    for cx in (0.08 * size, 0.92 * size):
        for j in range(n):
            for cy in (j * w + 0.3 * w, j * w + 0.7 * w):
                d = np.hypot(x - cx, y - cy)
                img[d < 2.2] = (70, 70, 72)
    return img


def stone(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    rows, cols = 4, 3                    # a 3 m tile: 0.75 m blocks, 1 m long
    row, col, joint = courses(size, rows, cols)
    tone = rng.uniform(0.85, 1.1, (rows, cols))[row, col]
    img = colourise(fbm(rng, size, (30, 10, 3), (0.5, 0.3, 0.2)), (118, 112, 98), (178, 170, 150)) * tone[..., None]
    img *= np.clip(joint / 4.0, 0.45, 1.0)[..., None]          # bevelled joints read as depth
    moss = periodic_noise(rng, size, 20)
    img[moss > 0.82] = img[moss > 0.82] * 0.7 + np.array([70, 90, 50]) * 0.3
    return img


def rock(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    crags = fbm(rng, size, (48, 16, 5, 2), (0.35, 0.3, 0.2, 0.15))
    img = colourise(crags, (92, 86, 78), (160, 152, 140))
    ridges = np.abs(periodic_noise(rng, size, 10) - 0.5) < 0.03
    img[ridges] *= 0.6                                        # cracks between the slabs
    lichen = periodic_noise(rng, size, 16) > 0.8
    img[lichen] = img[lichen] * 0.75 + np.array([110, 120, 70]) * 0.25
    return img


def grass(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    patches = fbm(rng, size, (70, 25, 8), (0.5, 0.3, 0.2))
    img = colourise(patches, (88, 96, 52), (138, 142, 74))
    blades = periodic_noise(rng, size, 0.9)
    img *= (0.85 + 0.3 * blades)[..., None]
    bare = periodic_noise(rng, size, 30) > 0.78
    img[bare] = img[bare] * 0.5 + np.array([120, 100, 70]) * 0.5
    return img


def concrete(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    img = colourise(fbm(rng, size, (40, 12, 3, 1), (0.4, 0.3, 0.2, 0.1)), (124, 124, 120), (176, 175, 168))
    x, y = _grid(size)
    panel = size / 2
    seam = np.minimum(np.minimum(x % panel, panel - x % panel), np.minimum(y % panel, panel - y % panel)) < 1.5
    img[seam] *= 0.62
    for cx in (panel / 4, 3 * panel / 4, panel + panel / 4, panel + 3 * panel / 4):
        for cy in (panel / 2, panel + panel / 2):
            img[np.hypot(x - cx, y - cy) < 2.5] *= 0.45      # form-tie holes
    stains = periodic_noise(rng, size, 24)
    img *= (0.9 + 0.15 * stains)[..., None]
    return img


def tarmac(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    img = colourise(fbm(rng, size, (30, 8, 2, 1), (0.3, 0.3, 0.2, 0.2)), (54, 55, 58), (96, 96, 98))
    chips = periodic_noise(rng, size, 0.8)
    img[chips > 0.78] = img[chips > 0.78] * 0.6 + np.array([150, 148, 140]) * 0.4
    crack = np.abs(periodic_noise(rng, size, 22) - 0.5) < 0.006
    img[crack] *= 0.45
    patch = periodic_noise(rng, size, 45) > 0.72
    img[patch] *= 0.8
    return img


def _plates(rng: np.random.Generator, size: int, img: np.ndarray) -> np.ndarray:
    x, y = _grid(size)
    p = size / 2
    seam = np.minimum(np.minimum(x % p, p - x % p), np.minimum(y % p, p - y % p))
    img = img * np.clip(0.75 + seam / 6.0, 0.75, 1.0)[..., None]
    for i in range(8):
        for j in (6, p - 6, p + 6, size - 6):
            cx = (i + 0.5) * size / 8
            img[np.hypot(x - cx, y - j) < 1.8] *= 1.35                   # rivet heads catch the light
    scuff = periodic_noise(rng, size, 2) > 0.86
    img[scuff] = img[scuff] * 0.75 + 40
    return np.clip(img, 0, 255)


def camo(rng: np.random.Generator, colours, size: int = SIZE) -> np.ndarray:
    a = periodic_noise(rng, size, 26)
    b = periodic_noise(rng, size, 18)
    img = np.empty((size, size, 3))
    img[:] = colours[0]
    img[a > 0.55] = colours[1]
    img[(b > 0.62) & (a <= 0.55)] = colours[2]
    img[(b < 0.28) & (a > 0.4)] = colours[3]
    img *= (0.88 + 0.2 * fbm(rng, size, (6, 2), (0.6, 0.4)))[..., None]
    return _plates(rng, size, img)


def camo_green(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    return camo(rng, [(92, 104, 60), (60, 72, 40), (118, 110, 74), (38, 40, 32)], size)


def camo_sand(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    return camo(rng, [(168, 146, 104), (138, 112, 76), (190, 172, 132), (104, 88, 62)], size)


def tracks(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    x, y = _grid(size)
    links = 16
    w = size / links
    phase = (x % w) / w
    img = colourise(fbm(rng, size, (6, 2), (0.6, 0.4)), (40, 38, 34), (70, 66, 60))
    img[phase < 0.18] *= 0.5                                    # the gap between links
    img[(phase > 0.35) & (phase < 0.55)] *= 1.35                # the grouser, polished by the ground
    pins = (np.abs(y - size / 2) < size * 0.04) & (phase < 0.3)
    img[pins] = (96, 92, 86)
    return np.clip(img, 0, 255)


def steel(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    img = colourise(fbm(rng, size, (20, 5, 1), (0.4, 0.35, 0.25)), (50, 52, 50), (86, 88, 84))
    x, y = _grid(size)
    brushed = periodic_noise(rng, size, 0.7)[:, :1]             # one column stretched: brushed lines
    img *= (0.92 + 0.16 * np.repeat(brushed, size, axis=1))[..., None]
    return np.clip(img, 0, 255)


#: name -> (painter, seed)
TEXTURES: dict[str, tuple[Callable[..., np.ndarray], int]] = {
    "brick": (brick, 11), "dirt": (dirt, 12), "planks": (planks, 13), "stone": (stone, 14),
    "grass": (grass, 15), "concrete": (concrete, 16), "tarmac": (tarmac, 17), "rock": (rock, 18),
    "camo_green": (camo_green, 21), "camo_sand": (camo_sand, 22), "tracks": (tracks, 23), "steel": (steel, 24),
}

#: metres per repeat of each texture on an arena (box projection)
TILE = {"brick": 3.0, "dirt": 4.0, "planks": 2.0, "stone": 3.0, "grass": 4.0, "concrete": 3.0, "tarmac": 4.0,
        "rock": 5.0, "camo_green": 3.0, "camo_sand": 3.0, "tracks": 2.4, "steel": 1.0}
#: bundled arena -> material (kind of part) -> texture; tools/make_arena_models.py and
#: :func:`texture_obj` give the models texture coordinates and name these
ARENA_TEXTURES = {
    "box": {"floor": "dirt", "wall": "brick", "crate": "planks"},
    "maze": {"floor": "grass", "wall": "stone"},
    "paper2002": {"floor": "tarmac", "wall": "concrete", "block": "concrete"},
    "hills": {"grass": "grass", "rock": "rock", "wall": "brick"},
    "fort": {"ground": "dirt", "wall": "stone", "deck": "planks", "ramp": "concrete", "rock": "rock"},
}
#: which vehicle uses which textures (tools/make_vehicle_models.py names them)
VEHICLE_TEXTURES = {"light": ("camo_green", "tracks", "steel"), "heavy": ("camo_sand", "tracks", "steel")}


def uses() -> dict[str, tuple[str, ...]]:
    """Bundle folder (relative to the checkout) -> the textures it needs."""
    out = {f"arenas/{a}": tuple(sorted(set(m.values()))) for a, m in ARENA_TEXTURES.items()}
    out.update({f"vehicles/{v}": t for v, t in VEHICLE_TEXTURES.items()})
    return out


def box_uv(vertices: np.ndarray, faces: np.ndarray, tile: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Texture coordinates by box projection, ``tile`` metres per repeat.

    Each face is mapped along the two axes across its normal's largest component (a
    floor by (x, z), a wall facing z by (x, y)...); faces are grouped by that axis and
    each group gets its own copy of its vertices, so the seams between the groups are
    sharp.  Returns (vertices (n', 3), faces (m, 3), uv (n', 2)); Y up."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    axis = np.argmax(np.abs(n), axis=1)
    # (u, v) axes per dominant axis: x-facing -> (z, y), y-facing -> (x, z), z-facing -> (x, y)
    across = {0: (2, 1), 1: (0, 2), 2: (0, 1)}
    out_v, out_uv = [], []
    out_f = np.empty_like(f)
    base = 0
    for a in (0, 1, 2):
        rows = np.flatnonzero(axis == a)
        if not len(rows):
            continue
        used, inverse = np.unique(f[rows], return_inverse=True)
        pts = v[used]
        u_ax, v_ax = across[a]
        out_v.append(pts)
        out_uv.append(np.column_stack([pts[:, u_ax], pts[:, v_ax]]) / tile)
        out_f[rows] = inverse.reshape(-1, 3) + base      # faces keep their order
        base += len(used)
    return np.vstack(out_v), out_f, np.vstack(out_uv)


def _obj_index(token: str, count: int) -> int:
    """A 1-based (or negative, relative) OBJ index as a 0-based one."""
    i = int(token)
    return i - 1 if i > 0 else count + i


def texture_obj(path: Path, textures: dict[str, str], folder: str = "textures") -> int:
    """Give an .obj texture coordinates and its .mtl the textures: every face of a
    material in ``textures`` that has no ``vt`` of its own gets a box projection
    (``TILE`` metres per repeat; each corner its own ``vt``, so no vertex moves or is
    duplicated in the file), and the material ``map_Kd <folder>/<texture>.png`` with a
    white ``Kd`` (MTL multiplies the two).  Positions and faces stay as they were: the
    walls and grids made from the model do not change.  Returns the faces given
    coordinates; running it again changes nothing."""
    lines = path.read_text().splitlines()
    verts: list[tuple[float, float, float]] = []
    n_vt = sum(1 for ln in lines if ln.startswith("vt "))
    material, out, done = None, [], 0
    for line in lines:
        words = line.split()
        if words[:1] == ["v"]:
            verts.append(tuple(float(w) for w in words[1:4]))
        elif words[:1] == ["usemtl"]:
            material = " ".join(words[1:])
        elif words[:1] == ["f"] and material in textures and all("/" not in w or w.split("/")[1] == ""
                                                                   for w in words[1:]):
            corners = [w.split("/") for w in words[1:]]
            idx = [_obj_index(c[0], len(verts)) for c in corners]
            p = np.array([verts[i] for i in idx], dtype=np.float64)
            normal = np.cross(p[1] - p[0], p[2] - p[0])
            a = int(np.argmax(np.abs(normal)))
            u_ax, v_ax = {0: (2, 1), 1: (0, 2), 2: (0, 1)}[a]
            tile = TILE[textures[material]]
            for q in p:
                out.append(f"vt {q[u_ax] / tile:.6g} {q[v_ax] / tile:.6g}")
            face = []
            for k, c in enumerate(corners):
                vt = n_vt + k + 1
                face.append(f"{c[0]}/{vt}" + (f"/{c[2]}" if len(c) > 2 and c[2] else ""))
            n_vt += len(corners)
            out.append("f " + " ".join(face))
            done += 1
            continue
        out.append(line)
    path.write_text("\n".join(out) + "\n")
    for mtl in _mtl_libraries(path):
        _texture_mtl(mtl, textures, folder)
    return done


def _mtl_libraries(obj: Path) -> list[Path]:
    from tanktool.formats.materials import mtl_libraries

    return mtl_libraries(obj)


def _texture_mtl(mtl: Path, textures: dict[str, str], folder: str) -> None:
    """Name each material's texture in an .mtl (white Kd, map_Kd), keeping what it has."""
    blocks: list[list[str]] = [[]]
    for line in mtl.read_text().splitlines():
        if line.startswith("newmtl"):
            blocks.append([])
        blocks[-1].append(line)
    out = []
    for block in blocks:
        name = block[0].split(maxsplit=1)[1].strip() if block and block[0].startswith("newmtl") else None
        if name in textures and not any(ln.lower().startswith("map_kd") for ln in block):
            block = [ln for ln in block if not ln.startswith("Kd ")]
            body = [ln for ln in block[1:] if ln.strip()]
            block = [block[0], "Kd 1.000 1.000 1.000", f"map_Kd {folder}/{textures[name]}.png", *body, ""]
        out += block
    mtl.write_text("\n".join(out).rstrip("\n") + "\n\n")


def paint(name: str, size: int = SIZE) -> np.ndarray:
    """(size, size, 3) uint8 pixels of texture ``name``."""
    painter, seed = TEXTURES[name]
    img = painter(np.random.default_rng(seed), size)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


def write_png(pixels: np.ndarray, path: Path) -> None:
    """A PNG with the licence and the tool in its text chunks, written atomically."""
    import io

    from PIL import Image
    from PIL.PngImagePlugin import PngInfo

    from tanktool.formats.bundle import atomic_write_bytes

    info = PngInfo()
    info.add_text("License", LICENSE)
    info.add_text("Software", "tanktool tools/make_textures.py")
    buf = io.BytesIO()
    Image.fromarray(pixels).save(buf, format="PNG", pnginfo=info, optimize=True)
    atomic_write_bytes(path, buf.getvalue())


def texture_arena_sources(root: Path = ROOT) -> list[str]:
    """Texture coordinates and textures for the .obj sources of the bundled arenas (the
    .3ds one is written with them by tools/make_arena_models.py)."""
    done = []
    for name, textures in ARENA_TEXTURES.items():
        manifest = root / "arenas" / name / "arena.toml"
        if not manifest.is_file():
            continue
        from tanktool.formats.bundle import read_toml

        src = manifest.parent / read_toml(manifest)["source"]["file"]
        if src.suffix.lower() == ".obj":
            done.append(f"{src.relative_to(root)}: {texture_obj(src, textures)} faces given texture coordinates")
    return done


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT, help="the checkout (bundles under arenas/ and vehicles/)")
    ap.add_argument("--only", action="append", help="only this bundle, e.g. arenas/box (repeatable)")
    ap.add_argument("--models", action="store_true",
                    help="also give the bundled arenas' .obj sources texture coordinates and name the textures "
                         "in their .mtl (then `make arenas` rebuilds the bundles)")
    args = ap.parse_args(argv)
    cache: dict[str, np.ndarray] = {}
    for bundle, names in uses().items():
        if args.only and bundle not in args.only:
            continue
        if not (args.out / bundle).is_dir():
            continue                                # a bundle this checkout does not have
        folder = args.out / bundle / "textures"
        folder.mkdir(parents=True, exist_ok=True)
        for name in names:
            if name not in cache:
                cache[name] = paint(name)
            write_png(cache[name], folder / f"{name}.png")
        print(f"{bundle}/textures: {', '.join(f'{n}.png' for n in names)}")
    if args.models:
        for line in texture_arena_sources(args.out):
            print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
