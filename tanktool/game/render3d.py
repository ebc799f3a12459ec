"""The 3D view: moderngl, OpenGL 3.3 core.

Models come from the bundles' ``model.glb`` (arena in the world frame, vehicles in the
vehicle frame), with their material colours and per-vertex normals: smooth across
edges gentler than 35° (wheels, barrels), split at sharper ones (box edges stay hard).
Lighting is Phong (Blinn's half vector) with one point light in the manner of the
paper's D3DLIGHT8 — position, range, attenuation 1/(a0 + a1 d + a2 d²) — plus an
ambient term.  Cameras: a chase camera behind the followed tank, first person from its
turret, and an overview of the arena.  Shells, muzzle flashes and explosions are small
emissive spheres; the HUD (``hud.py``) is a pygame surface drawn over the scene as a
texture.

With no window (``ctx=None``) the renderer makes an EGL standalone context and draws
into its own framebuffer, so screenshots work without any display.
"""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import TanktoolError
from .session import GameSession, tank_colour

CAMERAS = ("chase", "first-person", "overview")
SKY = (0.55, 0.68, 0.82)
#: how much of a tank's colour is its team tint (the rest is the model's own colours)
TINT = 0.8
SMOOTH_ANGLE = math.radians(35.0)

VERTEX = """
#version 330 core
uniform mat4 mvp;
uniform mat4 model;
in vec3 in_pos;
in vec3 in_normal;
in vec3 in_colour;
out vec3 v_pos;
out vec3 v_normal;
out vec3 v_colour;
void main() {
    vec4 world = model * vec4(in_pos, 1.0);
    v_pos = world.xyz;
    v_normal = mat3(model) * in_normal;
    v_colour = in_colour;
    gl_Position = mvp * vec4(in_pos, 1.0);
}
"""

FRAGMENT = """
#version 330 core
uniform vec3 light_pos;
uniform vec3 light_colour;
uniform vec3 attenuation;     // a0, a1, a2 as D3DLIGHT8's Attenuation0..2
uniform float light_range;
uniform vec3 ambient;
uniform vec3 eye;
uniform vec3 tint;
uniform float tint_amount;
uniform vec3 emissive;
uniform float alpha;
in vec3 v_pos;
in vec3 v_normal;
in vec3 v_colour;
out vec4 frag;
void main() {
    vec3 base = mix(v_colour, tint, tint_amount);
    vec3 n = normalize(v_normal);
    vec3 to_light = light_pos - v_pos;
    float d = length(to_light);
    vec3 l = to_light / d;
    float att = d > light_range ? 0.0 : 1.0 / (attenuation.x + attenuation.y * d + attenuation.z * d * d);
    float diffuse = max(dot(n, l), 0.0);
    vec3 h = normalize(l + normalize(eye - v_pos));
    float spec = diffuse > 0.0 ? pow(max(dot(n, h), 0.0), 32.0) : 0.0;
    vec3 colour = base * (ambient + light_colour * diffuse * att) + 0.25 * spec * att * light_colour + emissive;
    frag = vec4(colour, alpha);
}
"""

HUD_VERTEX = """
#version 330 core
in vec2 in_pos;
out vec2 uv;
void main() { uv = vec2(in_pos.x * 0.5 + 0.5, 0.5 - in_pos.y * 0.5); gl_Position = vec4(in_pos, 0.0, 1.0); }
"""

HUD_FRAGMENT = """
#version 330 core
uniform sampler2D hud;
in vec2 uv;
out vec4 frag;
void main() { frag = texture(hud, uv); }
"""


