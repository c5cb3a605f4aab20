"""Name the physical units of tiltlab Recordings and convert between them.

What belongs here: the table of accepted units per quantity, their spellings and the
multiplicative conversions. What does not: any check of values against their unit
labels (accelerometer ~1 g, raw ADC counts, the gyroscope's °/s-or-rad/s check,
temperature) and sensor saturation, which live in :mod:`tiltlab.quality`
(:func:`tiltlab.quality.check_gyr_units` is the one gyroscope-unit check);
:func:`tiltlab.schema.validate` runs them.

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

    Parameters
    ----------
    unit : str
        A unit spelling, canonical or an alias (case-insensitive, surrounding spaces
        ignored), e.g. ``"m/s2"``, ``"°/s"``, ``"dps"``.

    Returns
    -------
    str
        The canonical spelling, one of :data:`UNITS`.

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
    """Return the name of the physical quantity that ``unit`` measures.

    Parameters
    ----------
    unit : str
        A unit (any accepted spelling).

    Returns
    -------
    str
        A key of :data:`UNITS`, e.g. ``"angular_velocity"``.

    Examples
    --------
    >>> quantity_of("dps")
    'angular_velocity'
    """
    u = normalise_unit(unit)
    for q, us in UNITS.items():
        if u in us:
            return q
    raise UnitsError(f"unit {unit!r} has no quantity")  # pragma: no cover


def conversion_factor(src: str, dst: str) -> float:
    """Multiplicative factor converting values in ``src`` units to ``dst`` units.

    Temperatures (an affine conversion) and arbitrary units are refused.

    Parameters
    ----------
    src, dst : str
        Source and destination units (any accepted spelling); both must measure the same
        quantity.

    Returns
    -------
    float
        The factor ``f`` such that ``value_dst = f * value_src`` (``1.0`` if the units
        are the same).

    Raises
    ------
    UnitsError
        If a unit is unknown, the units measure different quantities, or their
        conversion is not multiplicative (temperatures, arbitrary units).
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
    """Return ``values`` (array-like) converted from ``src`` to ``dst`` units (a new array).

    Parameters
    ----------
    values : array_like
        Values in ``src`` units, any shape.
    src, dst : str
        Source and destination units (see :func:`conversion_factor`).

    Returns
    -------
    numpy.ndarray of float
        A new array of the shape of ``values``, in ``dst`` units.
    """
    return np.asarray(values, dtype=float) * conversion_factor(src, dst)


def acc_to_g(values, units: str) -> np.ndarray:
    """Acceleration in g from ``units`` ('g' or 'm/s^2').

    Parameters
    ----------
    values : array_like
        Accelerations, any shape (typically (N, 3)).
    units : str
        Units of ``values``: ``"g"`` or ``"m/s^2"`` (or an alias).

    Returns
    -------
    numpy.ndarray of float
        A new array of the shape of ``values``, in g (1 g = 9.80665 m/s²).
    """
    return convert(values, units, "g")


def gyr_to_rad_s(values, units: str) -> np.ndarray:
    """Angular velocity in rad/s from ``units`` ('deg/s' or 'rad/s').

    Parameters
    ----------
    values : array_like
        Angular velocities, any shape (typically (N, 3)).
    units : str
        Units of ``values``: ``"deg/s"`` or ``"rad/s"`` (or an alias).

    Returns
    -------
    numpy.ndarray of float
        A new array of the shape of ``values``, in rad/s.
    """
    return convert(values, units, "rad/s")
