r"""Training and inference inputs of the learned estimators, built from Recordings.

For every sample :math:`t` the network sees a window of the :math:`T` samples
:math:`t-T+1, \dots, t`: ten channels per sample (Zaheer et al. 2023, §5.3),

* the gyro-integrated quaternion :math:`q_{\omega,k} = q_0 \otimes \Delta q_{t-T \to k}`
  (4), where :math:`\Delta q_{t-T\to k}` integrates the gyroscope from sample
  :math:`t-T` to :math:`k` (zero-order hold) and :math:`q_0` is the orientation at
  :math:`t-T`;
* the specific force :math:`a_k / s_a` (3) and the magnetic field :math:`m_k / s_m`
  (3), with fixed scales :math:`s_a` (m/s²) and :math:`s_m` (µT) from the
  configuration.

Reading of the paper: the window's integration starts at its first sample, from an
orientation :math:`q_0` known at that time. In training :math:`q_0` is the reference
orientation at :math:`t-T` perturbed by a random rotation (the paper's augmentation of
the integrator's initial value); in use it is the network's own estimate :math:`T`
samples earlier (:mod:`tiltlab.learn.infer`), so the estimator is recursive with period
:math:`T`.

All increments are computed once per Recording from the cumulative integral
:math:`Q_k = \prod_{j<k} \exp(\omega_j \Delta t / 2)`:
:math:`\Delta q_{s\to k} = Q_s^{-1} \otimes Q_k`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from .. import _deprecate
from .. import _validate as _v
from .. import quaternion as quat
from ..filters import recordings as _rec
from ..filters.vectors import davenport, magnetic_dip

__all__ = ["Sequence", "sequence", "window_ends"]


@dataclass(frozen=True)
class Sequence:
    """One Recording's arrays for the learned estimators (float32 except ``fs``).

    Attributes
    ----------
    Q : ndarray, shape (N, 4)
        Cumulative gyroscope integral :math:`Q_k` (identity at k = 0).
    acc, mag : ndarray, shape (N, 3)
        Scaled specific force and magnetic field.
    q_vec : ndarray, shape (N, 4)
        Davenport (QUEST) orientation of every sample from ``acc`` and ``mag``.
    q_ref : ndarray, shape (N, 4) or None
        Reference orientation (NaN where unknown), when the Recording has ``q_ref``.
    fs : float
        Sampling rate (Hz).
    name : str
        The Recording's ``trial`` / ``session`` attr, or "".
    """

    Q: np.ndarray
    acc: np.ndarray
    mag: np.ndarray
    q_vec: np.ndarray
    q_ref: np.ndarray | None
    fs: float
    name: str

    def __len__(self) -> int:
        """Count the samples."""
        return self.Q.shape[0]


def _still_dip(acc: np.ndarray, mag: np.ndarray, fs: float) -> float:
    """Dip from the first second (the recording is expected to start at rest)."""
    n = max(1, int(round(fs)))
    return magnetic_dip(acc[:n], mag[:n])


#: the sensors the learned estimators read, with their names in messages
_NEEDED = (("gyr", "gyroscope"), ("mag", "magnetometer"))


def _require_sensors(rec: xr.Dataset) -> None:
    """Refuse a Recording without a gyroscope or magnetometer, naming the missing one."""
    if not isinstance(rec, xr.Dataset):
        return  # prepare() says what a Recording is
    missing = [f"a {what} ('{var}')" for var, what in _NEEDED if var not in rec]
    if missing:
        raise _v.RecordingError(
            f"the learned estimators need {' and '.join(missing)}: the recording has "
            f"only {', '.join(map(repr, map(str, rec.data_vars))) or 'no variables'} "
            "(an accelerometer-only recording cannot be used)"
        )


@_deprecate.renamed(recording="rec")
def sequence(
    rec: xr.Dataset,
    *,
    acc_scale: float = 9.81,
    mag_scale: float = 50.0,
) -> Sequence:
    """Build the arrays of a Recording for training or running a learned estimator.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording with ``acc``, ``gyr`` and ``mag`` (units in attrs, ``fs`` in
        attrs), optionally ``q_ref``.
    acc_scale : float
        Divisor of the specific force (m/s²).
    mag_scale : float
        Divisor of the magnetic field (in the magnetometer's own unit, µT for BROAD).

    Returns
    -------
    Sequence
        The float32 arrays of the learned estimators' inputs.

    Raises
    ------
    tiltlab._validate.RecordingError
        A Recording without a gyroscope or a magnetometer (naming the missing
        sensor), with non-finite samples or with time gaps.
    """
    acc_scale = _v.positive(acc_scale, "acc_scale")
    mag_scale = _v.positive(mag_scale, "mag_scale")
    _require_sensors(rec)
    inputs = _rec.prepare(rec, use_mag=True)
    for name, arr in (("acc", inputs.acc), ("gyr", inputs.gyr), ("mag", inputs.mag)):
        if not np.all(np.isfinite(arr)):
            raise _v.RecordingError(
                f"{name} has non-finite samples; the learned estimators need gap-free "
                "inputs"
            )
    time = inputs.like.time
    if time is not None and time.shape == (inputs.acc.shape[0],):
        segs = _v.segments(time, inputs.fs)
        if len(segs) > 1:
            raise _v.RecordingError(
                "the learned estimators need a recording without time gaps: "
                f"{_v.describe_gaps(time, inputs.fs, segs)} (split it first)"
            )
    Q = quat.integrate_gyro(inputs.gyr, inputs.fs)
    dip = _still_dip(inputs.acc, inputs.mag, inputs.fs)
    q_vec = davenport(inputs.acc, inputs.mag, dip=dip)
    q_ref = None
    if "q_ref" in rec:
        q_ref = rec["q_ref"].transpose("time", "quat").values.astype(np.float32)
    name = str(rec.attrs.get("trial", rec.attrs.get("session", "")))
    return Sequence(
        Q=Q.astype(np.float32),
        acc=(inputs.acc / acc_scale).astype(np.float32),
        mag=(inputs.mag / mag_scale).astype(np.float32),
        q_vec=q_vec.astype(np.float32),
        q_ref=q_ref,
        fs=inputs.fs,
        name=name,
    )


def window_ends(seq: Sequence, window: int, stride: int = 1) -> np.ndarray:
    """Find the window ends with a finite reference orientation at both ends.

    Parameters
    ----------
    seq : Sequence
        Arrays of a Recording with ``q_ref``.
    window : int
        Window length (samples).
    stride : int
        Keep every ``stride``-th end.

    Returns
    -------
    numpy.ndarray
        Indices ``t`` whose window ``t-window..t`` has a finite reference at both
        ends (training targets and initial orientations).
    """
    window = int(_v.integer(window, "window", minimum=1))
    stride = int(_v.integer(stride, "stride", minimum=1))
    if seq.q_ref is None:
        raise ValueError(f"sequence {seq.name!r} has no reference orientation q_ref")
    ok = np.all(np.isfinite(seq.q_ref), axis=1)
    t = np.arange(window, len(seq), stride)
    return t[ok[t] & ok[t - window]]
