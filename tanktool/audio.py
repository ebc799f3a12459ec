"""Positional sound: the 2002 Sound class (§3.2) with its 3D effects computed in numpy.

The maths lives in one pure function, :func:`spatialize`, that turns mono samples and
the geometry of one source and the listener into a stereo buffer:

- distance rolloff, OpenAL's inverse-distance-clamped model:
  ``gain = min_dist / (min_dist + rolloff * (clamp(d, min_dist, max_dist) - min_dist))``;
- interaural level difference from the head's shadow, Brown & Duda's spherical-head
  filter per ear (IEEE Trans. Speech Audio Proc. 6(5), 1998):
  ``H(ω, θ) = (1 + j α(θ) ω / 2ω0) / (1 + j ω / 2ω0)``, ``ω0 = c / a``,
  ``α(θ) = (1 + α_min/2) + (1 − α_min/2) cos(θ / θ_min · 180°)``, α_min = 0.1,
  θ_min = 150°, θ the angle between the ear's axis and the source: a source at 90° is
  about 0.6 dB louder in the near ear at 250 Hz, 5 dB at 1 kHz and 14 dB at 4 kHz,
  never silent in the far one (bilinear transform, pre-warped at the corner);
- interaural time difference, Woodworth's spherical head (radius 8.75 cm):
  ``itd = a/c · (θ + sin θ)`` for the lateral angle θ, 0.656 ms at 90°; the far ear is late;
- sources behind the listener are muffled by a one-pole low-pass whose cut-off falls
  from 20 kHz (beside) to 1.2 kHz (straight behind);
- Doppler: ``f' = f · (c + v_l·u) / (c + v_s·u)`` with ``u`` the unit vector from the
  listener to the source and c = 343 m/s; applied by resampling, so a pitched-up sound
  is shorter.

Axes as DESIGN.md: Y up, the right of a facing f is f × up = (−f_z, 0, f_x).

:class:`Sound` plays voices through ``pygame.mixer``: ``play``, ``stop``, ``set_range``,
``set_source``, ``set_listener``, ``set_pitch`` store changes and :meth:`Sound.update`
applies them all at once.  Looping voices are played in short chunks queued on their
channel, each one spatialised with the geometry of its moment, so a moving engine keeps
sounding right.  Without a sound device every method still works and nothing is heard.
"""

from __future__ import annotations

import math
import os
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Iterator, Sequence

import numpy as np
from scipy.signal import lfilter

SPEED_OF_SOUND = 343.0
HEAD_RADIUS = 0.0875
#: Woodworth's ITD at 90 degrees [s]
MAX_ITD = HEAD_RADIUS / SPEED_OF_SOUND * (math.pi / 2 + 1.0)
OPEN_CUTOFF = 20000.0
BEHIND_CUTOFF = 1200.0
RATE = 22050
#: seconds of a looping voice spatialised at a time
CHUNK = 0.2


@contextmanager
def _quiet_stderr() -> Iterator[None]:
    """Silence the process's stderr (file descriptor 2) for a moment: C libraries under
    SDL (ALSA above all) print a line per failed device; the caller says it once."""
    try:
        saved = os.dup(2)
    except OSError:
        yield
        return
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
            yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _vec(v: Sequence[float] | np.ndarray) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64).reshape(-1)
    if a.shape != (3,) or not np.isfinite(a).all():
        raise ValueError(f"expected a finite 3-vector, got {v!r}")
    return a


def rolloff_gain(distance: float, min_dist: float = 1.0, max_dist: float = 100.0, rolloff: float = 1.0) -> float:
    """OpenAL's AL_INVERSE_DISTANCE_CLAMPED gain for a source ``distance`` metres away."""
    d = min(max(distance, min_dist), max_dist)
    return min_dist / (min_dist + rolloff * (d - min_dist))


