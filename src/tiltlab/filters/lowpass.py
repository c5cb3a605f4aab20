r"""Tilt from the low-passed accelerometer (6D, heading zero)."""

from __future__ import annotations

import numpy as np

from .. import dsp
from ._common import samples, tilt_quaternion, unlabel
from ._docs import shared_docs

__all__ = ["lowpass_tilt"]


@shared_docs
def lowpass_tilt(
    acc, fs: float | None = None, *, cutoff_hz: float = 1.0, order: int = 2
) -> np.ndarray:
    r"""Tilt from the low-passed accelerometer (zero-phase Butterworth).

    :math:`g_s = \mathrm{LP}(a) / \|\mathrm{LP}(a)\|` with :func:`tiltlab.dsp.lowpass`
    (Butterworth of ``order`` applied forward and backward: effective order
    ``2·order``, zero phase). The quaternion is the minimal rotation taking
    :math:`g_s` to :math:`e_z` (heading part zero).

    Parameters
    ----------
    acc : array_like or xarray.DataArray, shape (N, 3)
        Specific force (any unit). A labelled DataArray is read by its attributes
        (``units``: converted to m/s² when present; ``fs``; see
        :mod:`tiltlab.filters`, "Labelled inputs").
    %(fs)s
    cutoff_hz : float
        Cut-off frequency (Hz), ``0 < cutoff_hz < fs/2``.
    order : int
        Butterworth order of each pass.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
    """
    fs, acc, _, _ = unlabel(fs, acc=acc)
    acc = samples(acc, "acc")
    lp = dsp.lowpass(acc, fs, cutoff_hz, order=order, name="acc")
    n = np.linalg.norm(lp, axis=1, keepdims=True)
    if np.any(n == 0):
        raise ValueError("the low-passed acceleration vanishes; no tilt can be defined")
    return tilt_quaternion(lp / n)
