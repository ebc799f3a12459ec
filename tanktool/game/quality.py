"""Graphics quality: presets, and the settings page's choices saved between runs.

A :class:`Quality` says what the 3D view draws; the presets are tuned for Mesa's
software renderer (llvmpipe), which pays for every pixel a shader touches:

======  =========================  ==========  ==================  ===============  ============
preset  shadows                    particles   sky                 textures         arena light
======  =========================  ==========  ==================  ===============  ============
low     none                       few         gradient            bilinear + mips  per vertex
medium  1024² map, 2×2 PCF         normal      gradient + clouds   bilinear + mips  per vertex
high    2048² map, 2×2 PCF         many        gradient + clouds   trilinear        per pixel
======  =========================  ==========  ==================  ===============  ============

``medium`` is the default (bench/render.py measures every preset).  Tanks are always
Phong-shaded (per pixel); the arena too at ``high``, lit per vertex below it, which
halves what a pixel of floor or wall costs the software renderer and looks the same
under a light this far away (the arena's big triangles are split to at most
``render3d.ARENA_EDGE`` metres).  Distance fog is always on: it costs little and gives
the depth cue.  The settings
(``$XDG_CONFIG_HOME/tanktool/settings.toml``) hold the preset, any override of shadows
or particles, the resolution and full screen, and the player's name for network play::

    quality = "medium"
    shadows = "high"        # overrides the preset's
    particles = "low"
    resolution = "1280x720"
    fullscreen = false
    name = "alice"
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..errors import FormatError

SHADOWS = ("off", "low", "high")
PARTICLES = ("off", "low", "normal", "high")
SKIES = ("gradient", "clouds")
#: shadow map side per shadow level
SHADOW_SIZE = {"low": 1024, "high": 2048}
#: how many particles may be alive at once per particle level
PARTICLE_BUDGET = {"off": 0, "low": 400, "normal": 1200, "high": 3000}
#: share of each effect's particles emitted per particle level
PARTICLE_SHARE = {"off": 0.0, "low": 0.4, "normal": 0.75, "high": 1.0}
NAME_CHARS = re.compile(r"^[A-Za-z0-9_.-]{1,16}$")


@dataclass(frozen=True)
class Quality:
    """What the 3D view draws (see the table in the module docstring)."""

    name: str = "medium"
    shadows: str = "low"
    particles: str = "normal"
    sky: str = "clouds"
    mipmaps: bool = True
    trilinear: bool = False
    #: how the arena is lit: "vertex" (its big triangles split, light per vertex, the
    #: shadow per pixel) or "pixel" (Phong shading); tanks are always lit per pixel
    arena_light: str = "vertex"

    def with_(self, **kw: Any) -> "Quality":
        """A copy with some choices changed; it is then named ``custom`` unless it is a preset."""
        q = replace(self, **kw)
        for p in PRESETS.values():
            if replace(q, name=p.name) == p:
                return p
        return replace(q, name="custom")

    @property
    def shadow_size(self) -> int:
        return SHADOW_SIZE.get(self.shadows, 0)


PRESETS = {
    "low": Quality("low", shadows="off", particles="low", sky="gradient", mipmaps=True, trilinear=False),
    "medium": Quality("medium", shadows="low", particles="normal", sky="clouds", mipmaps=True, trilinear=False),
    "high": Quality("high", shadows="high", particles="high", sky="clouds", mipmaps=True, trilinear=True,
                    arena_light="pixel"),
}
DEFAULT = "medium"


def preset(name: str) -> Quality:
    try:
        return PRESETS[name]
    except KeyError:
        raise FormatError(f"quality must be one of {', '.join(PRESETS)}, got {name!r}") from None


#: the settings' volume keys (0..1 each)
VOLUMES = ("master_volume", "effects_volume", "music_volume")


@dataclass
class Settings:
    """The settings page's choices."""

    quality: str = DEFAULT
    shadows: str | None = None           # None: the preset's
    particles: str | None = None
    resolution: str = "1280x720"
    fullscreen: bool = False
    name: str = ""
    #: the menu's last difficulty; None before the player ever started a match (a first
    #: start: the menu offers "easy")
    difficulty: str | None = None
    #: the controls overlay was shown at a first start (it then shows on F1 only)
    controls_seen: bool = False
    #: sound: the master volume and the effects' and music's under it (0..1), and mute
    master_volume: float = 0.8
    effects_volume: float = 1.0
    music_volume: float = 0.5
    mute: bool = False

    def volumes(self) -> tuple[float, float]:
        """(effects, music) as played: each times the master; both 0 when muted."""
        if self.mute:
            return 0.0, 0.0
        return self.master_volume * self.effects_volume, self.master_volume * self.music_volume

    def graphics(self) -> Quality:
        q = preset(self.quality)
        kw = {k: v for k, v in (("shadows", self.shadows), ("particles", self.particles)) if v is not None}
        return q.with_(**kw) if kw else q

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"quality": self.quality, "resolution": self.resolution, "fullscreen": self.fullscreen,
                             "name": self.name}
        if self.shadows is not None:
            d["shadows"] = self.shadows
        if self.particles is not None:
            d["particles"] = self.particles
        if self.difficulty is not None:
            d["difficulty"] = self.difficulty
        d["controls_seen"] = self.controls_seen
        for key in VOLUMES:
            d[key] = round(getattr(self, key), 2)
        d["mute"] = self.mute
        return d


def settings_path() -> Path:
    from .input import config_dir

    return config_dir() / "settings.toml"


def load_settings(path: str | os.PathLike | None = None) -> Settings:
    """Read the settings file; defaults when it does not exist.  A bad value is one
    error naming the file and the key."""
    from ..formats.bundle import read_toml

    path = Path(path) if path is not None else settings_path()
    if not path.is_file():
        return Settings()
    doc = read_toml(path)
    s = Settings()
    allowed = {"quality": tuple(PRESETS), "shadows": SHADOWS, "particles": PARTICLES,
               "difficulty": ("easy", "normal", "hard")}
    for key, options in allowed.items():
        if key in doc:
            v = doc[key]
            if v not in options:
                raise FormatError(f"{path}: {key} must be one of {', '.join(options)}, got {v!r}")
            setattr(s, key, v)
    if "resolution" in doc:
        v = doc["resolution"]
        if not (isinstance(v, str) and re.fullmatch(r"\d{2,5}x\d{2,5}", v)):
            raise FormatError(f"{path}: resolution must be like \"1280x720\", got {v!r}")
        s.resolution = v
    for key in VOLUMES:
        if key in doc:
            v = doc[key]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0.0 <= v <= 1.0:
                raise FormatError(f"{path}: {key} must be a number from 0 to 1, got {v!r}")
            setattr(s, key, float(v))
    for key in ("fullscreen", "controls_seen", "mute"):
        if key in doc:
            if not isinstance(doc[key], bool):
                raise FormatError(f"{path}: {key} must be true or false, got {doc[key]!r}")
            setattr(s, key, doc[key])
    if "name" in doc:
        v = doc["name"]
        if not (isinstance(v, str) and (v == "" or NAME_CHARS.match(v))):
            raise FormatError(f"{path}: name must be 1-16 letters, digits, '.', '_' or '-', got {v!r}")
        s.name = v
    return s


def save_settings(settings: Settings, path: str | os.PathLike | None = None) -> Path:
    """Write the settings atomically (creating the config folder); returns the path."""
    from .input import save_config

    return save_config(Path(path) if path is not None else settings_path(), settings.to_dict())
