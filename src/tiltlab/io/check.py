"""Trying a CSV mapping on a file without stopping at the first refusal."""

from __future__ import annotations

from collections.abc import Mapping
from os import PathLike
from typing import Any

from ._common import ReadError
from .csv import read_csv

__all__ = ["try_read"]


def try_read(path: str | PathLike, mapping: Mapping[str, Any] | PathLike) -> str | None:
    """Read a CSV file with a mapping and say why it is refused, if it is.

    Useful to check one mapping against every export of a logger (or several candidate
    mappings against one file) before building a cohort: each refusal comes back as
    text instead of stopping the loop.

    Parameters
    ----------
    path : str or path-like
        The CSV file, as :func:`~tiltlab.io.read_csv` takes it.
    mapping : dict or path-like
        The column/unit mapping (see :func:`~tiltlab.io.read_csv_mapping`).

    Returns
    -------
    str or None
        ``None`` if the file reads into a valid Recording, else the refusal as
        ``"ErrorType: message"``.

    Notes
    -----
    Only refusals are caught: a wrong mapping or unit (:class:`ValueError`, including
    :class:`~tiltlab.schema.RecordingError`) and an unreadable or missing file
    (:class:`~tiltlab.io.ReadError`). Anything else (a bug) still raises.
    """
    try:
        read_csv(path, mapping=mapping)
    except (ValueError, ReadError) as err:
        return f"{type(err).__name__}: {err}"
    return None
