"""BZFlag world files (``.bzw``) as arena models.

A ``.bzw`` file is a list of objects, each a keyword line, property lines and
``end``; ``#`` starts a comment; keywords are case-insensitive.  BZFlag is Z-up
and its units are about a metre (a tank is 6 long and 2.05 tall), so one unit is
taken as one metre; ``load_scene`` returns the scene in BZFlag's own Z-up frame and
:func:`tanktool.formats.models.load_scene` turns it into the world frame with the
usual Z-up conversion (x, y, z) -> (x, z, -y).

What becomes geometry (sizes as BZFlag reads them, rotations in degrees about z,
counter-clockwise seen from above):

- ``world``: ``size S`` is the *half*-width (bzfs doubles it: the world is
  2S x 2S); default S = 400, an 800 x 800 world.  A ground plane covers it and,
  unless ``nowalls`` is given, four outer walls 6.15 high (BZFlag's
  ``_wallHeight`` = 3 x tank height) stand just outside its edge.
- ``options``: the server options a world carries.  ``-set _worldSize W`` is the
  *full* width (BZFlag's BZDB variable, default 800: the same as ``world size
  W/2``) and ``-set _wallHeight H`` the outer walls' height; both ``world size`` and
  ``_worldSize`` set the same variable as bzfs reads the file, so the later one wins
  (with a warning when they disagree).  The other options (game rules: flags,
  jumping, shots, ...) do not change the arena and are named in one warning.
- ``box`` / ``meshbox``: ``size`` x and y are half-extents, z the full height
  from ``position``'s z up (default 30 30 9.42).
- ``pyramid`` / ``meshpyr``: a rectangle of half-extents x, y at z, apex at the
  centre size z above (default 8.2 8.2 10.25); ``flipz`` or a negative z size
  puts the apex at the bottom.
- ``base``: a box (default 30 30 0); a base of zero height is a flat pad
  drawn 1 cm above its position.
- ``wall``: a vertical plane of half-width size y and height size z, through
  ``position``, facing along the rotated x axis (BZFlag's WallObstacle).
- ``teleporter``: only its solid frame: two square posts of side ``border``
  (default 1.12) at y = +-(size y + 1.5 border), size z high, and a crossbar
  ``border`` thick on top (default size 0.5 4.48 20.16), as BZFlag builds it.

- ``mesh``: its vertices and polygon faces, shifted, scaled and spun as it says;
  ``group NAME``: the solids of ``define NAME`` ... ``enddef`` moved by the group's
  shift / scale / spin (formats/bzw_mesh.py).

Objects with ``drivethrough`` are left out (tanks pass through them).  Any other
object (``link``, ``arc``, ``cone``, ``sphere``, ``zone``, ...) is skipped with a
warning naming its line, and so is an unknown property of a known object; the solid
ones (``arc``, ``cone``, ``sphere``, ``tetra``, a group of no definition,
drivethrough objects) are also counted, by kind with their lines, in what the
import leaves out (``scene.metadata["left_out"]``).
``options -set _wallHeight 0`` means no outer walls and a teleporter of ``border 0``
has no frame (nothing solid), as in BZFlag.  Malformed numbers, a missing ``end`` or an
``end`` without an object raise :class:`FormatError` with the file and line.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import FormatError
from .bundle import read_input
from .bzw_mesh import BzwGroup, BzwMesh, _group_line, _mesh_line
from .limits import MAX_MODEL_BYTES, MAX_OBJECTS

#: warnings passed on per file (a file of a million unknown lines says so once)
MAX_WARNINGS = 50

#: BZFlag's default world half-width (``world size``; bzfs doubles it)
WORLD_SIZE = 400.0
#: BZFlag's _wallHeight = 3 x _tankHeight (2.05)
OUTER_WALL_HEIGHT = 6.15
#: thickness given to the outer walls (BZFlag's are planes): they stand outside the edge
OUTER_WALL_THICKNESS = 1.0
#: pads (zero-height bases) are lifted this much so they do not fight with the ground
PAD_LIFT = 0.01

#: default ``size`` per object kind (BZFlag's BZDB defaults: box base 30, box height
#: 6 x muzzle height 1.57, pyramid base 4 x and height 5 x tank height 2.05)
DEFAULT_SIZE = {
    "box": (30.0, 30.0, 9.42),
    "meshbox": (30.0, 30.0, 9.42),
    "pyramid": (8.2, 8.2, 10.25),
    "meshpyr": (8.2, 8.2, 10.25),
    "base": (30.0, 30.0, 0.0),
    "wall": (0.0, 40.0, OUTER_WALL_HEIGHT),
    "teleporter": (0.5, 4.48, 20.16),
}
SOLIDS = tuple(DEFAULT_SIZE)

#: RGBA per kind, and per base team colour (1 red, 2 green, 3 blue, 4 purple)
COLOURS = {
    "ground": (96, 140, 80, 255),
    "outer_wall": (150, 150, 160, 255),
    "box": (170, 140, 100, 255),
    "pyramid": (80, 110, 190, 255),
    "wall": (150, 150, 160, 255),
    "teleporter": (230, 200, 60, 255),
    "base": (200, 200, 200, 255),
}
TEAM_COLOURS = {1: (200, 50, 50, 255), 2: (50, 170, 60, 255), 3: (60, 90, 210, 255), 4: (150, 60, 180, 255)}

#: properties each object kind understands (besides name/colour/material ones, which
#: only change looks and are ignored without a warning)
_GEOMETRY_PROPS = {"position", "pos", "size", "rotation", "rot", "flipz", "drivethrough", "passable", "border"}
_QUIET_PROPS = {
    "name", "color", "shootthrough", "matref", "texture", "texsize", "texoffset", "phydrv",
    "outside", "top", "bottom", "inside", "startside", "endside", "sides", "edge", "x+", "x-",
    "y+", "y-", "z+", "z-", "noclusters", "smoothbounce", "ricochet", "oldcolor", "diffuse",
    "ambient", "specular", "emission", "shininess", "notextures", "noculling", "nosorting",
    "nolighting", "drawshadow", "noshadow", "horizontal", "flagheight", "teamcolor",
}
#: nested blocks inside a mesh's drawinfo, which close with their own ``end``
_DRAWINFO_BLOCKS = {"lod", "matref"}


@dataclass
class BzwObject:
    """One object of the world file, in BZFlag units and frame (Z up)."""

    kind: str
    line: int
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    size: tuple[float, float, float] = (1.0, 1.0, 1.0)
    rotation: float = 0.0          # degrees about +z, counter-clockwise from above
    flipz: bool = False
    drivethrough: bool = False
    border: float = 1.12           # teleporters only
    color: int = 0                 # bases only: team 1..4


@dataclass
class BzwWorld:
    """A parsed world: its half-width, objects and the warnings met on the way."""

    path: Path
    size: float = WORLD_SIZE       # half-width: the world spans [-size, size] in x and y
    walls: bool = True             # BZFlag's outer walls
    wall_height: float = OUTER_WALL_HEIGHT   # the outer walls' height (options -set _wallHeight)
    size_from: str = ""            # what set ``size`` last ("line 3: world size 60"), for warnings
    objects: list[BzwObject] = field(default_factory=list)
    meshes: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)   # placed ``mesh`` objects
    warnings: list[str] = field(default_factory=list)
    #: what the file holds but the arena does not: kind -> lines ("sphere": [40, 52])
    left_out: dict[str, list[int]] = field(default_factory=dict)
    #: ``define`` blocks: name -> (line, body lines); the parsed bodies; group nesting
    defines: dict[str, tuple[int, list[str]]] = field(default_factory=dict)
    parsed: dict[str, "BzwWorld"] = field(default_factory=dict)
    depth: int = 0

    def leave_out(self, kind: str, line: int) -> None:
        self.left_out.setdefault(kind, []).append(line)

    def left_out_text(self) -> list[str]:
        """One phrase per kind: "41 mesh objects (lines 12, 40, ...)"."""
        out = []
        for kind, lines in sorted(self.left_out.items()):
            where = ", ".join(map(str, lines[:4])) + (", ..." if len(lines) > 4 else "")
            out.append(f"{len(lines)} {kind}{'s' if len(lines) != 1 else ''} (line{'s' if len(lines) != 1 else ''} "
                       f"{where})")
        return out

    def counts(self) -> dict[str, int]:
        """Objects per kind (meshbox counted as box, meshpyr as pyramid)."""
        out: dict[str, int] = {}
        for o in self.objects:
            k = {"meshbox": "box", "meshpyr": "pyramid"}.get(o.kind, o.kind)
            out[k] = out.get(k, 0) + 1
        return out


def _strip(raw: str) -> str:
    i = raw.find("#")
    return (raw if i < 0 else raw[:i]).strip()


def _numbers(path: Path, lineno: int, key: str, args: list[str], count: int) -> tuple[float, ...]:
    if len(args) < count:
        raise FormatError(f"{path}:{lineno}: '{key}' expects {count} number{'s' if count > 1 else ''}, "
                          f"got {len(args)}")
    try:
        vals = tuple(float(a) for a in args[:count])
    except ValueError:
        raise FormatError(f"{path}:{lineno}: '{key}' expects {count} numbers, got {' '.join(args)!r}") from None
    if not all(math.isfinite(v) for v in vals):
        raise FormatError(f"{path}:{lineno}: '{key}' must be finite numbers, got {' '.join(args)!r}")
    return vals


def parse_bzw(path: str | os.PathLike, text: str | None = None, defines: dict | None = None,
              depth: int = 0) -> BzwWorld:
    """Parse a ``.bzw`` file (or ``text`` named after ``path``) into a :class:`BzwWorld`.

    Raises FormatError naming the file and line for malformed input; unknown objects
    and properties become ``warnings`` (strings ``file:line: ...``).  ``defines`` and
    ``depth``: the group definitions seen so far and the nesting, when the body of a
    ``define`` is read for a ``group`` (formats/bzw_mesh.py).
    """
    path = Path(path)
    if text is None:
        text = _read_text(path)
    world = BzwWorld(path, depth=depth)
    if defines is not None:
        world.defines = defines
    st = _ParseState()
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = _strip(raw)
        if not line:
            continue
        words = line.split()
        key = words[0].lower()
        args = words[1:]
        if _inside_block(st, path, lineno, raw, words, key, args, world):
            continue
        if st.current is None and st.in_world is None:
            _open_block(st, path, lineno, words, key, args, world)
            continue
        if key == "end":
            if st.current is not None:
                _finish(path, st.current, world)
                st.current = None
            else:
                st.in_world = None
            continue
        if st.in_world is not None:
            _world_line(path, lineno, words, key, args, world)
            continue
        assert st.current is not None
        _object_line(path, lineno, words, key, args, st.current, world.warnings.append)
    _check_closed(path, st)
    return world


def _read_text(path: Path) -> str:
    """The file's text: UTF-8, else Latin-1."""
    data = read_input(path, "a .bzw file", limit=MAX_MODEL_BYTES)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")   # old maps are often Latin-1; keywords are ASCII


