"""Checking the column/unit mappings of :func:`tiltlab.io.read_csv` and
:func:`tiltlab.io.read_multi`: every key is checked here, once, and every message names
the key and the fix.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .. import _validate
from .. import axes as _axes
from .. import quality as _quality
from .. import units as _units
from ._common import PathLike, ReadError
from .clock import (
    FS_RANGE,
    CLOCK_POLICIES,
    DATETIME,
    GAP_POLICIES,
    MAX_GAP,
    TIME_UNITS,
    time_factor,
)


#: Number of columns each Recording variable takes.
WIDTH = {"acc": 3, "gyr": 3, "mag": 3, "temp": 1, "q_ref": 4}

#: Keys shared by the one-file and the multi-file mappings (what to do with the data).
COMMON_KEYS = (
    "description",
    "fs",
    "fs_range",
    "gaps",
    "clock",
    "max_gap",
    "check_units",
    "axes",
    "preset",
    "axis_labels",
    "attrs",
)
#: Keys of a one-file mapping (besides pandas.read_csv options).
MAPPING_KEYS = (
    "columns",
    "units",
    "time_column",
    "time_scale",
    "time_units",
    "range",
    "scale",
    *COMMON_KEYS,
    "read_csv",
)
_NOT_READ_KWARGS = {"filepath_or_buffer", "usecols", "dtype"}
_RAW_UNITS = {"counts", "count", "lsb", "raw", "adc", "digits", "bits"}


def read_csv_params() -> frozenset[str]:
    """Options of :func:`pandas.read_csv` that a mapping may give."""
    import inspect

    import pandas as pd

    return frozenset(inspect.signature(pd.read_csv).parameters) - _NOT_READ_KWARGS


def scaled_unit_hint(var: str, unit: object) -> str:
    """A hint for a unit that is a known one with a prefix (``mg``, ``mdps``) or raw
    ADC counts: read the column with a ``scale`` factor instead.
    """
    if not isinstance(unit, str):
        return ""
    key = unit.strip()
    if key.lower() in _RAW_UNITS:
        example = {"acc": ("g", "1/16384 (±2 g)"), "gyr": ("deg/s", "1/131 (±250 °/s)")}
        u, f = example.get(var, ("its physical unit", "1/sensitivity"))
        return (
            f"; for raw ADC counts give the physical unit and a factor, e.g. "
            f"units {{{var!r}: {u!r}}} and scale {{{var!r}: {f}}}"
        )
    for prefix in ("m", "milli", "milli-"):
        rest = key[len(prefix) :]
        if key.startswith(prefix) and rest:
            try:
                canon = _units.normalise_unit(rest)
            except _units.UnitsError:
                continue
            return (
                f"; {unit!r} looks like milli-{canon}: give units {{{var!r}: {canon!r}}} "
                f"and scale {{{var!r}: 0.001}}"
            )
    return ""


def load_mapping(mapping: Mapping[str, Any] | PathLike) -> tuple[dict[str, Any], str]:
    """The raw mapping as a dict, and a prefix naming it in messages."""
    if isinstance(mapping, Mapping):
        return dict(mapping), "mapping: "
    if not isinstance(mapping, (str, os.PathLike)):
        raise TypeError(
            f"mapping must be a dict or the path of a JSON file, got {type(mapping).__name__}"
        )
    path = Path(mapping)
    if not path.is_file():
        raise ReadError(f"{path}: no such mapping file")
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise ReadError(f"{path}: not a text (JSON) file ({exc.reason})") from None
    except json.JSONDecodeError as exc:
        raise ValueError(
            f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})"
        ) from None
    if not isinstance(raw, dict):
        raise ValueError(
            f"{path}: a mapping is a JSON object with keys 'columns' and 'units', "
            f"got a JSON {type(raw).__name__}"
        )
    return raw, f"mapping {path}: "


def check_unit(var: str, unit: Any, where: str) -> str:
    """A variable's unit in its canonical spelling."""
    try:
        return _units.normalise_unit(unit)
    except _units.UnitsError as exc:
        raise ValueError(
            f"{where}units[{var!r}]: {exc}{scaled_unit_hint(var, unit)}"
        ) from None