def geometry(source_pos, listener_pos, listener_facing) -> tuple[float, float, float]:
    """(distance, azimuth, forwardness) of a source: azimuth in radians, 0 ahead, +π/2 on
    the right; forwardness = cos(azimuth), −1 straight behind."""
    d = _vec(source_pos) - _vec(listener_pos)
    f = _vec(listener_facing).copy()
    f[1] = 0.0                      # hearing is horizontal: a tank's facing lies in (x, z)
    n = np.linalg.norm(f)
    f = f / n if n > 0 else np.array([1.0, 0.0, 0.0])
    right = np.array([-f[2], 0.0, f[0]])
    dist = float(np.linalg.norm(d))
    x_r, x_f = float(d @ right), float(d @ f)
    if math.hypot(x_r, x_f) < 1e-9:
        return dist, 0.0, 1.0
    az = math.atan2(x_r, x_f)
    return dist, az, math.cos(az)


def itd_seconds(azimuth: float) -> float:
    """Interaural time difference [s] (> 0: the left ear is late, the source is right)."""
    lateral = math.asin(max(-1.0, min(1.0, math.sin(azimuth))))   # front/back mirror
    return HEAD_RADIUS / SPEED_OF_SOUND * (lateral + math.sin(lateral))


def doppler_ratio(source_pos, source_vel, listener_pos, listener_vel, c: float = SPEED_OF_SOUND) -> float:
    """Heard over emitted frequency."""
    d = _vec(source_pos) - _vec(listener_pos)
    n = float(np.linalg.norm(d))
    if n < 1e-9:
        return 1.0
    u = d / n
    # clamp so that nothing reaches the speed of sound (the formula would blow up)
    vl = min(float(_vec(listener_vel) @ u), 0.9 * c)
    vs = max(float(_vec(source_vel) @ u), -0.9 * c)
    vl = max(vl, -0.9 * c)
    vs = min(vs, 0.9 * c)
    return (c + vl) / (c + vs)


def _delay(x: np.ndarray, samples: float) -> np.ndarray:
    """``x`` delayed by a fractional number of samples (linear interpolation), same length."""
    if samples <= 0.0:
        return x
    t = np.arange(len(x), dtype=np.float64) - samples
    return np.interp(t, np.arange(len(x)), x, left=0.0)


def _lowpass(x: np.ndarray, rate: int, cutoff: float) -> np.ndarray:
    if cutoff >= 0.45 * rate:
        return x
    # one-pole: y[n] = y[n-1] + a (x[n] - y[n-1]), a = 1 - exp(-2π fc / fs)
    a = 1.0 - math.exp(-2.0 * math.pi * cutoff / rate)
    return lfilter([a], [1.0, a - 1.0], x)


#: Brown & Duda's head-shadow constants: the far ear's high-frequency gain and where it is least
ALPHA_MIN = 0.1
THETA_MIN = math.radians(150.0)


def shadow_alpha(theta: float) -> float:
    """Brown & Duda's α(θ): an ear's high-frequency gain for a source ``theta`` radians
    off its axis (2 facing it, ``ALPHA_MIN`` at ``THETA_MIN``)."""
    return (1.0 + ALPHA_MIN / 2.0) + (1.0 - ALPHA_MIN / 2.0) * math.cos(theta / THETA_MIN * math.pi)


def head_shadow(x: np.ndarray, rate: int, theta: float) -> np.ndarray:
    """``x`` as heard by an ear whose axis is ``theta`` radians from the source: the
    one-pole, one-zero head-shadow filter ``(α s + β) / (s + β)``, β = 2c/a, made
    digital by the bilinear transform pre-warped at β."""
    alpha = shadow_alpha(theta)
    beta = 2.0 * SPEED_OF_SOUND / HEAD_RADIUS
    k = beta / math.tan(beta / (2.0 * rate))         # pre-warp: the corner lands where it should
    b = np.array([alpha * k + beta, beta - alpha * k]) / (k + beta)
    a = np.array([1.0, (beta - k) / (k + beta)])
    return lfilter(b, a, x)


