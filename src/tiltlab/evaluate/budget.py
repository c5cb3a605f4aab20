r"""What bounds a tilt estimate's error against a reference: an error budget.

Three measured parts of the tilt error of several estimates of one recording:

* **slow and fast parts.** The tilt error vector
  :math:`\epsilon_k = \theta_k\, u_k` (angle :math:`\theta_k` between the estimated
  and the reference gravity-up directions, about the unit axis
  :math:`u_k \propto g^{\mathrm{ref}}_k \times \hat g_k`, sensor frame) is split by a
  zero-phase low-pass at ``cutoff_hz`` into a slow part and the fast rest. Over a
  fraction of a second an estimate follows its gyroscope integration, so estimators
  that share a gyroscope share their fast part when that integration is accurate
  (compare their ``fast`` values): it is then the reference's own fast errors
  (marker noise, a time offset between the two clocks under rotation), which no
  inertial estimator can remove.
* **spread.** The RMS tilt difference :math:`s_m` between estimate :math:`m` and a
  baseline :math:`b` bounds how much their errors can differ: per sample
  :math:`|\theta^m_k - \theta^b_k| \le \angle(\hat g^m_k, \hat g^b_k)` (the
  triangle inequality on the sphere), hence by Minkowski's inequality
  :math:`|\mathrm{RMSE}_m - \mathrm{RMSE}_b| \le s_m`. Estimates that differ from
  the baseline by little cannot beat it by more.

References
----------
.. [1] D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD — A Benchmark for Robust
   Inertial Orientation Estimation", Data 6(7):72, 2021. doi:10.3390/data6070072
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from .. import dsp
from .. import quaternion as quat
from .errors import _quat_array, _valid_mask, shift_quaternions

__all__ = ["error_budget"]

_PARTS = {
    "total": "tilt RMSE",
    "slow": "tilt RMSE, slow part",
    "fast": "tilt RMSE, fast part",
    "spread": "RMS tilt difference to the baseline",
}


def _error_vectors(q: np.ndarray, g_ref: np.ndarray) -> np.ndarray:
    """Return the rotation vectors (degrees) taking the reference gravity-up onto the estimate's."""
    g = quat.gravity(q)
    c = np.cross(g_ref, g)
    s = np.linalg.norm(c, axis=1, keepdims=True)
    theta = np.arctan2(s, np.sum(g_ref * g, axis=1, keepdims=True))
    return np.degrees(np.where(s > 0, c / np.where(s > 0, s, 1.0), 0.0) * theta)


def _filled_reference(rec: xr.Dataset) -> tuple[np.ndarray, np.ndarray]:
    """Bridge the tracking gaps of the reference (for filtering); return it and its valid rows."""
    q_ref = rec["q_ref"].transpose("time", "quat").values.astype(float)
    ok = np.all(np.isfinite(q_ref), axis=1)
    if not ok.any():
        raise ValueError("the reference 'q_ref' has no finite sample")
    if ok.all():
        return q_ref, ok
    idx = np.flatnonzero(ok)
    valid = q_ref[idx]
    # q and -q are one rotation: flip signs so that neighbours agree before bridging
    flips = np.cumsum(np.sum(valid[1:] * valid[:-1], axis=1) < 0) % 2
    valid = valid * np.concatenate([[1.0], 1.0 - 2.0 * flips])[:, None]
    t = np.arange(q_ref.shape[0])
    filled = np.column_stack([np.interp(t, idx, valid[:, j]) for j in range(4)])
    return quat.normalize(filled), ok


def _rms(v: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum(v * v, axis=1))))


