"""Opening any NetCDF file: its flavour from the first bytes, and its content as stored.

The layer under the NetCDF readers (:mod:`tiltlab.io.netcdf` for Recordings,
:mod:`tiltlab.io.tagtools` for tag-tools archives, :mod:`tiltlab.io.describe`).
"""

from __future__ import annotations

from pathlib import Path

import xarray as xr

from ._common import PathLike, ReadError, no_file

__all__ = ["netcdf_format", "open_netcdf", "is_recording"]

#: File attribute holding the attributes of a Recording written by tiltlab (JSON).
_ATTRS_KEY = "_tiltlab_attrs_json"

_MAGIC = {
    b"CDF\x01": "NetCDF-3 classic",
    b"CDF\x02": "NetCDF-3 64-bit offset",
    b"CDF\x05": "NetCDF-3 64-bit data (CDF-5)",
}


def netcdf_format(path: PathLike) -> str | None:
    """The NetCDF flavour of a file from its first bytes, or None if it is not NetCDF.

    Parameters
    ----------
    path
        File to inspect.

    Returns
    -------
    str or None
        ``"NetCDF-4"`` (an HDF5 file), ``"NetCDF-3 classic"``, ``"NetCDF-3 64-bit
        offset"``, ``"NetCDF-3 64-bit data (CDF-5)"``, or None.
    """
    try:
        with open(path, "rb") as f:
            head = f.read(8)
    except OSError:
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


def is_recording(ds: xr.Dataset) -> bool:
    """True if an opened NetCDF file holds a tiltlab Recording (or a file tiltlab wrote).

    Parameters
    ----------
    ds : xarray.Dataset
        An opened NetCDF file.

    Returns
    -------
    bool
        True if ``ds`` carries tiltlab's attributes, or has an ``acc`` variable, a
        ``time`` dimension and an ``fs`` attribute.
    """
    if _ATTRS_KEY in ds.attrs:
        return True
    return "acc" in ds.data_vars and "time" in ds.dims and "fs" in ds.attrs