@dataclass
class _ParseState:
    """What parse_bzw has open while it reads the lines."""
    current: BzwObject | None = None       # a known object being read
    in_world: int | None = None            # line of an open ``world`` block
    skipping: tuple[str, int] | None = None  # an unknown object being skipped: (kind, line)
    skip_stack: list[str] = field(default_factory=list)   # drawinfo / lod / matref blocks inside it
    in_define: int | None = None
    options: list[tuple[int, str]] | None = None   # tokens of an open ``options`` block, with lines
    options_line: int = 0
    mesh: BzwMesh | BzwGroup | None = None   # an open ``mesh`` or ``group`` block
    define: tuple[str, list[str]] = ("", [])   # the open define's name and body lines


def _inside_block(st: _ParseState, path: Path, lineno: int, raw: str, words: list[str], key: str,
                  args: list[str], world: BzwWorld) -> bool:
    """Feed a line to an open define, mesh, group, options or skipped block; False when none is open."""
    if st.in_define is not None:
        if key == "enddef":
            world.defines[st.define[0]] = (st.in_define, st.define[1])
            st.in_define = None
        else:
            st.define[1].append(raw)
        return True
    if st.mesh is not None:
        done = (_group_line(path, lineno, key, args, st.mesh, world) if isinstance(st.mesh, BzwGroup)
                else _mesh_line(path, lineno, key, args, st.mesh, world))
        if done:
            st.mesh = None
        return True
    if st.options is not None:
        if key == "end" and not args:
            _apply_options(path, st.options_line, st.options, world)
            st.options = None
        else:
            st.options.extend((lineno, w) for w in words)
        return True
    if st.skipping is not None:
        # BZFlag's mesh drawinfo nests blocks that close with their own ``end``
        if key == "drawinfo" or (key in _DRAWINFO_BLOCKS and st.skip_stack):
            st.skip_stack.append(key)
        elif key == "end":
            if st.skip_stack:
                st.skip_stack.pop()
            else:
                st.skipping = None
        return True
    return False


