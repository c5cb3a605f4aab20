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

from .._stack import user_stacklevel
import tiltlab._deprecate as _deprecate
from .. import schema
from ..quality import QualityWarning
from ._common import PathLike, ReadError, sensor_recording
from .ncfile import open_netcdf

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
        The file opened with :func:`tiltlab.io.open_netcdf`.

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
    """Tell whether an opened NetCDF file has the tag-tools layout (a sensor with a rate).

    Parameters
    ----------
    ds : xarray.Dataset
        The opened file.

    Returns
    -------
    bool
        True if a variable has a tiltlab role and a sampling rate.
    """
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
    """Return the variable's values with samples along the first axis."""
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
    """Tiltlab axes (``["x", "-y", "z"]``) from a tag-tools axes attribute (``"FRU"``)."""
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
    found = _select_sensors(ds, path, variables)
    fs = _common_rate(ds, found, path)
    widths = {"acc": 3, "mag": 3, "gyr": 3, "depth": 1, "temp": 1}
    data = {r: _samples_first(ds[n], path, widths[r]) for r, n in found.items()}
    data = _same_length(data, found, path)
    given = {"acc": acc_units, "mag": mag_units, "gyr": gyr_units}
    units = _sensor_units(ds, found, path, given)
    axis_kw = _axis_options(ds, found, path, axes, preset)
    meta, extra, t0 = _metadata(ds, found, data, path)
    try:
        return sensor_recording(
            data,
            fs,
            units,
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


def _select_sensors(
    ds: xr.Dataset, path: Path, variables: Sequence[str] | None
) -> dict[str, str]:
    """Role → variable name of the sensors to read (``acc`` required)."""
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
    return found


def _common_rate(ds: xr.Dataset, found: Mapping[str, str], path: Path) -> float:
    """Find the one sampling rate of the sensors; different rates are refused."""
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
    return distinct[0]


def _same_length(
    data: dict[str, np.ndarray], found: Mapping[str, str], path: Path
) -> dict[str, np.ndarray]:
    """Cut the sensors to a common length (a few samples at most, with a warning)."""
    lengths = {found[r]: len(v) for r, v in data.items()}
    n = min(lengths.values())
    if max(lengths.values()) == n:
        return data
    listed = ", ".join(f"{k} {v}" for k, v in lengths.items())
    if max(lengths.values()) - n > max(2, 0.01 * n):
        raise ReadError(
            f"{path}: sensors at the same rate have different lengths "
            f"({listed}); they do not cover the same time: read some with "
            "variables=[...]"
        )
    warnings.warn(
        f"{path.name}: sensors differ in length by "
        f"{max(lengths.values()) - n} sample(s) ({listed}); kept the first {n}",
        QualityWarning,
        stacklevel=user_stacklevel(),
    )
    return {r: v[:n] for r, v in data.items()}


def _sensor_units(
    ds: xr.Dataset,
    found: Mapping[str, str],
    path: Path,
    given: Mapping[str, str | None],
) -> dict[str, str | None]:
    """Each sensor's unit: as given, else as the file states it."""
    units: dict[str, str | None] = {
        r: _unit(ds[found[r]]) for r in ("acc", "mag", "gyr", "temp") if r in found
    }
    units.update({r: u for r, u in given.items() if u is not None and r in found})
    no_unit = [found[r] for r, u in units.items() if not u]
    if no_unit:
        raise ReadError(
            f"{path}: variable(s) {no_unit} state no unit; give them, e.g. "
            "acc_units='m/s^2', mag_units='uT' (tag-tools' defaults)"
        )
    return units


def _axis_options(
    ds: xr.Dataset,
    found: Mapping[str, str],
    path: Path,
    axes: Sequence[str] | Mapping[str, Sequence[str]] | None,
    preset: str | None,
) -> dict[str, Any]:
    """``axes``/``preset`` for make_recording, from the arguments or the file's axes."""
    if axes is not None or preset is not None:
        # a tag-tools frame is left-handed unless a preset says otherwise
        return {"axes": axes, "preset": preset or "tagtools"}
    codes = {
        r: str(_attr(ds[found[r]], "axes") or "FRU")
        for r in ("acc", "mag", "gyr")
        if r in found
    }
    specs = {r: _axes_spec(c, found[r], path) for r, c in codes.items()}
    if all(c.strip().upper() == "FRU" for c in codes.values()):
        return {"preset": "tagtools"}
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
    return {
        "preset": "tagtools" if hand == "left" else "animal",
        "axes": {"*": specs.get("acc", next(iter(specs.values()))), **specs},
    }


def _metadata(
    ds: xr.Dataset, found: Mapping[str, str], data: Mapping[str, np.ndarray], path: Path
) -> tuple[dict[str, Any], dict[str, Any], float]:
    """Provenance attributes, the depth variable (if any) and the start offset."""
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
    return meta, extra, t0


#: tag-tools variable name of each Recording variable written by :func:`write_tagtools`.
_WRITE_NAMES = {"acc": "A", "mag": "M", "gyr": "G", "temp": "T"}


@_deprecate.renamed(recording="rec")
def write_tagtools(
    rec: xr.Dataset,
    path: PathLike,
    *,
    axes: str = "FRU",
    format: str = "NETCDF4",
) -> Path:
    """Write a Recording in the tag-tools (animaltags) NetCDF layout.

    Each sensor becomes one variable (``A`` acceleration, ``M`` magnetometer, ``G``
    gyroscope, ``T`` temperature) over dimensions ``"<name> samples"`` and ``"<name>
    axes"``, with ``sampling_rate`` (Hz), ``unit`` (the Recording's own units, never
    converted) and ``axes``: one letter per column saying where it points (F/B
    forward/back, L/R left/right, U/D up/down). The default ``"FRU"`` is tag-tools'
    convention, a left-handed frame: its columns are the Recording's x, −y and z.
    Samples must be on a uniform grid (tag-tools has no time variable): gaps stay NaN.
    The Recording's ``session`` (or ``subject``) becomes the global ``depid``. The file
    reads back with :func:`read_tagtools`.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording (``acc``; ``mag``, ``gyr``, ``temp`` written when present).
    path : path-like
        The ``.nc`` file to write (replaced if it exists).
    axes : str
        Three letters, one per column, from F/B, L/R and U/D (one of each pair).
    format : {"NETCDF4", "NETCDF3_64BIT"}
        NetCDF-4 (HDF5) or the classic NetCDF-3 format that older tag-tools
        installations read.

    Returns
    -------
    pathlib.Path
        The path written.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from tiltlab import io, simulate
    >>> rec = simulate.simulate_session(5.0, 50.0, seed=1)
    >>> p = io.write_tagtools(rec, pathlib.Path(tempfile.mkdtemp()) / "tag.nc")
    >>> back = io.read_tagtools(p)
    >>> bool(abs(back["acc"] - rec["acc"].values).max() < 1e-12)
    True
    """
    if not isinstance(rec, xr.Dataset) or "acc" not in rec:
        raise TypeError("write_tagtools needs a Recording (an xarray.Dataset with acc)")
    schema.validate(rec, allow_nan=True, check_units=False)
    path = Path(path)
    code = str(axes).strip().upper()
    if len(code) != 3 or sorted(_LETTERS[c][0] for c in code if c in _LETTERS) != [
        0,
        1,
        2,
    ]:
        raise ValueError(
            f"axes must be three letters, one of F/B, one of L/R and one of U/D, one "
            f"per column (e.g. 'FRU'), got {axes!r}"
        )
    spec = _axes_spec(code, "axes", path)  # column k holds sign * our axis
    columns = [(1.0 if a[0] != "-" else -1.0, "xyz".index(a[-1])) for a in spec]
    order = [None] * 3
    for our_axis, (sign, col) in enumerate(columns):
        order[col] = (our_axis, sign)
    if format not in ("NETCDF4", "NETCDF3_64BIT"):
        raise ValueError(f"format must be 'NETCDF4' or 'NETCDF3_64BIT', got {format!r}")
    fs = float(rec.attrs["fs"])
    out = {}
    for var, name in _WRITE_NAMES.items():
        if var not in rec:
            continue
        da = rec[var]
        attrs = {
            "sampling_rate": fs,
            "sampling_rate_unit": "Hz",
            "unit": str(da.attrs.get("units", "")),
            "long_name": str(da.attrs.get("long_name", var)),
            "frame": "tag",
        }
        if da.ndim == 2:
            values = np.column_stack(
                [s * da.values[:, a] for a, s in order]  # type: ignore[misc]
            )
            dims: tuple[str, ...] = (f"{name} samples", f"{name} axes")
            attrs["axes"] = code
        else:
            values, dims = np.asarray(da.values, float), (f"{name} samples",)
        out[name] = (dims, values.astype(float), attrs)
    glob = {
        "depid": str(rec.attrs.get("session") or rec.attrs.get("subject", "")),
        "creator": "tiltlab.io.write_tagtools",
    }
    ds = xr.Dataset(out, attrs={k: v for k, v in glob.items() if v})
    path.parent.mkdir(parents=True, exist_ok=True)
    engine = "scipy" if format == "NETCDF3_64BIT" else None
    ds.to_netcdf(path, format=format, engine=engine)
    return path
