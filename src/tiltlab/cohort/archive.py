"""Read a folder of saved cohort feature tables, each checked against its SHA-256.

A cohort that takes too long to compute in a book build (Fayat et al.'s cohort at the
paper's scale, written by ``tools/make_paper_cohort.py``) is kept as a folder:
``features_<name>.nc`` (:func:`~tiltlab.cohort.save_features`, one per feature
configuration), optionally ``truth.csv`` (the planted effects of a simulated cohort),
``maps_<name>.nc`` and ``velocity_<name>.nc`` (Figs 3c–d and A5 of that
configuration: :func:`~tiltlab.cohort.group_tilt_maps`,
:func:`~tiltlab.cohort.circling_examples`, for figures that need the recordings),
``run.json`` (how it was made) and ``SHA256SUMS`` (``sha256sum`` format) listing
every data file. :func:`read_feature_archive` refuses a folder whose files do not
match their digests.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, NamedTuple

import pandas as pd
import xarray as xr

from ..io.checksums import SUMS_FILE, check_sums
from ..io.netcdf import load_netcdf
from .run import load_features

__all__ = ["FeatureArchive", "read_feature_archive"]


class FeatureArchive(NamedTuple):
    """Feature tables of one cohort under several configurations.

    Attributes
    ----------
    features : dict of str to xarray.Dataset
        Configuration name (``features_<name>.nc``) → feature table.
    truth : pandas.DataFrame or None
        Planted effects per session (indexed by ``session``), if saved.
    run : dict
        The folder's ``run.json`` (empty if absent).
    maps : dict of str to xarray.Dataset
        Configuration name → group-averaged tilt maps (``maps_<name>.nc``), if saved.
    velocity : dict of str to xarray.Dataset
        Configuration name → Fig. A5's angular velocity quantiles
        (``velocity_<name>.nc``), if saved.
    """

    features: dict[str, xr.Dataset]
    truth: pd.DataFrame | None
    run: dict[str, Any]
    maps: dict[str, xr.Dataset] = {}
    velocity: dict[str, xr.Dataset] = {}


def read_feature_archive(folder) -> FeatureArchive:
    r"""Read the feature tables of a folder after checking every file's SHA-256.

    Parameters
    ----------
    folder : str or os.PathLike
        Folder with ``SHA256SUMS`` and the ``features_<name>.nc`` files it lists.

    Returns
    -------
    FeatureArchive
        The tables by configuration name, the planted truth and the run record.

    Raises
    ------
    FileNotFoundError
        A missing folder.
    tiltlab.io.IntegrityError
        No ``SHA256SUMS``, a malformed one, or a listed file that is missing or whose
        digest differs (naming the file; :func:`tiltlab.io.check_sums`).
    ValueError
        No ``features_*.nc`` listed in ``SHA256SUMS``.

    Examples
    --------
    >>> import tempfile, numpy as np, xarray as xr
    >>> from pathlib import Path
    >>> from tiltlab import cohort, io
    >>> d = Path(tempfile.mkdtemp())
    >>> ds = xr.Dataset({"a": ("session", np.arange(2.0))}, coords={"session": ["s1", "s2"]})
    >>> _ = cohort.save_features(ds, d / "features_default.nc")
    >>> io.write_sums(d, {"features_default.nc": io.file_sha256(d / "features_default.nc")})
    >>> list(cohort.read_feature_archive(d).features)
    ['default']
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"no cohort archive folder {str(folder)!r}")
    listed = check_sums(folder)
    tables = {
        n[len("features_") : -len(".nc")]: n
        for n in listed
        if n.startswith("features_") and n.endswith(".nc")
    }
    if not tables:
        raise ValueError(f"{folder / SUMS_FILE} lists no features_<name>.nc file")
    features = {k: load_features(folder / n) for k, n in sorted(tables.items())}
    extra = {
        kind: {
            n[len(kind) + 1 : -len(".nc")]: load_netcdf(folder / n)
            for n in sorted(listed)
            if n.startswith(f"{kind}_") and n.endswith(".nc")
        }
        for kind in ("maps", "velocity")
    }
    truth = None
    if "truth.csv" in listed:
        truth = pd.read_csv(folder / "truth.csv").set_index("session")
    run_path = folder / "run.json"
    run = json.loads(run_path.read_text()) if run_path.is_file() else {}
    return FeatureArchive(features, truth, run, extra["maps"], extra["velocity"])