def error_budget(
    rec: xr.Dataset,
    estimates: Mapping[str, Any],
    *,
    cutoff_hz: float = 1.0,
    shift: float = 0.0,
    baseline: str | None = None,
    movement_only: bool = True,
) -> xr.Dataset:
    r"""Split the tilt errors of several estimates of one recording into measured parts.

    For each estimate: its tilt RMSE, the RMS of the slow and of the fast part of its
    tilt error vector (split at ``cutoff_hz``), and its RMS tilt difference from the
    ``baseline`` estimate, which bounds how much its RMSE can differ from the
    baseline's (see :mod:`tiltlab.evaluate.budget`).

    Parameters
    ----------
    rec : xarray.Dataset
        Recording with a reference ``q_ref`` (tracking gaps as NaN rows) and, when
        ``movement_only``, a boolean ``movement`` variable; ``fs`` in its attrs.
    estimates : mapping
        Method name → quaternions (N, 4) or a DataArray, one row per sample of ``rec``.
    cutoff_hz : float
        Frequency (Hz) separating the slow from the fast part (zero-phase second-order
        Butterworth, forward and backward).
    shift : float
        Time shift (samples) applied to every estimate first
        (:func:`~tiltlab.evaluate.shift_quaternions`; positive advances it).
    baseline : str, optional
        The estimate the spreads are measured from; default the first one.
    movement_only : bool
        Score only BROAD's ``movement`` samples (as :func:`broad_errors` does).

    Returns
    -------
    xarray.Dataset
        Over ``estimator``: ``total`` (equal to :func:`tilt_rmse` at the same shift),
        ``slow``, ``fast`` and ``spread`` (degrees), with ``units`` and
        ``long_name``; attrs ``cutoff_hz``, ``shift`` and ``baseline``.

    Raises
    ------
    ValueError
        If ``estimates`` is empty, ``baseline`` is not one of them, an estimate does
        not have one row per sample, or no sample is valid.

    Notes
    -----
    The parts are RMS values over the same samples; the slow and fast parts are not
    exactly orthogonal on a masked subset, so their squares need not add up to the
    total's. The bound :math:`|\mathrm{RMSE}_m - \mathrm{RMSE}_b| \le s_m` is exact.

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> from tiltlab import evaluate
    >>> n = 500
    >>> ref = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    >>> tipped = np.tile([np.cos(np.radians(0.25)), np.sin(np.radians(0.25)), 0, 0], (n, 1))
    >>> rec = xr.Dataset(
    ...     {"q_ref": (("time", "quat"), ref)}, attrs={"fs": 100.0}
    ... )
    >>> b = evaluate.error_budget(
    ...     rec, {"level": ref, "tipped": tipped}, movement_only=False
    ... )
    >>> np.round(b["total"].values, 3), np.round(b["spread"].values, 3)
    (array([0. , 0.5]), array([0. , 0.5]))
    """
    names = list(estimates)
    if not names:
        raise ValueError("estimates must hold at least one estimate")
    base = names[0] if baseline is None else baseline
    if base not in estimates:
        raise ValueError(f"baseline {base!r} is not one of the estimates {names}")
    fs = float(rec.attrs["fs"])
    q_ref, ok = _filled_reference(rec)
    g_ref = quat.gravity(q_ref)
    qs = {m: shift_quaternions(_quat_array(estimates[m], m), shift) for m in names}
    mask = ok & _valid_mask(qs[base], rec, movement_only)
    if not mask.any():
        raise ValueError("no valid samples (movement with a finite reference)")
    g_base = quat.gravity(qs[base])
    out = {k: [] for k in _PARTS}
    for m in names:
        e = _error_vectors(qs[m], g_ref)
        slow = dsp.lowpass(e, fs, cutoff_hz, name="tilt error")
        d = np.degrees(quat.angle_between(quat.gravity(qs[m])[mask], g_base[mask]))
        out["total"].append(_rms(e[mask]))
        out["slow"].append(_rms(slow[mask]))
        out["fast"].append(_rms((e - slow)[mask]))
        out["spread"].append(float(np.sqrt(np.mean(d * d))))
    return xr.Dataset(
        {
            k: ("estimator", np.array(v), {"units": "deg", "long_name": _PARTS[k]})
            for k, v in out.items()
        },
        coords={"estimator": names},
        attrs={"cutoff_hz": float(cutoff_hz), "shift": float(shift), "baseline": base},
    )
