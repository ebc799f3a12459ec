"""Game sounds: what happens in a session, heard from the followed tank.

Each tank has a looping engine voice whose pitch follows its speed; shots, hits and
kills start one-shot voices where they happen.  The listener rides on the followed
tank, facing where it faces.  All the 3D maths is :func:`tanktool.audio.spatialize`.
Generated music (``audio.synth_music``) loops under it at its own volume.
"""

from __future__ import annotations

import math
from typing import Sequence

from ..audio import Sound, synth_music
from ..sim.world import Event
from .session import GameSession

EAR_HEIGHT = 2.0
#: one-shot sounds per event kind, layered: (sound, gain, pitch); a hit is the ring of
#: armour over a dull thump, a kill the blast over a deep crack
EVENT_SOUNDS = {
    "shot": (("shot", 1.0, 1.0),),
    "hit": (("impact", 1.4, 1.0), ("shot", 0.8, 0.6)),
    "kill": (("explosion", 1.8, 1.0), ("shot", 1.2, 0.45), ("impact", 0.8, 0.7)),
    "wall_bump": (("impact", 0.7, 0.8),),
}


class GameAudio:
    """Keeps a :class:`Sound` in step with a session; silent when ``sound`` has no device."""

    def __init__(self, session: GameSession, sound: Sound | None = None,
                 volumes: tuple[float, float] = (1.0, 1.0)) -> None:
        self.session = session
        self.sound = sound if sound is not None else Sound()
        self.sound.set_volumes(*volumes)
        if self.sound.enabled:
            self.sound.play_music(_music(self.sound.rate))
        self.engines: list[int] = []
        for _ in session.world.tanks:
            v = self.sound.play("engine", loop=True)
            self.sound.set_range(v, 3.0, 120.0)
            self.engines.append(v)

    def on_events(self, events: Sequence[Event]) -> None:
        for e in events:
            layers = EVENT_SOUNDS.get(e.kind)
            if layers is None or (e.kind == "wall_bump" and e.value < 5000.0):
                continue          # gentle scrapes are not worth a clank
            for name, gain, pitch in layers:
                v = self.sound.play(name)
                self.sound.set_source(v, (e.x, 1.5, e.z))
                self.sound.set_range(v, 4.0, 300.0 if e.kind in ("shot", "kill") else 150.0)
                self.sound.set_gain(v, gain)
                self.sound.set_pitch(v, pitch)

    def update(self, alpha: float = 1.0) -> None:
        s = self.session
        while len(self.engines) < len(s.world.tanks):      # a network match: players come and go
            v = self.sound.play("engine", loop=True)
            self.sound.set_range(v, 3.0, 120.0)
            self.engines.append(v)
        me = s.focus_tank()
        x, z, h = s.pose(me.index, alpha)
        self.sound.set_listener((x, EAR_HEIGHT, z), (math.cos(h), 0.0, math.sin(h)), (me.vx, 0.0, me.vz))
        for v, t in zip(self.engines, s.world.tanks):
            tx, tz, _ = s.pose(t.index, alpha)
            self.sound.set_source(v, (tx, 1.0, tz), (t.vx, 0.0, t.vz) if t.alive else (0.0, 0.0, 0.0))
            # revs: idle at 0.7, rising with speed; a wreck's engine is muted
            self.sound.set_pitch(v, 0.7 + 0.9 * min(t.speed() / t.spec.top_speed, 1.2))
            self.sound.set_gain(v, 0.5 if t.alive else 0.0)
        self.sound.update()

    def set_volumes(self, volumes: tuple[float, float]) -> None:
        """(effects, music), 0..1 each (the settings' ``volumes()``)."""
        self.sound.set_volumes(*volumes)

    def close(self) -> None:
        self.sound.shutdown()


_MUSIC: dict[int, object] = {}


def _music(rate: int) -> object:
    """The generated music loop at ``rate`` (made once a run: a second of numpy)."""
    if rate not in _MUSIC:
        _MUSIC[rate] = synth_music(rate)
    return _MUSIC[rate]