def spatialize(samples: np.ndarray, rate: int, source_pos, source_vel, listener_pos, listener_facing,
               listener_vel, *, min_dist: float = 1.0, max_dist: float = 100.0, rolloff: float = 1.0,
               pitch: float = 1.0) -> np.ndarray:
    """Mono samples heard by a listener: an (n, 2) float64 array, columns left and right.

    Parameters
    ----------
    samples : (m,) mono samples in [-1, 1]
    rate : sample rate [Hz]
    source_pos, source_vel, listener_pos, listener_facing, listener_vel : 3-vectors, world
        axes (metres, m/s)
    min_dist, max_dist, rolloff : the inverse-distance-clamped model's parameters
    pitch : extra playback-rate factor (an engine's revs), multiplied with Doppler

    n = round(m / (pitch · doppler)): resampling changes the length.
    """
    x = np.asarray(samples, dtype=np.float64).reshape(-1)
    if rate <= 0:
        raise ValueError(f"rate must be positive, got {rate}")
    ratio = doppler_ratio(source_pos, source_vel, listener_pos, listener_vel) * float(pitch)
    if abs(ratio - 1.0) > 1e-9 and len(x) > 1:
        n = max(int(round(len(x) / ratio)), 1)
        x = np.interp(np.arange(n) * ratio, np.arange(len(x)), x, right=0.0)
    dist, az, fwd = geometry(source_pos, listener_pos, listener_facing)
    if fwd < 0.0:
        # muffle in proportion to how far behind: geometric between the two cut-offs
        cutoff = OPEN_CUTOFF * (BEHIND_CUTOFF / OPEN_CUTOFF) ** (-fwd)
        x = _lowpass(x, rate, cutoff)
    g = rolloff_gain(dist, min_dist, max_dist, rolloff)
    # each ear's angle to the source: the right ear's axis points at +90 degrees
    left = g * head_shadow(x, rate, abs(math.remainder(az + math.pi / 2.0, 2.0 * math.pi)))
    right = g * head_shadow(x, rate, abs(math.remainder(az - math.pi / 2.0, 2.0 * math.pi)))
    itd = itd_seconds(az) * rate
    if itd > 0:
        left = _delay(left, itd)
    elif itd < 0:
        right = _delay(right, -itd)
    return np.stack([left, right], axis=1)


# ---------------------------------------------------------------- synthesised sounds
def _envelope(n: int, rate: int, attack: float, decay: float) -> np.ndarray:
    t = np.arange(n) / rate
    return np.minimum(t / max(attack, 1e-6), 1.0) * np.exp(-t / decay)


def synth_engine(rate: int = RATE, base: float = 40.0, seconds: float = 1.0) -> np.ndarray:
    """A diesel idle that loops seamlessly: harmonics of ``base`` Hz with firing pulses.

    The length is a whole number of periods so a looped voice has no click."""
    periods = max(int(round(base * seconds)), 1)
    n = int(round(periods * rate / base))
    t = np.arange(n) / rate
    ph = 2 * np.pi * base * t
    x = sum((0.7 ** k) * np.sin(k * ph + k) for k in range(1, 9))
    pulse = 0.5 + 0.5 * np.cos(ph * 0.5) ** 8            # firing strokes every other period
    rng = np.random.default_rng(1)
    noise = _lowpass(rng.standard_normal(n), rate, 600.0)
    x = x * (0.6 + 0.4 * pulse) + 0.3 * noise / (np.abs(noise).max() + 1e-9)
    return (0.6 * x / np.abs(x).max()).astype(np.float64)


def synth_shot(rate: int = RATE) -> np.ndarray:
    """Cannon: a noise crack on top of a falling low thump."""
    n = int(0.6 * rate)
    t = np.arange(n) / rate
    rng = np.random.default_rng(2)
    crack = rng.standard_normal(n) * _envelope(n, rate, 0.001, 0.03)
    freq = 90.0 * np.exp(-t / 0.15) + 35.0
    thump = np.sin(2 * np.pi * np.cumsum(freq) / rate) * _envelope(n, rate, 0.002, 0.18)
    x = 0.5 * crack + thump
    return 0.9 * x / np.abs(x).max()


