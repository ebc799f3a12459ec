"""The 3D view's shadow maps (game/render3d.py's first pass).

The paper's single point light hangs high over the middle of the arena and everything
lies below it, so one perspective view from the light looking straight down, its
frustum fitted to the arena's bounding box, holds every shadow.  One depth map,
``Quality.shadow_size`` square, sampled with comparison (hardware 2×2 PCF through
``sampler2DShadow``): the arena's depth drawn once (it never moves) and kept, and every
frame the tanks drawn into it where they are, the arena's depth put back where they were.

Closed models cast from their back faces, so a lit side never shadows itself.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from . import shaders
from .matrices import _gl, frustum, look_at, set_uniform


def light_matrix(light_pos: Sequence[float], scene_box: np.ndarray) -> np.ndarray:
    """The light's view-projection: from ``light_pos`` straight down, the frustum fitted
    to ``scene_box`` ((x0, y0, z0), (x1, y1, z1)) with every corner inside."""
    lx, ly, lz = light_pos
    view = look_at(tuple(light_pos), (lx, ly - 1.0, lz), up=(0.0, 0.0, -1.0))
    (x0, y0, z0), (x1, y1, z1) = np.asarray(scene_box).tolist()
    corners = np.array([[x, y, z, 1.0] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)])
    cam = (view @ corners.T).T[:, :3]
    depth = -cam[:, 2]                                  # distance below the light
    near = max(float(depth.min()) * 0.9, 0.1)
    far = float(depth.max()) * 1.05 + 1.0
    sx, sy = cam[:, 0] / depth * near, cam[:, 1] / depth * near
    pad = 1.02
    proj = frustum(float(sx.min()) * pad, float(sx.max()) * pad, float(sy.min()) * pad, float(sy.max()) * pad,
                   near, far)
    return proj @ view


def shadow_lookup(light_vp: np.ndarray, bias: float = 0.0005) -> np.ndarray:
    """The light's matrix as the scene shader samples with it: clip space to [0, 1]
    texture coordinates and depth, the depth nudged towards the light."""
    b = np.array([[0.5, 0, 0, 0.5], [0, 0.5, 0, 0.5], [0, 0, 0.5, 0.5 - bias], [0, 0, 0, 1.0]])
    return b @ light_vp


class ShadowMaps:
    """The shadow map: the arena's depth from the light, drawn at once, and this frame's
    tanks drawn into it (:meth:`draw_tanks`); :meth:`bind` hands it to a scene program.

    One map rather than the arena's and the tanks' apart: the scene's pixels then do one
    shadow lookup, not two (on llvmpipe a lookup is about a tenth of an arena pixel's
    time).  The tanks' depth is taken out again where it was drawn: the rectangles the
    last frame's tanks covered are copied back from the arena's map (a few thousand
    texels, against a million to copy or redraw the whole map)."""

    def __init__(self, ctx: Any, depth_prog: Any, light_pos: Sequence[float], scene_box: np.ndarray,
                 size: int, arena: list[Any]) -> None:
        import moderngl

        self.ctx, self.depth_prog = ctx, depth_prog
        self.light_vp = light_matrix(light_pos, scene_box)
        self.size = size
        self.tex, self.fbo = self._target(size)
        self._draw(self.fbo, size, [(arena, [np.identity(4)])])
        # the arena's depth alone, as a plain float texture the restoring quads copy from
        self.arena_depth = ctx.texture((size, size), 1, self.tex.read(), dtype="f4")
        self.arena_depth.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._restore_prog = ctx.program(vertex_shader=shaders.source(shaders.RESTORE_VERTEX),
                                         fragment_shader=shaders.source(shaders.RESTORE_FRAGMENT))
        self._restore_prog["arena_depth"].value = 3
        self._quads = ctx.buffer(reserve=6 * 2 * 4 * 16, dynamic=True)
        self._restore = ctx.vertex_array(self._restore_prog, [(self._quads, "2f", "in_pos")])
        self._dirty = np.zeros((0, 4))                  # the map's rectangles the tanks were drawn over

    def _target(self, n: int) -> tuple[Any, Any]:
        """A depth texture of n x n sampled with comparison (hardware PCF) and its framebuffer."""
        import moderngl

        tex = self.ctx.depth_texture((n, n))
        tex.compare_func = "<="
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        return tex, self.ctx.framebuffer(depth_attachment=tex)

    def draw_tanks(self, groups: list[tuple[list[Any], list[np.ndarray], np.ndarray]]) -> None:
        """This frame's tanks into the map: each group's batches placed at each of its model
        matrices, ``(batches, models, corners)`` with ``corners`` the (8, 3) corners of the
        batches' bounding box in the model's frame (where the tank's depth can land)."""
        self.fbo.use()
        self.ctx.viewport = (0, 0, self.size, self.size)
        self._put_back(self._dirty)                  # the arena's depth where the last tanks were
        boxes = [self._texels(np.asarray(models), corners) for _, models, corners in groups if len(models)]
        self._dirty = np.concatenate(boxes) if boxes else np.zeros((0, 4))
        self._draw(self.fbo, self.size, [(b, models) for b, models, _ in groups], clear=False)

    def _put_back(self, rects: np.ndarray) -> None:
        """Copy the arena's depth into the map over ``rects`` ((n, 4) clip-space x0 y0 x1 y1)."""
        import moderngl

        if not len(rects):
            return
        x0, y0, x1, y1 = rects.T
        quads = np.stack([x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1], axis=1).astype("f4").tobytes()
        if len(quads) > self._quads.size:
            self._quads.orphan(2 * len(quads))
        self._quads.write(quads)
        ctx = self.ctx
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "1"                          # always: written whatever is there
        self.arena_depth.use(3)
        self._restore.render(moderngl.TRIANGLES, vertices=6 * len(rects))
        ctx.depth_func = "<"

    def _texels(self, models: np.ndarray, corners: np.ndarray) -> np.ndarray:
        """The map's rectangles (n, 4), as clip-space x0 y0 x1 y1, under a box (``corners``)
        placed by each of ``models`` (n, 4, 4), with two texels of margin for the filter."""
        pts = np.ones((4, len(corners)))
        pts[:3] = corners.T
        p = (self.light_vp @ models) @ pts                                # (n, 4, 8)
        w = p[:, 3]
        if (w <= 1e-9).any():                       # reaching above the light: all of the map
            return np.tile([-1.0, -1.0, 1.0, 1.0], (len(models), 1))
        x, y = p[:, 0] / w, p[:, 1] / w
        pad = 4.0 / self.size
        out = np.stack([x.min(axis=1) - pad, y.min(axis=1) - pad, x.max(axis=1) + pad, y.max(axis=1) + pad], axis=1)
        return np.clip(out, -1.0, 1.0)

    def _draw(self, fbo: Any, n: int, groups: list[tuple[list[Any], list[np.ndarray]]], clear: bool = True) -> None:
        """Depth from the light of each group's batches placed at each of its model matrices."""
        import moderngl

        ctx = self.ctx
        fbo.use()
        ctx.viewport = (0, 0, n, n)
        ctx.enable(moderngl.DEPTH_TEST)
        if clear:
            fbo.clear(depth=1.0)
        ctx.polygon_offset = (1.5, 2.0)
        for batches, models in groups:
            for model in models:
                self.depth_prog["mvp"].write(_gl(self.light_vp @ model))
                for b in batches:
                    # closed models cast from their back faces: the lit side never shadows itself
                    if b.closed:
                        ctx.enable(moderngl.CULL_FACE)
                        ctx.cull_face = "front"
                    else:
                        ctx.disable(moderngl.CULL_FACE)
                    b.depth_vao.render()
        ctx.cull_face = "back"
        ctx.disable(moderngl.CULL_FACE)
        ctx.polygon_offset = (0.0, 0.0)

    def bind(self, prog: Any) -> None:
        """The scene program's shadow uniforms, the map on texture unit 1."""
        set_uniform(prog, "light_vp", _gl(shadow_lookup(self.light_vp)))
        set_uniform(prog, "shadow_map", 1)
        self.tex.use(1)
