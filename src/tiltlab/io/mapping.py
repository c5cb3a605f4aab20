"""Check the column/unit mappings of :func:`~tiltlab.io.read_csv` and ``read_multi``.

Every key is checked here, once, and every message names the key and the fix. A
checked one-file mapping is a :class:`CsvMapping`, a frozen record.
"""

from __future__ import annotations

import dataclasses
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
    READ_GAP_POLICIES,
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
    """List the options of :func:`pandas.read_csv` that a mapping may give.

    Returns
    -------
    frozenset of str
        Every keyword of :func:`pandas.read_csv` but those tiltlab sets itself.
    """
    import inspect

    import pandas as pd

    return frozenset(inspect.signature(pd.read_csv).parameters) - _NOT_READ_KWARGS


def scaled_unit_hint(var: str, unit: object) -> str:
    """Suggest a ``scale`` factor for a prefixed unit (``mg``, ``mdps``) or raw counts.

    Parameters
    ----------
    var : str
        The variable (``acc``, ``gyr`` …).
    unit : object
        The unit as given.

    Returns
    -------
    str
        ``"; … give units … and scale …"``, or ``""`` when the unit is neither.
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


def load_mapping(
    mapping: Mapping[str, Any] | PathLike | CsvMapping,
) -> tuple[dict[str, Any], str]:
    """Load a mapping as written: a dict, a :class:`CsvMapping` or a JSON file.

    Parameters
    ----------
    mapping : dict, CsvMapping or path-like
        The mapping, or the path of a JSON file holding it.

    Returns
    -------
    raw : dict
        The mapping as a new dict (not yet checked).
    where : str
        A prefix naming it in messages (``"mapping: "`` or ``"mapping <path>: "``).
    """
    if isinstance(mapping, CsvMapping):
        return mapping.to_dict(), "mapping: "
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
    """Check a variable's unit and return it in its canonical spelling.

    Parameters
    ----------
    var : str
        The variable.
    unit : object
        The unit as given.
    where : str
        Prefix naming the mapping in messages.

    Returns
    -------
    str
        The canonical unit.

    Raises
    ------
    ValueError
        If the unit is unknown (with a ``scale`` hint for ``mg``, counts …).
    """
    try:
        return _units.normalise_unit(unit)
    except _units.UnitsError as exc:
        raise ValueError(
            f"{where}units[{var!r}]: {exc}{scaled_unit_hint(var, unit)}"
        ) from None


def check_time_unit(
    raw: Mapping[str, Any], time_column: Any, where: str, extra: Any = None
) -> tuple[float | None, str | None]:
    """Check the time column's unit, given as ``time_units``, ``time_scale`` or both.

    Parameters
    ----------
    raw : mapping
        The raw mapping (``time_units``, ``time_scale``).
    time_column : object
        The time column (None if there is none: then no unit may be given).
    where : str
        Prefix naming the mapping in messages.
    extra : object, optional
        A ``units['time']``, another way of giving ``time_units``.

    Returns
    -------
    scale : float or None
        The factor to seconds (None for date-times).
    name : str or None
        The unit's name, or None for another factor.
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


def _per_variable(value: Any, key: str, example: str, where: str) -> Mapping:
    """Check a key that maps variables to values (``range``, ``scale``); None is {}."""
    value = value or {}
    if not isinstance(value, Mapping):
        raise ValueError(f"{where}{key!r} must map variables to {example}")
    return value