def check_time_unit(
    raw: Mapping[str, Any], time_column: Any, where: str, extra: Any = None
) -> tuple[float | None, str | None]:
    """The time column's unit from ``time_units``, ``time_scale`` (and ``extra``, a
    ``units['time']``): the factor to seconds (None for date-times) and the unit's
    name.
    """
    sources = {
        k: v
        for k, v in (("time_units", raw.get("time_units")), ("units['time']", extra))
        if v is not None
    }
    if any(str(v).strip() == DATETIME for v in sources.values()):
        if raw.get("time_scale") is not None or len(sources) > 1:
            raise ValueError(
                f"{where}time_units 'datetime' reads date-time text: give no other "
                "time unit or time_scale"
            )
        if time_column is None:
            raise ValueError(f"{where}a time unit is given but no time_column")
        return None, DATETIME
    factors = {k: time_factor(v, where) for k, v in sources.items()}
    if raw.get("time_scale") is not None:
        factors["time_scale"] = _validate.positive(
            raw["time_scale"], f"{where}time_scale"
        )
    if len(set(factors.values())) > 1:
        raise ValueError(
            f"{where}the time unit is given twice and disagrees: {factors} (factors to seconds)"
        )
    if factors and time_column is None:
        raise ValueError(f"{where}a time unit is given but no time_column")
    scale = float(next(iter(factors.values()), 1.0))
    name = next((u for u, f in TIME_UNITS.items() if np.isclose(f, scale)), None)
    return scale, name


def check_range(
    range_in: Any, mapped: Sequence[str], where: str
) -> dict[str, float | list[float]]:
    """``range``: variable → the sensor's full scale."""
    range_in = range_in or {}
    if not isinstance(range_in, Mapping):
        raise ValueError(
            f"{where}'range' must map variables to their full scale, e.g. "
            '{"acc": 16, "gyr": 2000}'
        )
    full: dict[str, Any] = {}
    for var, value in range_in.items():
        if var not in ("acc", "gyr", "mag"):
            raise ValueError(
                f"{where}range[{var!r}]: a full scale is given for acc, gyr or mag only"
            )
        if var not in mapped:
            raise ValueError(
                f"{where}range[{var!r}] is given but {var!r} is not mapped"
            )
        try:
            lo, hi = _quality.limits(value, f"{where}range[{var!r}]")
        except ValueError as exc:
            raise ValueError(str(exc)) from None
        full[var] = hi if np.isclose(-lo, hi) else [lo, hi]
    return full


def check_scale(scale_in: Any, mapped: Sequence[str], where: str) -> dict[str, float]:
    """``scale``: variable → factor from the column's numbers to its unit."""
    scale_in = scale_in or {}
    if not isinstance(scale_in, Mapping):
        raise ValueError(
            f"{where}'scale' must map variables to factors, e.g. "
            '{"acc": 0.001} for a column in mg read as g'
        )
    scale: dict[str, float] = {}
    for var, value in scale_in.items():
        if var not in mapped or var == "q_ref":
            raise ValueError(
                f"{where}scale[{var!r}]: a factor is given for a mapped acc, gyr, mag "
                "or temp only"
            )
        scale[var] = _validate.positive(value, f"{where}scale[{var!r}]")
    return scale


def check_read_options(
    raw: Mapping[str, Any], where: str, allowed: frozenset[str]
) -> dict[str, Any]:
    """pandas.read_csv options given at the top level or under ``read_csv``."""
    read_kwargs = {k: v for k, v in raw.items() if k in allowed}
    nested = raw.get("read_csv") or {}
    if not isinstance(nested, Mapping):
        raise ValueError(
            f"{where}'read_csv' must be a mapping of pandas.read_csv options"
        )
    bad = [k for k in nested if k not in allowed]
    if bad:
        raise ValueError(
            f"{where}'read_csv' has option(s) pandas.read_csv does not take or tiltlab sets itself: {bad}"
        )
    read_kwargs.update(nested)
    return read_kwargs


