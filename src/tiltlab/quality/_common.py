"""Hold the shared pieces of the quality checks.

The thresholds, the finding record, the unit-check error and the reading of a variable
with its units.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .. import _validate
from .. import units as _units
from .._validate import RecordingError


#: Plausible median magnitude of an accelerometer (g): gravity dominates any recording.
ACC_MEDIAN_G: tuple[float, float] = (0.5, 2.0)
#: Median |acc| (g) beyond which the values cannot be physical (raw counts or wrong scale).
ACC_COUNTS_G: float = 50.0
#: 99th percentile of |gyr| (°/s) beyond which the values cannot be physical.
GYR_COUNTS_DEG_S: float = 10_000.0
#: Median |mag| (µT) beyond which the values cannot be physical (Earth: 25–65 µT).
MAG_COUNTS_UT: float = 10_000.0
#: 99th percentile of |gyr| (rad/s): above the first, a "rad/s" gyroscope looks like °/s
#: (warning); above the second, beyond any MEMS gyroscope's full scale, it must be (error).
GYR_RAD_S_P99: tuple[float, float] = (40.0, 100.0)
#: Operating range of MEMS inertial sensors (°C).
TEMP_RANGE_DEGC: tuple[float, float] = (-40.0, 85.0)

_VECTORS = ("acc", "gyr", "mag")
_PHYSICAL = {
    "acc": ("acceleration", "g", ACC_COUNTS_G, "median"),
    "gyr": ("angular velocity", "deg/s", GYR_COUNTS_DEG_S, "99th percentile"),
    "mag": ("magnetic field", "uT", MAG_COUNTS_UT, "median"),
}
_PRETTY = {"m/s^2": "m/s²", "deg/s": "°/s", "uT": "µT", "degC": "°C"}


class QualityWarning(UserWarning):
    """Data that satisfy the Recording contract but look doubtful (e.g. clipped samples)."""


#: The one switch that accepts unit labels as they are, in the form each entry point
#: takes it (the error message names the one the user is using).
UNIT_CHECK_SWITCH: dict[str, str] = {
    "python": "check_units=False",
    "mapping": '"check_units": false in the mapping',
    "cli": "--no-check-units",
    "manifest": 'reader_options {"check_units": false} in its manifest row',
}


class UnitCheckError(RecordingError):
    """Values that decisively contradict their unit labels.

    The message names every such variable and the unit its values look like, then the
    switch that accepts the labels as they are, in the form of the entry point in use
    (:data:`UNIT_CHECK_SWITCH`; :meth:`for_switch` re-words it).

    Attributes
    ----------
    findings : tuple of Finding
        The error findings, one per variable.
    switch : str
        A key of :data:`UNIT_CHECK_SWITCH`.
    """

    def __init__(self, findings: Sequence[Finding], switch: str = "python"):
        self.findings = tuple(findings)
        self.switch = switch if switch in UNIT_CHECK_SWITCH else "python"
        body = "; ".join(f.message for f in self.findings)
        super().__init__(
            f"{body}. If the labels are right after all, "
            f"{UNIT_CHECK_SWITCH[self.switch]} accepts them as they are"
        )

    def for_switch(self, switch: str) -> UnitCheckError:
        """Return the same error, naming the switch as ``switch`` takes it.

        Parameters
        ----------
        switch : str
            A key of :data:`UNIT_CHECK_SWITCH`.

        Returns
        -------
        UnitCheckError
            The re-worded error.
        """
        return UnitCheckError(self.findings, switch)

    def __reduce__(self):
        """Make the error picklable across process pools."""
        return (UnitCheckError, (self.findings, self.switch))


@dataclass(frozen=True)
class Finding:
    """One result of a quality check.

    Attributes
    ----------
    var : str
        The variable concerned (``"acc"``, ``"gyr"``, ``"mag"``, ``"temp"``).
    check : str
        Which check: ``"saturation"``, ``"range"``, ``"raw_counts"``, ``"acc_units"``,
        ``"gyr_units"`` or ``"temperature"``.
    severity : str
        ``"error"`` or ``"warning"`` (see the module's policy).
    message : str
        One line naming the variable, the problem and the fix.
    value : float, optional
        The number behind it (fraction clipped, median magnitude, percentile…).
    """

    var: str
    check: str
    severity: str
    message: str
    value: float | None = None

    @property
    def is_error(self) -> bool:
        """Whether the finding is an error (else a warning)."""
        return self.severity == "error"


def _u(unit: str) -> str:
    return _PRETTY.get(unit, unit)


# --------------------------------------------------------------------------- reading


def _raw_dtype(x, var: str):
    if isinstance(x, xr.Dataset):
        return x[var].dtype if var in x else np.dtype(float)
    if isinstance(x, xr.DataArray):
        return x.dtype
    try:
        return np.asarray(x).dtype
    except (TypeError, ValueError):  # pragma: no cover - reported by _validate
        return np.dtype(object)


def _read(x, name: str, *, units: str | None = None, need_units: bool = True):
    """Read a variable with its units, attrs and sampling rate.

    Returns the values (2-D, float, NaN kept), the canonical units (or None), the
    variable's attrs, fs, and whether the input had an integer dtype.
    """
    kind = _raw_dtype(x, name).kind
    if isinstance(x, xr.Dataset):
        # a Recording's variables: read directly (its time/fs consistency and shapes are
        # validate's business, with its tolerances); values are only read, never written
        if name not in x:
            raise RecordingError(f"the Recording has no variable {name!r}")
        da = x[name]
        fs = x.attrs.get("fs")
        fs = (
            None
            if fs is None
            else _validate.check_fs(fs, "the Recording's attribute fs")
        )
        u = da.attrs.get("units")
        if units is not None:
            u = u if u is not None else units
            if _units.normalise_unit(units) != _units.normalise_unit(u):
                raise RecordingError(
                    f"{name}: units = {units!r} contradicts the data's units {u!r}"
                )
        if u is None and need_units:
            raise RecordingError(f"{name}: its units are unknown (add attrs['units'])")
        v = np.asarray(da.values, dtype=float)
        if v.ndim == 1:
            v = v[:, None]
        elif v.ndim != 2:
            raise RecordingError(f"{name} must have dims (time,) or (time, axis)")
        u = None if u is None else _units.normalise_unit(u)
        return v, u, dict(da.attrs), fs, kind in "iu"
    sig = _validate.signal(
        x,
        name,
        units=units,
        need_fs=False,
        need_units=need_units,
        width=None,
        ndim=None,
        allow_nan=True,
    )
    v = sig.values
    if v.ndim == 1:
        v = v[:, None]
    elif v.ndim != 2:
        raise ValueError(f"{name} must have shape (N,) or (N, k), got {v.shape}")
    attrs = dict(x.attrs) if isinstance(x, xr.DataArray) else {}
    return v, sig.units, attrs, sig.fs, kind in "iu"


def _finite_rows(v: np.ndarray) -> np.ndarray:
    return v[np.isfinite(v).all(axis=1)]


def _integral(v: np.ndarray, is_int: bool) -> bool:
    if is_int:
        return True
    f = v[np.isfinite(v)]
    return bool(f.size) and bool(np.all(f == np.round(f)))


# --------------------------------------------------------------------------- saturation


def _name(x, var: str | None) -> str:
    if var is not None:
        return var
    if isinstance(x, xr.DataArray) and x.name is not None:
        return str(x.name)
    raise ValueError("give var= (e.g. var='acc') to name the data")
