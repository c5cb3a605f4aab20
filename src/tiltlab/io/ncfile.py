"""Opening any NetCDF file: its flavour from the first bytes, and its content as stored.

The layer under the NetCDF readers (:mod:`tiltlab.io.netcdf` for Recordings,
:mod:`tiltlab.io.tagtools` for tag-tools archives, :mod:`tiltlab.io.describe`).
"""

from __future__ import annotations

from pathlib import Path

import xarray as xr

import tiltlab._deprecate as _deprecate
from ._common import PathLike, ReadError, file_head, no_file

__all__ = ["netcdf_format", "open_netcdf", "is_recording"]

#: File attribute holding the attributes of a Recording written by tiltlab (JSON).
_ATTRS_KEY = "_tiltlab_attrs_json"

_MAGIC = {
    b"CDF\x01": "NetCDF-3 classic",
    b"CDF\x02": "NetCDF-3 64-bit offset",
    b"CDF\x05": "NetCDF-3 64-bit data (CDF-5)",
}


def netcdf_format(path: PathLike) -> str | None:
    """Name the NetCDF flavour of a file from its first bytes; None if it is not NetCDF.

    Parameters
    ----------
    path : path-like
        The file; its first 8 bytes, the format signature, are read.

    Returns
    -------
    str or None
        ``"NetCDF-4"`` (an HDF5 file), ``"NetCDF-3 classic"``, ``"NetCDF-3 64-bit
        offset"``, ``"NetCDF-3 64-bit data (CDF-5)"``, or None.
    """
    head = file_head(path, 8)
    if head is None:
        return None
    if head == b"\x89HDF\r\n\x1a\n":
        return "NetCDF-4"
    return _MAGIC.get(head[:4])


def open_netcdf(path: PathLike) -> xr.Dataset:
    """Open any NetCDF file (NetCDF-4 or NetCDF-3) into memory, values as stored.

    Times are not decoded; the engine is chosen from the file's first bytes.

    Parameters
    ----------
    path
        A NetCDF file.

    Returns
    -------
    xarray.Dataset
        The file's content, loaded.

    Raises
    ------
    ReadError
        If the file is missing, not NetCDF, or damaged.
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(no_file(path))
    kind = netcdf_format(path)
    if kind is None:
        raise ReadError(
            f"{path}: not a NetCDF file (neither NetCDF-4/HDF5 nor NetCDF-3)"
        )
    if "CDF-5" in kind:
        raise ReadError(
            f"{path}: {kind} file, which the installed NetCDF engines cannot read; "
            "rewrite it as NetCDF-4 (nccopy -k nc4 IN OUT)"
        )
    engine = "h5netcdf" if kind == "NetCDF-4" else "scipy"
    try:
        with xr.open_dataset(
            path, engine=engine, decode_times=False, mask_and_scale=False
        ) as f:
            return f.load()
    except Exception as exc:  # noqa: BLE001 - engines raise many types on damage
        raise ReadError(
            f"{path}: cannot read {kind} file ({type(exc).__name__}: {exc}); "
            "truncated or corrupt?"
        ) from None


@_deprecate.renamed(ds="data")
def is_recording(data: xr.Dataset) -> bool:
    """Tell whether an opened NetCDF file holds a tiltlab Recording (or tiltlab wrote it).

    Parameters
    ----------
    data : xarray.Dataset
        An opened NetCDF file.

    Returns
    -------
    bool
        True if ``data`` carries tiltlab's attributes, or has an ``acc`` variable, a
        ``time`` dimension and an ``fs`` attribute.
    """
    if _ATTRS_KEY in data.attrs:
        return True
    return "acc" in data.data_vars and "time" in data.dims and "fs" in data.attrs
