"""tag-tools (animaltags) NetCDF archives: bio-logging sensor streams into a Recording.

The tag-tools packages (R, MATLAB, Python; animaltags.org) store each sensor stream as
one NetCDF variable named by its abbreviation (``A`` acceleration, ``M`` magnetometer,
``G`` gyroscope, ``P`` depth/pressure, ``T`` temperature …) whose attributes describe
it: ``sampling_rate`` and ``sampling_rate_unit``, ``unit``, ``frame`` (``"tag"`` or
``"animal"``) and ``axes``, one letter per column saying where the column points
(``"FRU"``: forward, right, up; tag-tools' default and a left-handed frame). The
sample dimension is named ``"<name> samples"``; its place (first or last) depends on
the writer, so it is found by name, not by position. Deployment metadata are global
attributes (``depid`` …). Files are NetCDF-4 (HDF5) or NetCDF-3 (classic); both are read.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .. import schema
from ..quality import QualityWarning
from ._common import PathLike, ReadError
from .netcdf import open_netcdf

#: tiltlab role of each tag-tools variable name (first match wins).
ROLES: dict[str, tuple[str, ...]] = {
    "acc": ("A", "Aa", "Acc", "acc"),
    "mag": ("M", "Ma", "Mag", "mag"),
    "gyr": ("G", "Gyr", "gyr", "Gyro", "gyro"),
    "depth": ("P", "D", "Depth", "depth"),
    "temp": ("T", "Temp", "temp"),
}

#: tag-tools ``type`` attribute → role, for files whose variable names differ.
_TYPES = {"acc": "acc", "mag": "mag", "gyr": "gyr", "press": "depth", "temp": "temp"}

#: tag-tools unit spellings that tiltlab spells differently.
_UNITS = {
    "rads/s": "rad/s",
    "radians/s": "rad/s",
    "degrees/s": "deg/s",
    "degrees c": "degC",
    "degrees celsius": "degC",
    "\\mut": "uT",
    "mut": "uT",
    "micro tesla": "uT",
    "m/s^2": "m/s^2",
}

#: axis letters of tag-tools ``axes`` attributes → (our axis index, sign):
#: forward/left/up are +x/+y/+z of tiltlab's [forward, left, up] sensor frame.
_LETTERS = {
    "F": (0, 1),
    "B": (0, -1),
    "L": (1, 1),
    "R": (1, -1),
    "U": (2, 1),
    "D": (2, -1),
}


def _attr(var: xr.DataArray, *names: str) -> Any:
    for n in names:
        if n in var.attrs:
            v = var.attrs[n]
            if isinstance(v, bytes):
                v = v.decode("utf-8", "replace")
            if isinstance(v, np.ndarray) and v.size == 1:
                v = v.item()
            return v
    return None


def _unit(var: xr.DataArray) -> str | None:
    u = _attr(var, "unit", "units")
    if u is None:
        return None
    u = str(u).strip()
    return _UNITS.get(u.lower(), u)


def sensor_variables(ds: xr.Dataset) -> dict[str, str]:
    """Which variables of a tag-tools file hold which sensor: ``{role: name}``.

    Parameters
    ----------
    ds
        The file opened with :func:`tiltlab.io.netcdf.open_netcdf`.

    Returns
    -------
    dict
        Roles ``acc``, ``mag``, ``gyr``, ``depth``, ``temp`` found, each mapped to the
        variable's name; a variable counts only if it has a ``sampling_rate``.
    """
    found: dict[str, str] = {}
    rated = [str(n) for n in ds.data_vars if "sampling_rate" in ds[n].attrs]
    for role, names in ROLES.items():
        for n in names:
            if n in rated:
                found[role] = n
                break
    for n in rated:
        t = _attr(ds[n], "type")
        role = _TYPES.get(str(t).lower()) if t is not None else None
        if role and role not in found and n not in found.values():
            found[role] = n
    return found


def looks_like_tagtools(ds: xr.Dataset) -> bool:
    """True if an opened NetCDF file has the tag-tools layout (a sensor with a rate)."""
    return bool(sensor_variables(ds))


def _rate(var: xr.DataArray, path: Path) -> float:
    fs = _attr(var, "sampling_rate")
    try:
        fs = float(np.asarray(fs).ravel()[0])
    except (TypeError, ValueError, IndexError):
        raise ReadError(
            f"{path}: variable {var.name!r} has sampling_rate {fs!r}, not a number"
        ) from None
    unit = str(_attr(var, "sampling_rate_unit", "sampling_rate_units") or "Hz")
    scale = {"hz": 1.0, "khz": 1e3, "1/s": 1.0, "s-1": 1.0}.get(unit.strip().lower())
    if scale is None:
        raise ReadError(
            f"{path}: variable {var.name!r} has sampling_rate_unit {unit!r}; tiltlab "
            "reads rates in Hz or kHz"
        )
    if not np.isfinite(fs) or fs <= 0:
        raise ReadError(f"{path}: variable {var.name!r} has sampling rate {fs} Hz")
    return fs * scale


def _samples_first(var: xr.DataArray, path: Path, width: int | None) -> np.ndarray:
    """The variable's values with samples along the first axis."""
    values = np.asarray(var.values, dtype=float)
    if values.ndim == 1:
        return values if width in (None, 1) else values.reshape(-1, 1)
    if values.ndim != 2:
        raise ReadError(
            f"{path}: variable {var.name!r} has {values.ndim} dimensions "
            f"{var.dims}; expected (samples, axes)"
        )
    dims = [str(d).lower() for d in var.dims]
    if dims[1].endswith("samples") and not dims[0].endswith("samples"):
        values = values.T
    elif not dims[0].endswith("samples"):
        # no dimension named '... samples': the longer one is time
        if values.shape[1] > values.shape[0]:
            values = values.T
    if width is not None and values.shape[1] != width:
        raise ReadError(
            f"{path}: variable {var.name!r} has {values.shape[1]} columns, "
            f"expected {width}"
        )
    return values


