"""The 3D view's last passes before the HUD (game/render3d.py): the sky where nothing
was drawn, and the blended effects (particles and tracers).

- **sky**: a grid over the window at the far plane, drawn after the scene so only the
  pixels no geometry covered are shaded (gradient, the light's glow, with ``clouds`` a
  cloud layer); its rows below the horizon are never drawn;
- **effects**: the particles of game/particles.py as camera-facing quads instanced from
  one buffer, never wider on screen than ``PARTICLE_MAX_SCREEN`` of the window, and the
  tracers as ribbons, premultiplied-alpha blended without writing depth.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from . import shaders
from .matrices import _gl, cloud_pixels, set_uniform

#: the sky at the horizon (and the fog's colour), and overhead
SKY = (0.66, 0.75, 0.85)
ZENITH = (0.30, 0.48, 0.78)
#: the widest a particle may be on screen, as a share of the window's height
PARTICLE_MAX_SCREEN = 0.2
#: the height of a direction (its y, unit vector) under which the sky has no clouds
#: (the smoothstep's lower edge in shaders.SKY_VERTEX)
CLOUD_BASE = 0.02


class Sky:
    """The sky pass: its program, grid and (with ``clouds``) cloud texture."""

    def __init__(self, ctx: Any, clouds: bool, nx: int = 24, ny: int = 16, trilinear: bool = False) -> None:
        import moderngl

        self.ctx = ctx
        self.prog = ctx.program(vertex_shader=shaders.source(shaders.SKY_VERTEX),
                                fragment_shader=shaders.source(shaders.SKY_FRAGMENT, CLOUDS=clouds))
        self.cloud_tex = None
        if clouds:
            pix = cloud_pixels()
            self.cloud_tex = ctx.texture(pix.shape[::-1], 1, pix.tobytes())
            self.cloud_tex.repeat_x = self.cloud_tex.repeat_y = True
            self.cloud_tex.build_mipmaps()
            # between mipmap levels too only with trilinear: blending two levels doubles what
            # a pixel of sky costs llvmpipe (half the screen in the hills: 2.5 ms a frame),
            # and on soft clouds the step between levels does not show
            self.cloud_tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR if trilinear else moderngl.LINEAR_MIPMAP_NEAREST,
                                     moderngl.LINEAR)
        # rows of quads over the window, bottom row first (drawn from the horizon up)
        self.cols, self.rows = nx, ny
        xs, ys = np.linspace(-1, 1, nx + 1), np.linspace(-1, 1, ny + 1)
        quads = []
        for i in range(ny):
            for j in range(nx):
                a, b, c, d = (xs[j], ys[i]), (xs[j + 1], ys[i]), (xs[j + 1], ys[i + 1]), (xs[j], ys[i + 1])
                quads += [a, b, c, a, c, d]
        buf = ctx.buffer(np.array(quads, dtype="f4").tobytes())
        self.grid = ctx.vertex_array(self.prog, [(buf, "2f", "in_pos")])
        # the rows under the clouds' base (only the gradient there) drawn without the
        # cloud lookup: the shader would pay for it where its cover is 0
        self.plain_prog = self.prog
        self.plain_grid = self.grid
        if clouds:
            self.plain_prog = ctx.program(vertex_shader=shaders.source(shaders.SKY_VERTEX),
                                          fragment_shader=shaders.source(shaders.SKY_FRAGMENT, CLOUDS=False))
            self.plain_grid = ctx.vertex_array(self.plain_prog, [(buf, "2f", "in_pos")])
        gx, gy = np.meshgrid(xs, ys)                    # (ny + 1, nx + 1): the grid's corners
        self._corners = np.stack([gx, gy, np.ones_like(gx), np.ones_like(gx)], axis=-1).reshape(-1, 4)

    def draw(self, pv: np.ndarray, view: np.ndarray, eye: np.ndarray, sun_dir: Sequence[float], t: float) -> None:
        """The sky behind what is drawn, seen through ``pv`` from ``eye`` at time ``t``."""
        import moderngl

        inv = np.linalg.inv(pv)
        for prog in (self.prog,) if self.plain_prog is self.prog else (self.prog, self.plain_prog):
            prog["inv_view_proj"].write(_gl(inv))
            prog["horizon"].value = SKY
            prog["zenith"].value = ZENITH
            prog["sun_dir"].value = tuple(float(v) for v in sun_dir)
            prog["eye"].value = tuple(float(v) for v in eye)
            set_uniform(prog, "time", float(t))
        if self.cloud_tex is not None:
            self.prog["clouds"].value = 0
            self.cloud_tex.use(0)
        # the sky is only above the horizon: below it the clear colour (the horizon's,
        # the fog's) shows where nothing was drawn, and the grid's lower rows are not drawn
        fwd = -view[2, :3]
        flat = np.array([fwd[0], 0.0, fwd[2]])
        lowest = 0
        if np.linalg.norm(flat) > 1e-6:
            far = eye + flat / np.linalg.norm(flat) * 1e4 + np.array([0.0, -0.02 * 1e4, 0.0])
            clip = pv @ np.append(far, 1.0)
            if clip[3] > 0:
                ndc_y = clip[1] / clip[3]
                if ndc_y > 1.0:
                    return                          # looking down: no sky in view
                lowest = int(np.clip(math.floor((ndc_y + 1.0) / 2.0 * self.rows), 0, self.rows - 1))
        cloudy = self._cloudy_from(inv, eye, lowest) if self.plain_prog is not self.prog else lowest
        ctx = self.ctx
        ctx.depth_func = "<="
        ctx.depth_mask = False
        per_row = 6 * self.cols
        if cloudy > lowest:
            self.plain_grid.render(moderngl.TRIANGLES, vertices=(cloudy - lowest) * per_row, first=lowest * per_row)
        if cloudy < self.rows:
            self.grid.render(moderngl.TRIANGLES, vertices=(self.rows - cloudy) * per_row, first=cloudy * per_row)
        ctx.depth_mask = True
        ctx.depth_func = "<"

    def _cloudy_from(self, inv_pv: np.ndarray, eye: np.ndarray, lowest: int) -> int:
        """The first grid row from ``lowest`` up with a corner over the clouds' base (the
        sky shader's ``CLOUD_BASE``): the rows under it have no cloud to draw."""
        far = self._corners @ inv_pv.T
        d = far[:, :3] / far[:, 3:4] - eye
        up = (d[:, 1] / np.linalg.norm(d, axis=1)).reshape(self.rows + 1, self.cols + 1).max(axis=1)
        row_up = np.maximum(up[:-1], up[1:])             # a row spans two lines of corners
        over = np.nonzero(row_up[lowest:] > CLOUD_BASE)[0]
        return lowest + int(over[0]) if len(over) else self.rows


