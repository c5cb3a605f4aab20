"""Read a folder of saved cohort feature tables, each checked against its SHA-256.

A cohort that takes too long to compute in a book build (Fayat et al.'s cohort at the
paper's scale, written by ``tools/make_paper_cohort.py``) is kept as a folder:
``features_<name>.nc`` (:func:`~tiltlab.cohort.save_features`, one per feature
configuration), optionally ``truth.csv`` (the planted effects of a simulated cohort),
``run.json`` (how it was made) and ``SHA256SUMS`` (``sha256sum`` format) listing
every data file. :func:`read_feature_archive` refuses a folder whose files do not
match their digests.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any, NamedTuple

import pandas as pd
import xarray as xr

from ..datasets import file_sha256
from ..io import IntegrityError
from .run import load_features

__all__ = ["FeatureArchive", "read_feature_archive"]

_LINE = re.compile(r"^([0-9a-fA-F]{64}) [ *](\S.*)$")


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
    """

    features: dict[str, xr.Dataset]
    truth: pd.DataFrame | None
    run: dict[str, Any]


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
        A missing folder or ``SHA256SUMS``.
    ValueError
        A malformed ``SHA256SUMS`` line, or no ``features_*.nc`` listed in it.
    tiltlab.io.IntegrityError
        A listed file that is missing or whose digest differs (naming the file).

    Examples
    --------
    >>> import tempfile, hashlib, numpy as np, xarray as xr
    >>> from pathlib import Path
    >>> from tiltlab import cohort
    >>> d = Path(tempfile.mkdtemp())
    >>> ds = xr.Dataset({"a": ("session", np.arange(2.0))}, coords={"session": ["s1", "s2"]})
    >>> _ = cohort.save_features(ds, d / "features_default.nc")
    >>> h = hashlib.sha256((d / "features_default.nc").read_bytes()).hexdigest()
    >>> _ = (d / "SHA256SUMS").write_text(f"{h}  features_default.nc\n")
    >>> list(cohort.read_feature_archive(d).features)
    ['default']
    """
    folder = Path(folder)
    sums = folder / "SHA256SUMS"
    if not folder.is_dir():
        raise FileNotFoundError(f"no cohort archive folder {str(folder)!r}")
    if not sums.is_file():
        raise FileNotFoundError(f"{str(folder)!r} has no SHA256SUMS to check its files")
    listed = {}
    for k, line in enumerate(sums.read_text().splitlines(), 1):
        if not line.strip():
            continue
        m = _LINE.match(line)
        if m is None:
            raise ValueError(f"{sums}: line {k} is not '<sha256>  <file>': {line!r}")
        listed[m.group(2)] = m.group(1).lower()
    for name, digest in listed.items():
        path = folder / name
        if not path.is_file():
            raise IntegrityError(f"{name} is listed in {sums} but missing", path=path)
        got = file_sha256(path)
        if got != digest:
            raise IntegrityError(
                f"{name}: sha256 {got} differs from {sums} ({digest}): the file is "
                "corrupt or was altered",
                path=path,
            )
    tables = {
        n[len("features_") : -len(".nc")]: n
        for n in listed
        if n.startswith("features_") and n.endswith(".nc")
    }
    if not tables:
        raise ValueError(f"{sums} lists no features_<name>.nc file")
    features = {k: load_features(folder / n) for k, n in sorted(tables.items())}
    truth = None
    if "truth.csv" in listed:
        truth = pd.read_csv(folder / "truth.csv").set_index("session")
    run_path = folder / "run.json"
    run = json.loads(run_path.read_text()) if run_path.is_file() else {}
    return FeatureArchive(features, truth, run)