def synth_impact(rate: int = RATE) -> np.ndarray:
    """A shell on armour: inharmonic ringing partials and a click."""
    n = int(0.5 * rate)
    t = np.arange(n) / rate
    rng = np.random.default_rng(3)
    ring = sum(np.sin(2 * np.pi * f * t) * np.exp(-t / d)
               for f, d in ((523.0, 0.12), (1187.0, 0.08), (1931.0, 0.05), (2777.0, 0.03)))
    click = rng.standard_normal(n) * _envelope(n, rate, 0.0005, 0.006)
    x = ring + 2.0 * click
    return 0.8 * x / np.abs(x).max()


def synth_explosion(rate: int = RATE) -> np.ndarray:
    """Low-passed noise with a slow decay and a sub-bass rumble."""
    n = int(1.6 * rate)
    t = np.arange(n) / rate
    rng = np.random.default_rng(4)
    noise = _lowpass(_lowpass(rng.standard_normal(n), rate, 900.0), rate, 400.0)
    rumble = np.sin(2 * np.pi * (45.0 - 10.0 * t) * t)
    x = (noise / np.abs(noise).max() + 0.6 * rumble) * _envelope(n, rate, 0.01, 0.45)
    return 0.95 * x / np.abs(x).max()


def synth_music(rate: int = RATE, bpm: float = 96.0, bars: int = 8) -> np.ndarray:
    """A loop of generated music, (n, 2) stereo: a minor progression (Am F C G) as soft
    detuned pads, a plucked bass on the beats, a kick and a hat; whole bars, so it loops
    without a seam.  Made here, so there is no licence to track."""
    beat = 60.0 / bpm
    n = int(round(bars * 4 * beat * rate))
    t = np.arange(n) / rate
    chords = ((57, 60, 64), (53, 57, 60), (48, 52, 55), (55, 59, 62))     # MIDI: Am F C G
    pad = np.zeros(n)
    bass = np.zeros(n)
    bar_n = int(round(4 * beat * rate))
    for b in range(bars):
        chord = chords[b % len(chords)]
        lo, hi = b * bar_n, min((b + 1) * bar_n, n)
        tb = t[lo:hi] - t[lo]
        swell = np.minimum(tb / 0.4, 1.0) * np.minimum((tb[-1] - tb + 1e-3) / 0.3, 1.0)
        for note in chord:
            f = 440.0 * 2.0 ** ((note - 69) / 12.0)
            for detune in (0.997, 1.003):
                pad[lo:hi] += swell * np.sin(2 * np.pi * f * detune * tb + note)
        root = 440.0 * 2.0 ** ((chord[0] - 12 - 69) / 12.0)
        for k in range(4):
            s0 = lo + int(round(k * beat * rate))
            m = min(int(beat * rate), n - s0)
            tt = np.arange(m) / rate
            bass[s0:s0 + m] += np.sin(2 * np.pi * root * tt) * np.exp(-tt / 0.25)
    pad = _lowpass(pad, rate, 1800.0)
    drums = np.zeros(n)
    rng = np.random.default_rng(5)
    for k in range(bars * 4):
        s0 = int(round(k * beat * rate))
        m = min(int(0.3 * rate), n - s0)
        tt = np.arange(m) / rate
        drums[s0:s0 + m] += np.sin(2 * np.pi * (50.0 + 80.0 * np.exp(-tt / 0.03)) * tt) * np.exp(-tt / 0.12)
        h0 = int(round((k + 0.5) * beat * rate))
        if h0 < n:
            hm = min(int(0.05 * rate), n - h0)
            drums[h0:h0 + hm] += 0.15 * rng.standard_normal(hm) * np.exp(-np.arange(hm) / rate / 0.015)
    mono = 0.5 * pad / (np.abs(pad).max() + 1e-9) + 0.45 * bass / (np.abs(bass).max() + 1e-9) + 0.35 * drums
    wide = _lowpass(pad, rate, 900.0) / (np.abs(pad).max() + 1e-9)
    stereo = np.stack([mono + 0.15 * wide, mono - 0.15 * wide], axis=1)
    return 0.5 * stereo / np.abs(stereo).max()


