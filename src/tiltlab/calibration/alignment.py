r"""Frame alignment: head frame from markers, marker QC, IMU-to-head and mounting.

Frame alignment: head frame from motion-capture markers, marker quality control,
IMU-to-head alignment (Kabsch) and device-to-body mounting angles.

The geometry itself (marker head frame, Benhamou's mounting angles) is implemented once,
in :mod:`tiltlab.frames`; this module validates the inputs and solves the alignment
problems.

* Head frame from three markers (Fayat et al. 2021 [1]_ §2.6.4), with
  :math:`v_{21} = p_1 - p_2`, :math:`v_{23} = p_3 - p_2`:
  :math:`h_y = v_{21}/\|v_{21}\|`, :math:`h_z = (v_{23}\times h_y)/\|v_{23}\times h_y\|`,
  :math:`h_x = h_y \times h_z`. Head tilt is the world vertical :math:`m_z` expressed in
  :math:`(h_x, h_y, h_z)`.
* Marker QC (§2.6.3): the frames with the 2 % largest :math:`|d_{12} - \mathrm{median}(d_{12})|`
  are dropped; the optical tilt uncertainty is :math:`\arctan(\sigma_{d_{12}}/\mathrm{median}(d_{12}))`
  (0.21 mm → 0.38° in [1]_).
* IMU→head alignment (§2.6.6): the rotation minimising the distance between the
  normalised low-passed (< 2 Hz) acceleration in the IMU frame and the vertical in the
  head frame during stillness — the Kabsch problem [2]_, solved by
  :meth:`scipy.spatial.transform.Rotation.align_vectors`. The low-pass is
  :func:`tiltlab.dsp.lowpass` (zero-phase Butterworth).
* Device→body mounting angles from a level-rest acceleration (Benhamou 2023 [3]_ Eq. 1),
  delegated to :func:`tiltlab.frames.mounting_angles` / :func:`tiltlab.frames.mounting_matrix`.

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
.. [2] W. Kabsch, "A solution for the best rotation to relate two sets of vectors",
   Acta Cryst. A32:922–923, 1976. doi:10.1107/S0567739476001873
.. [3] S. Benhamou, arXiv:2310.05820, 2023. doi:10.48550/arXiv.2310.05820
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate as _v
from .. import frames as _frames
from ..frames import head_frame_from_markers
from .. import quaternion as _quat
from ..dsp import lowpass
from ._util import CalibrationError, vec3

__all__ = [
    "head_frame_from_markers",
    "tilt_from_markers",
    "MarkerQC",
    "marker_distance_qc",
    "optical_tilt_uncertainty",
    "Alignment",
    "imu_to_head_alignment",
    "mounting_rotation",
]


def tilt_from_markers(p1, p2, p3) -> np.ndarray:
    """Compute the head tilt: the world vertical m_z in head coordinates, R(head)ᵀ e_z.

    The head frame is :func:`tiltlab.frames.head_frame_from_markers` (also exported
    here), which raises ``ValueError`` for coincident or collinear markers.

    Parameters
    ----------
    p1, p2, p3 : array_like, shape (..., 3)
        Positions of the three head markers (world frame, any length unit); NaN marks
        a missing marker.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Unit vectors of the world vertical in head coordinates (NaN where a marker is
        missing).
    """
    return head_frame_from_markers(p1, p2, p3)[..., 2, :]


class MarkerQC(NamedTuple):
    """Result of :func:`marker_distance_qc`.

    ``keep`` (N,) frames kept, ``distance`` (N,) d₁₂, ``median``, ``sigma_all``,
    ``sigma_kept`` (units of the markers), ``tilt_uncertainty_deg``.
    """

    keep: np.ndarray
    distance: np.ndarray
    median: float
    sigma_all: float
    sigma_kept: float
    tilt_uncertainty_deg: float


def optical_tilt_uncertainty(sigma, median_distance) -> float:
    """Optical tilt uncertainty (°): arctan(σ_d / median d) (Fayat §2.6.3).

    ``sigma`` and ``median_distance`` are in the same length unit (e.g. mm).

    Parameters
    ----------
    sigma : float
        Standard deviation σ_d of the marker distance (≥ 0).
    median_distance : float
        Median marker distance d (> 0).

    Returns
    -------
    float
        The uncertainty (degrees).
    """
    sigma = _v.nonnegative(sigma, "sigma")
    median_distance = _v.positive(median_distance, "median_distance")
    return float(np.degrees(np.arctan(sigma / median_distance)))


def marker_distance_qc(p1, p2, *, drop_fraction: float = 0.02) -> MarkerQC:
    """Drop the ``drop_fraction`` frames with the largest |d₁₂ − median(d₁₂)| (Fayat §2.6.3).

    Frames with a missing marker (NaN) are dropped as well and do not count in the
    fraction.

    Parameters
    ----------
    p1, p2 : array_like, shape (N, 3)
        Positions of two markers (any length unit, e.g. mm); NaN marks a missing
        marker.
    drop_fraction : float
        Fraction of the valid frames dropped, in [0, 1) (default 0.02, 2 %).

    Returns
    -------
    MarkerQC
        ``keep`` (N,) bool, ``distance`` (N,), ``median``, ``sigma_all``,
        ``sigma_kept`` (units of the markers) and ``tilt_uncertainty_deg`` (°).

    Raises
    ------
    CalibrationError
        Fewer than three frames with both markers.
    """
    a = _v.vectors(p1, "p1", allow_nan=True)
    b = _v.vectors(p2, "p2", allow_nan=True)
    if a.shape != b.shape:
        raise ValueError(
            f"p1 and p2 must have the same shape (N, 3), got {a.shape} and {b.shape}"
        )
    drop_fraction = _v.fraction(drop_fraction, "drop_fraction", open_high=True)
    d = np.linalg.norm(a - b, axis=-1)
    ok = np.isfinite(d)
    if ok.sum() < 3:
        raise CalibrationError("fewer than three frames with both markers")
    med = float(np.median(d[ok]))
    dev = np.where(ok, np.abs(d - med), np.inf)
    n_drop = int(np.ceil(drop_fraction * ok.sum()))
    keep = ok.copy()
    if n_drop:
        keep[np.argsort(dev, kind="stable")[ok.sum() - n_drop : ok.sum()]] = False
    s_all, s_kept = float(np.std(d[ok], ddof=1)), float(np.std(d[keep], ddof=1))
    return MarkerQC(keep, d, med, s_all, s_kept, optical_tilt_uncertainty(s_kept, med))


class Alignment(NamedTuple):
    """Result of :func:`imu_to_head_alignment`.

    ``matrix`` (3, 3) IMU→head rotation, ``quaternion`` (4,), ``rms_deg`` RMS angle
    between aligned IMU gravity and head vertical, ``n`` samples used.
    """

    matrix: np.ndarray
    quaternion: np.ndarray
    rms_deg: float
    n: int


def imu_to_head_alignment(
    acc,
    tilt_head,
    fs: float | None = None,
    *,
    still=None,
    cutoff_hz: float = 2.0,
    min_spread_deg: float = 5.0,
) -> Alignment:
    r"""Find the IMU→head rotation that aligns still accelerations with the head vertical.

    Rotation R (IMU→head) minimising :math:`\sum_t \|R\,\hat a_t - z^h_t\|^2` over
    still samples (Kabsch).

    Parameters
    ----------
    acc : Recording, DataArray or array_like (N, 3)
        IMU acceleration (a Recording's ``acc``; any unit: it is normalised after
        low-pass filtering).
    tilt_head : DataArray or array_like (N, 3)
        Vertical in the head frame from motion capture (:func:`tilt_from_markers`);
        NaN where the markers are missing or dropped.
    fs : float, optional
        Sampling rate (Hz) of both (already synchronised) streams; read from the attrs
        of labelled input, mandatory for plain arrays.
    still : array_like (N,) of bool, optional
        Samples to use (immobility); default all finite ones.
    cutoff_hz : float
        Low-pass cut-off (Hz; 2 Hz in Fayat et al.), :func:`tiltlab.dsp.lowpass`.
    min_spread_deg : float
        The rotation about a single gravity direction is unobservable: the used tilts
        must spread over at least this angle (°) from their mean, else
        :class:`CalibrationError`.

    Returns
    -------
    Alignment
        The IMU→head rotation (``matrix``, ``quaternion``), the RMS angle (°) between
        aligned IMU gravity and head vertical, and the number of samples used.
    """
    sa = _v.signal(acc, "acc", fs=fs)
    a, fs = sa.values, sa.fs
    z = _v.signal(tilt_head, "tilt_head", fs=fs, allow_nan=True).values
    if z.shape != a.shape:
        raise ValueError(
            f"acc and tilt_head must have the same shape, got {a.shape} and {z.shape}"
        )
    cutoff_hz = _v.positive(cutoff_hz, "cutoff_hz")
    min_spread_deg = _v.nonnegative(min_spread_deg, "min_spread_deg")
    alp = lowpass(a, fs, cutoff_hz)
    u = alp / np.linalg.norm(alp, axis=1, keepdims=True)
    use = np.all(np.isfinite(z), axis=1)
    if still is not None:
        s = np.asarray(still, bool)
        if s.shape != (a.shape[0],):
            raise ValueError(
                f"still must have one value per sample ({a.shape[0]}), got shape {s.shape}"
            )
        use &= s
    if use.sum() < 3:
        raise CalibrationError("fewer than three usable still samples")
    zu = z[use] / np.linalg.norm(z[use], axis=1, keepdims=True)
    m = zu.mean(axis=0)
    spread = np.degrees(np.max(np.arccos(np.clip(zu @ (m / np.linalg.norm(m)), -1, 1))))
    if spread < min_spread_deg:
        raise CalibrationError(
            f"still tilts span only {spread:.2f}° (< min_spread_deg = {min_spread_deg}°): "
            "the rotation about gravity is not determined"
        )
    rot, rssd = Rotation.align_vectors(zu, u[use])
    R = rot.as_matrix()
    ang = _quat.angle_between(u[use] @ R.T, zu)
    return Alignment(
        R,
        _quat.from_scipy(rot),
        float(np.degrees(np.sqrt(np.mean(ang**2)))),
        int(use.sum()),
    )


def mounting_rotation(acc_rest) -> np.ndarray:
    r"""Device→body matrix :math:`R_2(\phi^*)R_1(\lambda^*)` from a level-rest acceleration (Benhamou Eq. 1).

    ``acc_rest`` is a tiltlab specific-force reading (or several, averaged) taken with
    the animal resting level; apply as ``B = M @ D``.

    Parameters
    ----------
    acc_rest : array_like, shape (3,) or (N, 3)
        Specific force at level rest (any unit; several readings are averaged).

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        The device→body rotation matrix ``M``.
    """
    a = vec3(acc_rest, "acc_rest")
    if a.ndim == 2:
        a = a.mean(axis=0)
    phi, lam = _frames.mounting_angles(a)
    return np.asarray(_frames.mounting_matrix(phi, lam))