def _open_block(st: _ParseState, path: Path, lineno: int, words: list[str], key: str, args: list[str],
                world: BzwWorld) -> None:
    """A line outside any block: it opens one (or is an error, or an unknown object skipped)."""
    if key == "end":
        raise FormatError(f"{path}:{lineno}: 'end' without an object to close")
    if key == "world":
        st.in_world = lineno
    elif key == "options":
        st.options, st.options_line = [(lineno, w) for w in args], lineno
    elif key in SOLIDS:
        if len(world.objects) >= MAX_OBJECTS:
            raise FormatError(f"{path}:{lineno}: more than {MAX_OBJECTS:,} objects (a world this tool reads "
                              f"has fewer)")
        st.current = BzwObject(key, lineno, size=DEFAULT_SIZE[key])
    elif key == "mesh":
        if len(world.meshes) >= MAX_OBJECTS:
            raise FormatError(f"{path}:{lineno}: more than {MAX_OBJECTS:,} meshes (a world this tool reads "
                              f"has fewer)")
        st.mesh = BzwMesh(lineno)
    elif key == "group":
        st.mesh = BzwGroup(lineno, " ".join(args).lower())
    elif key == "define":
        st.in_define, st.define = lineno, (" ".join(args).lower(), [])
    elif key in ("enddef",):
        raise FormatError(f"{path}:{lineno}: 'enddef' without 'define'")
    else:
        st.skipping = (key, lineno)
        st.skip_stack = []
        if key in _SOLID_UNSUPPORTED:
            world.leave_out(key, lineno)
        world.warnings.append(f"{path}:{lineno}: unknown or unsupported object '{words[0]}' skipped")


