"""The display: whether a window can be opened here (and one clear error when the
display named is not there), and the :class:`Presenter` that shows a finished pygame
surface in the window, plain or OpenGL.

With no display at all :func:`display_problem` says why and the CLI falls back to a
headless match; with a display variable that leads nowhere (``DISPLAY`` set, no X
server behind it, and SDL falling back to its invisible ``offscreen`` driver) it
raises :class:`DisplayError`: one clear error instead of a game running forever with
nothing shown.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")   # the command's output is ours

import pygame  # noqa: E402

from ..errors import TanktoolError  # noqa: E402

#: SDL's video drivers that show nothing on any screen
INVISIBLE_DRIVERS = ("offscreen", "dummy", "evdev")


class NoDisplay(TanktoolError):
    """There is no screen to open the window on."""


class DisplayError(TanktoolError):
    """A display is named (``DISPLAY``/``WAYLAND_DISPLAY``) but cannot be used."""


def x_display_socket(display: str) -> Path | None:
    """The Unix socket of a local X display (``:1``, ``:1.0``, ``unix:1``), or None
    for a remote one (``host:1``) or a name that is not a display."""
    host, sep, rest = display.rpartition(":")
    if not sep or host not in ("", "unix"):
        return None
    number = rest.split(".")[0]
    return Path("/tmp/.X11-unix") / f"X{number}" if number.isdigit() else None


def stale_display() -> str | None:
    """Why the display SDL opened is no display (None when it is a real one).

    ``DISPLAY=:99`` with no X server: SDL tries X11, then Wayland, then settles on its
    ``offscreen`` driver, and a game would run on it forever with nothing shown."""
    requested = os.environ.get("SDL_VIDEODRIVER", "")
    driver = pygame.display.get_driver() if pygame.display.get_init() else ""
    if driver not in INVISIBLE_DRIVERS or requested == driver:
        return None
    return _stale_message(driver)


def _stale_message(driver: str, detail: str = "") -> str:
    keys = [k for k in ("DISPLAY", "WAYLAND_DISPLAY") if os.environ.get(k)]
    named = [f"{k}={os.environ[k]}" for k in keys]
    why = " and ".join(named) or "a display"
    var = " and ".join(keys) or "DISPLAY"
    hint = ""
    sock = x_display_socket(os.environ.get("DISPLAY", ""))
    if sock is not None and not sock.exists():
        hint = f" ({sock} does not exist: no X server is running there)"
    shown = detail or f"SDL could only open its invisible '{driver}' driver, so nothing would be shown"
    return (f"{why} is set but no display answers there{hint}; {shown}.  Start the display server or fix "
            f"{var}, or unset {var} to run a headless match (or use tanktool play --headless)")


def display_problem() -> str | None:
    """Why no window can be opened here, or None when one can.  Raises DisplayError
    when a display is named but is not there (see :func:`stale_display`)."""
    driver = os.environ.get("SDL_VIDEODRIVER", "")
    if driver in ("dummy", "offscreen"):
        return f"SDL_VIDEODRIVER={driver}"
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return "neither DISPLAY nor WAYLAND_DISPLAY is set"
    # only X is named: SDL need not try Wayland (which prints its own complaints) nor
    # fall back to an invisible driver
    only_x = not driver and os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY")
    if only_x:
        os.environ["SDL_VIDEODRIVER"] = "x11"
    try:
        pygame.display.init()
    except pygame.error as e:
        if only_x:
            del os.environ["SDL_VIDEODRIVER"]
            raise DisplayError(_stale_message("x11", f"SDL cannot open it: {e}")) from None
        return f"SDL cannot open a display: {e}"
    stale = stale_display()
    if stale is not None:
        pygame.display.quit()
        raise DisplayError(stale)
    return None


class Presenter:
    """Shows a finished pygame surface in the window (plain or OpenGL)."""

    def __init__(self, size: tuple[int, int], fullscreen: bool, want_gl: bool) -> None:
        self.size = size
        self.ctx = None
        flags = pygame.FULLSCREEN if fullscreen else 0
        if want_gl:
            try:
                import moderngl

                pygame.display.gl_set_attribute(pygame.GL_CONTEXT_MAJOR_VERSION, 3)
                pygame.display.gl_set_attribute(pygame.GL_CONTEXT_MINOR_VERSION, 3)
                pygame.display.gl_set_attribute(pygame.GL_CONTEXT_PROFILE_MASK, pygame.GL_CONTEXT_PROFILE_CORE)
                self.window = pygame.display.set_mode(size, flags | pygame.OPENGL | pygame.DOUBLEBUF)
                self.ctx = moderngl.create_context(require=330)
            except Exception:
                self.ctx = None         # no OpenGL 3.3 here: a plain window, top view only
        if self.ctx is None:
            self.window = pygame.display.set_mode(size, flags)
        else:
            from .render3d import HUD_FRAGMENT, HUD_VERTEX
            import numpy as np

            prog = self.ctx.program(vertex_shader=HUD_VERTEX, fragment_shader=HUD_FRAGMENT)
            quad = np.array([-1, -1, 1, -1, -1, 1, 1, 1], dtype="f4")
            self._vao = self.ctx.vertex_array(prog, [(self.ctx.buffer(quad.tobytes()), "2f", "in_pos")])
            self._tex = self.ctx.texture(size, 4)
        self.canvas = pygame.Surface(size)
        pygame.display.set_caption("tanktool")

    @property
    def gl(self) -> bool:
        return self.ctx is not None

    def show(self, surface: "pygame.Surface") -> None:
        if self.ctx is None:
            self.window.blit(surface, (0, 0))
        else:
            import moderngl

            self.ctx.screen.use()
            self.ctx.viewport = (0, 0, *self.size)
            self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
            self._tex.write(pygame.image.tobytes(surface, "RGBA"))
            self._tex.use(0)
            self._vao.render(moderngl.TRIANGLE_STRIP)
        pygame.display.flip()
