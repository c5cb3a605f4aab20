"""Say what a data file is, in one line (:func:`detect`).

For example ``"tiltlab Recording (NetCDF)"``,
``"tag-tools NetCDF (variables A, M, P; 50 Hz)"``, ``"BROAD trial (HDF5)"``, ``"MATLAB v7.3 file with variables accelBuffer(12243×4
double)"``, ``"CSV with columns …"``. :func:`tiltlab.io.read` uses it to choose a
reader; the NetCDF reader uses it to say what a file that is not a Recording is.
"""

from __future__ import annotations

from pathlib import Path

from ._common import PathLike, ReadError, no_file
from .broad import _BROAD_VARS
from .mat import describe_mat, list_variables, mat_version
from .ncfile import is_recording, netcdf_format, open_netcdf
from .tagtools import _rate, sensor_variables

__all__ = ["detect", "TEXT_SUFFIXES"]

#: Suffixes read as delimited text (they need a column mapping).
TEXT_SUFFIXES = (".csv", ".tsv", ".txt", ".dat")


def _listing(items: list[str], limit: int = 8) -> str:
    shown = ", ".join(items[:limit])
    return shown + (f" … ({len(items) - limit} more)" if len(items) > limit else "")


def _describe_netcdf(path: Path, kind: str) -> str:
    ds = open_netcdf(path)
    if is_recording(ds):
        return "tiltlab Recording (NetCDF)"
    found = sensor_variables(ds)
    if found:
        names = list(found.values())
        rates = {}
        for n in names:
            try:
                rates[n] = _rate(ds[n], path)
            except ReadError:
                rates[n] = float("nan")
        distinct = sorted(set(rates.values()))
        if len(distinct) == 1:
            rate = f"{distinct[0]:g} Hz"
        else:
            rate = ", ".join(f"{n} {fs:g} Hz" for n, fs in rates.items())
        extra = "" if kind == "NetCDF-4" else f", {kind}"
        return f"tag-tools NetCDF (variables {', '.join(names)}; {rate}{extra})"
    variables = [f"{n}{tuple(ds[n].shape)}" for n in map(str, ds.data_vars)]
    return f"{kind} file with variables {_listing(variables) or 'none'}"


def _broad_like(names: set[str]) -> bool:
    return all(k in names for k in _BROAD_VARS)


def _describe_hdf5(path: Path) -> str:
    import h5py

    try:
        with h5py.File(path, "r") as f:
            names = [str(k) for k in f.keys()]
            shapes = {
                k: tuple(f[k].shape) for k in names if isinstance(f[k], h5py.Dataset)
            }
    except OSError as exc:
        raise ReadError(
            f"{path}: cannot read HDF5 file ({exc}); truncated or corrupt?"
        ) from None
    if _broad_like(set(names)):
        return "BROAD trial (HDF5)"
    listed = [f"{k}{shapes[k]}" if k in shapes else f"{k}/" for k in names]
    return f"HDF5 file with {_listing(listed) or 'nothing in it'}"


def _describe_text(path: Path) -> str:
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            head = [f.readline().rstrip("\r\n") for _ in range(2)]
    except OSError as exc:
        raise ReadError(f"{path}: cannot read ({exc})") from None
    if not head[0]:
        return "empty text file"
    line = head[0]
    sep = max((",", ";", "\t", "|"), key=line.count)
    if line.count(sep) == 0:
        return f"text file starting {line[:60]!r}"
    cols = [c.strip() for c in line.split(sep)]
    kind = {"\t": "TSV", ";": "CSV (';'-separated)", "|": "CSV ('|'-separated)"}.get(
        sep, "CSV"
    )
    return f"{kind} with columns {_listing(cols, 10)}"


def detect(path: PathLike) -> str:
    """One line saying what a data file looks like.

    Parameters
    ----------
    path
        Any file.

    Returns
    -------
    str
        E.g. ``"tiltlab Recording (NetCDF)"``, ``"tag-tools NetCDF (variables A, M,
        P; 50 Hz)"``, ``"BROAD trial (MATLAB v5)"``, ``"MATLAB v7.3 file with variables
        accelBuffer(12243×4 double)"``, ``"CSV with columns t, ax, ay, az"``.

    Raises
    ------
    ReadError
        If the file is missing or damaged beyond recognition.

    Examples
    --------
    >>> from tiltlab import io
    >>> io.detect("session.nc")  # doctest: +SKIP
    'tiltlab Recording (NetCDF)'
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(no_file(path))
    version = mat_version(path)
    if version is not None:
        names = {v[0] for v in list_variables(path)}
        if _broad_like(names):
            return f"BROAD trial (MATLAB v{version})"
        return describe_mat(path)
    kind = netcdf_format(path)
    if kind == "NetCDF-4":
        try:
            return _describe_netcdf(path, kind)
        except ReadError:
            return _describe_hdf5(path)  # HDF5 that is not NetCDF-4
    if kind is not None:
        if "CDF-5" in kind:
            return f"{kind} file"
        return _describe_netcdf(path, kind)
    if path.suffix.lower() in TEXT_SUFFIXES:
        return _describe_text(path)
    with open(path, "rb") as f:
        head = f.read(512)
    if head and b"\x00" not in head:
        return _describe_text(path)
    return f"file of unknown type ({path.suffix or 'no suffix'})"