def _world_line(path: Path, lineno: int, words: list[str], key: str, args: list[str], world: BzwWorld) -> None:
    """A property inside ``world``: its size and walls; the rest ignored."""
    if key == "size":
        (s,) = _numbers(path, lineno, "size", args, 1)
        if s <= 0:
            raise FormatError(f"{path}:{lineno}: world 'size' must be positive, got {s:g}")
        _set_size(world, s, lineno, f"world size {s:g}")
    elif key == "nowalls":
        world.walls = False
    elif key not in _QUIET_PROPS:
        world.warnings.append(f"{path}:{lineno}: world property '{words[0]}' ignored")


def _object_line(path: Path, lineno: int, words: list[str], key: str, args: list[str], current: BzwObject,
                 warn: Callable[[str], None]) -> None:
    """A property of the solid object being read."""
    if key in ("position", "pos"):
        current.position = _numbers(path, lineno, key, args, 3)  # type: ignore[assignment]
    elif key == "size":
        current.size = _numbers(path, lineno, key, args, 3)  # type: ignore[assignment]
    elif key in ("rotation", "rot"):
        (current.rotation,) = _numbers(path, lineno, key, args, 1)
    elif key == "flipz":
        current.flipz = True
    elif key in ("drivethrough", "passable"):
        current.drivethrough = True
    elif key == "border" and current.kind == "teleporter":
        (current.border,) = _numbers(path, lineno, key, args, 1)
    elif key == "color" and current.kind == "base":
        (c,) = _numbers(path, lineno, key, args, 1)
        current.color = int(c)
    elif key in _QUIET_PROPS:
        pass
    else:
        warn(f"{path}:{lineno}: {current.kind} property '{words[0]}' ignored")


