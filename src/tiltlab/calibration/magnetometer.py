r"""Magnetometer calibration: Benhamou's four-point procedure, per-axis min/max, and an
ellipsoid (hard- and soft-iron) fit.

A magnetometer reads :math:`r = W m + h + n`: the local field :math:`m` (sensor frame)
distorted by a soft-iron matrix :math:`W` and shifted by a hard-iron offset :math:`h`.
Calibrated values are :math:`\hat m = S(r - h)`.

* **Four-point** (Benhamou 2023 [1]_ §3, Eq. 4): readings with the surge axis horizontal
  pointing N, E, S, W, once resting on the bottom and once on a flank; each axis is
  mapped to ±1 when pointing horizontally North/South. Diagonal S; implemented in
  :func:`tiltlab.trig.four_point_mag_calibration` and re-used here.
* **Min/max** (§3): :math:`h_i = (r_{max}+r_{min})/2`, :math:`S_{ii} = 2/(r_{max}-r_{min})`.
  Diagonal S; needs each axis to have pointed along ± the field direction explored.
* **Ellipsoid**: :math:`\|S(r-h)\| = B` fitted to readings spread over many orientations
  (:func:`tiltlab.calibration.fit_ellipsoid` with a symmetric S, the usual soft-iron
  gauge). Corrects cross-axis soft iron, which the two diagonal methods cannot.

References
----------
.. [1] S. Benhamou, arXiv:2310.05820, 2023. doi:10.48550/arXiv.2310.05820
"""

from __future__ import annotations

import numpy as np

from .. import trig as _trig
from ._util import CalibrationError, vec3
from .accel import EllipsoidFit, fit_ellipsoid

__all__ = [
    "four_point_poses",
    "four_point_mag_calibration",
    "minmax_mag_calibration",
    "fit_mag_ellipsoid",
    "apply_mag_calibration",
]

# Benhamou Eq. 4 is implemented once, in tiltlab.trig
four_point_mag_calibration = _trig.four_point_mag_calibration


def four_point_poses(flank_on: str = "left") -> tuple[np.ndarray, np.ndarray]:
    """Sensor→world (ENU) quaternions of the eight poses of the four-point procedure.

    Returns
    -------
    bottom, flank : ndarray (4, 4)
        Surge axis horizontal pointing N, E, S, W (rows), resting on the bottom (level)
        and on the ``flank_on`` flank (bank −90° for the left flank: sway axis down).
    """
    if flank_on not in ("left", "right"):
        raise ValueError("flank_on must be 'left' or 'right'")
    az = np.array([np.pi / 2, 0.0, -np.pi / 2, np.pi])  # N, E, S, W, ccw from East
    bank = -np.pi / 2 if flank_on == "left" else np.pi / 2
    bottom = _trig.angles_to_quaternion(az, np.zeros(4), np.zeros(4))
    flank = _trig.angles_to_quaternion(az, np.zeros(4), np.full(4, bank))
    return np.asarray(bottom), np.asarray(flank)


def minmax_mag_calibration(mag) -> tuple[np.ndarray, np.ndarray]:
    """Per-axis min/max calibration: offset ``(max+min)/2`` and ``diag(2/(max-min))``.

    Parameters
    ----------
    mag : array_like (N, 3)
        Raw readings covering, for every axis, both the northward and southward extremes.
    """
    r = vec3(mag, "mag", ndim=2)
    lo, hi = r.min(axis=0), r.max(axis=0)
    if np.any(hi - lo <= 0):
        raise CalibrationError("an axis has zero range: rotate the device so that every axis sweeps the field")
    return 0.5 * (hi + lo), np.diag(2.0 / (hi - lo))


def fit_mag_ellipsoid(mag, *, field: float | None = None, max_condition: float = 1e4) -> EllipsoidFit:
    """Hard/soft-iron ellipsoid fit (symmetric soft-iron correction).

    Parameters
    ----------
    mag : array_like (N, 3)
        Raw readings over many orientations (N ≥ 9, spread over the sphere).
    field : float, optional
        Local field strength (µT): the corrected norm. Default: the mean raw norm about
        the algebraic centre (only directions matter for heading).
    """
    r = vec3(mag, "mag", ndim=2)
    if field is None:
        field = float(np.mean(np.linalg.norm(r - r.mean(axis=0), axis=1)))
    if not field > 0:
        raise ValueError("field must be positive")
    return fit_ellipsoid(r, radius=field, structure="symmetric", max_condition=max_condition,
                         max_norm_deviation=np.inf)


def apply_mag_calibration(mag, offset, matrix=None) -> np.ndarray:
    """Calibrated readings ``S (r − h)`` (delegates to :func:`tiltlab.trig.calibrate_magnetometer`)."""
    return _trig.calibrate_magnetometer(mag, offset, matrix)
