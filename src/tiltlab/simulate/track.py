r"""Synthetic movement for the bio-logging demonstrations of :mod:`tiltlab.trig`.

Synthetic movement for the bio-logging demonstrations of :mod:`tiltlab.trig`:
3-D tracks for dead reckoning (Benhamou 2023 §8) and flapping/gliding heave for the
oscillation statistics (§9).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import xarray as xr
from scipy.signal import lfilter

from .. import _validate as _v
from .. import units as _units
from ..frames import wrap_angle
from ..trig import velocity_components

__all__ = ["Track", "simulate_track", "simulate_heave"]


class Track(NamedTuple):
    """A simulated 3-D path.

    A simulated 3-D path: positions (n+1, 3) in m, per-step speed (m/s), azimuth and
    elevation (rad), step duration ``dt_s`` (s).
    """

    positions: np.ndarray
    speed: np.ndarray
    azimuth: np.ndarray
    elevation: np.ndarray
    dt_s: float


def simulate_track(
    n_steps: int,
    dt_s: float = 1.0,
    *,
    mean_speed: float = 1.0,
    turn_sd: float = 0.15,
    pitch_sd: float = 0.05,
    max_elevation: float = 0.6,
    rng: np.random.Generator | int | None = None,
) -> Track:
    """Simulate a smooth correlated random walk in 3-D (truth for dead-reckoning demonstrations).

    Azimuth performs a random walk (increments N(0, turn_sd²) per step, rad), elevation
    a mean-reverting walk bounded by ``max_elevation`` (rad), speed a positive
    log-normal AR(1) around ``mean_speed`` (m/s).

    Parameters
    ----------
    n_steps : int
        Number of steps (positions: ``n_steps + 1``).
    dt_s : float
        Step duration (s).
    mean_speed : float
        Speed (m/s) around which the log-normal speed varies.
    turn_sd : float
        Standard deviation of the azimuth increments (rad per step).
    pitch_sd : float
        Standard deviation of the elevation increments (rad per step).
    max_elevation : float
        Bound of the elevation (rad).
    rng : numpy.random.Generator or int, optional
        Random source or seed.

    Returns
    -------
    Track
        Positions (n_steps + 1, 3) in m, per-step speed (m/s), azimuth and elevation
        (rad), and the step duration.
    """
    n_steps = _v.integer(n_steps, "n_steps", minimum=1)
    dt_s = _v.positive(dt_s, "dt_s")
    mean_speed = _v.positive(mean_speed, "mean_speed")
    turn_sd = _v.nonnegative(turn_sd, "turn_sd")
    pitch_sd = _v.nonnegative(pitch_sd, "pitch_sd")
    max_elevation = _v.positive(max_elevation, "max_elevation")
    rng = np.random.default_rng(rng)
    az = wrap_angle(
        rng.uniform(-np.pi, np.pi) + np.cumsum(rng.normal(0, turn_sd, n_steps))
    )
    e = lfilter([1.0], [1.0, -0.9], rng.normal(0, pitch_sd, n_steps))  # AR(1)
    el = max_elevation * np.tanh(e / max_elevation)
    speed = mean_speed * np.exp(
        lfilter([1.0], [1.0, -0.95], rng.normal(0, 0.1, n_steps))
    )
    steps = velocity_components(speed, az, el) * dt_s
    pos = np.vstack([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
    return Track(pos, speed, az, el, float(dt_s))


def simulate_heave(
    duration_s: float,
    fs: float,
    *,
    flapping=None,
    period_s: float = 0.18,
    amplitude: float = 0.8,
    noise_sd: float = 0.05,
    glide_sd: float = 0.3,
    units: str = "g",
    rng: np.random.Generator | int | None = None,
) -> xr.DataArray:
    """Heave specific force (tiltlab sign) of a bird alternating flapping and gliding.

    While ``flapping`` (boolean per sample; default the first half) the signal is
    1 g + amplitude·sin(2πt/period_s) + white sensor noise (SD ``noise_sd``); while
    gliding it is 1 g + turbulence, an AR(1) process (coefficient 0.8 per sample,
    marginal SD ``glide_sd``) plus the same sensor noise. ``amplitude``, ``noise_sd``
    and ``glide_sd`` are in g.

    Parameters
    ----------
    duration_s : float
        Duration (s).
    fs : float
        Sampling rate (Hz).
    flapping : array_like of bool, shape (N,), optional
        Samples of flapping flight (default the first half).
    period_s : float
        Wing-beat period (s).
    amplitude : float
        Wing-beat amplitude (g).
    noise_sd : float
        Standard deviation of the sensor noise (g).
    glide_sd : float
        Marginal standard deviation of the gliding turbulence (g).
    units : str
        Units of the output ('g' or 'm/s^2').
    rng : numpy.random.Generator or int, optional
        Random source or seed.

    Returns
    -------
    xarray.DataArray
        ``heave`` (time), with attributes ``fs`` and ``units`` (the balance level is
        1 g in those units).
    """
    duration_s = _v.positive(duration_s, "duration_s")
    fs = _v.check_fs(fs)
    period_s = _v.positive(period_s, "period_s")
    amplitude = _v.nonnegative(amplitude, "amplitude")
    noise_sd = _v.nonnegative(noise_sd, "noise_sd")
    glide_sd = _v.nonnegative(glide_sd, "glide_sd")
    scale = _units.conversion_factor("g", units)
    rng = np.random.default_rng(rng)
    n = int(round(duration_s * fs))
    t = np.arange(n) / fs
    if flapping is None:
        flapping = t < duration_s / 2
    flapping = np.asarray(flapping, bool)
    if flapping.shape != (n,):
        raise ValueError(f"flapping must have shape ({n},), got {flapping.shape}")
    e = rng.normal(0, noise_sd, n)
    ar = lfilter([np.sqrt(1 - 0.8**2)], [1, -0.8], rng.normal(0, glide_sd, n))
    phase = 2 * np.pi * rng.random()
    flap = amplitude * np.sin(2 * np.pi * t / period_s + phase)
    sig = np.where(flapping, flap, ar) + e
    return xr.DataArray(
        (1.0 + sig) * scale,
        dims=("time",),
        coords={"time": t},
        name="heave",
        attrs={"fs": fs, "units": _units.normalise_unit(units)},
    )