def _check_closed(path: Path, st: _ParseState) -> None:
    """At the end of the file: an error naming the first block still open."""
    current, skipping, mesh = st.current, st.skipping, st.mesh
    for open_line, what in ((current.line if current else None, current.kind if current else ""),
                            (st.in_world, "world"),
                            (skipping[1] if skipping else None, skipping[0] if skipping else ""),
                            (st.in_define, "define"), (st.options_line if st.options is not None else None, "options"),
                            (mesh.line if mesh is not None else None,
                             "group" if isinstance(mesh, BzwGroup) else "mesh")):
        if open_line is not None:
            closer = "enddef" if what == "define" else "end"
            raise FormatError(f"{path}:{open_line}: '{what}' is never closed (expected '{closer}' "
                              f"before the end of the file)")


#: solid objects this reader does not build: counted in what the import leaves out
_SOLID_UNSUPPORTED = {"arc", "cone", "sphere", "tetra"}


def _set_size(world: BzwWorld, half: float, line: int, said: str) -> None:
    """The world's half-width, set by ``world size`` or ``_worldSize``: the later wins,
    as in bzfs (both set one variable while the file is read); say so if they differ."""
    if world.size_from and not math.isclose(half, world.size, rel_tol=1e-9):
        world.warnings.append(f"{world.path}:{line}: {said} replaces {world.size_from}: the world is "
                              f"{2 * half:g} x {2 * half:g} m (the later setting wins, as in bzfs)")
    world.size, world.size_from = half, f"{said} (line {line})"


#: BZDB variables that shape the arena, read from ``options -set NAME VALUE``
_GEOMETRY_VARS = ("_worldsize", "_wallheight")


def _apply_options(path: Path, line: int, tokens: list[tuple[int, str]], world: BzwWorld) -> None:
    """Read an ``options`` block's tokens (bzfs command-line arguments)."""
    ignored: list[str] = []
    i = 0
    while i < len(tokens):
        at, tok = tokens[i]
        if tok.lower() == "-set" and i + 2 < len(tokens) and tokens[i + 1][1].lower() in _GEOMETRY_VARS:
            name, value = tokens[i + 1][1], tokens[i + 2][1]
            try:
                v = float(value)
            except ValueError:
                v = math.nan
            wall = name.lower() == "_wallheight"   # 0: no outer walls, as bzfs builds them
            if not math.isfinite(v) or v < 0 or (v == 0 and not wall):
                raise FormatError(f"{path}:{tokens[i + 2][0]}: options -set {name} expects a "
                                  f"{'number >= 0' if wall else 'positive number'} (metres), got {value!r}")
            if name.lower() == "_worldsize":
                _set_size(world, v / 2, at, f"options -set {name} {value}")
            else:
                world.wall_height = v
                world.walls = world.walls and v > 0
            i += 3
            continue
        if tok.lower() == "-set" and i + 2 < len(tokens):
            ignored.append(f"-set {tokens[i + 1][1]} {tokens[i + 2][1]}")
            i += 3
            continue
        ignored.append(tok)
        i += 1
    if ignored:
        shown = " ".join(ignored)
        if len(shown) > 120:
            shown = shown[:117] + "..."
        world.warnings.append(f"{path}:{line}: options that do not change the arena ignored: {shown}")