def _axes_spec(letters: str, name: str, path: Path) -> list[str]:
    """tiltlab axes (``["x", "-y", "z"]``) from a tag-tools axes attribute (``"FRU"``)."""
    code = letters.strip().upper()
    placed: dict[int, str] = {}
    if len(code) == 3 and all(c in _LETTERS for c in code):
        for col, c in enumerate(code):
            axis, sign = _LETTERS[c]
            placed.setdefault(axis, ("-" if sign < 0 else "") + "xyz"[col])
    if len(placed) != 3:
        raise ReadError(
            f"{path}: variable {name!r} has axes {letters!r}, which tiltlab cannot place "
            "in a tag frame (it reads the letters F/B, L/R, U/D, one per column); "
            "give axes=['x', '-y', 'z'] (CLI: --preset NAME, or \"axes\" in the "
            "mapping) saying which column points forward, left and up"
        )
    return [placed[0], placed[1], placed[2]]


def _handedness(spec: list[str]) -> str:
    m = np.zeros((3, 3))
    for row, a in enumerate(spec):
        m[row, "xyz".index(a[-1])] = -1.0 if a.startswith("-") else 1.0
    return "left" if np.linalg.det(m) < 0 else "right"


def read_tagtools(
    path: PathLike,
    *,
    variables: Sequence[str] | None = None,
    axes: Sequence[str] | Mapping[str, Sequence[str]] | None = None,
    preset: str | None = None,
    acc_units: str | None = None,
    mag_units: str | None = None,
    gyr_units: str | None = None,
    check_units: bool = True,
    **attrs: Any,
) -> xr.Dataset:
    """Read a tag-tools (animaltags) NetCDF archive into a Recording.

    Parameters
    ----------
    path
        A ``.nc`` file written by tag-tools' ``save_nc``/``add_nc`` (NetCDF-4 or -3).
    variables : sequence of str, optional
        Names of the variables to read (e.g. ``["A", "M"]``); default every sensor
        found (acceleration ``A``, magnetometer ``M``, gyroscope ``G``, depth ``P``,
        temperature ``T``). An acceleration variable is required; the rest is optional.
    axes, preset : optional
        Override the axes read from the file's ``axes`` attributes (see
        :func:`tiltlab.axes.remap`). By default ``"FRU"`` (tag-tools' left-handed
        [forward, right, up]) gives preset ``"tagtools"`` and other F/B/L/R/U/D codes
        their own mapping; the result is always tiltlab's [forward, left, up]. Axes
        given without a preset are taken as those of a left-handed tag-tools frame.
    acc_units, mag_units, gyr_units : str, optional
        Units to use where the file states none, or states one wrongly.
    check_units : bool
        Check the values against their units (:func:`tiltlab.schema.validate`).
    **attrs
        Extra dataset attributes (``subject``, ``session`` …).

    Returns
    -------
    xarray.Dataset
        A Recording: ``acc``, optional ``gyr``, ``mag``, ``temp``; depth as the extra
        variable ``depth`` with its file unit. ``fs`` is the sensors' common rate.

    Raises
    ------
    ReadError
        If the file cannot be read, has no acceleration, states no usable unit or
        axes, or its sensors are sampled at different rates (named in the message).

    Examples
    --------
    >>> from tiltlab import io
    >>> rec = io.read_tagtools("deployment.nc")  # doctest: +SKIP
    >>> rec.attrs["axis_labels"]  # doctest: +SKIP
    ['forward', 'left', 'up']
    """
    path = Path(path)
    ds = open_netcdf(path)
    found = sensor_variables(ds)
    if variables is not None:
        wanted = [str(v) for v in variables]
        missing = [v for v in wanted if v not in ds.data_vars]
        if missing:
            raise ReadError(
                f"{path}: no variable(s) {missing}; sensor variables in the file: "
                + ", ".join(found.values())
            )
        found = {r: n for r, n in found.items() if n in wanted}
    if "acc" not in found:
        raise ReadError(
            f"{path}: no acceleration variable (A) with a sampling_rate; "
            "sensor variables found: "
            + (", ".join(f"{n} ({r})" for r, n in found.items()) or "none")
        )
    rates = {n: _rate(ds[n], path) for n in found.values()}
    distinct = sorted(set(rates.values()))
    if len(distinct) > 1:
        listed = ", ".join(f"{n} {fs:g} Hz" for n, fs in rates.items())
        same = [n for n, fs in rates.items() if fs == rates[found["acc"]]]
        raise ReadError(
            f"{path}: sensors are sampled at different rates ({listed}); a Recording "
            f"has one rate: read those at the accelerometer's rate with "
            f"variables={same!r}, or decimate the others to "
            f"{rates[found['acc']]:g} Hz first (tag-tools decdc)"
        )
    fs = distinct[0]
    widths = {"acc": 3, "mag": 3, "gyr": 3, "depth": 1, "temp": 1}
    data = {r: _samples_first(ds[n], path, widths[r]) for r, n in found.items()}
    lengths = {found[r]: len(v) for r, v in data.items()}
    n = min(lengths.values())
    if max(lengths.values()) != n:
        if max(lengths.values()) - n > max(2, 0.01 * n):
            raise ReadError(
                f"{path}: sensors at the same rate have different lengths "
                f"({', '.join(f'{k} {v}' for k, v in lengths.items())}); they do not "
                "cover the same time: read some with variables=[...]"
            )
        warnings.warn(
            f"{path.name}: sensors differ in length by "
            f"{max(lengths.values()) - n} sample(s) "
            f"({', '.join(f'{k} {v}' for k, v in lengths.items())}); "
            f"kept the first {n}",
            QualityWarning,
            stacklevel=2,
        )
        data = {r: v[:n] for r, v in data.items()}

    units: dict[str, str | None] = {
        r: _unit(ds[found[r]]) for r in ("acc", "mag", "gyr", "temp") if r in found
    }
    for role, given in (("acc", acc_units), ("mag", mag_units), ("gyr", gyr_units)):
        if given is not None and role in found:
            units[role] = given
    no_unit = [found[r] for r, u in units.items() if not u]
    if no_unit:
        raise ReadError(
            f"{path}: variable(s) {no_unit} state no unit; give them, e.g. "
            "acc_units='m/s^2', mag_units='uT' (tag-tools' defaults)"
        )

    axis_kw: dict[str, Any] = {}
    if axes is not None or preset is not None:
        # a tag-tools frame is left-handed unless a preset says otherwise
        axis_kw = {"axes": axes, "preset": preset or "tagtools"}
    else:
        codes = {
            r: str(_attr(ds[found[r]], "axes") or "FRU")
            for r in ("acc", "mag", "gyr")
            if r in found
        }
        specs = {r: _axes_spec(c, found[r], path) for r, c in codes.items()}
        if all(c.strip().upper() == "FRU" for c in codes.values()):
            axis_kw = {"preset": "tagtools"}
        else:
            hands = {r: _handedness(spec) for r, spec in specs.items()}
            if len(set(hands.values())) > 1:
                raise ReadError(
                    f"{path}: the sensors' axes differ in handedness ("
                    + ", ".join(f"{found[r]} {codes[r]!r}" for r in codes)
                    + "); give axes={...} per sensor saying which column points "
                    "forward, left and up"
                )
            # tagtools: left-handed device frame; animal: right-handed; both label
            # the result forward, left, up
            hand = hands["acc"] if "acc" in hands else next(iter(hands.values()))
            axis_kw = {
                "preset": "tagtools" if hand == "left" else "animal",
                "axes": {"*": specs.get("acc", next(iter(specs.values()))), **specs},
            }
    frames = sorted(
        {
            str(_attr(ds[found[r]], "frame") or "tag")
            for r in ("acc", "mag", "gyr")
            if r in found
        }
    )

    extra = {}
    if "depth" in found:
        var = ds[found["depth"]]
        extra["depth"] = (
            "time",
            data["depth"].reshape(-1),
            {
                "units": str(_unit(var) or ""),
                "long_name": str(_attr(var, "full_name", "description") or "depth"),
                "source_variable": found["depth"],
            },
        )
    glob = {
        k: (v.decode() if isinstance(v, bytes) else v)
        for k, v in ds.attrs.items()
        if isinstance(v, (str, bytes, int, float)) and not isinstance(v, bool)
    }
    meta = {
        "source": path.name,
        "source_format": "tag-tools NetCDF",
        "source_variables": ", ".join(f"{r}={n}" for r, n in found.items()),
        "source_frame": ", ".join(frames),
    }
    if "depid" in glob:
        meta["deployment"] = str(glob["depid"])
    offset = _attr(ds[found["acc"]], "start_offset")
    try:
        t0 = float(offset) if offset is not None else 0.0
    except (TypeError, ValueError):
        t0 = 0.0
    try:
        return schema.make_recording(
            data["acc"],
            data.get("gyr"),
            fs,
            acc_units=units["acc"],
            gyr_units=units.get("gyr"),
            mag=data.get("mag"),
            mag_units=units.get("mag"),
            temp=data["temp"].reshape(-1) if "temp" in data else None,
            temp_units=units.get("temp"),
            t0=t0,
            extra=extra or None,
            attrs={**meta, **attrs},
            check_units=check_units,
            # missing samples (NaN) are kept as gaps, as read_csv(gaps="nan") does
            allow_nan=any(
                bool(np.isnan(v).any()) for v in data.values() if v.dtype.kind == "f"
            ),
            **axis_kw,
        )
    except ValueError as exc:
        if isinstance(exc, schema.RecordingError):
            raise
        raise ReadError(f"{path}: {exc}") from None
