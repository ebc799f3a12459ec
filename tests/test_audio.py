"""3D sound: the maths of spatialize measured on its output, and the Sound class."""

import math

import numpy as np
import pytest

from tanktool import audio
from tanktool.audio import MAX_ITD, Sound, rolloff_gain, spatialize

RATE = 44100
ORIGIN = (0.0, 0.0, 0.0)
STILL = (0.0, 0.0, 0.0)
FACING_X = (1.0, 0.0, 0.0)          # facing +x, so the right is +z (f x up)


def noise(n=8192, seed=0):
    return np.random.default_rng(seed).uniform(-0.5, 0.5, n)


def lag_of(a, b):
    """Samples by which b lags a (cross-correlation peak)."""
    n = len(a) + len(b)
    c = np.fft.irfft(np.fft.rfft(b, n) * np.conj(np.fft.rfft(a, n)), n)
    k = int(np.argmax(c))
    return k if k < n // 2 else k - n


def peak_hz(x, rate):
    spec = np.abs(np.fft.rfft(x * np.hanning(len(x)), 8 * len(x)))
    return float(np.fft.rfftfreq(8 * len(x), 1.0 / rate)[np.argmax(spec)])


def band_energy(x, rate, lo, hi):
    spec = np.abs(np.fft.rfft(x)) ** 2
    f = np.fft.rfftfreq(len(x), 1.0 / rate)
    return float(spec[(f >= lo) & (f < hi)].sum())


def test_source_on_the_right_is_louder_and_earlier_in_the_right_ear():
    x = noise()
    out = spatialize(x, RATE, (0.0, 0.0, 5.0), STILL, ORIGIN, FACING_X, STILL)
    left, right = out[:, 0], out[:, 1]
    level = 20 * math.log10(np.sqrt(np.mean(right ** 2)) / np.sqrt(np.mean(left ** 2)))
    assert 4.0 < level < 20.0                # the head's shadow: louder on the right, never silent on the left
    expected = MAX_ITD * RATE
    assert 0.64e-3 < MAX_ITD < 0.67e-3
    assert abs(lag_of(right, left) - expected) <= 1.0       # the left ear hears it ~29 samples late


def test_source_on_the_left_mirrors_and_front_is_centred():
    x = noise()
    out = spatialize(x, RATE, (0.0, 0.0, -5.0), STILL, ORIGIN, FACING_X, STILL)
    assert np.abs(out[:, 0]).sum() > 1.5 * np.abs(out[:, 1]).sum() > 0
    # the delay at 60 degrees
    out = spatialize(x, RATE, (1.0, 0.0, -math.sqrt(3.0)), STILL, ORIGIN, FACING_X, STILL)
    th = math.pi / 3
    expected = audio.HEAD_RADIUS / audio.SPEED_OF_SOUND * (th + math.sin(th)) * RATE
    assert abs(lag_of(out[:, 0], out[:, 1]) - expected) <= 1.0
    ahead = spatialize(x, RATE, (5.0, 0.0, 0.0), STILL, ORIGIN, FACING_X, STILL)
    np.testing.assert_allclose(ahead[:, 0], ahead[:, 1])


def test_itd_at_45_degrees_follows_woodworth():
    x = noise()
    out = spatialize(x, RATE, (5.0, 0.0, 5.0), STILL, ORIGIN, FACING_X, STILL)
    th = math.pi / 4
    expected = audio.HEAD_RADIUS / audio.SPEED_OF_SOUND * (th + math.sin(th)) * RATE
    assert abs(lag_of(out[:, 1], out[:, 0]) - expected) <= 1.0


def test_inverse_distance_clamped_rolloff():
    assert rolloff_gain(0.2, 1.0, 50.0) == 1.0
    assert rolloff_gain(4.0, 1.0, 50.0) == pytest.approx(0.25)
    assert rolloff_gain(500.0, 1.0, 50.0) == pytest.approx(1.0 / 50.0)
    x = noise()
    near = spatialize(x, RATE, (2.0, 0.0, 0.0), STILL, ORIGIN, FACING_X, STILL)
    far = spatialize(x, RATE, (8.0, 0.0, 0.0), STILL, ORIGIN, FACING_X, STILL)
    assert np.abs(far).max() == pytest.approx(np.abs(near).max() / 4, rel=1e-6)


