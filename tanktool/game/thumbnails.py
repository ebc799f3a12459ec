"""Rendered previews of arenas and vehicles for the start menu.

Each bundle's ``model.glb`` (game/meshes.py) is drawn once, small, with the scene
shader of the 3D view (the paper's point light over it, textures, fog): an arena from
high over one corner, a vehicle from its front quarter in the player's colour.  The
window's OpenGL context draws them when it has one, else a headless EGL context; with
neither (no libEGL) the bundle's ``preview.png`` is scaled instead, and with no picture
at all a plain card says so.  Previews are cached by bundle and size.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from . import shaders

_CACHE: dict[tuple, Any] = {}
_STANDALONE: list[Any] = []          # one headless context for every preview


def _context(ctx: Any) -> Any:
    if ctx is not None:
        return ctx
    if not _STANDALONE:
        from .render3d import standalone_context

        _STANDALONE.append(standalone_context())
    return _STANDALONE[0]


def _bundle(kind: str, ref: Any) -> Path | None:
    from ..sim.match import bundle_dir

    try:
        return bundle_dir(ref, kind)
    except Exception:  # an unknown name or a broken bundle: the menu says so when START is pressed
        return None


def render_model(model: Any, size: tuple[int, int], eye: Any, target: Any, light: Any, ctx: Any = None,
                 tint: Any = None, span: float = 50.0, tint_amount: float = 0.8) -> np.ndarray:
    """(h, w, 3) uint8 picture of a :class:`~tanktool.game.meshes.Model`."""
    window = ctx is not None
    ctx = _context(ctx)
    if window:
        return _draw_model(ctx, True, model, size, eye, target, light, tint, span, tint_amount)
    with ctx:                 # made current: a headless renderer's context may be the current one
        return _draw_model(ctx, False, model, size, eye, target, light, tint, span, tint_amount)


def _draw_model(ctx: Any, window: bool, model: Any, size: tuple[int, int], eye: Any, target: Any, light: Any,
                tint: Any, span: float, tint_amount: float) -> np.ndarray:
    import moderngl

    from .render3d import SKY, _gl, look_at, perspective, set_uniform, vertex_format

    w, h = size
    fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer(size)], depth_attachment=ctx.depth_renderbuffer(size))
    d = dict(SHADOWS=0, PER_PIXEL=1)
    prog = ctx.program(vertex_shader=shaders.source(shaders.SCENE_VERTEX, **d),
                       fragment_shader=shaders.source(shaders.SCENE_FRAGMENT, **d))
    made = [fbo, prog]
    try:
        fbo.use()
        ctx.viewport = (0, 0, w, h)
        ctx.clear(*SKY, 1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.BLEND)
        pv = perspective(math.radians(40.0), w / h, 0.1, 50.0 * span) @ look_at(eye, target)
        values = {"mvp": _gl(pv), "model": _gl(np.identity(4)), "light_pos": tuple(map(float, light)),
                  "light_colour": (0.85, 0.82, 0.74), "light_range": 100.0 * span, "attenuation": (1.0, 0.0, 0.0),
                  "ambient": (0.36, 0.38, 0.42), "eye": tuple(map(float, eye)), "alpha": 1.0, "fog_colour": SKY,
                  "fog_k": 0.0, "tex": 0, "emissive": (0.0, 0.0, 0.0),
                  "tint": tuple(float(c) for c in (tint if tint is not None else (0, 0, 0))),
                  "tint_amount": tint_amount if tint is not None else 0.0}
        for k, v in values.items():
            set_uniform(prog, k, v)
        for b in model.batches:
            buf = ctx.buffer(np.ascontiguousarray(b.vertices, dtype="f4").tobytes())
            vao = ctx.vertex_array(prog, [vertex_format(prog, buf, (("in_pos", 3), ("in_normal", 3),
                                                                     ("in_colour", 3), ("in_uv", 2)))])
            made += [buf, vao]
            tex = None
            if b.image is not None:
                img = np.ascontiguousarray(b.image[::-1])
                tex = ctx.texture((img.shape[1], img.shape[0]), img.shape[2], img.tobytes())
                tex.build_mipmaps()
                tex.repeat_x = tex.repeat_y = True
                tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
                tex.use(0)
                made.append(tex)
            set_uniform(prog, "use_texture", 1.0 if tex is not None else 0.0)
            set_uniform(prog, "tex_luma", b.mean_luma())
            vao.render()
        data = fbo.read(components=3, alignment=1)
        return np.frombuffer(data, np.uint8).reshape(h, w, 3)[::-1].copy()
    finally:
        for obj in made:
            obj.release()
        if window:
            ctx.screen.use()          # the window draws on as before


def arena_picture(ref: Any, size: tuple[int, int], ctx: Any = None) -> np.ndarray:
    from ..arena import load_arena
    from .meshes import load_model

    folder = _bundle("arenas", ref)
    if folder is None:
        raise FileNotFoundError(ref)
    bundle = load_arena(folder)
    f = bundle.file("model")
    model = load_model(str(f if f.name else folder / "model.glb"), default_look=True)
    (x0, z0), (x1, z1) = np.asarray(bundle.bounds, dtype=np.float64).tolist()
    span = max(x1 - x0, z1 - z0, 1.0)
    c = np.array([(x0 + x1) / 2, bundle.floor_y, (z0 + z1) / 2])
    eye = c + np.array([0.55 * span, 0.75 * span, 0.85 * span])
    return render_model(model, size, eye, c, c + np.array([0.0, 0.5 * span, 0.0]), ctx, span=span)


def vehicle_picture(ref: Any, size: tuple[int, int], ctx: Any = None) -> np.ndarray:
    from .meshes import box_tank_model, load_model
    from .session import tank_colour

    folder = _bundle("vehicles", ref) if ref is not None else None
    if folder is not None:
        model = load_model(str(folder / "model.glb"))
    else:
        from ..sim.match import load_tank_spec

        model = box_tank_model(load_tank_spec(None))
    lo, hi = model.bounds()
    c = (lo + hi) / 2
    r = float(np.linalg.norm(hi - lo)) / 2 or 1.0
    eye = c + np.array([1.45 * r, 0.85 * r, 1.05 * r])
    tint = np.array(tank_colour(0)) / 255.0
    return render_model(model, size, eye, c, c + np.array([2 * r, 4 * r, 3 * r]), ctx, tint=tint, span=r,
                        tint_amount=0.5)


def cached(key: tuple) -> Any:
    """The preview of (kind, str(ref), size) if made already, else None."""
    return _CACHE.get(key)


def preview(kind: str, ref: Any, size: tuple[int, int], ctx: Any = None) -> Any:
    """A pygame surface of ``size`` picturing the bundle (cached)."""
    import pygame

    key = (kind, str(ref), size)
    if key in _CACHE:
        return _CACHE[key]
    surf = None
    try:
        pix = arena_picture(ref, size, ctx) if kind == "arenas" else vehicle_picture(ref, size, ctx)
        from .hud import surface_from_rgb

        surf = surface_from_rgb(pix)
    except Exception:  # no OpenGL here (or a broken model): the bundle's 2D preview, else a card
        folder = _bundle(kind, ref) if ref is not None else None
        png = folder / "preview.png" if folder is not None else None
        if png is not None and png.is_file():
            try:
                surf = pygame.transform.smoothscale(pygame.image.load(str(png)), size)
            except pygame.error:
                surf = None
    if surf is None:
        from .hud import text

        surf = pygame.Surface(size)
        surf.fill((40, 44, 42))
        text(surf, "no preview", (size[0] // 2, size[1] // 2), 24, (170, 170, 170), anchor="center")
    _CACHE[key] = surf
    return surf
