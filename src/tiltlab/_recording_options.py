"""Read the keyword options of :func:`tiltlab.schema.make_recording` into one record.

:func:`~tiltlab.schema.make_recording` takes its data and the most used options as
parameters, and the rest (per-sensor shorthands such as ``acc_units=``, the frame and
the validation switches) as keywords, read and checked here once. What a Recording is
stays in :mod:`tiltlab.schema`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Options", "read_options"]

_PLAIN = ("t0", "frame", "axes", "preset", "axis_labels", "validate_result")
_PLAIN += ("check_units",)


@dataclass(frozen=True)
class Options:
    """The keyword options of ``make_recording``, read and checked once."""

    units: dict[str, str | None] = field(default_factory=dict)
    ranges: dict[str, Any] = field(default_factory=dict)
    t0: float = 0.0
    frame: str = "sensor"
    axes: Any = None
    preset: str | None = None
    axis_labels: Any = None
    validate_result: bool = True
    check_units: bool = True
    validate_kwargs: dict[str, Any] = field(default_factory=dict)


def _per_sensor(
    mapping: Mapping[str, Any] | None,
    options: dict[str, Any],
    suffix: str,
    names: tuple[str, ...],
) -> dict[str, Any]:
    """Merge a per-sensor mapping with its ``<var>_<suffix>`` shorthand keywords."""
    merged = dict(mapping or {})
    for name in names:
        key = f"{name}_{suffix}"
        value = options.pop(key, None)
        if value is None:  # not given (readers pass their optional units as None)
            continue
        if name in merged:
            raise TypeError(
                f"make_recording: give the {suffix} of {name!r} once, as {key}= or "
                "in the mapping"
            )
        merged[name] = value
    unknown = sorted(set(merged) - set(names))
    if unknown:
        raise TypeError(
            f"make_recording: {suffix} given for unknown variables {unknown}; "
            f"known: {list(names)}"
        )
    return merged


def read_options(
    units: Mapping[str, str] | None,
    options: Mapping[str, Any],
    *,
    unit_vars: tuple[str, ...],
    range_vars: tuple[str, ...],
    validate_keys: tuple[str, ...],
) -> Options:
    """Read the keyword options of ``make_recording`` into one record.

    Parameters
    ----------
    units : mapping, optional
        The ``units`` argument: variable → unit.
    options : mapping
        The other keywords; ``<var>_units`` and ``<var>_range`` are shorthands for an
        entry of ``units`` and of the ``ranges`` keyword (None: not given).
    unit_vars, range_vars : tuple of str
        The variables that take a unit, and a full scale.
    validate_keys : tuple of str
        The keywords passed on to ``validate``.

    Returns
    -------
    Options
        The record.

    Raises
    ------
    TypeError
        An unknown keyword, or a unit or full scale given twice.
    """
    options = dict(options)
    per_var_units = _per_sensor(units, options, "units", unit_vars)
    ranges = _per_sensor(options.pop("ranges", None), options, "range", range_vars)
    plain = {k: options.pop(k) for k in _PLAIN if k in options}
    validate_kwargs = {k: options.pop(k) for k in validate_keys if k in options}
    if options:
        raise TypeError(
            f"make_recording() got unexpected keyword arguments {sorted(options)}"
        )
    return Options(
        units=per_var_units,
        ranges=ranges,
        validate_kwargs=validate_kwargs,
        **plain,
    )