def _finish(path: Path, obj: BzwObject, world: BzwWorld) -> None:
    sx, sy, sz = obj.size
    if obj.kind in ("box", "meshbox", "base", "teleporter") and (sx < 0 or sy < 0 or sz < 0):
        raise FormatError(f"{path}:{obj.line}: {obj.kind} 'size' must not be negative, got {sx:g} {sy:g} {sz:g}")
    if obj.kind == "teleporter" and obj.border < 0:
        raise FormatError(f"{path}:{obj.line}: teleporter 'border' must not be negative, got {obj.border:g}")
    if obj.kind == "teleporter" and obj.border == 0:
        return   # no frame: nothing solid (tanks drive through the field), as in BZFlag
    if obj.drivethrough:
        world.leave_out(f"drivethrough {obj.kind}", obj.line)
        world.warnings.append(f"{path}:{obj.line}: {obj.kind} is drivethrough: left out (tanks pass through it)")
        return
    flat = (sy == 0 or sz == 0) if obj.kind == "wall" else (sx == 0 or sy == 0 or sz == 0)
    if flat and obj.kind not in ("base", "teleporter"):
        world.warnings.append(f"{path}:{obj.line}: {obj.kind} has zero size: left out")
        return
    world.objects.append(obj)


# ---------------------------------------------------------------------------
# geometry (BZFlag frame: Z up)

_BOX_FACES = np.array([
    [0, 2, 1], [0, 3, 2],          # bottom (z = 0), facing down
    [4, 5, 6], [4, 6, 7],          # top, facing up
    [0, 1, 5], [0, 5, 4],          # -y side
    [1, 2, 6], [1, 6, 5],          # +x side
    [2, 3, 7], [2, 7, 6],          # +y side
    [3, 0, 4], [3, 4, 7],          # -x side
], dtype=np.int64)


def _place(local: np.ndarray, obj_pos: tuple[float, float, float], degrees: float) -> np.ndarray:
    """Rotate (n, 3) local points about z by ``degrees`` (counter-clockwise) and move them."""
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    out = np.empty_like(local)
    out[:, 0] = c * local[:, 0] - s * local[:, 1] + obj_pos[0]
    out[:, 1] = s * local[:, 0] + c * local[:, 1] + obj_pos[1]
    out[:, 2] = local[:, 2] + obj_pos[2]
    return out


def box_mesh(hx: float, hy: float, z0: float, z1: float) -> tuple[np.ndarray, np.ndarray]:
    """(8, 3) vertices and (12, 3) outward-wound faces of an axis-aligned local box."""
    v = np.array([[-hx, -hy, z0], [hx, -hy, z0], [hx, hy, z0], [-hx, hy, z0],
                  [-hx, -hy, z1], [hx, -hy, z1], [hx, hy, z1], [-hx, hy, z1]], dtype=np.float64)
    return v, _BOX_FACES.copy()


def pyramid_mesh(hx: float, hy: float, h: float) -> tuple[np.ndarray, np.ndarray]:
    """(5, 3) vertices and (6, 3) outward faces: base rectangle at z=0, apex at z=h
    (h < 0: the apex points down, the rectangle is the top)."""
    v = np.array([[-hx, -hy, 0.0], [hx, -hy, 0.0], [hx, hy, 0.0], [-hx, hy, 0.0], [0.0, 0.0, h]])
    f = np.array([[0, 2, 1], [0, 3, 2], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]], dtype=np.int64)
    if h < 0:
        f = f[:, ::-1].copy()       # mirrored in z: keep the faces wound outwards
    return v, f


def object_mesh(obj: BzwObject) -> tuple[np.ndarray, np.ndarray]:
    """World-placed (BZFlag frame) vertices and faces of one object."""
    sx, sy, sz = obj.size
    if obj.kind in ("box", "meshbox", "base"):
        if obj.kind == "base" and sz <= 0:
            v = np.array([[-sx, -sy, PAD_LIFT], [sx, -sy, PAD_LIFT], [sx, sy, PAD_LIFT], [-sx, sy, PAD_LIFT]])
            f = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
        else:
            v, f = box_mesh(sx, sy, 0.0, sz)
    elif obj.kind in ("pyramid", "meshpyr"):
        h = -abs(sz) if (obj.flipz or sz < 0) else sz
        v, f = pyramid_mesh(sx, sy, h)
        if h < 0:
            v[:, 2] += abs(h)       # flipped: it still stands on its position
    elif obj.kind == "wall":
        # a plane of zero thickness, as BZFlag's WallObstacle; the wall extraction
        # treats an open sheet as a thin wall (two walls, opposite normals)
        v = np.array([[0.0, -sy, 0.0], [0.0, sy, 0.0], [0.0, sy, sz], [0.0, -sy, sz]])
        f = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
    elif obj.kind == "teleporter":
        b = obj.border
        d = sy + 1.5 * b            # post centres (BZFlag: breadth - border/2, breadth = sy + 2 border)
        parts = []
        for cy in (-d, d):
            pv, pf = box_mesh(b / 2, b / 2, 0.0, sz)
            pv[:, 1] += cy
            parts.append((pv, pf))
        parts.append(box_mesh(b / 2, sy + 2 * b, sz, sz + b))
        v, f = _join(parts)
    else:  # pragma: no cover - parse_bzw only keeps the kinds above
        raise ValueError(obj.kind)
    return _place(v, obj.position, obj.rotation), f


