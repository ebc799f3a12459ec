"""The 3D view's shadow maps (game/render3d.py's first pass).

The paper's single point light hangs high over the middle of the arena and everything
lies below it, so one perspective view from the light looking straight down, its
frustum fitted to the arena's bounding box, holds every shadow.  Two depth maps, both
sampled with comparison (hardware 2×2 PCF through ``sampler2DShadow``):

- the **arena's**, drawn once (it never moves), ``Quality.shadow_size`` square;
- the **tanks'**, drawn every frame at half that size (at least 256).

Closed models cast from their back faces, so a lit side never shadows itself.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

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
    """The arena's shadow map (drawn at once) and the tanks' (:meth:`draw_tanks` every
    frame); :meth:`bind` hands both to a scene program."""

    def __init__(self, ctx: Any, depth_prog: Any, light_pos: Sequence[float], scene_box: np.ndarray,
                 size: int, arena: list[Any]) -> None:
        self.ctx, self.depth_prog = ctx, depth_prog
        self.light_vp = light_matrix(light_pos, scene_box)
        self.size = size
        self.static_tex, static_fbo = self._target(size)
        self._draw(static_fbo, size, [(arena, [np.identity(4)])])
        self.tank_size = max(size // 2, 256)
        self.tank_tex, self.fbo = self._target(self.tank_size)

    def _target(self, n: int) -> tuple[Any, Any]:
        """A depth texture of n x n sampled with comparison (hardware PCF) and its framebuffer."""
        import moderngl

        tex = self.ctx.depth_texture((n, n))
        tex.compare_func = "<="
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        return tex, self.ctx.framebuffer(depth_attachment=tex)

    def draw_tanks(self, groups: list[tuple[list[Any], list[np.ndarray]]]) -> None:
        """This frame's tank map: each group's batches placed at each of its model matrices."""
        self._draw(self.fbo, self.tank_size, groups)

    def _draw(self, fbo: Any, n: int, groups: list[tuple[list[Any], list[np.ndarray]]]) -> None:
        """Depth from the light of each group's batches placed at each of its model matrices."""
        import moderngl

        ctx = self.ctx
        fbo.use()
        ctx.viewport = (0, 0, n, n)
        ctx.enable(moderngl.DEPTH_TEST)
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
        """The scene program's shadow uniforms, the maps on texture units 1 and 2."""
        set_uniform(prog, "light_vp", _gl(shadow_lookup(self.light_vp)))
        set_uniform(prog, "shadow_static", 1)
        set_uniform(prog, "shadow_tanks", 2)
        self.static_tex.use(1)
        self.tank_tex.use(2)
