r"""Small recipes built on the selection and error functions.

The parameters of a grid's
optimum, a method as a Recording → quaternions callable, the tilt difference between two
methods on one Recording, and per-sample errors pooled over several Recordings.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr

from .. import _deprecate
from .. import filters as F
from .errors import pairwise_tilt_rms, tilt_errors
from .selection import optimum

__all__ = ["best_params", "estimator", "tilt_difference_rms", "pooled_errors"]

# keyword arguments of filters.estimate that are not method parameters
_ESTIMATE_OPTIONS = ("use_mag", "gaps", "min_segment_s")


def best_params(scores: xr.DataArray, **where) -> dict[str, Any]:
    """Return the parameters of the all-recordings optimum of a grid, without its score.

    Parameters
    ----------
    scores : xarray.DataArray
        Scores over parameter dims and the recording dim (e.g. a :func:`grid_search`
        result with its other dims selected away).
    **where
        ``dim`` (the recording dimension, averaged over; default ``"recording"``) and
        ``params`` (dims to optimise over; default all but ``dim``), as for
        :func:`optimum`.

    Returns
    -------
    dict
        Parameter name → value minimising the mean score over ``dim``, ready to pass
        as ``filters.estimate(rec, method, **best_params(scores))``.

    See Also
    --------
    optimum : the same, with the minimal mean score as ``score``.

    Examples
    --------
    >>> import xarray as xr
    >>> scores = xr.DataArray(
    ...     [[3.0, 2.0], [1.0, 1.5], [2.0, 4.0]],
    ...     dims=("beta", "recording"),
    ...     coords={"beta": [0.01, 0.1, 1.0]},
    ... )
    >>> best_params(scores)
    {'beta': 0.1}
    """
    best = optimum(scores, **where)
    return {k: v for k, v in best.items() if k != "score"}


def estimator(method: str, /, **params) -> Callable[[xr.Dataset], xr.DataArray]:
    """Wrap a method with fixed parameters as a Recording → quaternions callable.

    The estimators of :func:`error_table` are such callables.

    Parameters
    ----------
    method : str
        A name of :data:`tiltlab.filters.METHODS`.
    **params
        Method parameters, and the options of :func:`tiltlab.filters.estimate`
        (``use_mag``, ``gaps``, ``min_segment_s``).

    Returns
    -------
    callable
        ``f(rec)`` returning ``filters.estimate(rec, method, **params)``.

    Raises
    ------
    ValueError
        An unknown method or parameter (at once, not when the callable runs).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import schema
    >>> rec = schema.make_recording(np.tile([0.0, 0.0, 1.0], (200, 1)), fs=50.0,
    ...                             acc_units="g")
    >>> f = estimator("lowpass", cutoff_hz=1.0)
    >>> f.__name__
    'lowpass(cutoff_hz=1)'
    >>> f(rec).attrs["param_cutoff_hz"]
    1.0
    """
    m = F.get_method(method)
    m.resolve({k: v for k, v in params.items() if k not in _ESTIMATE_OPTIONS})

    def run(rec: xr.Dataset) -> xr.DataArray:
        return F.estimate(rec, method, **params)

    shown = ", ".join(
        f"{k}={v:g}" if isinstance(v, (int, float)) else f"{k}={v!r}"
        for k, v in params.items()
    )
    run.__name__ = run.__qualname__ = f"{method}({shown})"
    run.__doc__ = f"``filters.estimate(rec, {method!r}, {shown})``."
    return run


def _mask(recording: xr.Dataset, mask) -> np.ndarray | None:
    if mask is None:
        return None
    if isinstance(mask, str):
        if mask not in recording:
            raise ValueError(
                f"the recording has no {mask!r} variable to select samples with; "
                "pass mask=None to use every sample"
            )
        return np.asarray(recording[mask].values, bool)
    return np.asarray(mask, bool)


@_deprecate.renamed(recording="rec")
def tilt_difference_rms(
    rec: xr.Dataset,
    method_a: str,
    method_b: str,
    *,
    mask: str | np.ndarray | None = "movement",
) -> float:
    r"""Compute the RMS tilt difference (degrees) between two methods on one Recording.

    Both run with their default parameters.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording both methods run on; not modified.
    method_a, method_b : str
        Names of :data:`tiltlab.filters.METHODS` (two different ones).
    mask : str, array_like of bool or None
        Samples compared: the name of a boolean variable of the Recording (default
        ``"movement"``, BROAD's scored samples), a boolean array over ``time``, or
        None for every sample.

    Returns
    -------
    float
        :math:`\sqrt{\overline{\delta^2}}` of the angle :math:`\delta` between the
        two estimated gravity directions over the masked samples
        (:func:`pairwise_tilt_rms`).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import schema
    >>> rec = schema.make_recording(np.tile([0.0, 0.0, 1.0], (500, 1)),
    ...                             np.zeros((500, 3)), fs=50.0, acc_units="g",
    ...                             gyr_units="deg/s")
    >>> round(tilt_difference_rms(rec, "lowpass", "madgwick", mask=None), 6)
    0.0
    """
    if method_a == method_b:
        raise ValueError(f"compare two different methods, got {method_a!r} twice")
    m = _mask(rec, mask)
    q = {name: F.estimate(rec, name) for name in (method_a, method_b)}
    rms = pairwise_tilt_rms(q, mask=m)
    return float(rms.sel(estimator=method_a, other=method_b))


def pooled_errors(
    recordings: Sequence[xr.Dataset] | Mapping[Any, xr.Dataset],
    method: str,
    params: Mapping[str, Any] | None = None,
    *,
    reference: str = "tilt_ref",
) -> np.ndarray:
    """Compute the per-sample tilt errors (degrees) of one method over Recordings.

    The Recordings are concatenated in order.

    Parameters
    ----------
    recordings : sequence or mapping of Recordings
        Each holds the ``reference`` variable (a mapping's values are used, in order).
    method : str
        A name of :data:`tiltlab.filters.METHODS`.
    params : mapping, optional
        Method parameters (default: the registry's defaults), e.g.
        :func:`best_params` of a grid search.
    reference : str
        The reference variable of each Recording: a gravity direction (``time``,
        ``axis``), such as the simulator's ``tilt_ref``, or quaternions such as
        ``q_ref`` (:func:`tilt_errors`).

    Returns
    -------
    numpy.ndarray
        1-D, the errors of every Recording's samples one after the other (NaN where
        the reference is missing), ready for :func:`table1`, :func:`binned_by_speed`
        or :func:`ecdf`.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import schema
    >>> up = np.tile([0.0, 0.0, 1.0], (200, 1))
    >>> rec = schema.make_recording(up, fs=50.0, acc_units="g",
    ...                             extra={"tilt_ref": (("time", "axis"), up, {})})
    >>> e = pooled_errors([rec, rec], "lowpass", {"cutoff_hz": 2.0})
    >>> e.shape, bool(np.nanmax(e) < 1e-6)
    ((400,), True)
    """
    recs = list(recordings.values() if isinstance(recordings, Mapping) else recordings)
    if not recs:
        raise ValueError("recordings must not be empty")
    run = estimator(method, **dict(params or {}))
    for i, rec in enumerate(recs):
        if reference not in rec:
            raise ValueError(f"recording {i} has no {reference!r} reference variable")
    return np.concatenate([tilt_errors(run(rec), rec[reference]) for rec in recs])