SYNTHS = {"engine": synth_engine, "shot": synth_shot, "impact": synth_impact, "explosion": synth_explosion}


# ---------------------------------------------------------------- the Sound class
@dataclass
class Voice:
    """One playing sound and its 3D state (positions in world metres)."""

    id: int
    name: str
    loop: bool
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    min_dist: float = 1.0
    max_dist: float = 100.0
    pitch: float = 1.0
    gain: float = 1.0
    cursor: int = 0            # next sample of a looping voice
    started: bool = False
    channel: object = None


class Sound:
    """The paper's Sound class: named samples, voices placed in 3D, one listener.

    ``device=False`` (or no usable sound device) makes it silent: the bookkeeping and
    the DSP of :meth:`update` are skipped, nothing else changes for the caller.
    """

    def __init__(self, rate: int = RATE, device: bool = True, channels: int = 32) -> None:
        self.rate = int(rate)
        self.samples: dict[str, np.ndarray] = {name: make(self.rate) for name, make in SYNTHS.items()}
        self.voices: dict[int, Voice] = {}
        self._next = 1
        self.listener_pos = np.zeros(3)
        self.listener_facing = np.array([1.0, 0.0, 0.0])
        self.listener_vel = np.zeros(3)
        self.enabled = False
        self.reason = "disabled by the caller"
        self._mixer = None
        #: the effects' volume (every voice) and the music's, 0..1 (the settings' master times each)
        self.volume = 1.0
        self.music_volume = 1.0
        self._music = None
        if device:
            self._open(channels)

    def _open(self, channels: int) -> None:
        try:
            import pygame

            if not pygame.mixer.get_init():
                with _quiet_stderr():     # ALSA and friends write their own lines on failure
                    pygame.mixer.init(frequency=self.rate, size=-16, channels=2, buffer=1024)
            freq, _, nch = pygame.mixer.get_init()
            self.rate, self._nch = int(freq), int(nch)
            if self.rate != RATE:
                self.samples = {name: make(self.rate) for name, make in SYNTHS.items()}
            pygame.mixer.set_num_channels(channels)
            pygame.mixer.set_reserved(1)          # channel 0: the music, never taken by a voice
            self._mixer = pygame.mixer
            self.enabled = True
            self.reason = ""
        except Exception as e:          # no device, no SDL audio driver: play silent
            self.enabled = False
            self.reason = f"no sound device ({e})"

    # -------------------------------------------------------------- the paper's methods
    def load(self, name: str, samples: np.ndarray) -> None:
        """Add or replace a named mono sample (float, [-1, 1], at ``self.rate``)."""
        self.samples[name] = np.asarray(samples, dtype=np.float64).reshape(-1)

    def play(self, name: str, loop: bool = False) -> int:
        """Start a voice (heard from the next :meth:`update`); returns its id."""
        if name not in self.samples:
            raise KeyError(f"no sound named {name!r} (have: {', '.join(sorted(self.samples))})")
        vid = self._next
        self._next += 1
        self.voices[vid] = Voice(vid, name, bool(loop), position=self.listener_pos.copy())
        return vid

    def stop(self, voice: int) -> None:
        v = self.voices.pop(voice, None)
        if v is not None and v.channel is not None:
            v.channel.stop()

    def set_range(self, voice: int, min_dist: float, max_dist: float) -> None:
        if not (0 < min_dist <= max_dist):
            raise ValueError(f"need 0 < min <= max, got {min_dist}, {max_dist}")
        v = self.voices.get(voice)
        if v is not None:
            v.min_dist, v.max_dist = float(min_dist), float(max_dist)

    def set_source(self, voice: int, position, velocity=(0.0, 0.0, 0.0)) -> None:
        v = self.voices.get(voice)
        if v is not None:
            v.position, v.velocity = _vec(position), _vec(velocity)

    def set_pitch(self, voice: int, pitch: float) -> None:
        """Playback-rate factor (engine revs); 1 is the sample as synthesised."""
        v = self.voices.get(voice)
        if v is not None:
            v.pitch = min(max(float(pitch), 0.25), 4.0)

    def set_gain(self, voice: int, gain: float) -> None:
        """Volume factor on top of the distance rolloff (0 mutes a voice without stopping it)."""
        v = self.voices.get(voice)
        if v is not None:
            v.gain = min(max(float(gain), 0.0), 4.0)

    def set_listener(self, position, facing, velocity=(0.0, 0.0, 0.0)) -> None:
        self.listener_pos, self.listener_facing, self.listener_vel = _vec(position), _vec(facing), _vec(velocity)

    def render(self, voice: Voice, samples: np.ndarray) -> np.ndarray:
        """A voice's samples as heard now: (n, 2) float."""
        out = spatialize(samples, self.rate, voice.position, voice.velocity, self.listener_pos,
                         self.listener_facing, self.listener_vel, min_dist=voice.min_dist,
                         max_dist=voice.max_dist, pitch=voice.pitch)
        g = voice.gain * self.volume
        return out * g if g != 1.0 else out

    def set_volumes(self, effects: float, music: float) -> None:
        """The effects' and the music's volume, 0..1 (the music's at once, the effects'
        from their next chunk)."""
        self.volume = min(max(float(effects), 0.0), 1.0)
        self.music_volume = min(max(float(music), 0.0), 1.0)
        if self._music is not None:
            self._music.set_volume(self.music_volume)

    def play_music(self, stereo: np.ndarray) -> None:
        """Loop ``stereo`` ((n, 2) in [-1, 1]) as music, not placed in 3D, on its own channel."""
        if not self.enabled:
            return
        self.stop_music()
        channel = self._mixer.Channel(0)
        channel.play(self._buffer(np.asarray(stereo, dtype=np.float64)), loops=-1)
        channel.set_volume(self.music_volume)
        self._music = channel

    def stop_music(self) -> None:
        if self._music is not None:
            self._music.stop()
            self._music = None

    def update(self) -> None:
        """Apply every change since the last call: start new voices, feed looping ones
        their next chunk, forget finished one-shots."""
        for vid in list(self.voices):
            v = self.voices[vid]
            if not self.enabled:
                if not v.loop:
                    del self.voices[vid]     # a silent one-shot is over at once
                continue
            if not v.loop:
                if not v.started:
                    v.channel = self._start(self.render(v, self.samples[v.name]))
                    v.started = True
                elif v.channel is None or not v.channel.get_busy():
                    del self.voices[vid]
                continue
            # looping: keep one chunk playing and one queued
            if not v.started:
                v.channel = self._start(self._next_chunk(v))
                v.started = True
            if v.channel is not None and v.channel.get_queue() is None:
                v.channel.queue(self._buffer(self._next_chunk(v)))

    def _next_chunk(self, v: Voice) -> np.ndarray:
        src = self.samples[v.name]
        # read enough source samples for CHUNK seconds after pitch and Doppler
        ratio = v.pitch * doppler_ratio(v.position, v.velocity, self.listener_pos, self.listener_vel)
        n = max(int(round(CHUNK * self.rate * ratio)), 2)
        idx = (v.cursor + np.arange(n)) % len(src)
        v.cursor = int((v.cursor + n) % len(src))
        return self.render(v, src[idx])

    def _buffer(self, stereo: np.ndarray):
        pcm = np.clip(stereo * 32767.0, -32768, 32767).astype(np.int16)
        if self._nch == 1:
            pcm = pcm.mean(axis=1).astype(np.int16)
        elif self._nch > 2:
            pcm = np.concatenate([pcm, np.zeros((len(pcm), self._nch - 2), np.int16)], axis=1)
        return self._mixer.Sound(buffer=np.ascontiguousarray(pcm).tobytes())

    def _start(self, stereo: np.ndarray):
        return self._buffer(stereo).play()

    def shutdown(self) -> None:
        self.stop_music()
        for vid in list(self.voices):
            self.stop(vid)
        if self._mixer is not None:
            self._mixer.quit()
            self._mixer = None
        self.enabled = False
        self.reason = "shut down"
