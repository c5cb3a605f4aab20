"""Small input checks shared by the calibration submodules (private)."""

from __future__ import annotations

import numpy as np


class CalibrationError(ValueError):
    """Calibration input cannot support the requested fit, or a calibration was misapplied."""


def check_fs(fs) -> float:
    if fs is None:
        raise ValueError("fs (sampling rate, Hz) is mandatory")
    fs = float(fs)
    if not np.isfinite(fs) or fs <= 0:
        raise ValueError(f"fs must be a positive finite number of Hz, got {fs!r}")
    return fs


def vec3(x, name: str, *, ndim: int | None = None) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.ndim == 0 or a.shape[-1] != 3:
        raise ValueError(f"{name} must have last dimension 3, got shape {a.shape}")
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"{name} must be {ndim}-dimensional, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return a


def mat3(x, name: str) -> np.ndarray:
    m = np.asarray(x, dtype=float)
    if m.shape != (3, 3):
        raise ValueError(f"{name} must be a 3x3 matrix, got shape {m.shape}")
    if not np.all(np.isfinite(m)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return m
