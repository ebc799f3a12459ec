"""2D floor plans (``.dxf``, ``.svg``) as arena models.

Every line, polyline (open or closed), arc, circle and curve of the drawing is the
centre line of a wall ``thickness`` thick and ``height`` high: the lines are noded
and merged where they meet end to end (so corners are mitred, not notched), buffered
by half the thickness with flat ends, and the union is extruded.  A closed shape with
no other line inside it is filled solid (a pillar), except the largest closed shape
(the outer wall).  A floor
rectangle covers the walls' bounding box.  DXF text, points and hatches are not
lines and are ignored.

Coordinates: the drawing's (x, y) become the arena's (x, z), in drawing units (use
``--scale`` for millimetres, pixels, ...), so ``walls.txt`` holds the drawing's own
numbers.  The scene is returned Z-up (plan y stored as -y) and
:func:`tanktool.formats.models.load_scene` turns it upright like any Z-up model.

trimesh reads both formats into 2D paths: DXF with its own reader (ASCII DXF;
LINE, LWPOLYLINE, POLYLINE, ARC, CIRCLE, SPLINE, ...), SVG through ``svg.path`` and
``lxml``.  Before trimesh sees a file it is checked here so that a malformed one is
refused with its line: DXF group codes and numbers, SVG's XML and the numbers of
``line``/``rect``/``circle``/``polyline``/``polygon`` elements.
"""

from __future__ import annotations

import io
import math
import os
import re
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import FormatError
from .bundle import read_input
from .limits import MAX_MODEL_BYTES, MAX_OBJECTS

#: points of all the drawing's lines and sampled curves together
MAX_PLAN_POINTS = 2_000_000
#: pairs of segments with overlapping boxes a plan may hold (the cost of noding the
#: lines where they cross): a base plus a share for each segment
MAX_OVERLAPS_BASE = 1_000_000
MAX_OVERLAPS_PER_SEGMENT = 16
#: a coordinate of a drawing, in its own units (a 2 km town drawn in millimetres is
#: 2e6): beyond this (or inf) it is damage, refused with its line
MAX_DRAWING_COORDINATE = 1e9
#: how many wall thicknesses a drawing may be across
MAX_THICKNESSES = 1e6

#: extensions handled here
PLAN_EXTENSIONS = {".dxf", ".svg"}
DEFAULT_WALL_HEIGHT = 3.0
DEFAULT_WALL_THICKNESS = 0.5
#: longest a mitred corner may stick out, in wall half-thicknesses (sharper corners are bevelled)
MITRE_LIMIT = 4.0

WALL_RGBA = (170, 165, 150, 255)
FLOOR_RGBA = (110, 130, 100, 255)

_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


# ---------------------------------------------------------------- checks with line numbers

def check_dxf(path: Path, data: bytes) -> None:
    """Refuse a malformed ASCII DXF with the line of the first bad group.

    A DXF file is pairs of lines: an integer group code, then its value.  Codes
    10-59 and 140-147 carry numbers (coordinates, radii, angles)."""
    if data.startswith(b"AutoCAD Binary DXF"):
        raise FormatError(f"{path}: byte 0: binary DXF is not supported; save the drawing as ASCII DXF")
    text = data.decode("utf-8", "replace")
    lines = text.splitlines()
    if not any(line.strip() for line in lines):
        raise FormatError(f"{path}: empty file, expected an ASCII DXF drawing")
    for i in range(0, len(lines), 2):
        code_s = lines[i].strip()
        try:
            code = int(code_s)
        except ValueError:
            raise FormatError(f"{path}:{i + 1}: expected a DXF group code (an integer), got {code_s[:40]!r}") from None
        if i + 1 >= len(lines):
            raise FormatError(f"{path}:{i + 1}: group code {code} has no value line (file cut short?)")
        value = lines[i + 1].strip()
        if (10 <= code <= 59 or 140 <= code <= 147) and not _NUMBER.match(value):
            raise FormatError(f"{path}:{i + 2}: group code {code} expects a number, got {value[:40]!r}")
        if 10 <= code <= 39 and not abs(float(value)) <= MAX_DRAWING_COORDINATE:   # inf and nan fail too
            raise FormatError(f"{path}:{i + 2}: group code {code}: coordinate {value[:40]} is beyond "
                              f"{MAX_DRAWING_COORDINATE:g} drawing units from the origin")
        if code == 0 and value == "EOF":
            return


