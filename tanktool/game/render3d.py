"""The 3D view: moderngl, OpenGL 3.3 core.

Models come from the bundles' ``model.glb`` (arena in the world frame, vehicles in the
vehicle frame) with their textures and material colours (game/meshes.py).  A frame:

1. **shadow pass** (quality ``shadows`` on): the depth of the arena and the tanks seen
   from the light into a shadow map.  The light is the paper's point light high over
   the middle of the arena; everything lies below it, so one perspective view looking
   down, its frustum fitted to the arena's bounding box, holds every shadow.  One
   map: the arena's depth drawn once, the tanks drawn into it every frame and taken
   out again the next (game/shadows.py).
2. **scene**: tanks, then the arena (front to back: the software rasteriser skips what
   is hidden; the arena's triangles walls first, the lowest floor last), the tanks
   Phong-lit per pixel by the point light (position, range, attenuation 1/(a0 + a1 d +
   a2 d²) as D3DLIGHT8) plus ambient, textured, shadowed, fogged towards the horizon
   (game/shaders.py), the arena by its own program (lit per vertex below ``high``).
   Models are drawn indexed; closed ones with back faces culled.
3. **sky** at the far plane, only where nothing was drawn: gradient, the light's glow,
   clouds (game/sky.py, as the effects' pass).
4. **effects**: particles (game/particles.py: muzzle flashes, fire, smoke, sparks,
   debris, dust) and tracers, blended, never wider on screen than a share of the
   window and faded near the camera.
5. **HUD** (game/hud.py): a pygame surface; only the rectangles it drew are uploaded
   and blended (a full-window blend costs a software renderer more than the scene).

Tanks are placed at ``(x, y, z)`` with heading, pitch and roll when the simulation has
them (``y``, ``pitch``, ``roll`` of a tank; 0 before), so the same code draws flat and
terraced arenas.  Cameras: chase and first person (game/camera.py: along the slope,
rising over or pulled in before what would hide the tank, smoothed), overview.  With no window (``ctx=None``) the renderer makes an EGL standalone
context and draws into its own framebuffer, so screenshots work without any display.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..errors import TanktoolError
from . import shaders
# the matrices and GL helpers live in game/matrices.py (no OpenGL needed there)
from .matrices import _gl, cloud_pixels, frustum, look_at, perspective, set_uniform, tank_matrix, vertex_format  # noqa: F401
from .shadows import ShadowMaps, shadow_lookup  # noqa: F401
from .sky import PARTICLE_MAX_SCREEN, SKY, ZENITH, EffectsPass, Sky  # noqa: F401
from .meshes import STRIDE, Batch, Model, box_tank_model, load_model
from .quality import PRESETS, Quality
from .session import GameSession, pose3d, tank_colour

CAMERAS = ("chase", "first-person", "overview")
#: how much of a tank's colour is its team tint (the rest is the model's own colours)
TINT = 0.8
FOV_Y = math.radians(60.0)
#: a tank smaller than this on screen [px] is drawn without its small parts (wheels...)
LOD_PIXELS = 70.0
#: the longest triangle edge of the arena as drawn [m] (a tenth of the arena if larger):
#: attenuation and fog come from the vertices
ARENA_EDGE = 16.0
HUD_VERTEX, HUD_FRAGMENT = shaders.HUD_VERTEX, shaders.HUD_FRAGMENT


def _in_context(method: Callable) -> Callable:
    """Run a method with the renderer's own (headless) context current: several renderers
    or previews in one process each have one, and OpenGL draws in whichever is current
    (another's object names there draw nothing or garbage)."""
    @functools.wraps(method)
    def run(self: "Renderer3D", *args: Any, **kw: Any) -> Any:
        if not self.own_ctx:
            return method(self, *args, **kw)
        with self.ctx:
            return method(self, *args, **kw)
    return run


# ---------------------------------------------------------------- GPU side of a model
@dataclass
class GpuBatch:
    vao: Any
    depth_vao: Any
    flat_vao: Any
    texture: Any
    closed: bool
    luma: float
    triangles: int


class Renderer3D:
    """Draws a :class:`GameSession` in 3D.

    ``ctx`` is the window's moderngl context; None makes a headless EGL context and
    an offscreen framebuffer of ``size``.  ``quality`` is a ``game.quality.Quality``
    (default: the ``medium`` preset).
    """

    def __init__(self, session: GameSession, size: tuple[int, int] = (1280, 720), ctx: Any = None,
                 quality: Quality | None = None) -> None:
        import moderngl

        self.session = session
        self.size = (int(size[0]), int(size[1]))
        self.camera = "chase"
        self.own_ctx = ctx is None
        if ctx is None:
            ctx = standalone_context()
            self.fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer(self.size)],
                                       depth_attachment=ctx.depth_renderbuffer(self.size))
        else:
            self.fbo = ctx.screen
        self.ctx = ctx
        self.hud_prog = ctx.program(vertex_shader=HUD_VERTEX, fragment_shader=HUD_FRAGMENT)
        self.depth_prog = ctx.program(vertex_shader=shaders.source(shaders.DEPTH_VERTEX),
                                      fragment_shader=shaders.source(shaders.DEPTH_FRAGMENT))
        self.flat_prog = ctx.program(vertex_shader=shaders.source(shaders.FLAT_VERTEX),
                                     fragment_shader=shaders.source(shaders.FLAT_FRAGMENT))
        self.fx_pass = EffectsPass(ctx)
        quad = np.array([-1, -1, 1, -1, -1, 1, 1, 1], dtype="f4")
        self._quad = ctx.buffer(quad.tobytes())
        self.hud_vao = ctx.vertex_array(self.hud_prog, [(self._quad, "2f", "in_pos")])
        # two HUD textures used in turn: writing the one the last frame blended would wait
        # for that frame to be drawn
        self.hud_texs = [ctx.texture(self.size, 4), ctx.texture(self.size, 4)]
        for tex in self.hud_texs:
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.hud_tex = self.hud_texs[0]
        self._hud = None
        self._hud_rects: list[Any] = []
        self._placed: dict[tuple, np.ndarray] = {}       # tank matrices of this frame (shadow and scene)
        self._eye = None
        self._camera: Any = None          # game/camera.py's, made at the first chase frame
        (x0, z0), (x1, z1) = session.world.bounds.tolist()
        self.centre = ((x0 + x1) / 2, (z0 + z1) / 2)
        self.span = max(x1 - x0, z1 - z0, 1.0)
        self.arena_model = load_model(str(self._arena_model()), default_look=True)
        self.floor_y = self._floor_y()
        box = self.arena_model.bounds()
        top = float(box[1, 1]) if self.arena_model.triangles else 3.0
        # the paper's single light, high over the middle of the arena (above everything in it)
        self.light_pos = (self.centre[0], max(0.5 * self.span, top + 0.25 * self.span), self.centre[1])
        self.scene_box = np.array([[x0, min(float(box[0, 1]), self.floor_y - 1.0), z0],
                                   [x1, max(top, self.floor_y + 6.0), z1]])
        self.tank_models: dict[str, Model] = {}
        for t in session.world.tanks:
            if t.spec.name not in self.tank_models:
                self.tank_models[t.spec.name] = self._vehicle_model(t.spec)
        self.textures: dict[int, Any] = {}
        self._white = ctx.texture((1, 1), 3, bytes((255, 255, 255)))
        self._corners: dict[str, np.ndarray] = {}
        self._split: Model | None = None
        self.quality = quality or PRESETS["medium"]
        self.view = np.identity(4)
        self.proj = np.identity(4)
        self._setup_quality(self.quality)

    # ------------------------------------------------------------------ resources
    def _arena_model(self) -> Path:
        path = self.session.info.path
        if path is None:
            raise TanktoolError("the arena has no bundle folder, so no model.glb to draw")
        from ..arena import load_arena

        bundle = load_arena(path)
        self._bundle_floor = bundle.floor_y
        f = bundle.file("model")
        return f if f.name else Path(path) / "model.glb"

    def _floor_y(self) -> float:
        return float(getattr(self.session.info, "floor_y", getattr(self, "_bundle_floor", 0.0)))

    def _vehicle_model(self, spec: Any) -> Model:
        ref = self.session.vehicle_ref
        if ref is None:
            return box_tank_model(spec)
        from ..sim.match import bundle_dir

        folder = bundle_dir(ref, "vehicles")
        return load_model(str(folder / "model.glb"))

    def _texture(self, batch: Batch) -> Any:
        """The GL texture of a batch's image (shared by batches with the same pixels)."""
        import moderngl

        if batch.image is None:
            return None
        key = id(batch.image)
        if key not in self.textures:
            img = np.ascontiguousarray(batch.image[::-1])           # OpenGL's first row is the bottom
            tex = self.ctx.texture((img.shape[1], img.shape[0]), img.shape[2], img.tobytes())
            tex.repeat_x = tex.repeat_y = True
            tex.build_mipmaps()
            self.textures[key] = tex
        tex = self.textures[key]
        q = self.quality
        tex.filter = ((moderngl.LINEAR_MIPMAP_LINEAR if q.trilinear else moderngl.LINEAR_MIPMAP_NEAREST)
                      if q.mipmaps else moderngl.LINEAR, moderngl.LINEAR)
        return tex

    def _split_arena(self) -> Model:
        if self._split is None:
            split = self.arena_model.tessellated(max(ARENA_EDGE, self.span / 10.0))
            self._split = Model([Batch(occluders_first(b.vertices), b.image, b.closed) for b in split.batches])
        return self._split

    def _gpu(self, model: Model, prog: Any) -> list[GpuBatch]:
        out = []
        for b in model.batches:
            if not len(b.vertices):
                continue
            # each corner once and the triangles as indices: llvmpipe shades vertices on the
            # main thread, and with indices it shades a corner shared by several triangles
            # once (its vertex cache): a fifth of the work on a split arena
            rows, index = np.unique(np.ascontiguousarray(b.vertices, dtype="f4"), axis=0, return_inverse=True)
            buf = self.ctx.buffer(np.ascontiguousarray(rows).tobytes())
            ibo = self.ctx.buffer(np.ascontiguousarray(index.reshape(-1), dtype="u4").tobytes())

            def vao(p: Any, fmt: tuple) -> Any:
                return self.ctx.vertex_array(p, [fmt], index_buffer=ibo, index_element_size=4)

            vao_ = vao(prog, vertex_format(prog, buf, (("in_pos", 3), ("in_normal", 3), ("in_colour", 3), ("in_uv", 2))))
            depth = vao(self.depth_prog, (buf, f"3f {STRIDE - 3}x4", "in_pos"))
            flat = vao(self.flat_prog, (buf, f"3f {STRIDE - 3}x4", "in_pos"))
            out.append(GpuBatch(vao_, depth, flat, self._texture(b), b.closed, b.mean_luma(), b.triangles))
        return out

    @_in_context
    def set_quality(self, quality: Quality) -> None:
        """Switch the quality (shaders, shadow map, particle level)."""
        if quality != self.quality:
            self._setup_quality(quality)

    def _setup_quality(self, q: Quality) -> None:
        from .particles import SessionEffects

        self.quality = q
        ctx = self.ctx
        def scene(per_pixel: bool, arena: bool) -> Any:
            d = dict(SHADOWS=q.shadow_size > 0, PER_PIXEL=per_pixel, ARENA=arena)
            return ctx.program(vertex_shader=shaders.source(shaders.SCENE_VERTEX, **d),
                               fragment_shader=shaders.source(shaders.SCENE_FRAGMENT, **d))

        self.prog = scene(True, False)                             # tanks: always Phong per pixel
        # the arena's own program: no tint (game/shaders.py), lit per vertex below high
        self.arena_prog = scene(q.arena_light == "pixel", True)
        # no triangle so big that the light's attenuation or the fog change across it
        self.arena_shape = self._split_arena()
        self.arena = self._gpu(self.arena_shape, self.arena_prog)
        self.tanks = {name: self._gpu(m, self.prog) for name, m in self.tank_models.items()}
        # far away (and in the shadow map) a tank is drawn without its small parts
        self.tanks_far = {name: self._gpu(m.far, self.prog) if m.far is not None else self.tanks[name]
                          for name, m in self.tank_models.items()}
        self.sky = Sky(ctx, q.sky == "clouds", trilinear=q.trilinear)
        # one shadow map: the arena's depth once (it never moves), the tanks drawn in every frame
        self.shadows = (ShadowMaps(ctx, self.depth_prog, self.light_pos, self.scene_box, q.shadow_size, self.arena)
                        if q.shadow_size else None)
        self.effects = SessionEffects(q.particles, seed=int(getattr(self.session.world, "seed", 0)))

    # ------------------------------------------------------------------ shadows
    def _shadow_pass(self, alpha: float) -> None:
        """The tanks' shadow map for this frame."""
        by_kind: dict[str, list[np.ndarray]] = {}
        for t in self.session.world.tanks:
            by_kind.setdefault(t.spec.name, []).append(self._tank_model_matrix(t, alpha))
        self.shadows.draw_tanks([(self.tanks_far[name], models, self._tank_corners(name))
                                 for name, models in by_kind.items()])

    def _tank_corners(self, name: str) -> np.ndarray:
        """The (8, 3) corners of a vehicle model's bounding box (where its shadow is drawn from)."""
        if name not in self._corners:
            (x0, y0, z0), (x1, y1, z1) = self.tank_models[name].bounds().tolist()
            self._corners[name] = np.array([[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)])
        return self._corners[name]

    # ------------------------------------------------------------------ camera
    def toggle_camera(self) -> str:
        self.camera = CAMERAS[(CAMERAS.index(self.camera) + 1) % len(CAMERAS)]
        self._eye = None
        if self._camera is not None:
            self._camera.reset()
        return self.camera

    def _tank_model_matrix(self, t: Any, alpha: float) -> np.ndarray:
        w = getattr(self.session, "world_all", self.session.world)
        key = (id(w), w.steps, t.index, alpha)
        cached = self._placed.get(key)
        if cached is not None:
            return cached
        if len(self._placed) > 64:
            self._placed.clear()
        self._placed[key] = m = self._place(t, alpha)
        return m

    def _place(self, t: Any, alpha: float) -> np.ndarray:
        x, y, z, h, pitch, roll = pose3d(self.session, t.index, alpha)
        if not hasattr(t, "y"):
            y = self.floor_y
        return tank_matrix(x, z, h, y, pitch, roll)

    def camera_pose(self, alpha: float) -> tuple[np.ndarray, np.ndarray]:
        """(eye, target): the overview's, or the chase and first-person cameras of
        game/camera.py (slope, collision with the arena's model, smoothing)."""
        if self.camera == "overview":
            c = np.array([self.centre[0], self.floor_y, self.centre[1]])
            return c + np.array([0.0, 0.95 * self.span, 0.45 * self.span]), c
        if self._camera is None:
            from .camera import Camera, arena_mesh

            self._camera = Camera(arena_mesh(self.arena_model))       # what is drawn hides the tank
        return self._camera.pose(self.session, alpha, self.camera, self.floor_y)

    def matrices(self, alpha: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        eye, target = self.camera_pose(alpha)
        w, h = self.size
        self.view = look_at(eye, target)
        self.proj = perspective(FOV_Y, w / h, 0.3, 4.0 * self.span + 100.0)
        self._eye = eye
        return self.proj, self.view, eye

    def project(self, point) -> tuple[float, float, float]:
        """Pixel (column, row from the top) and depth of a world point in the last frame."""
        p = self.proj @ self.view @ np.append(np.asarray(point, dtype=np.float64), 1.0)
        ndc = p[:3] / p[3] if abs(p[3]) > 1e-12 else np.array([0.0, 0.0, 2.0])
        if p[3] <= 0:
            ndc[2] = 2.0                      # behind the camera
        w, h = self.size
        return (ndc[0] + 1) / 2 * w, (1 - ndc[1]) / 2 * h, ndc[2]

    def camera_yaw(self) -> float:
        """The heading the camera looks along (for the HUD's direction markers)."""
        fwd = -self.view[2, :3]
        return math.atan2(fwd[2], fwd[0])

    # ------------------------------------------------------------------ frame
    @_in_context
    def render(self, alpha: float = 1.0, fps: float = 0.0, message: str | None = None,
               hud: bool = True, controls: list[tuple[str, str]] | None = None) -> np.ndarray | None:
        """Draw one frame; headless, return it as an (h, w, 3) uint8 array (top row first)."""
        import moderngl

        ctx, s = self.ctx, self.session
        proj, view, eye = self.matrices(alpha)
        pv = proj @ view
        # the CPU's share of the frame before any upload: in a window the first texture
        # upload waits for llvmpipe to finish the last frame, and what comes before it
        # runs beside that (the effects, the tanks' places, the HUD drawn)
        self.effects.sync(s, self.floor_y)
        for t in s.world.tanks:
            self._tank_model_matrix(t, alpha)
        fx = self._effect_rows(eye, alpha)
        hud_rects = self._prepare_hud(fps, alpha, message, controls) if hud else []
        if self.shadows is not None:
            self._shadow_pass(alpha)
        self.fbo.use()
        ctx.viewport = (0, 0, *self.size)
        ctx.clear(*SKY, 1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.BLEND)
        self._scene_uniforms(self.prog, eye)
        if self.arena_prog is not self.prog:
            self._scene_uniforms(self.arena_prog, eye)
        for t in s.world.tanks:
            if s.focus() == t.index and self.camera == "first-person":
                continue            # we are inside it
            tint = np.array(tank_colour(t.index)) / 255.0 if t.alive else np.array((0.08, 0.07, 0.06))
            model = self._tank_model_matrix(t, alpha)
            self._draw(self.prog, self._lod(t, model, eye), pv, model, tint, TINT)
        self._draw(self.arena_prog, self.arena, pv, np.identity(4), (0, 0, 0), 0.0)
        self._draw_sky(pv, eye)
        self.fx_pass.draw(*fx, pv, self.view, eye, FOV_Y)
        if hud_rects:
            self._composite_hud(hud_rects)
        if not self.own_ctx:
            return None
        data = self.fbo.read(components=3, alignment=1)
        w, h = self.size
        return np.frombuffer(data, np.uint8).reshape(h, w, 3)[::-1].copy()

    def _scene_uniforms(self, prog: Any, eye: np.ndarray) -> None:
        set_uniform(prog, "light_pos", self.light_pos)
        set_uniform(prog, "light_colour", (0.85, 0.82, 0.74))
        set_uniform(prog, "light_range", 4.0 * self.span)
        # gentle fall-off: 1 under the light, about 75 % at the arena's corners; lit
        # tops stay just under white so colours keep their hue
        set_uniform(prog, "attenuation", (1.0, 0.2 / self.span, 0.2 / self.span ** 2))
        set_uniform(prog, "ambient", (0.34, 0.36, 0.40))
        set_uniform(prog, "eye", tuple(float(v) for v in eye))
        set_uniform(prog, "alpha", 1.0)
        set_uniform(prog, "fog_colour", SKY)
        # haze: a fifth of the colour gone at twice the arena's size (1 / (1 + k d^2) = 0.8)
        set_uniform(prog, "fog_k", 0.25 / (2.0 * max(self.span, 40.0)) ** 2)
        set_uniform(prog, "tex", 0)
        if self.shadows is not None:
            self.shadows.bind(prog)

    def _draw(self, prog: Any, batches: list[GpuBatch], pv: np.ndarray, model: np.ndarray, tint, amount: float,
              emissive=(0.0, 0.0, 0.0)) -> None:
        import moderngl

        set_uniform(prog, "mvp", _gl(pv @ model))
        set_uniform(prog, "model", _gl(model))
        set_uniform(prog, "tint", tuple(float(c) for c in tint))
        set_uniform(prog, "tint_amount", float(amount))
        set_uniform(prog, "emissive", tuple(float(c) for c in emissive))
        for b in batches:
            if b.closed:
                self.ctx.enable(moderngl.CULL_FACE)
            else:
                self.ctx.disable(moderngl.CULL_FACE)
            # the arena's program always samples its texture: white for vertex colours alone
            (b.texture or self._white).use(0)
            set_uniform(prog, "use_texture", 1.0 if b.texture is not None else 0.0)
            set_uniform(prog, "tex_luma", b.luma)
            b.vao.render()
        self.ctx.disable(moderngl.CULL_FACE)

    def _lod(self, t: Any, model: np.ndarray, eye: np.ndarray) -> list[GpuBatch]:
        """A tank's batches: without its small parts when it is under LOD_PIXELS tall on screen."""
        if t.index == self.session.focus() and self.camera == "chase":
            return self.tanks[t.spec.name]            # the followed tank: always in full
        d = float(np.linalg.norm(model[:3, 3] - eye))
        tall = t.spec.height / max(2.0 * d * math.tan(FOV_Y / 2), 1e-6) * self.size[1]
        return self.tanks[t.spec.name] if tall >= LOD_PIXELS else self.tanks_far[t.spec.name]

    def _draw_sky(self, pv: np.ndarray, eye: np.ndarray) -> None:
        d = np.array(self.light_pos) - np.array([self.centre[0], self.floor_y, self.centre[1]])
        self.sky.draw(pv, self.view, eye, d / np.linalg.norm(d) * np.array([0.4, 1.0, 0.4]), self.session.t)

    def _effect_rows(self, eye: np.ndarray, alpha: float) -> tuple[np.ndarray, np.ndarray]:
        """This frame's particle instances and tracer vertices (game/particles.py)."""
        from .particles import SessionEffects

        return self.effects.particles.instances(eye), SessionEffects.tracers(self.session, alpha, eye)

    def _prepare_hud(self, fps: float, alpha: float, message: str | None,
                     controls: list[tuple[str, str]] | None = None) -> list[Any]:
        """Draw the HUD on its surface and upload the rectangles it covers, before the
        scene: a texture upload waits for the rasteriser, so done after the scene it
        would stall the frame."""
        import pygame

        from .hud import Hud

        if self._hud is None:
            self._hud = Hud(self.session, self.size)
            self._hud_surface = pygame.Surface(self.size, pygame.SRCALPHA)
        surf = self._hud_surface
        for r in self._hud_rects:                 # clear only what the last frame drew
            surf.fill((0, 0, 0, 0), r)
        rects = self._hud.draw(surf, self.session, fps, alpha, message, view=f"3D {self.camera}",
                               project=self.project, facing=self.camera_yaw(), controls=controls)
        self._hud_rects = rects
        self.hud_tex = self.hud_texs[1] if self.hud_tex is self.hud_texs[0] else self.hud_texs[0]
        for r in rects:
            if r.w > 0 and r.h > 0:
                self.hud_tex.write(pygame.image.tobytes(surf.subsurface(r), "RGBA"), viewport=(r.x, r.y, r.w, r.h))
        return rects

    def _composite_hud(self, rects: list[Any]) -> None:
        import moderngl

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

    # ------------------------------------------------------------------ benchmark reference
    @_in_context
    def render_reference(self, alpha: float = 1.0) -> np.ndarray | None:
        """The benchmark's reference: the same triangles (arena and tanks) with depth
        test, one colour, no light, texture, shadow, sky, effects or HUD; read back
        like :meth:`render` (the figure every quality level is divided by)."""
        import moderngl

        ctx, s = self.ctx, self.session
        proj, view, eye = self.matrices(alpha)
        pv = proj @ view
        self.fbo.use()
        ctx.viewport = (0, 0, *self.size)
        ctx.clear(*SKY, 1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.BLEND)
        self.flat_prog["colour"].value = (0.5, 0.5, 0.5)
        for t in s.world.tanks:
            if s.focus() == t.index and self.camera == "first-person":
                continue
            model = self._tank_model_matrix(t, alpha)
            self.flat_prog["mvp"].write(_gl(pv @ model))
            for b in self._lod(t, model, eye):
                b.flat_vao.render()
        self.flat_prog["mvp"].write(_gl(pv))
        for b in self.arena:
            b.flat_vao.render()
        if not self.own_ctx:
            return None
        data = self.fbo.read(components=3, alignment=1)
        w, h = self.size
        return np.frombuffer(data, np.uint8).reshape(h, w, 3)[::-1].copy()

    def triangles(self, alpha: float = 1.0) -> int:
        """Triangles of the arena and the tanks in the frame the camera sees now."""
        _, _, eye = self.matrices(alpha)
        return sum(b.triangles for b in self.arena) + sum(
            sum(b.triangles for b in self._lod(t, self._tank_model_matrix(t, alpha), eye))
            for t in self.session.world.tanks)

    def release(self) -> None:
        if self.own_ctx:
            self.ctx.release()


def occluders_first(vertices: np.ndarray) -> np.ndarray:
    """A batch's triangles (rows of 3 vertices) reordered for a camera above the floor:
    walls first, then what faces up from the highest down, the lowest floor last.  The
    software rasteriser shades a pixel only when it is nearer than what is already drawn,
    so a floor drawn before the wall or roof in front of it is shaded for nothing (a
    third of the fort's arena pixels were)."""
    if len(vertices) < 6:
        return vertices
    tri = vertices[:, :3].reshape(-1, 3, 3).astype(np.float64)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    up = n[:, 1] / np.maximum(np.linalg.norm(n, axis=1), 1e-12)
    wall = np.abs(up) < 0.7
    order = np.lexsort((-tri[:, :, 1].max(axis=1), ~wall))        # walls, then by height, highest first
    return vertices.reshape(-1, 3, vertices.shape[1])[order].reshape(vertices.shape)


def standalone_context() -> Any:
    """A headless OpenGL 3.3 context through EGL (Mesa llvmpipe without a GPU)."""
    import moderngl

    try:
        return moderngl.create_standalone_context(backend="egl", require=330)
    except Exception as e:
        raise TanktoolError(f"cannot create a headless OpenGL 3.3 context through EGL ({e}); "
                            "install libegl1 and libgl1-mesa-dri, or use --view top") from None