def check_common(raw: Mapping[str, Any], where: str) -> dict[str, Any]:
    """The keys shared by every mapping (:data:`COMMON_KEYS`), checked."""
    fs = raw.get("fs")
    if fs is not None:
        fs = _validate.check_fs(fs, f"{where}fs")
    fs_range = raw.get("fs_range", FS_RANGE)
    if fs_range is not None:
        if not isinstance(fs_range, Sequence) or len(fs_range) != 2:
            raise ValueError(
                f"{where}fs_range must be [low, high] in Hz, got {fs_range!r}"
            )
        lo = _validate.positive(fs_range[0], f"{where}fs_range[0]")
        hi = _validate.positive(fs_range[1], f"{where}fs_range[1]", allow_inf=True)
        if lo >= hi:
            raise ValueError(f"{where}fs_range must be [low, high], got {fs_range!r}")
        fs_range = (lo, hi)
    gaps = raw.get("gaps") or "raise"
    if gaps not in GAP_POLICIES:
        raise ValueError(
            f"{where}gaps must be one of {', '.join(map(repr, GAP_POLICIES))}, got {gaps!r}"
        )
    clock = raw.get("clock") or "grid"
    if clock not in CLOCK_POLICIES:
        raise ValueError(
            f"{where}clock must be one of {', '.join(map(repr, CLOCK_POLICIES))}, "
            f"got {clock!r}"
        )
    max_gap = raw.get("max_gap")
    max_gap = (
        MAX_GAP if max_gap is None else _validate.positive(max_gap, f"{where}max_gap")
    )
    if max_gap < 1.5:
        raise ValueError(
            f"{where}max_gap is in sample periods and must be at least 1.5 "
            f"(a normal step is 1), got {max_gap!r}"
        )
    check_units = raw.get("check_units", True)
    if not isinstance(check_units, (bool, np.bool_)):
        raise ValueError(
            f"{where}check_units must be true or false, got {check_units!r}"
        )
    axes = raw.get("axes")
    if axes is not None:
        try:
            if isinstance(axes, Mapping):
                for k, v in axes.items():
                    _axes.parse_axes(v, f"{where}axes[{k!r}]")
            else:
                _axes.parse_axes(axes, f"{where}axes")
        except ValueError as exc:
            raise ValueError(str(exc)) from None
    preset = raw.get("preset")
    if preset is not None and not isinstance(preset, str):
        raise ValueError(
            f"{where}preset must be a name ({', '.join(_axes.PRESETS)}), got {preset!r}"
        )
    labels = raw.get("axis_labels")
    if labels is not None:
        labels = _axes.check_labels(labels, f"{where}axis_labels")
    attrs = raw.get("attrs") or {}
    if not isinstance(attrs, Mapping):
        raise ValueError(
            f"{where}'attrs' must be a mapping of attribute names to values"
        )
    return {
        "fs": fs,
        "fs_range": fs_range,
        "gaps": gaps,
        "clock": clock,
        "max_gap": float(max_gap),
        "check_units": bool(check_units),
        "axes": axes,
        "preset": preset,
        "axis_labels": labels,
        "attrs": dict(attrs),
    }


def check_columns(columns: Any, where: str) -> dict[str, list[str]]:
    """``columns``: variable → list of column names (``acc`` required)."""
    if not isinstance(columns, Mapping) or not columns:
        raise ValueError(
            f"{where}'columns' must map variables to column names, e.g. "
            '{"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]}'
        )
    cols: dict[str, list[str]] = {}
    for var, names in columns.items():
        if var not in WIDTH:
            raise ValueError(
                f"{where}unknown variable {var!r} in 'columns' (known: {', '.join(WIDTH)})"
            )
        names = [names] if isinstance(names, str) else names
        if not isinstance(names, Sequence) or not all(
            isinstance(c, str) for c in names
        ):
            raise ValueError(
                f"{where}columns[{var!r}] must be a column name or a list of names, got {names!r}"
            )
        if len(names) != WIDTH[var]:
            raise ValueError(
                f"{where}columns[{var!r}] needs {WIDTH[var]} column(s), got {len(names)}: {list(names)}"
            )
        cols[var] = list(names)
    if "acc" not in cols:
        raise ValueError(
            f"{where}'columns' must map 'acc' (gyr, mag, temp and q_ref are optional)"
        )
    return cols