_SVG_NUMBERS = {
    "line": ("x1", "y1", "x2", "y2"),
    "rect": ("x", "y", "width", "height"),
    "circle": ("cx", "cy", "r"),
    "ellipse": ("cx", "cy", "rx", "ry"),
}
_ANY_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
_SVG_UNIT = re.compile(r"(px|mm|cm|in|pt|pc|%)$")
_SVG_LENGTH = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?(px|mm|cm|in|pt|pc|%)?$")


def check_svg(path: Path, data: bytes) -> None:
    """Refuse malformed SVG (XML errors, non-numeric coordinates) with the line."""
    from lxml import etree

    try:
        root = etree.fromstring(data, parser=etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError as e:
        line = e.position[0] if e.position else getattr(e, "lineno", 0)
        msg = " ".join(str(e.msg).split())  # lxml's messages run over several lines
        raise FormatError(f"{path}:{line}: not well-formed SVG/XML: {msg}") from None
    if not isinstance(root.tag, str) or etree.QName(root).localname != "svg":
        raise FormatError(f"{path}:{root.sourceline}: expected an <svg> document")
    for el in root.iter():
        if not isinstance(el.tag, str):
            continue
        tag = etree.QName(el).localname
        for attr, v in el.attrib.items():   # path data, transforms, viewBox: no number beyond the limit
            far = next((m.group() for m in _ANY_NUMBER.finditer(v)
                        if not abs(float(m.group())) <= MAX_DRAWING_COORDINATE), None)
            if far is not None:
                raise FormatError(f"{path}:{el.sourceline}: <{tag}> {etree.QName(attr).localname}: {far[:40]} is "
                                  f"beyond {MAX_DRAWING_COORDINATE:g} drawing units from the origin")
        for attr in _SVG_NUMBERS.get(tag, ()):
            v = el.get(attr)
            if v is not None and not _SVG_LENGTH.match(v.strip()):
                raise FormatError(f"{path}:{el.sourceline}: <{tag}> {attr} expects a number, got {v[:40]!r}")
            if v is not None and not abs(float(_SVG_UNIT.sub("", v.strip()))) <= MAX_DRAWING_COORDINATE:
                raise FormatError(f"{path}:{el.sourceline}: <{tag}> {attr} {v[:40]} is beyond "
                                  f"{MAX_DRAWING_COORDINATE:g} drawing units from the origin")
        if tag in ("polyline", "polygon"):
            pts = el.get("points", "")
            nums = [p for p in re.split(r"[\s,]+", pts.strip()) if p]
            bad = next((p for p in nums if not _NUMBER.match(p)), None)
            if bad is not None:
                raise FormatError(f"{path}:{el.sourceline}: <{tag}> points expects numbers, got {bad[:40]!r}")
            far = next((p for p in nums if not abs(float(p)) <= MAX_DRAWING_COORDINATE), None)
            if far is not None:
                raise FormatError(f"{path}:{el.sourceline}: <{tag}> points: {far[:40]} is beyond "
                                  f"{MAX_DRAWING_COORDINATE:g} drawing units from the origin")
            if len(nums) % 2:
                raise FormatError(f"{path}:{el.sourceline}: <{tag}> points has an odd count of numbers ({len(nums)})")


# ---------------------------------------------------------------- reading

def read_plan(path: str | os.PathLike) -> list[np.ndarray]:
    """The drawing's lines as a list of (k, 2) polylines in its own (x, y), k >= 2
    (closed ones end where they start).  Raises FormatError for unreadable files and
    drawings without lines."""
    import trimesh

    path = Path(path)
    fmt = path.suffix.lower()[1:]
    data = read_input(path, "a floor plan", limit=MAX_MODEL_BYTES)
    if fmt == "dxf":
        check_dxf(path, data)
    elif fmt == "svg":
        check_svg(path, data)
    else:
        raise FormatError(f"{path}: not a floor plan (expected .dxf or .svg)")
    try:
        drawing = trimesh.load(io.BytesIO(data), file_type=fmt)
    except FormatError:
        raise
    except ImportError as e:
        raise FormatError(f"{path}: reading .{fmt} needs a missing package ({e.name}); "
                          f"reinstall tanktool with its dependencies") from None
    except Exception as e:  # trimesh raises many kinds for bad drawings
        raise FormatError(f"{path}: cannot read as .{fmt}: {' '.join(str(e).split())[:300]}") from None
    lines: list[np.ndarray] = []
    entities = getattr(drawing, "entities", ())
    if len(entities) > MAX_OBJECTS:
        raise FormatError(f"{path}: {len(entities):,} lines and shapes, more than the {MAX_OBJECTS:,} this tool reads")
    vertices = np.asarray(getattr(drawing, "vertices", np.zeros((0, 2))), dtype=np.float64)
    if len(vertices) and not np.isfinite(vertices).all():
        raise FormatError(f"{path}: the drawing has non-finite coordinates")
    # trimesh samples curves finely enough for a sagitta of 5 % of ``scale`` units; with
    # its default of 1 unit a circle of radius 1e7 would become 1.2e9 points.  Tie it
    # to the drawing's size instead (unchanged for drawings up to 100 units across; at
    # most about 12,600 points per curve)
    extent = float(np.ptp(vertices, axis=0).max()) if len(vertices) else 0.0
    scale = max(1.0, extent / 100.0)
    total = 0
    for entity in entities:
        if type(entity).__name__ == "Text":
            continue
        try:
            pts = np.asarray(entity.discrete(vertices, scale=scale), dtype=np.float64)
        except (MemoryError, RecursionError):
            raise FormatError(f"{path}: a {type(entity).__name__.lower()} cannot be sampled (too large)") from None
        except Exception:  # an entity trimesh cannot sample (degenerate arc, ...)
            continue
        total += len(pts)
        if total > MAX_PLAN_POINTS:
            raise FormatError(f"{path}: the drawing's lines and curves make more than {MAX_PLAN_POINTS:,} points")
        if pts.ndim != 2 or pts.shape[0] < 2 or pts.shape[1] < 2:
            continue
        pts = pts[:, :2]
        if not np.isfinite(pts).all():
            raise FormatError(f"{path}: a {type(entity).__name__.lower()} has non-finite coordinates")
        if np.ptp(pts, axis=0).max() > 0:
            lines.append(pts)
    if not lines:
        raise FormatError(f"{path}: the drawing has no lines or polylines to make walls of")
    return lines


# ---------------------------------------------------------------- geometry

def plan_walls(lines: list[np.ndarray], thickness: float):
    """The walls' footprint: a shapely (Multi)Polygon, the union of every line
    buffered by ``thickness / 2`` with flat ends and mitred corners."""
    import shapely

    if not (math.isfinite(thickness) and thickness > 0):
        raise FormatError(f"--wall-thickness must be a positive number, got {thickness}")
    pts = np.concatenate(lines)
    extent = float(np.ptp(pts, axis=0).max())
    if extent > MAX_THICKNESSES * thickness:
        # GEOS loses itself (it hangs) on walls this thin for their length, and no
        # arena is a million walls wide: a unit mistake
        raise FormatError(f"the drawing is {extent:.4g} units across, more than {MAX_THICKNESSES:,.0f} wall "
                          f"thicknesses ({thickness:g}): wrong units? (--wall-thickness is in drawing units)")
    # the same line drawn twice is one wall: GEOS nodes 1,000 copies of a square in
    # 900 MB, so copies (either direction) go before the union
    seen: set[bytes] = set()
    unique = []
    for ln in lines:
        key = min(ln.tobytes(), ln[::-1].tobytes())
        if key not in seen:
            seen.add(key)
            unique.append(ln)
    lines = unique
    check_overlaps(lines)
    geoms = [shapely.LineString(ln) for ln in lines]
    # noding splits lines where they cross; merging joins pieces that meet end to end,
    # so separate LINE entities around a corner are mitred like one polyline
    merged = shapely.get_parts(shapely.line_merge(shapely.union_all(geoms)))
    # trimesh samples a circle into ~250 points; a sagitta of 1/20 of the thickness is
    # invisible in the wall and keeps the wall list short.  Piece by piece, then one
    # union: GEOS buffers a network of thousands of lines as a whole 5x slower
    merged = shapely.simplify(merged, thickness / 20.0, preserve_topology=True)
    pieces = shapely.buffer(merged, thickness / 2.0, cap_style="flat", join_style="mitre", mitre_limit=MITRE_LIMIT)
    fills = solid_shapes(lines, geoms, thickness)
    walls = shapely.union_all([*pieces, *fills])
    walls = shapely.make_valid(walls)
    polys = [p for p in shapely.get_parts(walls) if p.geom_type == "Polygon" and p.area > 0]
    if not polys:
        raise FormatError("the drawing's lines make no wall area")
    return shapely.multipolygons(polys) if len(polys) > 1 else polys[0]


def overlap_budget(segments: int) -> int:
    """Pairs of segments whose boxes overlap that a plan of ``segments`` may hold."""
    return MAX_OVERLAPS_BASE + MAX_OVERLAPS_PER_SEGMENT * segments


def check_overlaps(lines: list[np.ndarray]) -> int:
    """Count the pairs of segments whose bounding boxes overlap (the work GEOS does to
    node the lines where they cross), stopping as soon as there are more than
    :func:`overlap_budget`: FormatError then.  A drawn plan's walls meet at their ends
    (a few pairs a segment); 30,000 random lines across a page overlap 10^8 times and
    kept GEOS busy for minutes.  The count runs in slices of the segments small
    enough that one slice's answer stays under 8 M pairs (128 MB)."""
    import shapely

    a = np.concatenate([ln[:-1, :2] for ln in lines])
    b = np.concatenate([ln[1:, :2] for ln in lines])
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    boxes = shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])
    n = len(boxes)
    budget = overlap_budget(n)
    tree = shapely.STRtree(boxes)
    step = max(1, min(4096, 8_000_000 // max(n, 1)))
    total = 0
    for start in range(0, n, step):
        total += len(tree.query(boxes[start:start + step])[0])
        if total > budget:
            raise FormatError(f"the drawing's {n:,} segments cross or overlap more than {budget:,} times "
                              f"(the limit: {MAX_OVERLAPS_BASE:,} + {MAX_OVERLAPS_PER_SEGMENT} a segment): "
                              f"not a floor plan? draw walls that meet at their ends")
    return total


def solid_shapes(lines: list[np.ndarray], geoms: list, thickness: float) -> list:
    """Closed shapes to fill: those with no other line inside them (a pillar, a block),
    except the largest closed shape (the arena's outer wall stays a ring).  A closed
    line has no door, so what it encloses could never be reached anyway.

    One spatial index query for all of them (a plan with 800 pillars and 600 lines
    asked 480,000 intersection questions one by one)."""
    import shapely

    closed = [i for i, ln in enumerate(lines) if len(ln) >= 4 and np.allclose(ln[0], ln[-1])]
    if len(closed) < 2:
        return []            # a lone closed shape is the largest: it stays a ring
    polys = shapely.make_valid(np.array([shapely.Polygon(lines[i]) for i in closed], dtype=object))
    areas = shapely.area(polys)
    largest = int(np.argmax(areas))
    inner = shapely.buffer(polys, -thickness / 2.0)
    hit_shape, hit_line = shapely.STRtree(geoms).query(inner, predicate="intersects")
    encloses = np.zeros(len(closed), dtype=bool)
    own = np.asarray(closed)[hit_shape]
    encloses[hit_shape[hit_line != own]] = True   # another wall inside: a walled yard, keep it a ring
    keep = (areas > 0) & ~encloses
    keep[largest] = False
    return list(polys[keep])


def extrude(footprint, height: float) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) vertices and (m, 3) outward faces of ``footprint`` (a shapely polygon or
    multipolygon in (x, y)) extruded from z = 0 to ``height``: a closed solid whose
    side quads follow every ring (holes included)."""
    import shapely

    verts: list[np.ndarray] = []
    faces: list[np.ndarray] = []
    n = 0
    for poly in shapely.get_parts(footprint):
        poly = shapely.orient_polygons(poly) if hasattr(shapely, "orient_polygons") else \
            shapely.geometry.polygon.orient(poly, 1.0)
        tris = shapely.get_parts(shapely.constrained_delaunay_triangles(poly))
        tris = tris[shapely.area(tris) > 0]
        if len(tris):
            # every triangle at once: its first 3 ring points, made counter-clockwise
            # from above so that the top faces up
            c = shapely.get_coordinates(tris).reshape(len(tris), 4, 2)[:, :3]
            cw = ((c[:, 1, 0] - c[:, 0, 0]) * (c[:, 2, 1] - c[:, 0, 1])
                  - (c[:, 1, 1] - c[:, 0, 1]) * (c[:, 2, 0] - c[:, 0, 0])) < 0
            c[cw] = c[cw, ::-1]
            k = len(c)
            top = np.concatenate([c, np.full((k, 3, 1), height)], axis=2).reshape(-1, 3)
            bottom = np.concatenate([c[:, ::-1], np.zeros((k, 3, 1))], axis=2).reshape(-1, 3)
            verts += [top, bottom]
            idx = n + 3 * np.arange(k)[:, None] + np.arange(3)[None, :]
            faces += [idx, idx + 3 * k]
            n += 6 * k
        # exterior counter-clockwise, holes clockwise: the solid is on the left of each
        # ring, so (p0, q0, q1) with the ring's direction faces outwards
        for ring in (poly.exterior, *poly.interiors):
            c = np.asarray(ring.coords)[:, :2]
            p, q = c[:-1], c[1:]
            k = len(p)
            quad = np.concatenate([
                np.column_stack([p, np.zeros(k)]), np.column_stack([q, np.zeros(k)]),
                np.column_stack([q, np.full(k, height)]), np.column_stack([p, np.full(k, height)])])
            idx = n + np.arange(k)
            verts.append(quad)
            faces.append(np.column_stack([idx, idx + k, idx + 2 * k]))
            faces.append(np.column_stack([idx, idx + 2 * k, idx + 3 * k]))
            n += 4 * k
    if not verts:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(verts), np.concatenate(faces).astype(np.int64)


#: what load_scene reports to its ``progress`` callback, in order
PLAN_STAGES = ("plan lines", "plan walls", "plan solid")


def load_scene(path: str | os.PathLike, wall_height: float = DEFAULT_WALL_HEIGHT,
               wall_thickness: float = DEFAULT_WALL_THICKNESS, progress: Callable[[str], None] | None = None):
    """Read a .dxf/.svg floor plan as a Z-up ``trimesh.Scene``: ``walls`` (the
    extruded lines) and ``floor`` (their bounding rectangle at z = 0).  ``progress``
    is called with each of ``PLAN_STAGES`` as it is done (big plans take a while)."""
    import trimesh

    path = Path(path)
    if not (math.isfinite(wall_height) and wall_height > 0):
        raise FormatError(f"--wall-height must be a positive number of metres, got {wall_height}")
    lines = read_plan(path)
    if progress:
        progress(PLAN_STAGES[0])
    try:
        footprint = plan_walls(lines, wall_thickness)
    except FormatError as e:
        raise FormatError(f"{path}: {e}") from None
    if progress:
        progress(PLAN_STAGES[1])
    # plan (x, y) must end up as world (x, z); the Z-up conversion maps y to -z
    v, f = extrude(footprint, wall_height)
    if progress:
        progress(PLAN_STAGES[2])
    v[:, 1] *= -1.0
    f = f[:, ::-1].copy()                 # the mirror flips the winding back outwards
    x0, y0, x1, y1 = footprint.bounds
    floor_v = np.array([[x0, -y0, 0.0], [x1, -y0, 0.0], [x1, -y1, 0.0], [x0, -y1, 0.0]])
    floor_f = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
    if np.cross(floor_v[1] - floor_v[0], floor_v[2] - floor_v[0])[2] < 0:
        floor_f = floor_f[:, ::-1].copy()  # facing up (+z)
    scene = trimesh.Scene()
    for name, (vv, ff, rgba) in (("floor", (floor_v, floor_f, FLOOR_RGBA)), ("walls", (v, f, WALL_RGBA))):
        mesh = trimesh.Trimesh(vertices=vv, faces=ff, process=False)
        mesh.visual.face_colors = np.tile(np.array(rgba, dtype=np.uint8), (len(ff), 1))
        scene.add_geometry(mesh, geom_name=name, node_name=name)
    return scene
