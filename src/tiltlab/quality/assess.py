"""Every finding of a Recording, and the policy: errors raised, the rest warned."""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Sequence

import xarray as xr

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


def plausibility(ds: xr.Dataset) -> list[Finding]:
    """Every plausibility finding of a Recording: raw counts, accelerometer and gyroscope
    units, temperature (see the ``check_*`` functions). NaN samples are ignored.
    """
    out: list[Finding] = []
    counts = set()
    for name in _VECTORS:
        if name in ds:
            f = check_raw_counts(ds, var=name)
            if f is not None:
                out.append(f)
                counts.add(name)
    if "acc" in ds and "acc" not in counts:
        f = check_acc_units(ds, var="acc")
        if f is not None:
            out.append(f)
    if "gyr" in ds and "gyr" not in counts:
        f = check_gyr_units(ds, var="gyr")
        if f is not None:
            out.append(f)
    if "temp" in ds:
        f = check_temperature(ds, var="temp")
        if f is not None:
            out.append(f)
    return out


def assess(
    ds: xr.Dataset, *, units: bool = True, saturation: bool = True
) -> list[Finding]:
    """All quality findings of a Recording (plausibility, then saturation), without
    raising or warning. ``units`` / ``saturation`` select the checks.
    """
    out: list[Finding] = []
    if units:
        out += plausibility(ds)
    if saturation:
        out += check_saturation(ds)
    return out


def _stacklevel() -> int:
    """The stack level of the first caller outside tiltlab, for :func:`warnings.warn`
    called from :func:`emit`.
    """
    pkg = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # tiltlab
    frame = sys._getframe(1)  # emit
    level = 1
    while frame.f_back is not None and os.path.abspath(
        frame.f_code.co_filename
    ).startswith(pkg + os.sep):
        frame = frame.f_back
        level += 1
    return level


def emit(findings: Sequence[Finding]) -> None:
    """Raise :class:`RecordingError` with every error's message (joined by ``"; "``),
    else warn each warning as a :class:`QualityWarning`.
    """
    errors = [f for f in findings if f.is_error]
    if errors:
        raise UnitCheckError(errors)
    level = _stacklevel()
    for f in findings:
        warnings.warn(f.message, QualityWarning, stacklevel=level)
