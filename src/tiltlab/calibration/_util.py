"""Small input checks shared by the calibration submodules (private)."""

from __future__ import annotations

import numpy as np

from ..units import check_fs


class CalibrationError(ValueError):
    """Calibration input cannot support the requested fit, or a calibration was misapplied."""


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