def check_range(
    range_in: Any, mapped: Sequence[str], where: str
) -> dict[str, float | list[float]]:
    """Check ``range``: variable → the sensor's full scale.

    Parameters
    ----------
    range_in : mapping or None
        The raw ``range`` key.
    mapped : sequence of str
        The variables the mapping reads.
    where : str
        Prefix naming the mapping in messages.

    Returns
    -------
    dict
        Variable → ``r`` (for ±r) or ``[low, high]``.
    """
    range_in = _per_variable(
        range_in, "range", 'their full scale, e.g. {"acc": 16, "gyr": 2000}', where
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


def _check_scale(scale_in: Any, mapped: Sequence[str], where: str) -> dict[str, float]:
    """``scale``: variable → positive factor from the column's numbers to its unit."""
    scale_in = _per_variable(
        scale_in,
        "scale",
        'factors, e.g. {"acc": 0.001} for a column in mg read as g',
        where,
    )
    return {
        var: _validate.positive(value, f"{where}scale[{var!r}]")
        for var, value in scale_in.items()
        if _scalable(var, mapped, where)
    }


def _scalable(var: str, mapped: Sequence[str], where: str) -> bool:
    if var not in mapped or var == "q_ref":
        raise ValueError(
            f"{where}scale[{var!r}]: a factor is given for a mapped acc, gyr, mag "
            "or temp only"
        )
    return True


def check_read_options(
    raw: Mapping[str, Any], where: str, allowed: frozenset[str]
) -> dict[str, Any]:
    """Collect the pandas.read_csv options given at the top level or under ``read_csv``.

    Parameters
    ----------
    raw : mapping
        The raw mapping (or one entry of a multi-file mapping).
    where : str
        Prefix naming the mapping in messages.
    allowed : frozenset of str
        The options a mapping may give (:func:`read_csv_params`).

    Returns
    -------
    dict
        Keyword arguments for :func:`pandas.read_csv`.
    """
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


def _check_fs_range(fs_range: Any, where: str) -> tuple[float, float] | None:
    """``fs_range``: [low, high] Hz, or None (no check)."""
    if fs_range is None:
        return None
    if not isinstance(fs_range, Sequence) or len(fs_range) != 2:
        raise ValueError(f"{where}fs_range must be [low, high] in Hz, got {fs_range!r}")
    lo = _validate.positive(fs_range[0], f"{where}fs_range[0]")
    hi = _validate.positive(fs_range[1], f"{where}fs_range[1]", allow_inf=True)
    if lo >= hi:
        raise ValueError(f"{where}fs_range must be [low, high], got {fs_range!r}")
    return (lo, hi)


def _one_of(value: Any, choices: Sequence[str], key: str, where: str) -> str:
    if value not in choices:
        raise ValueError(
            f"{where}{key} must be one of {', '.join(map(repr, choices))}, got {value!r}"
        )
    return value


def _check_max_gap(max_gap: Any, where: str) -> float:
    """``max_gap``: sample periods, at least 1.5 (default :data:`MAX_GAP`)."""
    if max_gap is None:
        return float(MAX_GAP)
    max_gap = _validate.positive(max_gap, f"{where}max_gap")
    if max_gap < 1.5:
        raise ValueError(
            f"{where}max_gap is in sample periods and must be at least 1.5 "
            f"(a normal step is 1), got {max_gap!r}"
        )
    return float(max_gap)


def _check_frame(raw: Mapping[str, Any], where: str) -> dict[str, Any]:
    """``check_units``, ``axes``, ``preset`` and ``axis_labels``, checked."""
    check_units = raw.get("check_units", True)
    if not isinstance(check_units, (bool, np.bool_)):
        raise ValueError(
            f"{where}check_units must be true or false, got {check_units!r}"
        )
    axes = raw.get("axes")
    try:
        if isinstance(axes, Mapping):
            for k, v in axes.items():
                _axes.parse_axes(v, f"{where}axes[{k!r}]")
        elif axes is not None:
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
    return {
        "check_units": bool(check_units),
        "axes": axes,
        "preset": preset,
        "axis_labels": labels,
    }


def check_common(raw: Mapping[str, Any], where: str) -> dict[str, Any]:
    """Check the keys shared by every mapping (:data:`COMMON_KEYS`).

    Parameters
    ----------
    raw : mapping
        The raw mapping.
    where : str
        Prefix naming the mapping in messages.

    Returns
    -------
    dict
        ``fs`` (float or None), ``fs_range``, ``gaps``, ``clock``, ``max_gap``,
        ``check_units``, ``axes``, ``preset``, ``axis_labels`` and ``attrs``, with
        their defaults filled in.
    """
    fs = raw.get("fs")
    attrs = raw.get("attrs") or {}
    if not isinstance(attrs, Mapping):
        raise ValueError(
            f"{where}'attrs' must be a mapping of attribute names to values"
        )
    return {
        "fs": None if fs is None else _validate.check_fs(fs, f"{where}fs"),
        "fs_range": _check_fs_range(raw.get("fs_range", FS_RANGE), where),
        "gaps": _one_of(raw.get("gaps") or "raise", READ_GAP_POLICIES, "gaps", where),
        "clock": _one_of(raw.get("clock") or "grid", CLOCK_POLICIES, "clock", where),
        "max_gap": _check_max_gap(raw.get("max_gap"), where),
        **_check_frame(raw, where),
        "attrs": dict(attrs),
    }


def check_columns(columns: Any, where: str) -> dict[str, list[str]]:
    """Check ``columns``: variable → list of column names (``acc`` required).

    Parameters
    ----------
    columns : mapping
        The raw ``columns`` key.
    where : str
        Prefix naming the mapping in messages.

    Returns
    -------
    dict
        Variable → list of column names.
    """
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


def _check_unknown_keys(raw: Mapping[str, Any], where: str, allowed_read) -> None:
    unknown, hint = _validate.unknown_keys(
        raw,
        {*MAPPING_KEYS, *allowed_read},
        hints={"files": "; 'files' (one file per sensor) is read by read_multi"},
    )
    if unknown:
        raise ValueError(
            f"{where}unknown key(s) {unknown}; a mapping has {', '.join(MAPPING_KEYS)} "
            f"and pandas.read_csv options (sep, decimal, skiprows, comment, encoding, ...){hint}"
        )


def _check_units(
    units_in: Any, cols: Mapping[str, Sequence[str]], where: str
) -> dict[str, str]:
    """``units``: variable → canonical unit, for every mapped variable but q_ref."""
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
    return units


def _check_time_column(time_column: Any, where: str) -> str | None:
    if time_column is not None and not isinstance(time_column, str):
        raise ValueError(
            f"{where}time_column must be a column name, got {time_column!r}"
        )
    return time_column


def _check_clock_source(
    time_column: str | None, common: Mapping[str, Any], where: str
) -> None:
    """Require a rate or a time column, and the time column for resampling."""
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


def check_mapping(raw: Mapping[str, Any], where: str) -> CsvMapping:
    """Check a raw one-file mapping (see :func:`tiltlab.io.read_csv_mapping`).

    Parameters
    ----------
    raw : mapping
        The mapping as written (JSON object or dict).
    where : str
        Prefix naming the mapping in messages (``"mapping: "``, or the file).

    Returns
    -------
    CsvMapping
        The checked mapping, every default filled in.
    """
    allowed_read = read_csv_params()
    _check_unknown_keys(raw, where, allowed_read)
    cols = check_columns(raw.get("columns"), where)
    units_in = raw.get("units") or {}
    units = _check_units(units_in, cols, where)
    time_column = _check_time_column(raw.get("time_column"), where)
    time_scale, time_unit = check_time_unit(
        raw, time_column, where, units_in.get("time")
    )
    common = check_common(raw, where)
    _check_clock_source(time_column, common, where)
    return CsvMapping(
        columns=cols,
        units=units,
        time_column=time_column,
        time_scale=time_scale,
        time_units=time_unit,
        range=check_range(raw.get("range"), list(cols), where),
        scale=_check_scale(raw.get("scale"), list(cols), where),
        **common,
        read_csv=check_read_options(raw, where, allowed_read),
    )


@dataclasses.dataclass(frozen=True)
class CsvMapping:
    """A checked column/unit mapping of one CSV file (:func:`tiltlab.io.read_csv`).

    Built by :meth:`from_dict` / :meth:`load` (or
    :func:`tiltlab.io.read_csv_mapping`), which check every key; the fields are the
    mapping's keys with their defaults filled in. ``m["columns"]`` reads a field as
    ``m.columns`` does (the dict returned before this record existed).

    Attributes
    ----------
    columns : dict
        Variable (``acc``, ``gyr``, ``mag``, ``temp``, ``q_ref``) → column names.
    units : dict
        Variable → unit, in its canonical spelling.
    time_column : str or None
        Column of sample times.
    time_scale : float or None
        Factor from the time column to seconds (None for date-time text).
    time_units : str or None
        The time unit's name (``"s"``, ``"ms"``, …, ``"datetime"``), or None for
        another factor.
    range : dict
        Variable → the sensor's full scale (``r`` for ±r, or ``[low, high]``).
    scale : dict
        Variable → factor from the column's numbers to ``units``.
    fs : float or None
        Sampling rate (Hz); None estimates it from the time column.
    fs_range : (float, float) or None
        Plausible sampling rates (Hz).
    gaps : {"raise", "nan"}
        What to do with samples missing from the time column.
    clock : {"grid", "resample"}
        Whether samples sit on a grid or are resampled onto one.
    max_gap : float
        Longest step (sample periods) interpolated across with ``clock="resample"``.
    check_units : bool
        Whether :func:`tiltlab.schema.make_recording` checks the units.
    axes, preset, axis_labels
        Device axes and sign conventions (:mod:`tiltlab.axes`).
    attrs : dict
        Extra Recording attributes.
    read_csv : dict
        Options for :func:`pandas.read_csv`.

    Examples
    --------
    >>> from tiltlab import io
    >>> m = io.CsvMapping.from_dict({"columns": {"acc": ["ax", "ay", "az"]},
    ...                              "units": {"acc": "g"}, "fs": 50, "sep": ";"})
    >>> m.fs, m.clock, m.read_csv
    (50.0, 'grid', {'sep': ';'})
    >>> io.CsvMapping.from_dict(m.to_dict()) == m
    True
    """

    columns: dict[str, list[str]]
    units: dict[str, str]
    time_column: str | None = None
    time_scale: float | None = 1.0
    time_units: str | None = "s"
    range: dict[str, Any] = dataclasses.field(default_factory=dict)
    scale: dict[str, float] = dataclasses.field(default_factory=dict)
    fs: float | None = None
    fs_range: tuple[float, float] | None = FS_RANGE
    gaps: str = "raise"
    clock: str = "grid"
    max_gap: float = MAX_GAP
    check_units: bool = True
    axes: Any = None
    preset: str | None = None
    axis_labels: Any = None
    attrs: dict[str, Any] = dataclasses.field(default_factory=dict)
    read_csv: dict[str, Any] = dataclasses.field(default_factory=dict)

    @classmethod
    def from_dict(cls, raw: Mapping[str, Any], where: str = "mapping: ") -> CsvMapping:
        """Check a mapping given as a dict (keys as in :func:`~tiltlab.io.read_csv_mapping`).

        Parameters
        ----------
        raw : mapping
            The mapping as written.
        where : str, optional
            Prefix naming the mapping in error messages.

        Returns
        -------
        CsvMapping
            The checked mapping.
        """
        return check_mapping(raw, where)

    @classmethod
    def load(cls, mapping: Mapping[str, Any] | PathLike | CsvMapping) -> CsvMapping:
        """Load and check a mapping: a dict, the path of a JSON file, or a record.

        Parameters
        ----------
        mapping : dict, path-like or CsvMapping
            The mapping.

        Returns
        -------
        CsvMapping
            The checked mapping.
        """
        raw, where = load_mapping(mapping)
        return check_mapping(raw, where)

    def to_dict(self) -> dict[str, Any]:
        """Write the mapping as a JSON-ready dict that :meth:`from_dict` reads back.

        Returns
        -------
        dict
            The raw mapping: ``columns``, ``units``, the time keys, the options that
            differ from nothing given, and ``read_csv``.
        """
        raw: dict[str, Any] = {
            "columns": {k: list(v) for k, v in self.columns.items()},
            "units": dict(self.units),
        }
        if self.time_column is not None:
            raw["time_column"] = self.time_column
            if self.time_scale is None:
                raw["time_units"] = DATETIME
            else:
                raw["time_scale"] = self.time_scale
        options = {
            "fs": self.fs,
            "fs_range": None if self.fs_range is None else list(self.fs_range),
            "range": dict(self.range),
            "scale": dict(self.scale),
            "gaps": self.gaps,
            "clock": self.clock,
            "max_gap": self.max_gap,
            "check_units": self.check_units,
            "axes": self.axes,
            "preset": self.preset,
            "axis_labels": self.axis_labels,
            "attrs": dict(self.attrs),
            "read_csv": dict(self.read_csv),
        }
        raw.update(
            {k: v for k, v in options.items() if v is not None or k == "fs_range"}
        )
        return raw

    def __getitem__(self, key: str) -> Any:
        """Read a field by name (``m["units"]`` is ``m.units``)."""
        if key not in self.__dataclass_fields__:
            raise KeyError(key)
        return getattr(self, key)
