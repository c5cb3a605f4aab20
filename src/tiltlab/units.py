"""Physical units used by tiltlab Recordings, conversions between them, and a
plausibility check that catches a gyroscope whose units are mislabelled.

The magnitude checks of values against their unit labels (accelerometer ~1 g, raw ADC
counts, gyroscope ranges, temperature) and sensor saturation live in
:mod:`tiltlab.quality`; :func:`tiltlab.schema.validate` runs both.

Units travel as strings in the ``units`` attribute of each variable. Only the
spellings listed in :data:`UNITS` are accepted; aliases are normalised by
:func:`normalise_unit`.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "G0",
    "UNITS",
    "UnitsError",
    "normalise_unit",
    "conversion_factor",
    "convert",
    "acc_to_g",
    "gyr_to_rad_s",
    "check_gyro_units",
    "check_fs",
]

#: Standard gravity (m/s²), the conversion factor between g and m/s² (CGPM 1901).
G0: float = 9.80665

#: Accepted units per physical quantity, canonical spelling first.
UNITS: dict[str, tuple[str, ...]] = {
    "acceleration": ("g", "m/s^2"),
    "angular_velocity": ("deg/s", "rad/s"),
    "magnetic_field": ("uT", "nT", "gauss", "a.u."),
    "temperature": ("degC", "K"),
    "dimensionless": ("1",),
    "time": ("s",),
    "length": ("m", "mm"),
}

_ALIASES: dict[str, str] = {
    "g": "g",
    "m/s^2": "m/s^2",
    "m/s2": "m/s^2",
    "m/s²": "m/s^2",
    "m s-2": "m/s^2",
    "deg/s": "deg/s",
    "°/s": "deg/s",
    "dps": "deg/s",
    "degree/s": "deg/s",
    "rad/s": "rad/s",
    "rad s-1": "rad/s",
    "ut": "uT",
    "µt": "uT",
    "μt": "uT",
    "microtesla": "uT",
    "nt": "nT",
    "gauss": "gauss",
    "a.u.": "a.u.",
    "degc": "degC",
    "°c": "degC",
    "celsius": "degC",
    "k": "K",
    "1": "1",
    "": "1",
    "s": "s",
    "m": "m",
    "mm": "mm",
}

# factor to the SI-like base unit of each quantity
_TO_BASE: dict[str, float] = {
    "g": G0,
    "m/s^2": 1.0,
    "deg/s": np.pi / 180.0,
    "rad/s": 1.0,
    "uT": 1.0,
    "nT": 1e-3,
    "gauss": 100.0,
    "1": 1.0,
    "s": 1.0,
    "m": 1.0,
    "mm": 1e-3,
}


class UnitsError(ValueError):
    """A unit string is unknown, or data are implausible for their stated unit."""


def normalise_unit(unit: str) -> str:
    """Return the canonical spelling of ``unit``.

    Raises
    ------
    UnitsError
        If the unit is not one tiltlab knows.
    """
    if not isinstance(unit, str):
        raise UnitsError(f"units must be a string, got {unit!r}")
    key = unit.strip()
    canon = _ALIASES.get(key) or _ALIASES.get(key.lower())
    if canon is None:
        known = sorted({u for us in UNITS.values() for u in us})
        raise UnitsError(f"unknown unit {unit!r}; known units: {', '.join(known)}")
    return canon


def quantity_of(unit: str) -> str:
    """Name of the physical quantity that ``unit`` measures."""
    u = normalise_unit(unit)
    for q, us in UNITS.items():
        if u in us:
            return q
    raise UnitsError(f"unit {unit!r} has no quantity")  # pragma: no cover


def conversion_factor(src: str, dst: str) -> float:
    """Multiplicative factor converting values in ``src`` units to ``dst`` units.

    Temperatures (an affine conversion) and arbitrary units are refused.
    """
    s, d = normalise_unit(src), normalise_unit(dst)
    if s == d:
        return 1.0
    if quantity_of(s) != quantity_of(d):
        raise UnitsError(
            f"cannot convert {src!r} ({quantity_of(s)}) to {dst!r} ({quantity_of(d)})"
        )
    if s not in _TO_BASE or d not in _TO_BASE:
        raise UnitsError(f"no multiplicative conversion between {src!r} and {dst!r}")
    return _TO_BASE[s] / _TO_BASE[d]


def convert(values, src: str, dst: str) -> np.ndarray:
    """Return ``values`` (array-like) converted from ``src`` to ``dst`` units (a new array)."""
    return np.asarray(values, dtype=float) * conversion_factor(src, dst)


def acc_to_g(values, units: str) -> np.ndarray:
    """Acceleration in g from ``units`` ('g' or 'm/s^2')."""
    return convert(values, units, "g")


def gyr_to_rad_s(values, units: str) -> np.ndarray:
    """Angular velocity in rad/s from ``units`` ('deg/s' or 'rad/s')."""
    return convert(values, units, "rad/s")


def check_gyro_units(
    gyr,
    gyr_units: str,
    acc,
    fs: float,
    *,
    min_tilt_rate: float = 0.5,
    raise_error: bool = True,
) -> float | None:
    """Check that the gyroscope's stated unit is consistent with the accelerometer.

    When the sensor turns, the direction of the (low-passed) acceleration turns too, and
    its angular rate is a lower bound of the true angular speed: the component of
    ``ω`` perpendicular to gravity. We estimate that tilt rate from the accelerometer
    on the samples where it exceeds ``min_tilt_rate`` (rad/s) and compare it with the
    gyroscope norm converted with the *stated* unit. A correct unit gives a median ratio
    of order one (≥ ~0.5); a gyroscope in rad/s labelled °/s gives ~1/57, one in °/s
    labelled rad/s gives ~57.

    Parameters
    ----------
    gyr : array_like, shape (N, 3)
        Angular velocity in ``gyr_units``.
    gyr_units : str
        Stated unit ('deg/s' or 'rad/s').
    acc : array_like, shape (N, 3)
        Acceleration in any unit (only its direction is used).
    fs : float
        Sampling rate (Hz).
    min_tilt_rate : float
        Tilt rates (rad/s) below this are too small to judge and ignored.
    raise_error : bool
        Raise :class:`UnitsError` on an implausible ratio (default), else return it.

    Returns
    -------
    float or None
        Median ratio ‖ω‖ / tilt rate, or None when the recording has too little rotation
        to decide (e.g. a static recording).
    """
    gyr = np.asarray(gyr, dtype=float)
    acc = np.asarray(acc, dtype=float)
    fs = check_fs(fs)
    # too short to judge, also when the ~50 ms smoothing window spans the recording
    if gyr.shape[0] < 10 or 0.05 * fs >= gyr.shape[0] / 2:
        return None
    # smooth the acceleration direction over ~50 ms to suppress noise and vibration
    w = max(1, int(round(0.05 * fs)))
    kernel = np.ones(w) / w
    a = np.column_stack([np.convolve(acc[:, k], kernel, mode="same") for k in range(3)])
    n = np.linalg.norm(a, axis=1, keepdims=True)
    ok = n[:, 0] > 0
    u = np.where(ok[:, None], a / np.where(n > 0, n, 1.0), np.nan)
    step = max(1, w)
    cosang = np.clip(np.sum(u[step:] * u[:-step], axis=1), -1.0, 1.0)
    tilt_rate = np.arccos(cosang) * fs / step
    omega = np.linalg.norm(gyr, axis=1) * conversion_factor(gyr_units, "rad/s")
    omega_mid = 0.5 * (omega[step:] + omega[:-step])
    sel = np.isfinite(tilt_rate) & (tilt_rate > min_tilt_rate)
    if sel.sum() < max(20, int(0.2 * fs)):
        return None
    ratio = float(np.median(omega_mid[sel] / tilt_rate[sel]))
    if raise_error and not (0.2 < ratio < 20.0):
        hint = (
            "values look like rad/s labelled deg/s"
            if ratio <= 0.2
            else "values look like deg/s labelled rad/s"
        )
        raise UnitsError(
            f"gyroscope units {gyr_units!r} are implausible: the gyroscope norm is {ratio:.3g}× the "
            f"rotation rate of the acceleration direction (expected ≥ ~0.5 and ≲ a few); {hint}. "
            "Fix the 'units' attribute, or pass check_units=False to validate()."
        )
    return ratio


# one implementation, in the validation module (imported last: it imports this module)
from ._validate import check_fs  # noqa: E402