class EffectsPass:
    """Particles and tracers: their programs and the dynamic buffers they are streamed into."""

    def __init__(self, ctx: Any) -> None:
        self.ctx = ctx
        self.particle_prog = ctx.program(vertex_shader=shaders.source(shaders.PARTICLE_VERTEX),
                                         fragment_shader=shaders.source(shaders.PARTICLE_FRAGMENT))
        self.beam_prog = ctx.program(vertex_shader=shaders.source(shaders.BEAM_VERTEX),
                                     fragment_shader=shaders.source(shaders.BEAM_FRAGMENT))
        self._particle_buf = ctx.buffer(reserve=64 * 9 * 4, dynamic=True)
        self._corners = ctx.buffer(np.array([-1, -1, 1, -1, -1, 1, 1, 1], dtype="f4").tobytes())
        self._beam_buf = ctx.buffer(reserve=64 * 9 * 4, dynamic=True)
        self._make_vaos()

    def _make_vaos(self) -> None:
        self.particle_vao = self.ctx.vertex_array(self.particle_prog, [
            (self._corners, "2f", "in_corner"),
            (self._particle_buf, "4f 4f 1f/i", "in_particle", "in_rgba", "in_glow")])
        self.beam_vao = self.ctx.vertex_array(self.beam_prog, [
            (self._beam_buf, "3f 2f 4f", "in_pos", "in_across", "in_rgba")])

    def draw(self, parts: np.ndarray, beams: np.ndarray, pv: np.ndarray, view: np.ndarray, eye: np.ndarray,
             fov_y: float) -> None:
        """Blend the particle instances and tracer vertices (rows as game/particles.py makes them)."""
        import moderngl

        if not len(parts) and not len(beams):
            return
        ctx = self.ctx
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA      # premultiplied alpha
        ctx.depth_mask = False
        if len(beams):
            self._upload(beams, "_beam_buf")
            self.beam_prog["view_proj"].write(_gl(pv))
            self.beam_vao.render(moderngl.TRIANGLES, vertices=len(beams))
        if len(parts):
            self._upload(parts, "_particle_buf")
            p = self.particle_prog
            p["view_proj"].write(_gl(pv))
            p["cam_right"].value = tuple(float(v) for v in view[0, :3])
            p["cam_up"].value = tuple(float(v) for v in view[1, :3])
            p["eye"].value = tuple(float(v) for v in eye)
            p["max_screen"].value = PARTICLE_MAX_SCREEN
            p["tan_half_fov"].value = math.tan(fov_y / 2)
            self.particle_vao.render(moderngl.TRIANGLE_STRIP, vertices=4, instances=len(parts))
        ctx.depth_mask = True
        ctx.disable(moderngl.BLEND)

    def _upload(self, rows: np.ndarray, name: str) -> None:
        """Write rows into a dynamic buffer, growing it (and its vertex arrays) when needed."""
        data = np.ascontiguousarray(rows, dtype="f4").tobytes()
        buf = getattr(self, name)
        if len(data) > buf.size:
            grown = max(len(data), 2 * buf.size)
            buf.release()
            setattr(self, name, self.ctx.buffer(reserve=grown, dynamic=True))
            self._make_vaos()
            buf = getattr(self, name)
        buf.write(data)
