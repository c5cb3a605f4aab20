r"""Clocks: constant lag between two sensors, and TTL-synchronised streams with slips.

* :func:`estimate_lag` — the lag maximising the normalised cross-correlation of two
  recordings of the same motion, refined below one sample by maximising the correlation
  with a cubic-spline fractional shift. LaCanna (2018) [1]_ measured by hand a lag of
  0.2996 ± 0.0374 s between a MetaWear C-Pro and an Arduino sensor fixed together.
* :func:`repair_ttl_slips` — Fayat et al. (2021) [2]_ App. A.2: a TTL pulse every
  ``cycle`` motion-capture frames timestamps one IMU sample; when two consecutive
  timestamps are ``cycle ± 1`` IMU samples apart (clock phase slip, 0.07 % of cycles),
  the last mocap sample of that cycle is duplicated (+1) or deleted (−1) so that mocap
  and IMU never drift apart by more than one sample.

References
----------
.. [1] C. Q. LaCanna, MSc thesis, Rutgers University, 2018.
.. [2] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import minimize_scalar
from scipy.signal import correlate, correlation_lags

from .. import _validate as _v
from ._util import CalibrationError

__all__ = ["LagEstimate", "estimate_lag", "SlipRepair", "repair_ttl_slips"]


class LagEstimate(NamedTuple):
    """Result of :func:`estimate_lag`.

    ``lag_s`` (s; positive when ``y`` lags ``x``, i.e. y(t) ≈ x(t − lag)), ``lag_samples``
    (in samples of ``fs``), ``correlation`` (normalised correlation at the lag).
    """

    lag_s: float
    lag_samples: float
    correlation: float


def _centre(z: np.ndarray) -> np.ndarray:
    if z.ndim == 1:
        z = z[:, None]
    return z - z.mean(axis=0)


def _channels(data, name: str, var: str, fs, need_fs: bool) -> _v.Signal:
    s = _v.signal(data, name, var=var, fs=fs, width=None, ndim=None, need_fs=need_fs)
    if s.values.ndim not in (1, 2):
        raise ValueError(f"{name} must have shape (N,) or (N, k), got {s.values.shape}")
    return s


def estimate_lag(
    x,
    y,
    fs: float | None = None,
    *,
    fs_y: float | None = None,
    max_lag_s: float | None = None,
    var: str = "acc",
) -> LagEstimate:
    """Constant lag between two recordings of the same motion.

    Parameters
    ----------
    x, y : Recording, DataArray or array_like (N,) or (N, k)
        The two signals (same channels; e.g. acceleration norms or axes; for a
        Recording, its variable ``var``). Channel correlations are summed.
    fs : float, optional
        Sampling rate of ``x`` (Hz); read from the attrs of labelled ``x``, mandatory
        for a plain array.
    fs_y : float, optional
        Sampling rate of ``y`` (Hz); read from the attrs of labelled ``y``; default
        ``fs``. If different, ``y`` is interpolated (cubic spline) onto the time grid
        of ``x`` first.
    max_lag_s : float, optional
        Search range (s); default a quarter of the shorter record.
    var : str
        Variable read from a Recording.

    Returns
    -------
    LagEstimate
    """
    sx = _channels(x, "x", var, fs, True)
    sy = _channels(y, "y", var, fs_y, False)
    fs = sx.fs
    fy = fs if sy.fs is None else sy.fs
    a, b = _centre(sx.values), _centre(sy.values)
    if a.shape[1] != b.shape[1]:
        raise ValueError(
            f"x and y must have the same number of channels, got {a.shape[1]} and "
            f"{b.shape[1]}"
        )
    if max_lag_s is not None:
        max_lag_s = _v.nonnegative(max_lag_s, "max_lag_s")
    if fy != fs:
        ty = np.arange(b.shape[0]) / fy
        tx = np.arange(int(np.floor(ty[-1] * fs)) + 1) / fs
        b = _centre(CubicSpline(ty, b, axis=0)(tx))
    n = min(a.shape[0], b.shape[0])
    if n < 8:
        raise CalibrationError(
            f"signals too short to estimate a lag ({n} common samples, needs 8)"
        )
    max_lag = int(round((max_lag_s if max_lag_s is not None else n / fs / 4) * fs))
    cc = sum(
        correlate(b[:, j], a[:, j], mode="full", method="fft")
        for j in range(a.shape[1])
    )
    lags = correlation_lags(b.shape[0], a.shape[0], mode="full")
    sel = np.abs(lags) <= max_lag
    k0 = int(lags[sel][np.argmax(cc[sel])])
    spl = CubicSpline(np.arange(b.shape[0]), b, axis=0)
    ia = np.arange(a.shape[0])

    def neg_corr(d):
        # correlation of x(t) with y(t + d): y lags x by d samples
        t = ia + d
        ok = (t >= 0) & (t <= b.shape[0] - 1)
        if ok.sum() < 8:
            return 0.0
        xa, yb = a[ok], spl(t[ok])
        xa, yb = xa - xa.mean(axis=0), yb - yb.mean(axis=0)
        den = np.sqrt(np.sum(xa * xa) * np.sum(yb * yb))
        return -float(np.sum(xa * yb) / den) if den > 0 else 0.0

    res = minimize_scalar(
        neg_corr, bounds=(k0 - 1.0, k0 + 1.0), method="bounded", options={"xatol": 1e-4}
    )
    d = float(res.x)
    return LagEstimate(d / fs, d, -float(res.fun))


class SlipRepair(NamedTuple):
    """Result of :func:`repair_ttl_slips`.

    ``mocap`` aligned mocap samples, one per IMU sample of ``imu_index``; ``imu_index``
    (M,) IMU sample indices covered (from the first to the last timestamp); ``n_duplicated``
    and ``n_deleted`` cycle corrections; ``cycle_lengths`` IMU samples between timestamps.
    """

    mocap: np.ndarray
    imu_index: np.ndarray
    n_duplicated: int
    n_deleted: int
    cycle_lengths: np.ndarray


def repair_ttl_slips(
    mocap, ttl_imu_index, *, cycle: int = 6, first_frame: int = 0, max_slip: int = 1
) -> SlipRepair:
    """Align motion-capture frames with IMU samples using TTL timestamps (Fayat App. A.2).

    Parameters
    ----------
    mocap : array_like (F, ...)
        Mocap frames (any trailing shape, e.g. markers × xyz).
    ttl_imu_index : array_like (K,)
        Index of the IMU sample carrying each TTL timestamp, in order; TTL k was emitted
        at mocap frame ``first_frame + k * cycle``.
    cycle : int
        Mocap frames per TTL (6 in Fayat et al.: 300 Hz video, 50 Hz TTL).
    first_frame : int
        Mocap frame of the first TTL.
    max_slip : int
        Largest accepted |IMU samples − cycle| per cycle; larger gaps (a lost TTL, a
        wrong ``cycle``) raise :class:`CalibrationError` instead of being "repaired".

    Returns
    -------
    SlipRepair
        For a cycle spanning L IMU samples, the ``cycle`` mocap frames are kept and the
        last one duplicated L − cycle times (L > cycle) or the last cycle − L frames
        dropped (L < cycle).
    """
    m = np.asarray(mocap)
    idx = np.asarray(ttl_imu_index, dtype=np.int64)
    if idx.ndim != 1 or idx.size < 2:
        raise CalibrationError("need at least two TTL timestamps")
    cycle = _v.integer(cycle, "cycle", minimum=1)
    first_frame = _v.integer(first_frame, "first_frame", minimum=0)
    max_slip = _v.integer(max_slip, "max_slip", minimum=0)
    L = np.diff(idx)
    if np.any(L <= 0):
        raise CalibrationError("TTL timestamps must be strictly increasing IMU indices")
    bad = np.abs(L - cycle) > max_slip
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        raise CalibrationError(
            f"cycle {k} spans {L[k]} IMU samples for {cycle} mocap frames (slip > {max_slip}): "
            "a TTL pulse is missing or the cycle length is wrong"
        )
    need = first_frame + cycle * (idx.size - 1)
    if m.shape[0] < need:
        raise CalibrationError(
            f"mocap has {m.shape[0]} frames, the timestamps need {need}"
        )
    pieces = []
    for k, n_imu in enumerate(L):
        f0 = first_frame + k * cycle
        frames = np.arange(f0, f0 + cycle)
        if n_imu > cycle:
            frames = np.concatenate([frames, np.full(n_imu - cycle, f0 + cycle - 1)])
        else:
            frames = frames[:n_imu]
        pieces.append(frames)
    sel = np.concatenate(pieces)
    return SlipRepair(
        m[sel],
        np.arange(idx[0], idx[-1]),
        int(np.sum(np.maximum(L - cycle, 0))),
        int(np.sum(np.maximum(cycle - L, 0))),
        L,
    )