def _join(parts: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    verts, faces, n = [], [], 0
    for v, f in parts:
        verts.append(v)
        faces.append(f + n)
        n += len(v)
    if not verts:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(verts), np.concatenate(faces)


def world_meshes(world: BzwWorld) -> dict[str, tuple[np.ndarray, np.ndarray, tuple[int, int, int, int]]]:
    """Named (vertices, faces, rgba) groups of the whole world in BZFlag's frame:
    ``ground``, ``outer_walls`` and one group per object kind present."""
    s = world.size
    groups: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    ground = (np.array([[-s, -s, 0.0], [s, -s, 0.0], [s, s, 0.0], [-s, s, 0.0]]),
              np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64))
    out: dict[str, tuple[np.ndarray, np.ndarray, tuple[int, int, int, int]]] = {
        "ground": (*ground, COLOURS["ground"])}
    if world.walls:
        t = OUTER_WALL_THICKNESS
        walls = []
        for cx, cy, hx, hy in ((0.0, -s - t / 2, s + t, t / 2), (0.0, s + t / 2, s + t, t / 2),
                               (-s - t / 2, 0.0, t / 2, s), (s + t / 2, 0.0, t / 2, s)):
            v, f = box_mesh(hx, hy, 0.0, world.wall_height)
            v[:, 0] += cx
            v[:, 1] += cy
            walls.append((v, f))
        out["outer_walls"] = (*_join(walls), COLOURS["outer_wall"])
    bases: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}
    for obj in world.objects:
        if obj.kind == "base":
            bases.setdefault(obj.color, []).append(object_mesh(obj))
            continue
        kind = {"meshbox": "box", "meshpyr": "pyramid"}.get(obj.kind, obj.kind)
        groups.setdefault(kind, []).append(object_mesh(obj))
    for kind, parts in groups.items():
        out[kind + "es" if kind == "box" else kind + "s"] = (*_join(parts), COLOURS[kind])
    if world.meshes:
        out["meshes"] = (*_join(world.meshes), COLOURS["box"])
    for team, parts in sorted(bases.items()):
        out[f"bases_team{team}"] = (*_join(parts), TEAM_COLOURS.get(team, COLOURS["base"]))
    return out


def load_scene(path: str | os.PathLike, warn: Callable[[str], None] | None = None):
    """Read a ``.bzw`` file as a ``trimesh.Scene`` in BZFlag's frame (Z up, 1 unit = 1 m).

    Each warning (unknown object or property, skipped drivethrough object) is passed
    to ``warn``.  Raises FormatError for malformed files.
    """
    import trimesh

    world = parse_bzw(path)
    if warn is not None:
        for w in world.warnings[:MAX_WARNINGS]:
            warn(w)
        if len(world.warnings) > MAX_WARNINGS:
            warn(f"{path}: {len(world.warnings) - MAX_WARNINGS:,} more warnings like these not shown")
    scene = trimesh.Scene()
    for name, (v, f, rgba) in world_meshes(world).items():
        mesh = trimesh.Trimesh(vertices=v, faces=f, process=False)
        mesh.visual.face_colors = np.tile(np.array(rgba, dtype=np.uint8), (len(f), 1))
        scene.add_geometry(mesh, geom_name=name, node_name=name)
    scene.metadata["left_out"] = world.left_out_text()   # the import's "left out" line says them
    return scene
