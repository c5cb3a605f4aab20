"""Short names, units and axis labels of the cohort features, for tables and figures.

:func:`feature_name` gives a feature's short display name (the variable name when it
has none), :func:`feature_units` its units as printed on an axis (``"°/s"`` for
``deg/s``, nothing for a fraction) from :func:`~tiltlab.cohort.feature_specs`, and
:func:`feature_label` both together, e.g. ``"tilt to sagittal plane (°)"``.
"""

from __future__ import annotations

from .config import FeatureConfig
from .features import feature_specs

__all__ = [
    "FEATURE_NAMES",
    "UNIT_TEXT",
    "feature_name",
    "feature_units",
    "feature_label",
]

#: Short display names of the features of Fayat et al.'s Tables A1–A8.
FEATURE_NAMES: dict[str, str] = {
    "immobile_fraction": "immobile fraction",
    "visited_fraction_moving": "sphere visited, moving",
    "tilt_immobile_sagittal_deg": "tilt to sagittal plane",
    "circling_index": "circling index",
}

#: Units of :func:`~tiltlab.cohort.feature_specs` → their text on an axis (other units
#: are shown as they are; dimensionless ones not at all).
UNIT_TEXT: dict[str, str] = {
    "1": "",
    "deg": "°",
    "deg/s": "°/s",
    "1/min": "circles/min",
}


def feature_name(feature: str) -> str:
    """Give the short display name of a feature.

    Parameters
    ----------
    feature : str
        A feature variable of the cohort table.

    Returns
    -------
    str
        Its entry in :data:`FEATURE_NAMES`, else ``feature`` itself.

    Examples
    --------
    >>> feature_name("visited_fraction_moving")
    'sphere visited, moving'
    >>> feature_name("dba_mean")
    'dba_mean'
    """
    return FEATURE_NAMES.get(feature, feature)


def feature_units(feature: str, config: FeatureConfig | None = None) -> str:
    """Give a feature's units as text for an axis or a column header.

    Parameters
    ----------
    feature : str
        A feature of :func:`~tiltlab.cohort.feature_specs` for ``config``.
    config : FeatureConfig, optional
        The configuration that names the features (default ``FeatureConfig()``).

    Returns
    -------
    str
        ``""`` for a dimensionless feature, ``"°"``, ``"°/s"``, ``"circles/min"``, or
        the units as stored.

    Raises
    ------
    ValueError
        If ``feature`` is not a feature of ``config``.

    Examples
    --------
    >>> feature_units("circling_index"), feature_units("immobile_fraction")
    ('circles/min', '')
    """
    specs = feature_specs(config)
    if feature not in specs:
        raise ValueError(
            f"feature {feature!r} is not a cohort feature; known: {', '.join(specs)}"
        )
    units = specs[feature][0]
    return UNIT_TEXT.get(units, units)


def feature_label(
    feature: str, config: FeatureConfig | None = None, *, prefix: str = ""
) -> str:
    """Make an axis label: ``prefix``, the short name and the units in parentheses.

    Parameters
    ----------
    feature : str
        A feature of :func:`~tiltlab.cohort.feature_specs` for ``config``.
    config : FeatureConfig, optional
        Default ``FeatureConfig()``.
    prefix : str
        Text before the name, e.g. ``"Δ "``.

    Returns
    -------
    str

    Examples
    --------
    >>> feature_label("tilt_immobile_sagittal_deg", prefix="Δ ")
    'Δ tilt to sagittal plane (°)'
    >>> feature_label("immobile_fraction")
    'immobile fraction'
    """
    units = feature_units(feature, config)
    return f"{prefix}{feature_name(feature)}" + (f" ({units})" if units else "")
