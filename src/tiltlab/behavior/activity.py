r"""Measure activity from the accelerometer (Benhamou 2023 §2, §9; Qasem et al. 2012).

Static acceleration, DBA/ODBA and one value per step.

The static acceleration :math:`\bar{\mathbf a}` is the per-axis mean over a Δt window;
the dynamic body acceleration (vectorial DBA, VeDBA) is
:math:`\|\mathbf a - \bar{\mathbf a}\|`. ``acc`` is a Recording (its ``acc``), a
labelled DataArray (``fs`` and ``units`` read from its attributes) or a plain array
with ``fs``; outputs keep the units of ``acc`` and are labelled when it is.

References
----------
.. [1] S. Benhamou, arXiv:2310.05820, 2023. doi:10.48550/arXiv.2310.05820
.. [2] L. Qasem et al., "Tri-axial dynamic acceleration as a proxy for animal energy
   expenditure; should we be summing values or calculating the vector?", PLoS ONE
   7:e31187, 2012. doi:10.1371/journal.pone.0031187
"""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np

from ..dsp import window_samples
from ._common import label, read_behavior_input, start_time, windowed

__all__ = [
    "window_length",
    "static_acceleration",
    "dba",
    "odba",
    "step_summary",
    "StepSummary",
]


class StepSummary(NamedTuple):
    """One value per Δt step (§9).

    Centre time (s), static acceleration (n, 3) and mean DBA.
    """

    time: np.ndarray
    static: np.ndarray
    dba: np.ndarray


def window_length(window_s: float, fs: float) -> int:
    """Count the samples k = round(f Δt) of a Δt window (at least 1).

    Parameters
    ----------
    window_s : float
        Window duration Δt (s).
    fs : float
        Sampling rate f (Hz).

    Returns
    -------
    int
        Window length k (samples), at least 1.
    """
    return window_samples(window_s, fs)


def _read_acc(acc, fs):
    # NaN marks a gap of a recording read with gaps="nan"; windows touching it are NaN
    return read_behavior_input(acc, "acc", fs=fs, need_fs=True, allow_nan=True)


def _sliding_mean(a: np.ndarray, k: int) -> np.ndarray:
    """Return the mean over a centred window of k samples, truncated at the ends.

    NaN where the window holds a non-finite sample (a gap), finite elsewhere.
    """
    n = a.shape[0]
    before = k // 2
    after = k - 1 - before
    bad = ~np.isfinite(a).all(axis=1)
    c = np.vstack(
        [np.zeros((1, a.shape[1])), np.cumsum(np.where(bad[:, None], 0, a), 0)]
    )
    cb = np.r_[0, np.cumsum(bad)]
    i = np.arange(n)
    lo = np.maximum(0, i - before)
    hi = np.minimum(n, i + after + 1)
    out = (c[hi] - c[lo]) / (hi - lo)[:, None]
    out[(cb[hi] - cb[lo]) > 0] = np.nan
    return out


def static_acceleration(
    acc,
    fs=None,
    *,
    window_s: float,
    mode: Literal["sliding", "jumping"] = "sliding",
):
    r"""Compute the static acceleration :math:`\bar{\mathbf a}` over a Δt window (§2).

    It is the per-axis mean over the window.

    ``"sliding"``: centred window of k = round(fΔt) samples attributed to its centre
    ((k−1)/2 samples either side for odd k; k/2 before and (k−2)/2 after for even k);
    near the ends the window is truncated to the available samples (no NaN). A window
    that holds a non-finite sample (a gap left as NaN by a reader) gives NaN. Output
    shape = input shape (N, 3).

    ``"jumping"``: means of consecutive non-overlapping blocks of k samples; a
    trailing incomplete block is dropped. Output shape (N // k, 3) (labelled: over the
    block-centre times, ``fs`` = blocks per second).

    Parameters
    ----------
    acc : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        Acceleration (any unit, kept).
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    window_s : float
        Window duration Δt (s).
    mode : {"sliding", "jumping"}
        Sliding (one value per sample) or jumping (one per block) window.

    Returns
    -------
    numpy.ndarray or xarray.DataArray
        Static acceleration, shape (N, 3) (``"sliding"``) or (N // k, 3)
        (``"jumping"``), in the units of ``acc``.

    Raises
    ------
    ValueError
        If ``mode`` is neither ``"sliding"`` nor ``"jumping"``.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import behavior
    >>> t = np.arange(400) / 100.0
    >>> acc = np.column_stack([np.sin(2 * np.pi * 5 * t), 0 * t, 1 + 0 * t])  # g
    >>> stat = behavior.static_acceleration(acc, 100.0, window_s=0.2)
    >>> np.round(stat[200], 3)
    array([0., 0., 1.])
    >>> behavior.static_acceleration(acc, 100.0, window_s=0.2, mode="jumping").shape
    (20, 3)
    """
    if mode not in ("sliding", "jumping"):
        raise ValueError(f"mode must be 'sliding' or 'jumping', got {mode!r}")
    s = _read_acc(acc, fs)
    a = s.values
    k = window_samples(window_s, s.fs)
    if mode == "jumping":
        nb = a.shape[0] // k
        out = a[: nb * k].reshape(nb, k, 3).mean(axis=1)
        centre = (np.arange(nb) * k + (k - 1) / 2) / s.fs
        return windowed(
            out,
            s,
            "static_acceleration",
            centre_s=centre,
            fs_out=s.fs / k,
            units=s.units,
        )
    return label(_sliding_mean(a, k), s, "static_acceleration", s.units)


