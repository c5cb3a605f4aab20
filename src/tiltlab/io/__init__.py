"""Readers and writers. I/O only: each reader parses a file into a Recording
(:mod:`tiltlab.schema`) without any processing beyond unit labelling, and each
writer stores one losslessly.

Supported formats
-----------------
* Fayat et al. 2021 CSV files: the freely-moving example (``read_fayat_imu``) and
  the tumble test (``read_fayat_tumble``).
* BROAD benchmark trials, ``.hdf5`` and MATLAB ``.mat`` layouts (``read_broad``).
* A generic CSV with a column/unit mapping (``read_csv``), the mapping given as a dict
  or a JSON file (``read_csv_mapping``); time columns in s, ms or µs.
* One numeric variable of a MATLAB file, v4–v7 or v7.3/HDF5 (``read_matrix``), in
  MATLAB's own shape.
* NetCDF via h5netcdf (``save_netcdf`` / ``load_netcdf``), exact round trip
  including attributes of any JSON-serialisable type.
"""

from __future__ import annotations

from ._common import ReadError
from .broad import read_broad
from .csv import FS_RANGE, GAP_POLICIES, TIME_UNITS, read_csv, read_csv_mapping
from .fayat import read_fayat_imu, read_fayat_tumble
from .mat import read_matrix
from .netcdf import load_netcdf, save_netcdf

__all__ = [
    "ReadError",
    "read_fayat_imu",
    "read_fayat_tumble",
    "read_broad",
    "read_csv",
    "read_csv_mapping",
    "TIME_UNITS",
    "FS_RANGE",
    "GAP_POLICIES",
    "save_netcdf",
    "load_netcdf",
    "read_matrix",
]
