"""One session of a cohort, found by subject and time point, and its tilt.

:func:`session_row` returns the manifest row of a subject's (usable) session at a time
point; :func:`load_session_tilt` reads that session and computes its corrected
Recording and tilt exactly as the feature pipeline does, for figures that need the
per-sample data (tilt maps, angular velocity in a gravity-aligned frame).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import pandas as pd
import xarray as xr

from .config import FeatureConfig
from .features import session_tilt
from .manifest import Manifest
from .sessions import load_calibration, load_session

__all__ = ["session_row", "load_session_tilt"]


def session_row(
    manifest: Manifest,
    subject,
    timepoint,
    sessions: pd.DataFrame | None = None,
) -> dict[str, Any]:
    """Find the manifest row of a subject's session at a time point.

    Parameters
    ----------
    manifest : Manifest
        The cohort manifest (:func:`~tiltlab.cohort.read_manifest`).
    subject, timepoint
        Compared as strings with the manifest's (or ``sessions``') columns.
    sessions : pandas.DataFrame, optional
        The sessions to choose from, indexed by session id with ``subject`` and
        ``timepoint`` columns — e.g. the usable ones,
        ``stats.session_table(features).query("status == 'ok'")``. Default: every
        session of the manifest.

    Returns
    -------
    dict
        The row (as :meth:`Manifest.row` gives it) of the first such session.

    Raises
    ------
    KeyError
        If there is no such session.

    Examples
    --------
    >>> row = session_row(manifest, "Kainate03", "1d")             # doctest: +SKIP
    >>> rec, tilt = load_session_tilt(row, manifest.root)          # doctest: +SKIP
    """
    table = manifest.table
    if sessions is None:
        ids = table["session"].astype(str)
        subjects, timepoints = table["subject"], table["timepoint"]
    else:
        missing = [c for c in ("subject", "timepoint") if c not in sessions.columns]
        if missing:
            raise ValueError(f"sessions lacks column(s) {missing}")
        ids = pd.Series(sessions.index.astype(str), index=sessions.index)
        subjects, timepoints = sessions["subject"], sessions["timepoint"]
    at = (subjects.astype(str) == str(subject)) & (
        timepoints.astype(str) == str(timepoint)
    )
    found = ids[at.to_numpy()]
    if found.empty:
        raise KeyError(f"no session of subject {subject!r} at time point {timepoint!r}")
    hit = table["session"].astype(str) == found.iloc[0]
    if not hit.any():
        raise KeyError(f"session {found.iloc[0]!r} is not in the manifest")
    return table[hit].iloc[0].to_dict()


def load_session_tilt(
    row: Mapping[str, Any], root, config: FeatureConfig | None = None
) -> tuple[xr.Dataset, xr.DataArray]:
    """Load a session's corrected Recording and tilt, as the features see them.

    Reads the row's recording (:func:`~tiltlab.cohort.load_session`) and tumble test
    (:func:`~tiltlab.cohort.load_calibration`) and applies
    :func:`~tiltlab.cohort.session_tilt`.

    Parameters
    ----------
    row : mapping
        A manifest row (:func:`session_row`, :meth:`Manifest.row`).
    root : path-like
        The manifest's folder (``manifest.root``).
    config : FeatureConfig, optional
        The pipeline's configuration (default ``FeatureConfig()``).

    Returns
    -------
    rec : xarray.Dataset
        The corrected Recording.
    tilt : xarray.DataArray
        Gravity-up direction in the sensor frame (time, axis).
    """
    rec = load_session(row, root)
    tumble = load_calibration(row, root)
    return session_tilt(rec, config, calibration=tumble)
