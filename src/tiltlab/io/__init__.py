"""Read and write recordings: one module per format, every reader giving a Recording.

I/O only: each reader parses a file into a Recording (:mod:`tiltlab.schema`) without
any processing beyond unit labelling and axis mapping, and each writer stores one
losslessly.

Supported formats
-----------------
* Any file below through one entry point, :func:`read` (the reader chosen from the
  file's content), and :func:`detect`, one line saying what a file looks like.
* Fayat et al. 2021 CSV files: the freely-moving example (``read_fayat_imu``) and
  the tumble test (``read_fayat_tumble``).
* BROAD benchmark trials, ``.hdf5`` and MATLAB ``.mat`` layouts (``read_broad``).
* A generic CSV with a column/unit mapping (``read_csv``), the mapping given as a dict
  or a JSON file, checked into a :class:`CsvMapping` record (``read_csv_mapping``,
  ``CsvMapping.load``); time columns in s, ms, µs, ns or date-times,
  on a regular grid or resampled from a jittery clock (``clock="resample"``);
  ``try_read`` returns why a file is refused instead of raising.
* Exports with one file per sensor, each on its own clock (``read_multi``).
* Mappings for public recordings from other labs (``mapping_template``).
* tag-tools (animaltags) NetCDF archives, NetCDF-4 or NetCDF-3 (``read_tagtools``;
  ``write_tagtools`` writes that layout).
* One numeric variable of a MATLAB file, v4–v7 or v7.3/HDF5 (``read_matrix``), in
  MATLAB's own shape.
* NetCDF via h5netcdf (``save_netcdf`` / ``load_netcdf``), exact round trip
  including attributes of any JSON-serialisable type, each variable's SHA-256 stored
  and verified on load (:class:`IntegrityError` on a mismatch, ``verify=False`` to
  salvage; ``netcdf_checksums`` reads them); ``open_netcdf`` opens any NetCDF-4 or
  NetCDF-3 file as stored.
* C3D motion-capture exports (``read_c3d``): marker trajectories as a Dataset
  (``markers`` frame × marker × axis, NaN where not reconstructed), computed channels
  kept apart; ``c3d_path`` resolves ``"foreign:REL"`` in the data mirror.
"""

from __future__ import annotations

from .._stack import user_stacklevel
from ._common import IntegrityError, ReadError
from .broad import read_broad
from .c3d import c3d_path, read_c3d
from .check import try_read
from .checksums import SUMS_FILE, check_sums, file_sha256, read_sums, write_sums
from .csv import (
    FS_RANGE,
    READ_GAP_POLICIES,
    TIME_UNITS,
    CsvMapping,
    read_csv,
    read_csv_mapping,
)
from .detect import detect, read
from .fayat import read_fayat_imu, read_fayat_tumble
from .templates import mapping_template
from .mat import read_matrix
from .multi import read_multi
from .ncfile import netcdf_format, open_netcdf
from .netcdf import (
    NotRecordingError,
    load_netcdf,
    netcdf_checksums,
    save_netcdf,
)
from .tagtools import read_tagtools, write_tagtools

__all__ = [
    "ReadError",
    "IntegrityError",
    "SUMS_FILE",
    "file_sha256",
    "read_sums",
    "check_sums",
    "write_sums",
    "NotRecordingError",
    "read",
    "detect",
    "read_fayat_imu",
    "read_fayat_tumble",
    "read_broad",
    "read_c3d",
    "c3d_path",
    "read_csv",
    "read_csv_mapping",
    "CsvMapping",
    "try_read",
    "read_tagtools",
    "write_tagtools",
    "read_matrix",
    "read_multi",
    "mapping_template",
    "TIME_UNITS",
    "FS_RANGE",
    "READ_GAP_POLICIES",
    "save_netcdf",
    "load_netcdf",
    "open_netcdf",
    "netcdf_format",
    "netcdf_checksums",
]


def __getattr__(name: str):
    """Resolve the old name ``GAP_POLICIES`` (now :data:`READ_GAP_POLICIES`), warning."""
    if name == "GAP_POLICIES":
        import warnings

        warnings.warn(
            "tiltlab.io.GAP_POLICIES was renamed READ_GAP_POLICIES; the old name goes "
            "in the next release",
            FutureWarning,
            stacklevel=user_stacklevel(),
        )
        return READ_GAP_POLICIES
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
