"""Shared pieces of the readers: the error type and the checked table reader."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .. import schema

PathLike = str | os.PathLike


class ReadError(OSError):
    """A file is missing, truncated, corrupt or not in the expected layout."""


class IntegrityError(ReadError, ValueError):
    """A file's content differs from the checksum recorded when it was written.

    Raised by :func:`tiltlab.io.load_netcdf` (a variable or the attributes of a
    saved Recording changed since :func:`tiltlab.io.save_netcdf` wrote them) and by
    :mod:`tiltlab.learn` (model weights that differ from their recorded sha256, or
    a malformed ``SHA256SUMS`` file). The message names the file and, where there is
    one, the variable (also in :attr:`path` and :attr:`variable`). A
    :class:`ReadError` (an :class:`OSError`) and a :class:`ValueError`.
    """

    def __init__(self, message: str, *, path=None, variable: str | None = None):
        super().__init__(message)
        self.path = None if path is None else Path(path)
        self.variable = variable

    def __reduce__(self):
        return (_integrity_error, (str(self), self.path, self.variable))


def _integrity_error(message, path, variable):
    return IntegrityError(message, path=path, variable=variable)


def file_head(path: PathLike, size: int) -> bytes | None:
    """Read the first bytes of a file, where a format states its signature.

    Parameters
    ----------
    path : path-like
        The file.
    size : int
        How many bytes to read (fewer if the file is shorter).

    Returns
    -------
    bytes or None
        The bytes, or None if the file cannot be opened.
    """
    try:
        with open(path, "rb") as f:
            return f.read(size)
    except OSError:
        return None


def no_file(path) -> str:
    """Say why ``path`` cannot be read as a file: it is a folder, or nothing is there.

    Parameters
    ----------
    path : path-like
        The path that is not a file.

    Returns
    -------
    str
        The message, starting with the path.
    """
    p = Path(path)
    return f"{p}: is a directory, not a file" if p.is_dir() else f"{p}: no such file"


def _missing_columns_message(
    path: Path,
    df: pd.DataFrame,
    missing: Sequence[str],
    roles: Mapping[str, str] | None,
) -> str:
    import difflib

    found = [str(c) for c in df.columns]
    parts = []
    for c in missing:
        role = (roles or {}).get(c)
        if role == "time_column":
            role = " (time_column)"
        elif role is not None:
            role = f" (mapped to {role})"
        else:
            role = ""
        folded = {f.strip().lower(): f for f in found}
        close = difflib.get_close_matches(str(c).strip().lower(), folded, 1, 0.6)
        hint = f", did you mean {folded[close[0]]!r}?" if close else ""
        parts.append(f"{c!r}{role}{hint}")
    msg = (
        f"{path}: missing column(s) {'; '.join(parts)}; "
        f"available columns: {', '.join(repr(c) for c in found)}"
    )
    if len(found) == 1 and any(sep in found[0] for sep in ";\t|, "):
        msg += " (one column only: is the separator right? give sep, e.g. sep=';')"
    return msg


def read_table_or_fail(path, **kwargs) -> pd.DataFrame:
    """Read a table with :func:`pandas.read_csv`, raising its parse errors as ReadError.

    Parameters
    ----------
    path : path-like
        CSV file.
    **kwargs
        Options for :func:`pandas.read_csv`.

    Returns
    -------
    pandas.DataFrame
        The table.

    Raises
    ------
    ReadError
        Naming the file, for any parse error.
    """
    try:
        return pd.read_csv(path, **kwargs)
    except (
        pd.errors.ParserError,
        pd.errors.EmptyDataError,
        UnicodeDecodeError,
        ValueError,
        TypeError,
    ) as exc:
        raise ReadError(f"{path}: not a readable CSV table ({exc})") from None


def _read_table(
    path: PathLike,
    required: Sequence[str],
    *,
    final_newline: bool = False,
    roles: Mapping[str, str] | None = None,
    **kwargs,
) -> pd.DataFrame:
    path = Path(path)
    if not path.is_file():
        raise ReadError(no_file(path))
    if final_newline:
        # files written line by line end with a newline; a missing one means the copy was cut short
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            if f.tell() == 0:
                raise ReadError(f"{path}: empty file")
            f.seek(-1, os.SEEK_END)
            if f.read(1) not in (b"\n", b"\r"):
                raise ReadError(
                    f"{path}: last line is incomplete (no final newline): truncated file?"
                )
    df = read_table_or_fail(path, **kwargs)
    missing = [c for c in required if c not in df.columns]
    if missing:
        raise ReadError(_missing_columns_message(path, df, missing, roles))
    sub = df[list(required)]
    numeric = sub.apply(pd.to_numeric, errors="coerce")
    bad = numeric.isna() & ~sub.isna()
    if bad.to_numpy().any():
        row, col = np.argwhere(bad.to_numpy())[0]
        raise ReadError(
            f"{path}: non-numeric value {sub.iat[row, col]!r} in column {required[col]!r}, data row {row}"
        )
    if numeric.isna().to_numpy().any():
        row, col = np.argwhere(numeric.isna().to_numpy())[0]
        n_missing = int(numeric.isna().to_numpy().sum())
        try:  # the text as written: an empty field, or a word such as NaN or NA
            raw = pd.read_csv(
                path, **{**kwargs, "dtype": str, "keep_default_na": False}
            )
            text = str(raw[required[col]].iat[row]).strip()
        except (ValueError, KeyError, IndexError, OSError):
            text = ""
        what = f"missing value {text!r}" if text else "empty field"
        hint = " (truncated file?)" if not text else ""
        raise ReadError(
            f"{path}: {what} in column {required[col]!r}, data row {row}"
            f" ({n_missing} missing value(s) in all){hint}; the readers of published "
            "data sets need every sample"
        )
    if len(numeric) < 2:
        raise ReadError(f"{path}: fewer than two samples")
    return numeric


def sensor_recording(
    get: Mapping[str, np.ndarray],
    fs: float,
    units: Mapping[str, str | None],
    **options,
):
    """Build a Recording from the sensors a reader found, each with its unit.

    Parameters
    ----------
    get : mapping
        Variable (``acc`` required; ``gyr``, ``mag``, ``temp``, ``q_ref``) → samples;
        ``temp`` may be (N,) or (N, 1).
    fs : float
        Sampling rate (Hz).
    units : mapping
        Variable → unit, for every sensor in ``get``.
    **options
        Any other argument of :func:`tiltlab.schema.make_recording`.

    Returns
    -------
    xarray.Dataset
        The validated Recording.
    """
    temp = get.get("temp")
    return schema.make_recording(
        get["acc"],
        get.get("gyr"),
        fs,
        acc_units=units["acc"],
        gyr_units=units.get("gyr"),
        mag=get.get("mag"),
        mag_units=units.get("mag"),
        temp=None if temp is None else temp.reshape(-1),
        temp_units=units.get("temp"),
        **options,
    )