# ---------------------------------------------------------------- matrices (column vectors)
def perspective(fov_y: float, aspect: float, near: float, far: float) -> np.ndarray:
    f = 1.0 / math.tan(fov_y / 2.0)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)], [0, 0, -1, 0]])


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    if np.linalg.norm(s) < 1e-9:          # looking straight down: any horizontal "up" will do
        s = np.cross(f, (1.0, 0.0, 0.0))
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.identity(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def tank_matrix(x: float, z: float, heading: float) -> np.ndarray:
    """Vehicle frame (+x forward, +z right) to world, as ``Tank.to_world`` turns points."""
    c, s = math.cos(heading), math.sin(heading)
    return np.array([[c, 0, -s, x], [0, 1, 0, 0], [s, 0, c, z], [0, 0, 0, 1.0]])


def _gl(m: np.ndarray) -> bytes:
    return np.ascontiguousarray(m.T, dtype="f4").tobytes()   # OpenGL wants column-major


# ---------------------------------------------------------------- meshes
def _face_colours(mesh: Any) -> np.ndarray:
    """(F, 3) floats in [0, 1]: face colours, or the material's main colour."""
    vis = mesh.visual
    if getattr(vis, "kind", None) == "face" or type(vis).__name__ == "ColorVisuals":
        try:
            return np.asarray(vis.face_colors, dtype=np.float64)[:, :3] / 255.0
        except Exception:
            pass
    mat = getattr(vis, "material", None)
    colour = getattr(mat, "main_color", None) if mat is not None else None
    if colour is None:
        colour = (180, 180, 180, 255)
    return np.tile(np.asarray(colour[:3], dtype=np.float64) / 255.0, (len(mesh.faces), 1))


def mesh_arrays(meshes: list[Any]) -> np.ndarray:
    """Interleaved (n, 9) float32 vertices ``x y z nx ny nz r g b``, three per triangle."""
    parts = []
    for m in meshes:
        if len(m.faces) == 0:
            continue
        colours = _face_colours(m)
        tri = np.asarray(m.vertices)[m.faces]                     # (F, 3, 3)
        fn = np.asarray(m.face_normals)                            # (F, 3)
        vn = np.asarray(m.vertex_normals)[m.faces]                 # (F, 3, 3), smooth
        # keep the smooth normal only where it is close to the face's own (crease angle)
        close = np.einsum("fkc,fc->fk", vn, fn) > math.cos(SMOOTH_ANGLE)
        normals = np.where(close[:, :, None], vn, fn[:, None, :])
        cols = np.repeat(colours[:, None, :], 3, axis=1)
        parts.append(np.concatenate([tri, normals, cols], axis=2).reshape(-1, 9))
    if not parts:
        return np.zeros((0, 9), dtype="f4")
    return np.concatenate(parts).astype("f4")


@lru_cache(maxsize=16)
def load_glb(path: str) -> np.ndarray:
    """A bundle's model.glb as vertex arrays (scene transforms applied)."""
    import trimesh

    p = Path(path)
    if not p.is_file():
        raise TanktoolError(f"{p}: no such model (rebuild the bundle: tanktool import-arena / import-vehicle)")
    try:
        import io

        from ..formats.bundle import read_input
        from ..formats.gltf import read_gltf, sanitized_glb

        # validated first (formats/gltf.py): a hostile model.glb cannot crash the game
        glb = sanitized_glb(read_gltf(read_input(p, "a .glb model"), str(p)))
        scene = trimesh.load(io.BytesIO(glb), file_type="glb", force="scene", process=False)
    except Exception as e:
        raise TanktoolError(f"{p}: cannot read the model ({e})") from None
    meshes = []
    for node in scene.graph.nodes_geometry:
        transform, name = scene.graph[node]
        g = scene.geometry[name]
        if not hasattr(g, "faces"):
            continue
        m = g.copy()
        m.merge_vertices(merge_tex=True, merge_norm=True)   # smooth normals need shared corners
        m.apply_transform(transform)
        meshes.append(m)
    return mesh_arrays(meshes)


def sphere_arrays(subdivisions: int = 1) -> np.ndarray:
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    m.visual.face_colors = (255, 255, 255, 255)
    return mesh_arrays([m])


def box_tank_arrays(spec: Any) -> np.ndarray:
    """The built-in box tank (no vehicle bundle): its hull as a box."""
    import trimesh

    xs = [p[0] for p in spec.hull]
    zs = [p[2] for p in spec.hull]
    ext = (max(xs) - min(xs), spec.height, max(zs) - min(zs))
    m = trimesh.creation.box(extents=ext)
    m.apply_translation(((max(xs) + min(xs)) / 2, spec.height / 2, (max(zs) + min(zs)) / 2))
    m.visual.face_colors = (110, 120, 80, 255)
    return mesh_arrays([m])


# ---------------------------------------------------------------- the renderer
class Renderer3D:
    """Draws a :class:`GameSession` in 3D.

    ``ctx`` is the window's moderngl context; None makes a headless EGL context and
    an offscreen framebuffer of ``size``.
    """

    def __init__(self, session: GameSession, size: tuple[int, int] = (1280, 720), ctx: Any = None) -> None:
        import moderngl

        self.session = session
        self.size = (int(size[0]), int(size[1]))
        self.camera = "chase"
        self.own_ctx = ctx is None
        if ctx is None:
            try:
                ctx = moderngl.create_standalone_context(backend="egl", require=330)
            except Exception as e:
                raise TanktoolError(f"cannot create a headless OpenGL 3.3 context through EGL ({e}); "
                                    "install libegl1 and libgl1-mesa-dri, or use --view top") from None
            self.fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer(self.size)],
                                       depth_attachment=ctx.depth_renderbuffer(self.size))
        else:
            self.fbo = ctx.screen
        self.ctx = ctx
        self.prog = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
        self.hud_prog = ctx.program(vertex_shader=HUD_VERTEX, fragment_shader=HUD_FRAGMENT)
        self.arena = self._vao(load_glb(str(self._arena_model())))
        self.tank_models: dict[str, Any] = {}
        for t in session.world.tanks:
            if t.spec.name not in self.tank_models:
                self.tank_models[t.spec.name] = self._vao(self._vehicle_arrays(t.spec))
        self.sphere = self._vao(sphere_arrays())
        quad = np.array([-1, -1, 1, -1, -1, 1, 1, 1], dtype="f4")
        self.hud_vao = ctx.vertex_array(self.hud_prog, [(ctx.buffer(quad.tobytes()), "2f", "in_pos")])
        self.hud_tex = ctx.texture(self.size, 4)
        self.hud_tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._hud = None
        self._eye = None
        (x0, z0), (x1, z1) = session.world.bounds.tolist()
        self.centre = ((x0 + x1) / 2, (z0 + z1) / 2)
        self.span = max(x1 - x0, z1 - z0, 1.0)
        # the paper's single light, high over the middle of the arena
        self.light_pos = (self.centre[0], 0.5 * self.span, self.centre[1])
        self.view = np.identity(4)
        self.proj = np.identity(4)

    def _arena_model(self) -> Path:
        path = self.session.info.path
        if path is None:
            raise TanktoolError("the arena has no bundle folder, so no model.glb to draw")
        from ..arena import load_arena

        bundle = load_arena(path)
        f = bundle.file("model")
        return f if f.name else Path(path) / "model.glb"

    def _vehicle_arrays(self, spec: Any) -> np.ndarray:
        ref = self.session.vehicle_ref
        if ref is None:
            return box_tank_arrays(spec)
        from ..sim.match import _bundle_dir

        folder = _bundle_dir(ref, "vehicles", ())
        return load_glb(str(folder / "model.glb"))

    def _vao(self, arrays: np.ndarray) -> Any:
        buf = self.ctx.buffer(arrays.tobytes())
        return self.ctx.vertex_array(self.prog, [(buf, "3f 3f 3f", "in_pos", "in_normal", "in_colour")])

    # ------------------------------------------------------------------ camera
    def toggle_camera(self) -> str:
        self.camera = CAMERAS[(CAMERAS.index(self.camera) + 1) % len(CAMERAS)]
        self._eye = None
        return self.camera

    def camera_pose(self, alpha: float) -> tuple[np.ndarray, np.ndarray]:
        s = self.session
        t = s.focus_tank()
        x, z, h = s.pose(t.index, alpha)
        f = np.array([math.cos(h), 0.0, math.sin(h)])
        p = np.array([x, 0.0, z])
        size = max(t.spec.radius, 1.0)
        if self.camera == "first-person":
            eye = p + np.array([0.0, t.spec.height + 0.4, 0.0]) + f * 0.3 * size
            return eye, eye + f * 10.0 + np.array([0.0, -0.6, 0.0])
        if self.camera == "overview":
            c = np.array([self.centre[0], 0.0, self.centre[1]])
            return c + np.array([0.0, 0.95 * self.span, 0.45 * self.span]), c
        eye = p - f * 4.5 * size + np.array([0.0, 2.2 * size, 0.0])
        # a wall between the tank and the camera would hide the tank: pull the camera in
        hit = s.world.walls.first_hit(x, z, float(eye[0]), float(eye[2]))
        if hit is not None:
            k = max(hit[0] - 0.6 / (4.5 * size), 0.05)
            eye = np.array([x + k * (eye[0] - x), eye[1], z + k * (eye[2] - z)])
        return eye, p + f * 2.5 * size + np.array([0.0, 1.0, 0.0])

    def matrices(self, alpha: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        eye, target = self.camera_pose(alpha)
        w, h = self.size
        self.view = look_at(eye, target)
        self.proj = perspective(math.radians(60.0), w / h, 0.3, 4.0 * self.span + 100.0)
        return self.proj, self.view, eye

    def project(self, point) -> tuple[float, float, float]:
        """Pixel (column, row from the top) and depth of a world point in the last frame."""
        p = self.proj @ self.view @ np.append(np.asarray(point, dtype=np.float64), 1.0)
        ndc = p[:3] / p[3]
        w, h = self.size
        return (ndc[0] + 1) / 2 * w, (1 - ndc[1]) / 2 * h, ndc[2]

    # ------------------------------------------------------------------ frame
    def render(self, alpha: float = 1.0, fps: float = 0.0, message: str | None = None, hud: bool = True) -> np.ndarray | None:
        """Draw one frame; headless, return it as an (h, w, 3) uint8 array (top row first)."""
        import moderngl

        ctx, prog, s = self.ctx, self.prog, self.session
        self.fbo.use()
        ctx.viewport = (0, 0, *self.size)
        ctx.clear(*SKY, 1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.BLEND)
        proj, view, eye = self.matrices(alpha)
        pv = proj @ view
        prog["light_pos"].value = self.light_pos
        prog["light_colour"].value = (0.8, 0.78, 0.72)
        prog["light_range"].value = 4.0 * self.span
        # gentle fall-off: 1 under the light, about 75 % at the arena's corners; lit
        # tops stay just under white so colours keep their hue
        prog["attenuation"].value = (1.0, 0.2 / self.span, 0.2 / self.span ** 2)
        prog["ambient"].value = (0.36, 0.37, 0.4)
        prog["eye"].value = tuple(float(v) for v in eye)
        prog["alpha"].value = 1.0
        self._draw(self.arena, pv, np.identity(4), (0, 0, 0), 0.0)
        for t in s.world.tanks:
            if s.focus() == t.index and self.camera == "first-person":
                continue            # we are inside it
            x, z, h = s.pose(t.index, alpha)
            tint = np.array(tank_colour(t.index)) / 255.0 if t.alive else np.array((0.08, 0.07, 0.06))
            amount = TINT if t.alive else 0.8
            self._draw(self.tank_models[t.spec.name], pv, tank_matrix(x, z, h), tint, amount)
        for p in s.shell_points(alpha):
            m = np.diag([0.25, 0.25, 0.25, 1.0])
            m[:3, 3] = p
            self._draw(self.sphere, pv, m, (1.0, 0.9, 0.4), 1.0, emissive=(0.8, 0.6, 0.2))
        if s.effects:
            ctx.enable(moderngl.BLEND)
            ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
            for e in s.effects:
                a = e.age(s.t)
                if a >= 1.0:
                    continue
                r = {"flash": 0.7, "impact": 1.0, "explosion": 4.5}[e.kind] * (0.4 + a)
                colour = {"flash": (1.0, 0.85, 0.4), "impact": (1.0, 0.6, 0.2), "explosion": (1.0, 0.45, 0.1)}[e.kind]
                m = np.diag([r, r, r, 1.0])
                m[:3, 3] = (e.x, e.y, e.z)
                prog["alpha"].value = float(max(1.0 - a, 0.0))
                self._draw(self.sphere, pv, m, colour, 1.0, emissive=tuple(0.8 * c for c in colour))
            prog["alpha"].value = 1.0
        if hud:
            self._draw_hud(fps, alpha, message)
        if not self.own_ctx:
            return None
        data = self.fbo.read(components=3, alignment=1)
        w, h = self.size
        return np.frombuffer(data, np.uint8).reshape(h, w, 3)[::-1].copy()

    def _draw(self, vao: Any, pv: np.ndarray, model: np.ndarray, tint, amount: float,
              emissive=(0.0, 0.0, 0.0)) -> None:
        self.prog["mvp"].write(_gl(pv @ model))
        self.prog["model"].write(_gl(model))
        self.prog["tint"].value = tuple(float(c) for c in tint)
        self.prog["tint_amount"].value = float(amount)
        self.prog["emissive"].value = tuple(float(c) for c in emissive)
        vao.render()

    def _draw_hud(self, fps: float, alpha: float, message: str | None) -> None:
        import moderngl
        import pygame

        from .hud import Hud

        if self._hud is None:
            self._hud = Hud(self.session, self.size)
            self._hud_surface = pygame.Surface(self.size, pygame.SRCALPHA)
        surf = self._hud_surface
        surf.fill((0, 0, 0, 0))
        rects = self._hud.draw(surf, self.session, fps, alpha, message, view=f"3D {self.camera}")
        self.hud_tex.write(pygame.image.tobytes(surf, "RGBA"))
        self.ctx.disable(moderngl.DEPTH_TEST)
        self.ctx.enable(moderngl.BLEND)
        self.ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        self.hud_tex.use(0)
        # blend only where the HUD drew: llvmpipe pays per pixel of a full-window quad
        h = self.size[1]
        for r in rects:
            if r.w > 0 and r.h > 0:
                self.ctx.scissor = (r.x, h - r.bottom, r.w, r.h)       # GL counts rows from the bottom
                self.hud_vao.render(moderngl.TRIANGLE_STRIP)
        self.ctx.scissor = None
        self.ctx.disable(moderngl.BLEND)

    def release(self) -> None:
        if self.own_ctx:
            self.ctx.release()