def test_doppler_approaching_rises_receding_falls():
    t = np.arange(RATE // 2) / RATE
    tone = np.sin(2 * np.pi * 1000.0 * t)
    src = (20.0, 0.0, 0.0)
    approach = spatialize(tone, RATE, src, (-30.0, 0.0, 0.0), ORIGIN, FACING_X, STILL)
    recede = spatialize(tone, RATE, src, (30.0, 0.0, 0.0), ORIGIN, FACING_X, STILL)
    f_up, f_down = peak_hz(approach[:, 0], RATE), peak_hz(recede[:, 0], RATE)
    assert f_up == pytest.approx(1000.0 * 343.0 / 313.0, abs=3.0)
    assert f_down == pytest.approx(1000.0 * 343.0 / 373.0, abs=3.0)
    # a listener driving towards a still source hears it higher too
    f_l = peak_hz(spatialize(tone, RATE, src, STILL, ORIGIN, FACING_X, (30.0, 0.0, 0.0))[:, 0], RATE)
    assert f_l == pytest.approx(1000.0 * 373.0 / 343.0, abs=3.0)


def test_source_behind_loses_high_frequencies():
    x = noise(16384)
    front = spatialize(x, RATE, (5.0, 0.0, 0.0), STILL, ORIGIN, FACING_X, STILL)[:, 0]
    behind = spatialize(x, RATE, (-5.0, 0.0, 0.0), STILL, ORIGIN, FACING_X, STILL)[:, 0]
    hi_ratio = band_energy(behind, RATE, 6000, 20000) / band_energy(front, RATE, 6000, 20000)
    lo_ratio = band_energy(behind, RATE, 20, 300) / band_energy(front, RATE, 20, 300)
    assert hi_ratio < 0.1
    assert lo_ratio > 0.8


def test_bad_vectors_are_rejected():
    with pytest.raises(ValueError):
        spatialize(noise(), RATE, (0.0, 1.0), STILL, ORIGIN, FACING_X, STILL)
    with pytest.raises(ValueError):
        spatialize(noise(), RATE, (math.nan, 0, 0), STILL, ORIGIN, FACING_X, STILL)


def test_synthesised_sounds_are_finite_and_audible():
    for name, make in audio.SYNTHS.items():
        x = make(22050)
        assert np.isfinite(x).all() and 0.3 < np.abs(x).max() <= 1.0, name
    # the engine loops without a click: its ends meet
    e = audio.synth_engine(22050)
    assert abs(e[0] - e[-1]) < 0.1


def test_sound_class_plays_through_the_dummy_device():
    snd = Sound()
    if not snd.enabled:
        pytest.skip(f"pygame.mixer unavailable: {snd.reason}")
    try:
        snd.set_listener((0, 0, 0), (1, 0, 0), (0, 0, 0))
        engine = snd.play("engine", loop=True)
        snd.set_source(engine, (10, 0, 3), (0, 0, 0))
        snd.set_range(engine, 2.0, 80.0)
        snd.set_pitch(engine, 1.5)
        shot = snd.play("shot")
        snd.update()
        assert snd.voices[engine].channel is not None and snd.voices[engine].started
        assert snd.voices[engine].channel.get_queue() is not None     # next chunk already queued
        assert snd.voices[shot].started
        snd.stop(engine)
        assert engine not in snd.voices
    finally:
        snd.shutdown()


def test_sound_without_device_is_silent_but_works():
    snd = Sound(device=False)
    assert not snd.enabled
    v = snd.play("explosion")
    snd.set_source(v, (1, 2, 3), (0, 0, 0))
    snd.update()
    assert v not in snd.voices
    loop = snd.play("engine", loop=True)
    snd.update()
    assert loop in snd.voices
    with pytest.raises(KeyError):
        snd.play("no-such-sound")
    snd.shutdown()


def tone_ild(freq, degrees, rate=RATE):
    """The level difference [dB] between the near (right) and the far ear for a tone
    from ``degrees`` to the right, in the steady state."""
    t = np.arange(rate) / rate
    a = math.radians(degrees)
    out = spatialize(np.sin(2 * math.pi * freq * t), rate, (5 * math.cos(a), 0.0, 5 * math.sin(a)), STILL,
                     ORIGIN, FACING_X, STILL)[rate // 4:]
    return 20 * math.log10(np.sqrt(np.mean(out[:, 1] ** 2)) / np.sqrt(np.mean(out[:, 0] ** 2)))


@pytest.mark.parametrize("rate", [22050, 44100])
def test_head_shadow_level_difference_follows_frequency(rate):
    """Brown & Duda's spherical head at 90 degrees: a few dB at low frequencies, about
    5-10 dB at 1 kHz, 10-20 dB above 3 kHz; smaller towards the front."""
    assert 0.0 < tone_ild(250, 90, rate) <= 3.0
    assert 5.0 <= tone_ild(1000, 90, rate) <= 10.0
    assert 10.0 <= tone_ild(4000, 90, rate) <= 20.0
    assert tone_ild(1000, 30, rate) < tone_ild(1000, 90, rate)
    assert abs(tone_ild(1000, 0, rate)) < 0.01                 # straight ahead: both ears alike


def test_generated_music_is_a_stereo_loop():
    from tanktool.audio import synth_music

    m = synth_music(22050, bpm=96.0, bars=8)
    assert m.ndim == 2 and m.shape[1] == 2 and np.isfinite(m).all() and np.abs(m).max() <= 0.5 + 1e-9
    assert abs(len(m) / 22050 - 8 * 4 * 60 / 96) < 1e-3          # whole bars: it loops in time
    assert np.sqrt(np.mean(m ** 2)) > 0.05                        # heard
    assert not np.allclose(m[:, 0], m[:, 1])                      # some width
