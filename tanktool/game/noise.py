"""Seamless noise for procedural images (the sky's clouds; tools/make_textures.py's
textures): white noise low-passed in the frequency domain, so it tiles exactly."""

from __future__ import annotations

import numpy as np


def periodic_noise(rng: np.random.Generator, size: int, scale: float) -> np.ndarray:
    """(size, size) smooth periodic noise in [0, 1]: white noise low-passed at
    ``scale`` pixels (a Gaussian in the frequency domain keeps it seamless)."""
    white = rng.standard_normal((size, size))
    f = np.fft.fftfreq(size)
    fx, fy = np.meshgrid(f, f)
    kernel = np.exp(-(fx ** 2 + fy ** 2) * (np.pi * scale) ** 2 / 2)
    n = np.real(np.fft.ifft2(np.fft.fft2(white) * kernel))
    n -= n.min()
    return n / max(n.max(), 1e-12)


def fbm(rng: np.random.Generator, size: int, scales=(64, 24, 8, 3), weights=(0.45, 0.3, 0.17, 0.08)) -> np.ndarray:
    """Fractal noise: octaves of :func:`periodic_noise`, in [0, 1]."""
    n = sum(w * periodic_noise(rng, size, s) for s, w in zip(scales, weights))
    n -= n.min()
    return n / max(n.max(), 1e-12)