def check_mapping(raw: Mapping[str, Any], where: str) -> dict[str, Any]:
    """Check a raw one-file mapping and return it normalised (see
    :func:`tiltlab.io.read_csv_mapping`).
    """
    allowed_read = read_csv_params()
    unknown = [k for k in raw if k not in MAPPING_KEYS and k not in allowed_read]
    if unknown:
        hint = (
            "; 'files' (one file per sensor) is read by read_multi"
            if "files" in unknown
            else ""
        )
        raise ValueError(
            f"{where}unknown key(s) {unknown}; a mapping has {', '.join(MAPPING_KEYS)} "
            f"and pandas.read_csv options (sep, decimal, skiprows, comment, encoding, ...){hint}"
        )
    cols = check_columns(raw.get("columns"), where)
    units_in = raw.get("units") or {}
    if not isinstance(units_in, Mapping):
        raise ValueError(f"{where}'units' must map variables to unit strings")
    units: dict[str, str] = {}
    for var, unit in units_in.items():
        if var == "time":
            continue
        if var not in WIDTH:
            raise ValueError(
                f"{where}unknown variable {var!r} in 'units' (known: {', '.join(WIDTH)}, time)"
            )
        units[var] = check_unit(var, unit, where)
    for var in cols:
        if var != "q_ref" and var not in units:
            raise ValueError(
                f"{where}units must give the unit of {var!r}; tiltlab does not assume one"
            )
    time_column = raw.get("time_column")
    if time_column is not None and not isinstance(time_column, str):
        raise ValueError(
            f"{where}time_column must be a column name, got {time_column!r}"
        )
    time_scale, time_unit = check_time_unit(
        raw, time_column, where, units_in.get("time")
    )
    common = check_common(raw, where)
    if common["fs"] is None and time_column is None:
        raise ValueError(
            f"{where}give fs, or a time_column from which to estimate it; "
            "tiltlab never assumes a sampling rate"
        )
    if common["clock"] == "resample" and time_column is None:
        raise ValueError(
            f"{where}clock 'resample' needs a time_column: it interpolates from the "
            "sample times onto a uniform grid"
        )
    return {
        "columns": cols,
        "units": units,
        "time_column": time_column,
        "time_scale": time_scale,
        "time_units": time_unit,
        "range": check_range(raw.get("range"), list(cols), where),
        "scale": check_scale(raw.get("scale"), list(cols), where),
        **common,
        "read_csv": check_read_options(raw, where, allowed_read),
    }


#: Mappings for public recordings made by other labs, by name (see
#: :func:`mapping_template`).
TEMPLATES: tuple[str, ...] = ("sunsided_board", "twlogger_tag", "gaitmap_foot")


def mapping_template(name: str) -> dict[str, Any]:
    """A mapping shipped with tiltlab for a public recording from another lab.

    Each is a worked example of one kind of export: ``"sunsided_board"`` (one MATLAB
    v7.3 file per sensor on separate bursty clocks, gravity-signed accelerometer and
    reversed gyroscope axes), ``"twlogger_tag"`` (a bio-logging tag's CSV with an
    accelerometer and magnetometer only, raw counts and a jittery millisecond clock)
    and ``"gaitmap_foot"`` (a CSV with a two-row header, no time column). The
    ``description`` key says what is inferred rather than documented.

    Parameters
    ----------
    name : str
        One of :data:`TEMPLATES`.

    Returns
    -------
    dict
        A new mapping (edit it freely), for :func:`tiltlab.io.read` /
        :func:`tiltlab.io.read_csv` / :func:`tiltlab.io.read_multi` or, saved as
        JSON, ``tiltlab convert --mapping``.

    Examples
    --------
    >>> from tiltlab import io
    >>> sorted(io.mapping_template("sunsided_board")["files"])
    ['acc', 'gyr', 'mag']
    """
    import json
    from importlib import resources

    if name not in TEMPLATES:
        raise ValueError(
            f"unknown mapping template {name!r}; known: {', '.join(TEMPLATES)}"
        )
    text = resources.files("tiltlab").joinpath("_mappings", f"{name}.json").read_text()
    return json.loads(text)