def _dynamic(acc, fs, window_s: float):
    """Return the Signal read from ``acc`` and its dynamic part a − ā per sample."""
    s = _read_acc(acc, fs)
    a = s.values
    return s, a - _sliding_mean(a, window_samples(window_s, s.fs))


def dba(acc, fs=None, *, window_s: float):
    r"""Compute the dynamic body acceleration :math:`\|\mathbf a - \bar{\mathbf a}\|`.

    One value per sample (vectorial DBA, VeDBA [2]_).

    Posture-independent: it is invariant to any rotation of the device. Same units as
    ``acc``; see :func:`static_acceleration` for the inputs.

    Parameters
    ----------
    acc : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        Acceleration (any unit, kept), e.g. in g or m/s².
    fs : float, optional
        Sampling rate (Hz) of a plain array; read from the attributes when labelled.
    window_s : float
        Window duration Δt (s) of the sliding static-acceleration mean.

    Returns
    -------
    numpy.ndarray or xarray.DataArray (N,)
        DBA per sample, in the units of ``acc``; NaN where the window touches a gap.
    """
    s, dyn = _dynamic(acc, fs, window_s)
    return label(np.linalg.norm(dyn, axis=-1), s, "dba", s.units)


def odba(acc, fs=None, *, window_s: float):
    r"""Compute the overall DBA :math:`|d_U|+|d_V|+|d_W|` per sample (Wilson et al. 2006).

    Shown for comparison only: it depends on the device orientation (it is not
    rotation invariant), unlike :func:`dba`.

    Parameters
    ----------
    acc, fs, window_s : array_like (N, 3), float, float
        As in :func:`dba`: the acceleration (a Recording, a labelled DataArray or a
        plain array with ``fs``), its sampling rate and the window (s) of the static
        acceleration.

    Returns
    -------
    numpy.ndarray or xarray.DataArray (N,)
        ODBA per sample, in the units of ``acc``; NaN where the window touches a gap.
    """
    s, dyn = _dynamic(acc, fs, window_s)
    return label(np.abs(dyn).sum(axis=-1), s, "odba", s.units)


def step_summary(acc, fs=None, *, window_s: float) -> StepSummary:
    r"""Keep one value per Δt step (§9): subsampled static acceleration, averaged DBA.

    The sliding-window :math:`\bar{\mathbf a}` is subsampled at the centre sample of
    each consecutive block of k = round(fΔt) samples, and the per-sample DBA is
    averaged over the block. Trailing incomplete block dropped. ``time`` is the time of
    the centre sample (s, from the first sample or on the input's time axis).

    Parameters
    ----------
    acc, fs : array_like (N, 3), float
        As in :func:`dba`: the acceleration (a Recording, a labelled DataArray or a
        plain array with ``fs``) and its sampling rate.
    window_s : float
        Step duration Δt (s); k = round(fΔt) samples per step.

    Returns
    -------
    StepSummary
        ``time`` (N // k,) centre times (s; absolute times when the input is
        labelled), ``static`` (N // k, 3) static acceleration and ``dba`` (N // k,)
        mean DBA, both in the units of ``acc`` (DataArrays when the input is labelled).
    """
    s = _read_acc(acc, fs)
    a = s.values
    k = window_samples(window_s, s.fs)
    stat = _sliding_mean(a, k)
    d = np.linalg.norm(a - stat, axis=-1)
    nb = a.shape[0] // k
    centre = np.arange(nb) * k + k // 2
    mean_dba = d[: nb * k].reshape(nb, k).mean(axis=1)
    t = centre / s.fs
    if not s.labelled:
        return StepSummary(t, stat[centre], mean_dba)
    return StepSummary(
        start_time(s) + t,
        windowed(
            stat[centre],
            s,
            "static_acceleration",
            centre_s=t,
            fs_out=s.fs / k,
            units=s.units,
        ),
        windowed(mean_dba, s, "dba", centre_s=t, fs_out=s.fs / k, units=s.units),
    )
