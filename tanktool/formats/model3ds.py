"""What a 3D Studio (.3ds) file holds, as :func:`tanktool.formats.threeds.read_3ds`
returns it: materials (colours, texture maps), triangle mesh objects in the file's own
axes (Z up) and the keyframer's object nodes."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: colour of faces that have no material (neutral grey, opaque), RGBA uint8
DEFAULT_COLOR = (128, 128, 128, 255)


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


# Shared read-only defaults: a file made of thousands of empty objects must not cost
# four fresh arrays each (memory stays proportional to the file, see the fuzz test).
_NO_VERTICES = _frozen(np.zeros((0, 3)))
_NO_FACES = _frozen(np.zeros((0, 3), dtype=np.int32))
_NO_FLAGS = _frozen(np.zeros(0, dtype=np.uint16))
_NO_MATERIALS = _frozen(np.zeros(0, dtype=np.int32))
_IDENTITY = _frozen(np.eye(4))


@dataclass(slots=True)
class TextureMap:
    """A texture map of a material: image file name and strength (0..1)."""

    kind: str
    file: str | None = None
    strength: float | None = None


@dataclass(slots=True)
class Material:
    """One 0xAFFF material entry.  Colours are RGB floats 0..1; percentages are
    given as fractions (``transparency`` 0 = opaque, 1 = invisible)."""

    name: str
    ambient: tuple[float, float, float] | None = None
    diffuse: tuple[float, float, float] | None = None
    specular: tuple[float, float, float] | None = None
    shininess: float | None = None
    shininess_strength: float | None = None
    transparency: float = 0.0
    two_sided: bool = False
    maps: dict[str, TextureMap] = field(default_factory=dict)
    offset: int = 0

    @property
    def texture(self) -> str | None:
        """File name of the diffuse texture map, if any."""
        m = self.maps.get("diffuse")
        return m.file if m else None

    def rgba(self) -> tuple[int, int, int, int]:
        """Diffuse colour with alpha from the transparency, as uint8 RGBA."""
        if self.diffuse is None:
            rgb = DEFAULT_COLOR[:3]
        else:
            rgb = tuple(int(round(float(np.clip(c, 0.0, 1.0)) * 255)) for c in self.diffuse)
        alpha = int(round((1.0 - float(np.clip(self.transparency, 0.0, 1.0))) * 255))
        return (rgb[0], rgb[1], rgb[2], alpha)


@dataclass(slots=True)
class MeshObject:
    """One triangle mesh (a 0x4100 inside a 0x4000 named object).

    Attributes
    ----------
    vertices : (n, 3) float64, in the file's axes (Z up), master scale NOT applied
    faces : (m, 3) int32 indices into ``vertices``
    face_flags : (m,) uint16 edge-visibility / wrap flags as stored
    face_material : (m,) int32 index into ``Model3DS.materials``, -1 for none
    uv : (k, 2) float64 texture coordinates (k is normally n) or None
    smoothing : (m,) uint32 smoothing-group bit masks or None
    matrix : (4, 4) float64 object matrix from 0x4160 (columns: x, y, z axes and
        origin).  The vertices are already in world space; this is informational.
        Without a 0x4160 chunk it is a shared read-only identity, and the arrays of
        an object with no 0x4110 / 0x4120 chunk are shared read-only empties.
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    face_flags: np.ndarray
    face_material: np.ndarray
    uv: np.ndarray | None = None
    smoothing: np.ndarray | None = None
    matrix: np.ndarray = field(default_factory=lambda: _IDENTITY)
    offset: int = 0


@dataclass(slots=True)
class KeyframerNode:
    """An object node (0xB002) of the keyframer: which object it instances."""

    name: str
    instance: str | None = None
    node_id: int | None = None
    parent: int | None = None

    @property
    def instance_name(self) -> str:
        """``name`` or ``name.instance`` when the node names its instance."""
        return f"{self.name}.{self.instance}" if self.instance else self.name


@dataclass
class Model3DS:
    """Everything read from one .3ds file."""

    source: str
    master_scale: float = 1.0
    version: int | None = None
    mesh_version: int | None = None
    materials: list[Material] = field(default_factory=list)
    objects: list[MeshObject] = field(default_factory=list)
    nodes: list[KeyframerNode] = field(default_factory=list)

    @property
    def instance_names(self) -> list[str]:
        return [n.instance_name for n in self.nodes]

    def material_index(self, name: str) -> int:
        for i, m in enumerate(self.materials):
            if m.name == name:
                return i
        return -1
