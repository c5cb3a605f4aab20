"""Collect every finding of a Recording, and apply the policy: errors raised, the rest warned."""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import xarray as xr

from .._stack import user_stacklevel
from .._deprecate import renamed
from ._common import (
    Finding,
    QualityWarning,
    UnitCheckError,
    _VECTORS,
)
from .clipping import (
    check_raw_counts,
    check_saturation,
)
from .unitcheck import (
    check_acc_units,
    check_gyr_units,
    check_temperature,
)


@renamed(ds="rec")
def plausibility(rec: xr.Dataset) -> list[Finding]:
    """Return every plausibility finding of a Recording's values against their units.

    Raw counts, accelerometer and gyroscope units, temperature (see the ``check_*``
    functions); a variable found to hold raw counts is not checked further. NaN samples
    are ignored.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording (``ds`` is its old name).

    Returns
    -------
    list of Finding
        Errors and warnings, in the order of the checks.
    """
    out: list[Finding] = []
    counts = set()
    for name in _VECTORS:
        if name in rec:
            f = check_raw_counts(rec, var=name)
            if f is not None:
                out.append(f)
                counts.add(name)
    if "acc" in rec and "acc" not in counts:
        f = check_acc_units(rec, var="acc")
        if f is not None:
            out.append(f)
    if "gyr" in rec and "gyr" not in counts:
        f = check_gyr_units(rec, var="gyr")
        if f is not None:
            out.append(f)
    if "temp" in rec:
        f = check_temperature(rec, var="temp")
        if f is not None:
            out.append(f)
    return out


@renamed(ds="rec")
def assess(
    rec: xr.Dataset, *, units: bool = True, saturation: bool = True
) -> list[Finding]:
    """Return all quality findings of a Recording, without raising or warning.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording (``ds`` is its old name).
    units : bool
        Include the plausibility of the values against their units
        (:func:`plausibility`).
    saturation : bool
        Include clipped samples and stale full scales
        (:func:`~tiltlab.quality.check_saturation`).

    Returns
    -------
    list of Finding
        The plausibility findings, then the saturation ones.
    """
    out: list[Finding] = []
    if units:
        out += plausibility(rec)
    if saturation:
        out += check_saturation(rec)
    return out


def emit(findings: Sequence[Finding]) -> None:
    """Raise the error findings, else warn each warning as a :class:`QualityWarning`.

    Parameters
    ----------
    findings : sequence of Finding
        As returned by :func:`assess`.

    Raises
    ------
    UnitCheckError
        (a :class:`~tiltlab.RecordingError`) When a finding is an error; its message
        joins every error's message.
    """
    errors = [f for f in findings if f.is_error]
    if errors:
        raise UnitCheckError(errors)
    level = user_stacklevel()
    for f in findings:
        warnings.warn(f.message, QualityWarning, stacklevel=level)
